#pragma once
// Running EGML event graphs (docs/EVENTS.md): a scheduler that advances every running event
// by one animation tick at a time and composes what the Plays say into each character's pose.
//
// Each event, once started, runs as a thread of its own (a Running) with the parameters its
// path through the graph has gathered: the speed (multiplied down the graph), the character,
// the named parameters. Control events start, advance and stop their children; leaves act
// on the character (Play) or the environment (Wind). A graph started while others run (one
// injected into a live anim-server) starts at once, and its Plays blend from whatever the
// character is doing. Events sent from outside reach the running state machines at the next
// tick.
//
// A scene's characters are the scheduler's actors: each Play and Path acts on the one its
// character (its own, or inherited down the graph) names, or on the only one when it names
// none; each actor has its own layers and Path, and the wind blows on all.
//
// The pose: every Play started on the character is a layer over the ones before it, in the
// order they started, weighted from 0 to 1 over its blend time; a Play that ends leaves its
// last pose as a layer until a later one covers it, so the character holds where a motion
// stopped. A joint's world transforms are blended as the micro-interpolation does (SLERP of
// the rotation, linear translation); a Play anchored (the default) has its motion's path
// turned and moved, about the vertical, to go on from where the character stands. A Path
// moves the whole composed pose about the vertical on top of that: carried at a speed, or
// steering the character's own travel along its turns.

#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/events/graph.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::events {

/// A character a scheduler moves: its avatar, and the names Plays and Paths call it by (a
/// scheduler of one actor also answers to its avatar's own name, and to no name at all).
struct Actor {
  const scene::Avatar* avatar = nullptr;
  std::vector<std::string> names;
};

/// Which of `actors` an event of character `character` (its own or inherited) acts on: the
/// one that answers to the name, or the only one when it names none; -1 when none does.
[[nodiscard]] int actorOf(const std::vector<Actor>& actors, const std::string& character);

/// The motions graphs play, each loaded once onto the avatar of the actor that plays it
/// (retargeted as drape run --motion retargets, at the run's frame rate).
class Motions {
 public:
  /// Loads what `graph` plays that is not loaded yet: each Play's motion onto the avatar of
  /// the actor it plays on (a Play that names no actor of them loads nothing: starting the
  /// graph says so). `options` gives the rate and the shipped joint maps; each Play's
  /// animation and joint map come from the Play.
  void load(const Graph& graph, const std::vector<Actor>& actors, const motion::MotionOptions& options);
  /// The same for one avatar, which every Play plays on.
  void load(const Graph& graph, const scene::Avatar& avatar, const motion::MotionOptions& options) {
    load(graph, {Actor{&avatar, {}}}, options);
  }
  /// The motion a Play plays on `avatar` (loaded before).
  [[nodiscard]] const motion::AvatarAnimation& of(const Event& play, const scene::Avatar& avatar) const;

 private:
  void load(const Event& e, const std::string& inherited, const std::vector<Actor>& actors,
            const motion::MotionOptions& options);
  std::map<std::tuple<const scene::Avatar*, std::string, std::string, std::string>, std::unique_ptr<motion::AvatarAnimation>>
      loaded_;
};

/// A Path event's course, as its fields define it: the polyline by arc length, the turn
/// the character makes along it, and, carried at a speed, where it is when.
class PathCourse {
 public:
  explicit PathCourse(const Event& path);
  /// Its length on the floor (m): the horizontal lengths of its segments.
  [[nodiscard]] double length() const { return lengths_.back(); }
  /// The point `s` metres along it (clamped to its ends); the height moves with the rest.
  [[nodiscard]] Vec3 at(double s) const;
  /// How far the character has turned about the vertical (radians, anticlockwise seen from
  /// above; 0 at the start) `s` metres along: each corner's turn, spread over `corner`
  /// metres centred on it (less where a segment beside it is shorter).
  [[nodiscard]] double turn(double s) const;
  /// Carried at its speed: how long it takes (s), and how far along it is after `t` seconds:
  /// speeding up at a constant rate over the ease, then steady, then slowing down as it came
  /// (on a path too short to reach its speed, it turns back half way).
  [[nodiscard]] double duration() const;
  [[nodiscard]] double travelled(double t) const;

 private:
  std::vector<Vec3> points_;
  std::vector<double> lengths_;  ///< arc length at each point
  std::vector<double> turns_;    ///< the turn at each inner point (radians)
  double speed_, ease_, corner_;
};

/// What one tick gives.
struct Tick {
  std::vector<std::vector<RigidTransform>> poses;  ///< per actor: its joints in the world
  std::optional<Vec3> wind;                        ///< the wind a Wind event set (none: the scene's holds)
};

class Running;
struct PathState;

class Scheduler {
 public:
  /// The characters `actors` (Plays name each by any of its names, or not at all when there
  /// is one). The ticks are 1 / rate apart; `parameters` are set for every graph (a
  /// Parameters event below overrides them).
  Scheduler(std::vector<Actor> actors, double rate, std::vector<std::pair<std::string, std::string>> parameters = {});
  /// One character, `avatar`, which Plays name by any of `names` (or not at all).
  Scheduler(const scene::Avatar& avatar, std::vector<std::string> names, double rate,
            std::vector<std::pair<std::string, std::string>> parameters = {});
  ~Scheduler();
  Scheduler(const Scheduler&) = delete;
  Scheduler& operator=(const Scheduler&) = delete;

  /// Starts `graph` at the coming tick; `motions` (which must hold its motions, and outlive
  /// it) gives what its Plays play. Throws drape::Error when a Play or Path names no actor,
  /// or names none among several.
  void start(const Graph& graph, const Motions& motions);
  /// An event for the running state machines, acted on at the next tick.
  void send(const std::string& event);
  /// The next tick: the first at time 0, each next 1 / rate later. Returns whether any graph
  /// still runs after it.
  bool tick(Tick& out);

