#include "drape/core/progress.hpp"

#include <unistd.h>

#include <cstdio>

namespace drape {

Progress::Progress(std::string label, std::int64_t total)
    : label_(std::move(label)),
      total_(total),
      enabled_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      lastDraw_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::int64_t done) {
  if (!enabled_) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (elapsed < 1.0 || (shown_ && now - lastDraw_ < std::chrono::milliseconds(100))) return;
  lastDraw_ = now;
  shown_ = true;
  if (total_ <= 0) {  // a live run: how far it has come, with no end known
    std::fprintf(stderr, "\r%s: %lld, %.1fs elapsed   ", label_.c_str(), static_cast<long long>(done), elapsed);
    std::fflush(stderr);
    return;
  }
  const double fraction = static_cast<double>(done) / static_cast<double>(total_);
  const double eta = fraction > 0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "\r%s: %lld/%lld (%3.0f%%) %.1fs elapsed, ~%.1fs left   ", label_.c_str(),
               static_cast<long long>(done), static_cast<long long>(total_), 100.0 * fraction,
               elapsed, eta);
  std::fflush(stderr);
}

void Progress::finish() {
  if (shown_) {
    std::fprintf(stderr, "\n");
    shown_ = false;
  }
  enabled_ = false;
}

}  // namespace drape
