#include "live_run.hpp"

#include <algorithm>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/studio/takes.hpp"

namespace drape::cli {

void prepareLiveRun(const RunSetup& setup, CharacterSetup& character) {
  if (!character.keepApart.empty())
    buildPartFieldsOnce(setup, character, fmt::format("to keep {} apart", fmt::join(character.keepApart, ", ")));
}

LiveRun::LiveRun(RunSetup& setup, CharacterSetup& character, LiveCapture& capture, long maxFrames)
    : capture_(capture),
      joints_(capture.motion().jointCount()),
      frameRate_(setup.settings.frameRate_hz),
      leadIn_s_(character.leadIn_s),
      maxFrames_(maxFrames) {
  const motion::LiveMotion& live = capture.motion();
  const std::span<const int> driving = live.drivingJoint();
  animation_ = std::make_shared<motion::AvatarAnimation>(motion::AvatarAnimation::streamed(
      live.jointCount(), live.rate(), TimeCode{0, live.rate()}, std::vector<int>(driving.begin(), driving.end())));
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

std::vector<std::pair<std::size_t, std::string>> liveSources(const RunSetup& setup,
                                                             const std::vector<std::string>& options) {
  std::vector<std::pair<std::size_t, std::string>> out;
  for (const std::string& option : options) {
    const std::optional<std::pair<std::size_t, std::string>> named = forCharacter(setup, option, "--live");
    if (!named) {
      if (setup.characters.size() > 1)
        throw Error(fmt::format("--live {}: the scene has {} characters ({}): say which the capture moves, --live "
                                "NAME=SOURCE",
                                option, setup.characters.size(), characterNames(setup)));
      if (!out.empty()) throw Error(fmt::format("--live {}: the scene's one character has a source already", option));
      out.emplace_back(0, option);
      continue;
    }
    for (const auto& [c, source] : out)
      if (c == named->first)
        throw Error(fmt::format("--live {}: {} has a source already ({})", option, setup.characters[c].name, source));
    out.push_back(*named);
  }
  const auto stdins = std::count_if(out.begin(), out.end(), [](const auto& s) { return s.second == "-"; });
  if (stdins > 1) throw Error("--live: standard input (-) is one source; give the others theirs");
  return out;
}

void addMotionsOfTheOthers(RunSetup& setup, const std::vector<std::pair<std::size_t, std::string>>& sources,
                           const std::string& scenePath, double metresPerUnit, const std::string& jointMap) {
  for (std::size_t c = 0; c < setup.characters.size(); ++c) {
    CharacterSetup& character = setup.characters[c];
    const bool live = std::any_of(sources.begin(), sources.end(), [c](const auto& s) { return s.first == c; });
    if (live || character.motion.empty()) continue;
    const MotionChoice m = sceneMotion(setup, &character, scenePath, character.motion, "");
    addMotion(setup, character, m.path, metresPerUnit, jointMap, m.animation, m.sampled.get());
  }
}

LiveCast::LiveCast(RunSetup& setup, const std::vector<std::pair<std::size_t, std::string>>& sources,
                   const Options& options, const motion::MotionOptions& motion, const std::atomic<bool>& stop)
    : several_(sources.size() > 1) {
  for (const auto& [c, source] : sources) prepareLiveRun(setup, setup.characters[c]);
  for (const auto& [c, source] : sources) {
    Member& m = members_.emplace_back();
    m.character = setup.characters[c].name;
    m.capture = std::make_unique<LiveCapture>(
        *setup.characters[c].avatar, LiveCapture::Options{source, options.headerFile, std::chrono::seconds(5), options.giveUp},
        motion, stop);
  }
  for (std::size_t k = 0; k < sources.size(); ++k)
    members_[k].run =
        std::make_unique<LiveRun>(setup, setup.characters[sources[k].first], *members_[k].capture, options.maxFrames);
}

bool LiveCast::admit(long frame) {
  for (Member& m : members_)
    if (!m.run->admit(frame)) return false;
  return true;
}

double LiveCast::lag_s() const {
  double lag = 0.0;
  for (const Member& m : members_) lag = std::max(lag, m.run->lag_s());
  return lag;
}

bool LiveCast::silent() const {
  return std::any_of(members_.begin(), members_.end(), [](const Member& m) { return m.capture->silent(); });
}

std::vector<std::string> LiveCast::summary() const {
  std::vector<std::string> lines;
  for (const Member& m : members_) {
    const LiveCapture& c = *m.capture;
    const std::string ended = c.ended();
    lines.push_back(fmt::format(
        "live: {} motion frames{} from {} ({} source frames{}){}", m.run->motionFrames(),
        several_ ? " of " + m.character : std::string(), c.name(), c.motion().sourceFrames(),
        c.badLines() > 0 ? fmt::format(", {} bad line{}", c.badLines(), c.badLines() == 1 ? "" : "s") : std::string(),
        ended.empty() ? "" : "; " + ended));
  }
  return lines;
}

void LiveCast::logKeptApart() const {
  for (const Member& m : members_)
    if (m.capture->keptApart()) cli::logKeptApart(m.capture->keptApart()->report());
}

std::string LiveCast::names() const {
  std::vector<std::string> names;
  for (const Member& m : members_) names.push_back(m.capture->name());
  return fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace drape::cli
