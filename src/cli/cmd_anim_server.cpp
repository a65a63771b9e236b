// `drape anim-server SCENE [--motion FILE]`: the studio's animation server (docs/STUDIO.md).
// Plays the scene avatar's motion, retargeted as drape run retargets it, into a pose stream
// on a NATS JetStream server: one take, frame by frame at the scene's frame rate.

#include <atomic>
#include <chrono>
#include <deque>
#include <csignal>
#include <list>
#include <optional>
#include <span>
#include <vector>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/core/progress.hpp"
#include "drape/events/runtime.hpp"
#include "drape/motion/live_motion.hpp"
#include "drape/studio/publisher.hpp"
#include "drape/studio/takes.hpp"
#include "live_capture.hpp"
#include "live_run.hpp"
#include "run_setup.hpp"
#include "stop_signal.hpp"
#include "studio_options.hpp"

namespace drape::cli {
namespace {

struct AnimServerOptions {
  std::string scene, motion, animation, name = "anim", take, events, live, liveHeader;
  std::string timecode;  ///< --timecode: motion frame 0's time code, HH:MM:SS:FF or now
  std::string character;  ///< --character: which of the scene's characters it plays
  std::vector<std::string> sets;
  long frames = 0;
  bool fast = false, hold = false;
  StudioOptions studio;
};

/// Set by SIGINT and SIGTERM (stopOnSignals()): a live take ends at the next frame, with its End sent.
const std::atomic<bool>& stopAsked = detail::stopAsked;

/// The time code of the take's motion frame 0: --timecode's (now: the time of day), else `own`.
TimeCode takeStart(const AnimServerOptions& o, TimeCode own) {
  return o.timecode.empty() ? own : TimeCode::parseOption(o.timecode, own.rate);
}

/// What the take calls the character it moves: the scene's name for it, --character's, or in a
/// scene of one its avatar's.
std::string whoOf(const AnimServerOptions& o, const scene::Avatar& avatar) {
  return o.character.empty() ? avatar.name : o.character;
}

/// A pose take's first message: the character and its joints (every frame lists them in
/// this order), the motion joints driving them, and how the frames are numbered (`frames`
/// 0: not known ahead, a live take).
studio::PoseStart poseStart(const std::string& character, const scene::Avatar& avatar, std::span<const int> driving,
                            TimeCode start, std::int64_t frames) {
  studio::PoseStart p;
  p.character = character;
  for (const scene::Joint& j : avatar.joints) p.joints.push_back(j.name);
  p.driving.assign(driving.begin(), driving.end());
  p.start = start;
  p.frames = frames;
  return p;
}

/// What an Inject asks of a live take: a graph started at once, an event sent; the answer.
studio::InjectReply injected(const studio::Inject& in, long frame, events::Scheduler& scheduler,
                             events::Motions& motions, std::list<events::Graph>& graphs,
                             const motion::MotionOptions& options) {
  std::vector<std::string> done;
  try {
    if (!in.graph.empty()) {
      events::Graph g = events::parseGraph(in.graph, fmt::format("graph injected at frame {}", frame), in.baseDir);
      motions.load(g, scheduler.actors(), options);
      graphs.push_back(std::move(g));
      scheduler.start(graphs.back(), motions);
      done.push_back(fmt::format("started graph{} at frame {}",
                                 graphs.back().name.empty() ? "" : " '" + graphs.back().name + "'", frame));
    }
    if (!in.event.empty()) {
      scheduler.send(in.event);
      done.push_back(fmt::format("sent event '{}' at frame {}", in.event, frame));
    }
  } catch (const Error& e) {
    return {false, e.what()};
  }
  if (done.empty()) return {false, "the request asks for nothing (give a graph or an event)"};
  spdlog::info("{}", fmt::join(done, "; "));
  return {true, fmt::format("{}", fmt::join(done, "; "))};
}

/// `--events`: plays an event graph live, frame by frame, taking graphs and events injected
/// while it runs (drape inject). The graph runs for every character of the scene (`cast`),
/// so that what one character's events wait for takes the time it takes in drape run, and the
/// take carries `character`'s poses.
int runEventGraph(const AnimServerOptions& o, RunSetup& setup, CharacterSetup& character,
                  const std::vector<CharacterSetup>& cast) {
  const scene::Avatar& avatar = *character.avatar;
  const double rate = setup.settings.frameRate_hz;
  // Kept apart as drape run keeps a graph's motion apart: each frame goes out the
  // correction's delay after its tick, so an injection shows that much later too.
  const std::shared_ptr<sim::LiveKeepApart> keep = liveKeepApart(setup, character, rate);
  const motion::MotionOptions mo = motionOptions(setup);
  std::list<events::Graph> graphs;
  graphs.push_back(events::readGraph(o.events));
  const std::vector<events::Actor> actors = eventActors(cast);
  std::size_t actor = 0;
  while (actor + 1 < cast.size() && cast[actor].name != character.name) ++actor;
  events::Motions motions;
  motions.load(graphs.back(), actors, mo);
  events::Scheduler scheduler(actors, rate, parameterOptions(o.sets));
  scheduler.start(graphs.back(), motions);

  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape anim-server " + o.name);
  studio::Publisher publisher(bus, o.name, studio::Precision::Double, o.studio.giveUp());
  studio::Listener requests = bus.listen(studio::requestSubjectOf(o.name));
  const std::string take = o.take.empty() ? studio::newTakeId() : o.take;
  // Its length known ahead only when it holds to --frames; else 0: live, as long as its graphs run.
  publisher.beginTake(take, poseStart(whoOf(o, avatar), avatar, std::vector<int>(avatar.joints.size(), -1),
                                      takeStart(o, TimeCode{0, rate}), o.hold ? o.frames : 0));
  (void)stopOnSignals();
  spdlog::info("take {}: the event graph {} on {} at {:g} Hz, on {} ({}); drape inject --to {} starts graphs and sends "
               "events while it runs",
               take, o.events, whoOf(o, avatar), rate, studio::subjectOf(o.name), o.fast ? "as fast as the server takes it" : "in real time",
               o.name);

  const auto began = std::chrono::steady_clock::now();
  const auto frameTime = std::chrono::duration<double>(1.0 / rate);
  events::Tick tick;
  studio::PoseFrame frame;
  frame.joints.resize(avatar.joints.size());
  std::deque<std::optional<Vec3>> winds;  // the ticks' winds, until their frames go out
  std::int64_t sent = 0;
  // A tick's frame out: at once, or kept apart once the correction has it.
  const auto sendReady = [&] {
    if (!keep) {
      frame.frame = sent++;
      frame.joints = tick.poses[actor];
      frame.wind = tick.wind;
      publisher.send(frame);
      return;
    }
    while (keep->next(frame.joints)) {
      frame.frame = sent++;
      frame.wind = winds.front();
      winds.pop_front();
      publisher.send(frame);
    }
  };
  long f = 0;
  for (; o.frames == 0 || f < o.frames; ++f) {
    if (!o.fast)
      std::this_thread::sleep_until(began + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                frameTime * static_cast<double>(f)));
    while (const std::optional<studio::Request> r = requests.next(std::chrono::milliseconds(0))) {
      studio::InjectReply reply{false, "not a drape inject request"};
      try {
        const studio::Message m = studio::decode(r->data);
        if (const auto* in = std::get_if<studio::Inject>(&m.payload))
          reply = injected(*in, f, scheduler, motions, graphs, mo);
      } catch (const Error& e) {
        reply.message = e.what();
      }
      if (!reply.accepted) spdlog::warn("an injection refused: {}", reply.message);
      requests.answer(*r, studio::encode(studio::Message{o.name, take, reply}));
    }
    const bool more = scheduler.tick(tick);
    if (keep) {
      keep->push(tick.poses[actor]);
      winds.push_back(tick.wind);
    }
    sendReady();
    if ((!more && !o.hold) || stopAsked) {
      ++f;
      break;
    }
  }
  if (keep) {
    keep->finish();
    sendReady();
  }
  publisher.send(studio::End{sent, "", stopAsked ? "stopped (a signal)" : "", 0});
  if (keep) logKeptApart(keep->report());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  fmt::print("sent take {}: {} pose frames of {}'s event graph to {} on {} in {:.1f} s\n", take, sent, whoOf(o, avatar),
             studio::subjectOf(o.name), bus.url(), seconds);
  return 0;
}

/// `--live SOURCE`: a BVH written while it is captured, from standard input, a TCP server or
/// a named pipe, retargeted and sent frame by frame as it comes (motion/live_motion.hpp).
int runLiveMotion(const AnimServerOptions& o, RunSetup& setup, CharacterSetup& character) {
  const scene::Avatar& avatar = *character.avatar;
  (void)stopOnSignals();
  // The server first: a studio with no NATS server is said before the capture is waited for;
  // then the keep-apart's fields, so that the capture's first frames do not wait for them.
  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape anim-server " + o.name);
  prepareLiveRun(setup, character);
  LiveCapture capture(avatar, {o.live, o.liveHeader, o.studio.patience(), o.studio.giveUp()}, motionOptions(setup),
                      stopAsked);
  const motion::LiveMotion& live = capture.motion();
  // The stream carries the motion kept apart, as it carries a recorded motion's.
  capture.keepApart(liveKeepApart(setup, character, live.rate()));

  studio::Publisher publisher(bus, o.name, studio::Precision::Double, o.studio.giveUp());
  const std::string take = o.take.empty() ? studio::newTakeId() : o.take;
  // Live: as long as the source sends. A capture does not come again, so a take of this name
  // in the stream cannot be completed.
  if (publisher.beginTake(take, poseStart(whoOf(o, avatar), avatar, live.drivingJoint(),
                                          takeStart(o, TimeCode{0, live.rate()}), 0)) > 0)
    throw Error(fmt::format("--take {}: {} holds that take already, and a live capture cannot be sent again to "
                            "complete it; give the take another name",
                            take, studio::subjectOf(o.name)));
  spdlog::info("take {}: live motion from {} ({} joints at {:g} Hz in {}, joint map '{}') on {}, sent at {:g} Hz as it "
               "comes, on {} ({})",
               take, capture.name(), capture.header().joints.size(), live.sourceRate(), live.report().units.name,
               live.jointMap().name, whoOf(o, avatar), live.rate(), studio::subjectOf(o.name), bus.url());

  const auto began = std::chrono::steady_clock::now();
  studio::PoseFrame frame;
  frame.joints.resize(live.jointCount());
  std::int64_t sent = 0;
  while (capture.next(frame.joints)) {
    frame.frame = sent++;
    publisher.send(frame);
    if (sent == 1) spdlog::info("the first pose frame is out; frames follow as the capture sends them");
  }
  const std::string ended = capture.ended();
  const int code = capture.silent() ? static_cast<int>(ExitCode::Unavailable) : 0;
  publisher.send(studio::End{sent, "", ended, code});
  if (capture.keptApart()) logKeptApart(capture.keptApart()->report());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  fmt::print("sent take {}: {} pose frames of {} from {} ({} source frames{}) to {} on {} in {:.1f} s{}\n", take, sent,
             whoOf(o, avatar), capture.name(), live.sourceFrames(),
             capture.badLines() > 0
                 ? fmt::format(", {} bad line{}", capture.badLines(), capture.badLines() == 1 ? "" : "s")
                 : std::string(),
             studio::subjectOf(o.name), bus.url(), seconds, ended.empty() ? "" : "; " + ended);
  return code;
}

/// A recorded motion's take: its frames numbered from the motion's own time code, counted in
/// its frames at the rate it plays.
studio::PoseStart poseStart(const std::string& character, const scene::Avatar& avatar,
                            const motion::AvatarAnimation& motion) {
  return poseStart(character, avatar, motion.drivingJoint(),
                   TimeCode{static_cast<std::int64_t>(std::llround(motion.start().seconds() * motion.rate())), motion.rate()},
                   static_cast<std::int64_t>(motion.frameCount()));
}

int runAnimServer(const AnimServerOptions& o) {
  studio::checkSourceName(o.name, "--name");
  RunSetup setup = runSetupFromScene(o.scene);
  const std::vector<CharacterSetup> cast = setup.characters;  // an event graph moves them all
  CharacterSetup* character = chooseCharacter(setup, o.character, "--character");
  if (!character) throw Error(fmt::format("{}: the scene has no avatar to move", o.scene));
  if (!o.timecode.empty() && o.timecode != "now")
    (void)TimeCode::parseSmpte(o.timecode, setup.settings.frameRate_hz);  // said before anything waits
  if (!o.live.empty()) {
    if (!o.motion.empty() || !o.animation.empty() || !o.events.empty())
      throw Error(fmt::format("--live plays the motion its source sends: give it or {}, not both",
                              !o.events.empty() ? "--events" : !o.motion.empty() ? "--motion" : "--animation"));
    if (!o.sets.empty() || o.hold || o.frames > 0 || o.fast)
      throw Error(fmt::format("{}: a live take goes at the pace its source sends, for as long",
                              !o.sets.empty() ? "--set" : o.hold ? "--hold" : o.frames > 0 ? "--frames" : "--fast"));
    return runLiveMotion(o, setup, *character);
  }
  if (!o.liveHeader.empty()) throw Error("--live-header is the skeleton of a --live source: give --live SOURCE");
  if (!o.events.empty()) {
    if (!o.motion.empty() || !o.animation.empty())
      throw Error("--events plays an event graph's motions: give it or --motion, not both");
    return runEventGraph(o, setup, *character, cast);
  }
  if (!o.sets.empty() || o.hold || o.frames > 0)
    throw Error(fmt::format("{}: it is for an event graph: give --events FILE.egml",
                            !o.sets.empty() ? "--set" : o.hold ? "--hold" : "--frames"));
  const MotionChoice choice =
      sceneMotion(setup, character, o.scene, o.motion.empty() ? character->motion : o.motion, o.animation);
  if (choice.path.empty())
    throw Error(fmt::format("{}: nothing moves the avatar: give --motion FILE (its own file carries no animation)",
                            o.scene));
  addMotion(setup, *character, choice.path, 0.0, "", choice.animation, choice.sampled.get());
  // Where the scene keeps parts apart, the stream carries the motion corrected, as drape
  // run plays it: the correction needs the parts' distance fields, hence the world.
  std::unique_ptr<sim::CharacterWorld> world;
  if (!character->keepApart.empty()) world = buildWorld(setup, *character);
  const motion::AvatarAnimation& motion = world ? *world->playedMotion() : *character->animation;
  const scene::Avatar& avatar = *character->avatar;

  studio::Bus bus = studio::Bus::connect(o.studio.server, "drape anim-server " + o.name);
  studio::Publisher publisher(bus, o.name, studio::Precision::Double, o.studio.giveUp());
  const std::string take = o.take.empty() ? studio::newTakeId() : o.take;
  studio::PoseStart start = poseStart(whoOf(o, avatar), avatar, motion);
  start.start = takeStart(o, start.start);
  publisher.beginTake(take, start);
  if (publisher.complete()) {
    fmt::print("take {} is in {} already, to its end\n", take, studio::subjectOf(o.name));
    return 0;
  }
  spdlog::info("take {}: {} frames of {} at {:g} Hz from {}, on {} ({})", take, motion.frameCount(), whoOf(o, avatar),
               motion.rate(), start.start.smpte(), studio::subjectOf(o.name), bus.url(),
               o.fast ? "as fast as the server takes them" : "in real time");

  const auto began = std::chrono::steady_clock::now();
  const auto frameTime = std::chrono::duration<double>(1.0 / motion.rate());
  Progress progress("drape anim-server", static_cast<std::int64_t>(motion.frameCount()));
  studio::PoseFrame frame;
  for (std::size_t f = 0; f < motion.frameCount(); ++f) {
    if (!o.fast) std::this_thread::sleep_until(began + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                         frameTime * static_cast<double>(f)));
    frame.frame = static_cast<std::int64_t>(f);
    const std::span<const RigidTransform> joints = motion.frame(f);
    frame.joints.assign(joints.begin(), joints.end());
    publisher.send(frame);
    progress.update(static_cast<std::int64_t>(f + 1));
  }
  publisher.send(studio::End{static_cast<std::int64_t>(motion.frameCount()), "", "", 0});
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  fmt::print("sent take {}: {} pose frames of {} to {} on {} in {:.1f} s\n", take, motion.frameCount(), whoOf(o, avatar),
             studio::subjectOf(o.name), bus.url(), seconds);
  return 0;
}