  [[nodiscard]] long ticks() const { return ticks_; }
  [[nodiscard]] const std::vector<Actor>& actors() const { return actors_; }
  [[nodiscard]] double rate() const { return rate_; }
  [[nodiscard]] bool running() const { return !graphs_.empty(); }

  // For the running events.
  struct Context {
    std::string character;
    std::map<std::string, std::string> parameters;
    const Motions* motions = nullptr;
  };
  [[nodiscard]] std::unique_ptr<Running> launch(const Event& e, const Context& context);
  /// The actor an event of character `character` acts on (checked when its graph started).
  [[nodiscard]] std::size_t actorFor(const std::string& character) const;
  /// A new pose layer on top of actor a's (weight 0 to 1); with `root`, its poses are
  /// anchored: turned and moved about the vertical so that `root` lands where the layers
  /// below it stand. Returns its id.
  std::uint64_t addLayer(std::size_t a, std::vector<RigidTransform> pose, double weight,
                         std::optional<RigidTransform> root);
  /// Updates layer `id`'s pose and weight, if it is not covered yet.
  void setLayer(std::uint64_t id, std::span<const RigidTransform> pose, double weight);
  /// The Path that moves actor a from this tick's composition on; a Path started after
  /// another takes over from it.
  void follow(std::size_t a, std::shared_ptr<PathState> path);
  [[nodiscard]] const PathState* following(std::size_t a) const { return figures_[a].path.get(); }
  std::uint64_t pushWind(const Vec3& velocity);
  void popWind(std::uint64_t id);
  void setBaseWind(const Vec3& velocity) { baseWind_ = velocity; }

 private:
  struct Layer {
    std::uint64_t id = 0;
    std::vector<RigidTransform> pose;     ///< as the motion has it
    double weight = 0.0;
    std::optional<RigidTransform> root;   ///< to be anchored: the motion's root at its start
    std::optional<RigidTransform> anchor; ///< found when first composed
  };
  /// What moves one actor: its layers and the Paths.
  struct Figure {
    std::vector<Layer> layers;
    std::vector<RigidTransform> composite;  ///< the layers' pose, before the carrier
    // Where the Paths have moved the actor: the carrier, applied on top of the layers
    // (anchoring reads the layers' pose, so a motion anchored after a Path goes on from
    // where the path left it), and the root as the layers had it at the last tick.
    RigidTransform carrier = RigidTransform::identity();
    std::optional<RigidTransform> lastRoot;
    std::shared_ptr<PathState> path;
    std::shared_ptr<PathState> leaving;  ///< taken over at this tick: its last step still to make
    bool carried = false;  ///< a Path has moved it (else the layers' pose is the pose, to the bit)
  };
  void compose(const scene::Avatar& avatar, Figure& f);
  void checkCharacters(const Event& e, const std::string& inherited) const;

  std::vector<Actor> actors_;
  double rate_;
  std::map<std::string, std::string> parameters_;
  std::vector<std::unique_ptr<Running>> graphs_;
  std::vector<std::unique_ptr<Running>> starting_;  ///< started since the last tick
  std::vector<std::string> pending_;                ///< events sent since the last tick
  std::vector<Figure> figures_;                     ///< per actor
  std::vector<std::pair<std::uint64_t, Vec3>> winds_;
  std::optional<Vec3> baseWind_;
  std::uint64_t nextId_ = 1;
  long ticks_ = 0;
};

/// A running event: advanced by its parent, stopped by it before its end when cut.
class Running {
 public:
  virtual ~Running() = default;
  /// Runs on for `dt` seconds of its own time. Returns the part of dt left over when it
  /// ended within it (>= 0), or -1 while it runs on.
  virtual double advance(double dt) = 0;
  /// Ends it now (its parent's time is up, or its state was left).
  virtual void stop() {}
  /// An event sent from outside, for the state machines in it.
  virtual void send(const std::string&) {}
};

/// A graph rendered frame by frame, as drape run plays it.
struct Rendered {
  motion::AvatarAnimation animation;
  std::vector<std::optional<Vec3>> wind;  ///< per frame
  long frames = 0;
  bool ended = false;  ///< the graph ended (else it was cut at the most frames asked for)
};

/// An event sent at a time of the script: `drape run --send NAME@SECONDS`.
struct TimedEvent {
  std::string name;
  double at_s = 0.0;
};

/// A graph rendered frame by frame for several actors.
struct RenderedCast {
  std::vector<motion::AvatarAnimation> animations;  ///< per actor
  std::vector<std::optional<Vec3>> wind;            ///< per frame
  long frames = 0;
  bool ended = false;
};

/// Runs `graph` from its start until it ends, or for `maxFrames` frames (> 0) at most, with
/// `events` sent at their times. Throws drape::Error for a graph that never ends when
/// maxFrames is 0.
[[nodiscard]] RenderedCast render(const Graph& graph, const Motions& motions, const std::vector<Actor>& actors,
                                  double rate, long maxFrames, const std::vector<TimedEvent>& events,
                                  const std::vector<std::pair<std::string, std::string>>& parameters);
/// The same for one character, `avatar`, which Plays name by any of `names`.
[[nodiscard]] Rendered render(const Graph& graph, const Motions& motions, const scene::Avatar& avatar,
                              const std::vector<std::string>& names, double rate, long maxFrames,
                              const std::vector<TimedEvent>& events,
                              const std::vector<std::pair<std::string, std::string>>& parameters);

}  // namespace drape::events
