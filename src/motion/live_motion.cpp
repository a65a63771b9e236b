#include "drape/motion/live_motion.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/motion/interpolate.hpp"
#include "drape/motion/standing.hpp"

namespace drape::motion {
namespace {

constexpr std::size_t kTPoseTestFrames = 3;  // firstFrameIsReferenceTPose compares frames 0, 1 and 2

// The header as a clip of no frames: its skeleton in metres and the units report, exactly as
// loadClip makes them for the whole file.
Clip headerClip(const formats::BvhFile& header, const ClipLoadOptions& options, ClipLoadReport& report) {
  formats::BvhFile empty = header;
  empty.frameCount = 0;
  empty.values.clear();
  ClipLoadOptions o = options;
  o.skipRestUnfold = false;
  return clipFromBvh(empty, o, &report);
}

}  // namespace

LiveMotion::LiveMotion(const scene::Avatar& avatar, const formats::BvhFile& header, const MotionOptions& options)
    : header_(header),
      options_(options),
      opening_(headerClip(header, options.clip, report_)),
      map_(jointMapFor(opening_, avatar, options)),
      retargeter_(avatar, opening_.skeleton, map_, options.retarget, header.source) {
  header_.values = {};  // the frames come by push()
  scale_ = options.clip.metresPerUnit.value_or(report_.units.metresPerUnit);
  sourceRate_ = 1.0 / header.frameTime;
  resampling_ = options.clip.rate > 0.0 && std::abs(options.clip.rate - sourceRate_) > 1e-9 * sourceRate_;
  rate_ = resampling_ ? options.clip.rate : sourceRate_;
  opening_.rate = sourceRate_;
  opened_ = !options.clip.skipReferenceTPose;
  const std::size_t n = header.joints.size();
  converted_.local.resize(n);
  previous_.local.resize(n);
  current_.local.resize(n);
}

void LiveMotion::push(std::span<const double> values) {
  if (values.size() != header_.channelCount)
    throw Error(fmt::format("a frame of {} values for a motion of {} channels", values.size(), header_.channelCount),
                ExitCode::Internal);
  ++pushed_;
  bvhFramePose(header_, values.data(), converted_.local, converted_.root);
  // Stood up as the header's skeleton was (a capture standing along +z).
  if (report_.standingAxis != "+y") turnPose(converted_.local, converted_.root, report_.standingTurn);
  converted_.root *= scale_;
  if (opened_) {
    accept(converted_);
    return;
  }
  opening_.rotations.insert(opening_.rotations.end(), converted_.local.begin(), converted_.local.end());
  opening_.rootTranslations.push_back(converted_.root);
  if (opening_.frameCount() < kTPoseTestFrames) return;
  // Three frames: a reference T-pose first is dropped, as loading the whole file drops it.
  tposeSkipped_ = firstFrameIsReferenceTPose(opening_);
  acceptOpening(tposeSkipped_ ? 1 : 0);
}

void LiveMotion::acceptOpening(std::size_t from) {
  opened_ = true;
  SourcePose pose;
  for (std::size_t f = from; f < opening_.frameCount(); ++f) {
    const auto r = opening_.frameRotations(f);
    pose.local.assign(r.begin(), r.end());
    pose.root = opening_.rootTranslations[f];
    accept(pose);
  }
  opening_.rotations.clear();
  opening_.rootTranslations.clear();
}

void LiveMotion::finish() {
  if (!opened_) acceptOpening(0);  // fewer than three frames: no T-pose test, as for so short a file
  if (accepted_ == 0 || !resampling_) return;
  emitUpTo(static_cast<double>(accepted_ - 1), true);
}

void LiveMotion::accept(const SourcePose& pose) {
  std::swap(previous_, current_);
  current_.local = pose.local;
  current_.root = pose.root;
  ++accepted_;
  if (!resampling_) {
    emit(current_, current_, 0.0);  // the motion rate already: each frame as it comes
    return;
  }
  emitUpTo(static_cast<double>(accepted_ - 1), false);
}

// resample()'s frames k as far as source frame `lastIndex` makes them: while streaming,
// those whose two source frames have come (floor(u) + 1 <= lastIndex); at the end, the rest
// up to the file's count, u clamped to the last frame, in resample()'s arithmetic.
void LiveMotion::emitUpTo(double lastIndex, bool ending) {
  const auto last = static_cast<std::size_t>(lastIndex);
  for (;;) {
    const double k = static_cast<double>(emitted_);
    if (ending && k > std::floor(lastIndex * rate_ / sourceRate_ + 1e-9)) return;
    const double u = ending ? std::min(k * sourceRate_ / rate_, lastIndex) : k * sourceRate_ / rate_;
    const auto i = static_cast<std::size_t>(std::floor(u));
    if (!ending && i + 1 > last) return;
    const double s = u - static_cast<double>(i);
    // Only source frames last - 1 and last are kept: frame i is one of them.
    emit(i == last ? current_ : previous_, current_, s);
  }
}

void LiveMotion::emit(const SourcePose& a, const SourcePose& b, double s) {
  ++emitted_;
  const std::size_t n = a.local.size();
  local_.resize(n);
  for (std::size_t j = 0; j < n; ++j) local_[j] = resampling_ ? slerp(a.local[j], b.local[j], s) : a.local[j];
  const Vec3 root = resampling_ ? Vec3((1.0 - s) * a.root + s * b.root) : a.root;
  std::vector<RigidTransform> world;
  if (!spare_.empty()) {
    world = std::move(spare_.back());
    spare_.pop_back();
  }
  world.resize(retargeter_.jointCount());
  retargeter_.retarget(local_, root, world);
  if (options_.retarget.groundFeet) ground(world);
  ready_.push_back(std::move(world));
}

// Grounding over trailing windows: build()'s two one-second windows (the lowest point's
// minimum, then its mean), each ending at this frame instead of centred on it.
void LiveMotion::ground(std::vector<RigidTransform>& world) {
  if (!retargeter_.hasGroundSamples()) return;
  const std::size_t width = 2 * groundHalfWindow(rate_) + 1;
  lowest_.push_back(retargeter_.lowestAboveFloor(world));
  if (lowest_.size() > width) lowest_.pop_front();
  window_.push_back(*std::min_element(lowest_.begin(), lowest_.end()));
  if (window_.size() > width) window_.pop_front();
  double sum = 0.0;
  for (const double w : window_) sum += w;
  const double correction = sum / static_cast<double>(window_.size());
  for (RigidTransform& t : world) t.translation.y() -= correction;
}

bool LiveMotion::next(std::span<RigidTransform> out) {
  if (ready_.empty()) return false;
  std::copy(ready_.front().begin(), ready_.front().end(), out.begin());
  spare_.push_back(std::move(ready_.front()));
  ready_.pop_front();
  return true;
}

}  // namespace drape::motion
