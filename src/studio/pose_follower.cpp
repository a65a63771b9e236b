#include "drape/studio/pose_follower.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/motion/interpolate.hpp"

namespace drape::studio {
namespace {

/// Where `joints` (the stream's) and the avatar's differ, or "".
std::string jointMismatch(const scene::Avatar& avatar, const std::vector<std::string>& joints) {
  if (joints.size() != avatar.joints.size())
    return fmt::format("{} joints, where avatar '{}' has {}", joints.size(), avatar.name, avatar.joints.size());
  for (std::size_t j = 0; j < joints.size(); ++j)
    if (joints[j] != avatar.joints[j].name)
      return fmt::format("joint {} '{}', where avatar '{}' has '{}'", j, joints[j], avatar.name, avatar.joints[j].name);
  return "";
}

}  // namespace

void PoseFollower::followNextTake(const scene::Avatar& avatar, double rate, const std::string& take) {
  for (;;) {
    std::optional<Message> m = pending_ ? std::move(pending_) : stream_.next("a take's poses");
    pending_.reset();
    const auto* start = std::get_if<PoseStart>(&m->payload);
    if (start == nullptr || (!take.empty() && m->take != take)) continue;  // an earlier take's frames
    if (const std::string bad = jointMismatch(avatar, start->joints); !bad.empty())
      throw Error(fmt::format("pose take {} from '{}' moves {}: the anim-server plays another avatar than this scene's",
                              m->take, stream_.source(), bad));
    if (start->start.rate != rate)
      throw Error(fmt::format("pose take {} from '{}' plays {:g} frames per second, the scene {:g}: give both the same "
                              "scene (its Simulation frameRate)",
                              m->take, stream_.source(), start->start.rate, rate));
    take_ = m->take;
    start_ = *start;
    animation_.emplace(motion::AvatarAnimation::streamed(avatar.joints.size(), rate, start->start, start->driving));
    wind_.clear();
    ended_ = false;
    filled_ = skipped_ = 0;
    spdlog::info("following pose take {} from '{}': {} at {:g} Hz from {}{}", take_, stream_.source(), start->character, rate,
                 start->start.smpte(), start->frames > 0 ? fmt::format(", {} frames", start->frames) : std::string());
    return;
  }
}

void PoseFollower::add(const PoseFrame& frame) {
  const auto have = static_cast<std::int64_t>(animation_->frameCount());
  if (frame.frame < have) {
    ++skipped_;
    spdlog::debug("pose take {}: frame {} again; dropped", take_, frame.frame);
    return;
  }
  if (frame.joints.size() != start_.joints.size()) {
    ++skipped_;
    spdlog::warn("pose take {}: frame {} has {} joints, the take {}; skipped", take_, frame.frame, frame.joints.size(),
                 start_.joints.size());
    return;
  }
  if (frame.frame > have) {
    // Frames that never came: in between the last one and this, as the micro-interpolation
    // would take them (frame 0 missing: this frame held from the start).
    spdlog::warn("pose take {}: frames {} to {} never came; filled in between their neighbours", take_, have,
                 frame.frame - 1);
    std::vector<RigidTransform> fill(frame.joints.size());
    for (std::int64_t f = have; f < frame.frame; ++f) {
      const double s = have == 0 ? 1.0 : static_cast<double>(f - have + 1) / static_cast<double>(frame.frame - have + 1);
      for (std::size_t j = 0; j < fill.size(); ++j)
        fill[j] = have == 0 ? frame.joints[j]
                            : motion::interpolate(animation_->frame(static_cast<std::size_t>(have - 1))[j], frame.joints[j], s);
      animation_->appendFrame(fill);
      wind_.push_back(frame.wind);
      ++filled_;
    }
  }
  animation_->appendFrame(frame.joints);
  wind_.push_back(frame.wind);
}

bool PoseFollower::waitForFrames(std::int64_t count) {
  while (!ended_ && static_cast<std::int64_t>(animation_->frameCount()) < count) {
    std::optional<Message> m = stream_.next(fmt::format("pose frame {} of take {}", animation_->frameCount(), take_));
    if (std::holds_alternative<PoseStart>(m->payload)) {
      if (m->take == take_) continue;  // the same take announced again (a restarted anim-server)
      pending_ = std::move(m);
      throw NewTake(fmt::format("the pose stream '{}' started take {} before take {} ended (after {} frames)", stream_.source(),
                                pending_->take, take_, animation_->frameCount()));
    }
    if (m->take != take_) {
      ++skipped_;
      continue;
    }
    if (const auto* frame = std::get_if<PoseFrame>(&m->payload)) {
      add(*frame);
    } else if (const auto* end = std::get_if<End>(&m->payload)) {
      ended_ = true;
      if (!end->error.empty()) spdlog::warn("pose take {} ended early: {}", take_, end->error);
      if (animation_->frameCount() == 0)
        throw Error(fmt::format("pose take {} from '{}' ended without a frame", take_, stream_.source()));
    } else {
      ++skipped_;
      spdlog::warn("pose take {}: a {} on the pose stream; skipped", take_, describe(m->payload));
    }
  }
  return static_cast<std::int64_t>(animation_->frameCount()) >= count;
}

}  // namespace drape::studio
