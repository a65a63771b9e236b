#pragma once
// A progress line for long work (simulation runs, field builds, renders). It shows only
// when standard error is a terminal and the work has run longer than a second, so logs,
// CI and tests stay clean.

#include <chrono>
#include <cstdint>
#include <string>

namespace drape {

class Progress {
 public:
  /// `total` 0: no end known (a live run): it counts what is done.
  Progress(std::string label, std::int64_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Reports that `done` of `total` units are complete; cheap enough to call every frame.
  void update(std::int64_t done);
  /// Ends the line (called by the destructor too).
  void finish();

 private:
  std::string label_;
  std::int64_t total_;
  bool enabled_;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point lastDraw_;
};

}  // namespace drape
