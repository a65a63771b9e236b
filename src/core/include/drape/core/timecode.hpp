#pragma once
// Time codes: a frame number at a frame rate, printable as SMPTE HH:MM:SS:FF.
// Every frame that leaves the simulation (cloth, pose) carries one.

#include <cstdint>
#include <string>

namespace drape {

struct TimeCode {
  std::int64_t frame = 0;  ///< frame number from the start of the take
  double rate = 30.0;      ///< frames per second

  [[nodiscard]] double seconds() const { return static_cast<double>(frame) / rate; }
  /// SMPTE non-drop-frame "HH:MM:SS:FF" (rate rounded to whole frames per second); a
  /// frame before 0 as "-HH:MM:SS:FF" before it.
  [[nodiscard]] std::string smpte() const;
  /// Parses "HH:MM:SS:FF" (or "-HH:MM:SS:FF", as smpte() prints a frame before 0) at the
  /// given rate; throws drape::Error on malformed text.
  [[nodiscard]] static TimeCode parseSmpte(const std::string& text, double rate);
  /// The time of day on this machine's clock (local time, from midnight) as a time code at
  /// `rate`: what a studio's time-of-day time code reads now.
  [[nodiscard]] static TimeCode timeOfDay(double rate);
  /// A command line's time code: "now" (timeOfDay) or HH:MM:SS:FF, as parseSmpte.
  [[nodiscard]] static TimeCode parseOption(const std::string& text, double rate);
};

}  // namespace drape
