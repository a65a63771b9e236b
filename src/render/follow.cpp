#include "drape/render/follow.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/render/run_replay.hpp"

namespace drape::render {
namespace {

/// The horizontal half size a square box centred at (x, z) needs to hold `box`.
double halfWidthFor(const Aabb& box, double x, double z) {
  return std::max({x - box.min.x(), box.max.x() - x, z - box.min.z(), box.max.z() - z});
}

}  // namespace

std::vector<Aabb> followFraming(const std::vector<Aabb>& frameBoxes, double frameRate, double window_s) {
  if (!(frameRate > 0) || !std::isfinite(frameRate))
    throw Error(fmt::format("follow camera: frame rate {} is not positive", frameRate));
  const auto first = std::find_if(frameBoxes.begin(), frameBoxes.end(), [](const Aabb& b) { return !b.empty(); });
  if (first == frameBoxes.end()) throw Error("follow camera: no frame has anything to frame");

  // Every frame gets a box: an empty one takes the last non-empty one before it.
  std::vector<Aabb> boxes(frameBoxes.size());
  Aabb last = *first;
  for (std::size_t i = 0; i < frameBoxes.size(); ++i) boxes[i] = last = frameBoxes[i].empty() ? last : frameBoxes[i];

  const std::size_t n = boxes.size();
  // Prefix sums of the centres: each window's mean in constant time.
  std::vector<double> sumX(n + 1, 0.0), sumZ(n + 1, 0.0);
  double minY = boxes[0].min.y(), maxY = boxes[0].max.y();
  for (std::size_t i = 0; i < n; ++i) {
    sumX[i + 1] = sumX[i] + boxes[i].center().x();
    sumZ[i + 1] = sumZ[i] + boxes[i].center().z();
    minY = std::min(minY, boxes[i].min.y());
    maxY = std::max(maxY, boxes[i].max.y());
  }
  const auto reach = static_cast<std::size_t>(std::max(0.0, std::round(0.5 * window_s * frameRate)));
  std::vector<double> centreX(n), centreZ(n);
  double halfWidth = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // Symmetric about i, narrowed at the ends: a steady motion's mean is its own centre.
    const std::size_t h = std::min({reach, i, n - 1 - i});
    const double count = static_cast<double>(2 * h + 1);
    centreX[i] = (sumX[i + h + 1] - sumX[i - h]) / count;
    centreZ[i] = (sumZ[i + h + 1] - sumZ[i - h]) / count;
    halfWidth = std::max(halfWidth, halfWidthFor(boxes[i], centreX[i], centreZ[i]));
  }
  std::vector<Aabb> framing(n);
  for (std::size_t i = 0; i < n; ++i) {
    framing[i].min = Vec3(centreX[i] - halfWidth, minY, centreZ[i] - halfWidth);
    framing[i].max = Vec3(centreX[i] + halfWidth, maxY, centreZ[i] + halfWidth);
  }
  return framing;
}

std::vector<Aabb> followFraming(const RunReplay& replay) {
  std::vector<Aabb> boxes;
  for (std::int64_t i = 0; i < replay.frameCount().value_or(0); ++i) boxes.push_back(replay.frameBounds(i));
  return followFraming(boxes, replay.frameRate());
}

Aabb FollowCamera::update(const Aabb& frameBox, double dt_s) {
  if (frameBox.empty()) return framing_;
  const Vec3 c = frameBox.center();
  if (!started_) {
    started_ = true;
    centreX_ = c.x();
    centreZ_ = c.z();
    minY_ = frameBox.min.y();
    maxY_ = frameBox.max.y();
  } else {
    const double ease = timeConstant_s_ > 0 ? 1.0 - std::exp(-std::max(0.0, dt_s) / timeConstant_s_) : 1.0;
    centreX_ += ease * (c.x() - centreX_);
    centreZ_ += ease * (c.z() - centreZ_);
    minY_ = std::min(minY_, frameBox.min.y());
    maxY_ = std::max(maxY_, frameBox.max.y());
  }
  halfWidth_ = std::max(halfWidth_, halfWidthFor(frameBox, centreX_, centreZ_));
  framing_ = frame();
  return framing_;
}

Aabb FollowCamera::frame() const {
  Aabb box;
  box.min = Vec3(centreX_ - halfWidth_, minY_, centreZ_ - halfWidth_);
  box.max = Vec3(centreX_ + halfWidth_, maxY_, centreZ_ + halfWidth_);
  return box;
}

}  // namespace drape::render
