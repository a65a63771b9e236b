#include "live_run.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/takes.hpp"

namespace drape::cli {

void prepareLiveRun(RunSetup& setup) {
  CharacterSetup* character = oneCharacter(setup, "--live (a live capture)");
  if (character && !character->keepApart.empty())
    buildPartFieldsOnce(setup, *character, fmt::format("to keep {} apart", fmt::join(character->keepApart, ", ")));
}

LiveRun::LiveRun(RunSetup& setup, LiveCapture& capture, long maxFrames)
    : capture_(capture),
      joints_(capture.motion().jointCount()),
      frameRate_(setup.settings.frameRate_hz),
      leadIn_s_(oneCharacter(setup, "--live (a live capture)")->leadIn_s),
      maxFrames_(maxFrames) {
  const motion::LiveMotion& live = capture.motion();
  const std::span<const int> driving = live.drivingJoint();
  animation_ = std::make_shared<motion::AvatarAnimation>(motion::AvatarAnimation::streamed(
      live.jointCount(), live.rate(), TimeCode{0, live.rate()}, std::vector<int>(driving.begin(), driving.end())));
  CharacterSetup& character = *oneCharacter(setup, "--live (a live capture)");
  // The capture keeps the parts apart on its way in, so the world is given the motion
  // corrected and keeps nothing apart itself.
  if (std::shared_ptr<sim::LiveKeepApart> keep = liveKeepApart(setup, character, live.rate())) {
    capture.keepApart(keep);
    lag_s_ = static_cast<double>(keep->delay()) / live.rate();
    character.liveKeptApart = std::move(keep);
    character.keepApart.clear();
  }
  character.animation = animation_;
  setup.motionStreamed = true;
  setup.frames = maxFrames;
  if (!waitForFrames(1))
    throw Error(fmt::format("{} ended before its first frame{}", capture.name(),
                            capture.ended().empty() ? "" : " (" + capture.ended() + ")"),
                ExitCode::Unavailable);
  spdlog::info("live motion from {} ({} joints at {:g} Hz in {}, joint map '{}') on {} at {:g} Hz, simulated as it comes",
               capture.name(), capture.header().joints.size(), live.sourceRate(), live.report().units.name,
               live.jointMap().name, character.avatar->name, live.rate());
}

bool LiveRun::waitForFrames(std::int64_t count) {
  while (!ended_ && motionFrames() < count) {
    if (capture_.next(joints_)) animation_->appendFrame(joints_);
    else ended_ = true;
  }
  return motionFrames() >= count;
}

bool LiveRun::admit(long frame) {
  if (maxFrames_ > 0 && frame > maxFrames_) return false;
  if (frame == 0) return true;  // its motion frame came before the world was built
  const double motionRate = animation_->rate();
  if (waitForFrames(studio::motionFramesNeeded(frame, frameRate_, leadIn_s_, motionRate))) return true;
  // The capture ended: the frames up to its last motion frame's time are still simulated.
  return frame <= studio::clothFramesOf(motionFrames(), frameRate_, leadIn_s_, motionRate);
}

}  // namespace drape::cli
