#include "drape/core/timecode.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <cstdio>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape {

std::string TimeCode::smpte() const {
  const auto fps = std::max<std::int64_t>(1, std::llround(rate));
  // Before the take's start (a studio's lead-in): the time to go, signed.
  const std::int64_t f = frame < 0 ? -frame : frame;
  const std::int64_t ff = f % fps;
  const std::int64_t totalSeconds = f / fps;
  return fmt::format("{}{:02}:{:02}:{:02}:{:02}", frame < 0 ? "-" : "", totalSeconds / 3600, (totalSeconds / 60) % 60,
                     totalSeconds % 60, ff);
}

TimeCode TimeCode::parseSmpte(const std::string& text, double rate) {
  int h = 0, m = 0, s = 0, f = 0;
  char tail = 0;
  const bool before = !text.empty() && text.front() == '-';  // as smpte() prints a frame before 0
  const char* digits = text.c_str() + (before ? 1 : 0);
  if (std::sscanf(digits, "%d:%d:%d:%d%c", &h, &m, &s, &f, &tail) != 4 || digits[0] == '-' || digits[0] == '+' || h < 0 || m < 0 ||
      m > 59 || s < 0 || s > 59 || f < 0 || f >= std::llround(rate)) {
    throw Error(fmt::format("time code '{}': expected HH:MM:SS:FF at {} frames/s", text, rate));
  }
  const auto fps = std::llround(rate);
  const std::int64_t frame = ((static_cast<std::int64_t>(h) * 60 + m) * 60 + s) * fps + f;
  return TimeCode{before ? -frame : frame, rate};
}

TimeCode TimeCode::timeOfDay(double rate) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t seconds = std::chrono::system_clock::to_time_t(now);
  std::tm local{};
  localtime_r(&seconds, &local);
  const double sinceMidnight =
      (local.tm_hour * 60.0 + local.tm_min) * 60.0 + local.tm_sec +
      std::chrono::duration<double>(now - std::chrono::system_clock::from_time_t(seconds)).count();
  const auto fps = std::max<std::int64_t>(1, std::llround(rate));
  return TimeCode{static_cast<std::int64_t>(std::floor(sinceMidnight * static_cast<double>(fps))), rate};
}

TimeCode TimeCode::parseOption(const std::string& text, double rate) {
  return text == "now" ? timeOfDay(rate) : parseSmpte(text, rate);
}

}  // namespace drape