RunFunction setupAnimServer(CLI::App& app) {
  static AnimServerOptions o;
  app.add_option("scene", o.scene, "VRML97 scene whose avatar moves (the cloth-servers and players read it too)")
      ->required();
  app.add_option("--motion", o.motion, std::string("Motion for the avatar ") + kMotionHelp);
  app.add_option("--animation", o.animation, kAnimationHelp);
  app.add_option("--character", o.character,
                 "Which of the scene's characters it moves (its Avatar or Humanoid node's name); needed in a scene of "
                 "several, each played by an anim-server of its own")
      ->type_name("NAME");
  app.add_option("--name", o.name, "This broadcaster's name: it publishes on drape.NAME, into the stream DRAPE_NAME")
      ->capture_default_str();
  app.add_option("--take", o.take,
                 "The take's name (default: the date and time). A take the stream already holds in part is "
                 "completed, not sent again");
  app.add_option("--timecode", o.timecode,
                 "The time code of the take's first motion frame: HH:MM:SS:FF, or now (this machine's time of day, "
                 "local); default the motion's own, 00:00:00:00 for most files and for live and scripted takes")
      ->type_name("TIMECODE|now");
  app.add_flag("--fast", o.fast, "Send the frames as fast as the server acknowledges them, not at the frame rate");
  app.add_option("--events", o.events,
                 "Instead of a motion: play an EGML event graph live (docs/EVENTS.md), taking graphs and events "
                 "injected while it runs (drape inject --to NAME)");
  app.add_option("--live", o.live, std::string("Instead of a motion: ") + kLiveHelp + "; its frames are sent as they come")
      ->type_name("SOURCE");
  app.add_option("--live-header", o.liveHeader, kLiveHeaderHelp)->type_name("FILE.bvh");
  app.add_option("--set", o.sets, "With --events: a parameter of the graph, NAME=VALUE; repeatable");
  app.add_flag("--hold", o.hold,
               "With --events: go on when the graphs end, the character holding its pose, until stopped (Ctrl-C, "
               "SIGTERM) or --frames");
  app.add_option("--frames", o.frames, "With --events: end the take after N frames")->check(CLI::PositiveNumber);
  o.studio.add(app, "a server (with --live, without a line from the source)");
  app.footer("Every role reads the same scene: what it says of the avatar (cutAtJoints, keepApart) they all do alike.\n"
             "Exit codes: 0 sent, 2 bad input, 4 no NATS server with JetStream answers (or a --live source that does not "
             "answer, or stays silent past --give-up).");
  return [] { return runAnimServer(o); };
}

const bool registered_cmd_anim_server = registerCommand(
    {"anim-server", "Studio: play an avatar's motion into a pose stream on a NATS JetStream server", "", 70,
     &setupAnimServer});

}  // namespace
}  // namespace drape::cli
