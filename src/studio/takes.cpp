#include "drape/studio/takes.hpp"

#include <chrono>
#include <cmath>
#include <ctime>
#include <random>

#include <fmt/format.h>

namespace drape::studio {

std::string newTakeId() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  std::random_device device;
  return fmt::format("{:04d}{:02d}{:02d}T{:02d}{:02d}{:02d}Z-{:04x}", utc.tm_year + 1900, utc.tm_mon + 1, utc.tm_mday,
                     utc.tm_hour, utc.tm_min, utc.tm_sec, device() & 0xffffu);
}

std::string messageId(const std::string& take, const char* kind, std::int64_t frame, std::int64_t garment) {
  return garment < 0 ? fmt::format("{}.{}.{}", take, kind, frame) : fmt::format("{}.{}.{}.{}", take, kind, frame, garment);
}

std::int64_t motionFramesNeeded(std::int64_t clothFrame, double clothRate, double leadIn_s, double motionRate) {
  const double motionTime = static_cast<double>(clothFrame) / clothRate - leadIn_s;
  if (motionTime < 0.0) return 1;  // the lead-in blends into frame 0
  // The frame at the end of the cloth frame and the one after it; a millionth of a frame
  // more, so that a substep whose time rounds a little past a frame finds its neighbour.
  return static_cast<std::int64_t>(std::floor(motionTime * motionRate + 1e-6)) + 2;
}

std::int64_t clothFramesOf(std::int64_t motionFrames, double clothRate, double leadIn_s, double motionRate) {
  const double duration = motionFrames > 1 ? static_cast<double>(motionFrames - 1) / motionRate : 0.0;
  return static_cast<std::int64_t>(std::ceil((leadIn_s + duration) * clothRate));
}

TimeCode clothTimeCode(std::int64_t clothFrame, const TimeCode& poseStart, double leadIn_s) {
  const auto leadInFrames = static_cast<std::int64_t>(std::llround(leadIn_s * poseStart.rate));
  return TimeCode{poseStart.frame + clothFrame - leadInFrames, poseStart.rate};
}

}  // namespace drape::studio
