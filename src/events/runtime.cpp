#include "drape/events/runtime.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/motion/interpolate.hpp"

namespace drape::events {
namespace {

constexpr double kRunning = -1.0;
/// Times this close are one: durations summed tick by tick come out a rounding short.
constexpr double kTimeEpsilon = 1e-9;
/// Events that end without taking time, in one advance, before a loop of them is an error.
constexpr int kMostZeroTimeRounds = 10000;

/// An angle in (-pi, pi].
double wrapped(double a) {
  a = std::remainder(a, 2.0 * M_PI);
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

/// The heading of a direction on the floor, as yawOf measures it.
double headingOf(const Vec3& d) { return std::atan2(d.x(), d.z()); }

/// The yaw of a rotation: its forward axis (+z) turned about the vertical.
double yawOf(const Quat& q) {
  const Vec3 forward = q * Vec3::UnitZ();
  return std::atan2(forward.x(), forward.z());
}

/// The transform about the vertical that carries `from`'s place on the floor and heading onto `to`'s.
RigidTransform anchorOnto(const RigidTransform& to, const RigidTransform& from) {
  const Quat turn(Eigen::AngleAxisd(yawOf(to.rotation) - yawOf(from.rotation), Vec3::UnitY()));
  const Vec3 fromFloor(from.translation.x(), 0.0, from.translation.z());
  const Vec3 toFloor(to.translation.x(), 0.0, to.translation.z());
  return {turn, toFloor - turn * fromFloor};
}

// --- control events ------------------------------------------------------------------

/// What Sequence, Parallel and Loop share: their own speed and cut.
class Control : public Running {
 public:
  Control(Scheduler& s, const Event& e, Scheduler::Context context) : s_(s), e_(e), context_(std::move(context)) {
    if (!e.character.empty()) context_.character = e.character;
  }
  double advance(double dt) final {
    // Its duration counts in its parent's time; its children run at its speed.
    double take = dt;
    bool cut = false;
    if (e_.duration_s >= 0.0 && elapsed_ + dt >= e_.duration_s - kTimeEpsilon) {
      take = std::max(0.0, e_.duration_s - elapsed_);
      cut = true;
    }
    elapsed_ += take;
    // What is left over is never below 0: a rounding below would read as "runs on".
    const double left = run(take * e_.speed);
    if (left >= 0.0) return std::max(0.0, left / e_.speed + (dt - take));
    if (!cut) return kRunning;
    stop();
    return std::max(0.0, dt - take);
  }

 protected:
  /// Runs the children for dt of this event's own time: the left-over, or kRunning.
  virtual double run(double dt) = 0;
  Scheduler& s_;
  const Event& e_;
  Scheduler::Context context_;
  double elapsed_ = 0.0;
};

class Sequence : public Control {
 public:
  Sequence(Scheduler& s, const Event& e, const Scheduler::Context& c, int rounds) : Control(s, e, c), rounds_(rounds) {
    (void)startNext();
  }
  void stop() override {
    if (current_) current_->stop();
    current_.reset();
  }
  void send(const std::string& event) override {
    if (current_) current_->send(event);
  }

 private:
  /// Starts the next child (the first again after the last, while rounds are left); false
  /// when none is left.
  bool startNext() {
    if (e_.children.empty()) return false;
    if (index_ == e_.children.size()) {
      index_ = 0;
      if (rounds_ > 0 && ++round_ >= rounds_) return false;
    }
    current_ = s_.launch(e_.children[index_++], context_);
    return true;
  }
  double run(double dt) override {
    int idle = 0;  // children in a row that ended without taking time
    while (current_) {
      const double left = current_->advance(dt);
      if (left < 0.0) return kRunning;
      idle = left >= dt ? idle + 1 : 0;
      if (idle > kMostZeroTimeRounds)
        throw Error::at(e_.where, fmt::format("{}: repeats events that take no time, for ever", kindName(e_.kind)));
      current_.reset();
      dt = left;
      if (!startNext()) return dt;
    }
    return dt;
  }

  int rounds_;  ///< 1 for a Sequence; a Loop's count (0: for ever)
  std::size_t index_ = 0;
  int round_ = 0;
  std::unique_ptr<Running> current_;
};

class Parallel : public Control {
 public:
  Parallel(Scheduler& s, const Event& e, const Scheduler::Context& c) : Control(s, e, c) {
    for (const Event& child : e.children) children_.push_back(s_.launch(child, context_));
  }
  void stop() override {
    for (auto& c : children_)
      if (c) c->stop();
    children_.clear();
  }
  void send(const std::string& event) override {
    for (auto& c : children_)
      if (c) c->send(event);
  }

 private:
  double run(double dt) override {
    double left = dt;
    bool any = false;
    for (auto& c : children_) {
      if (!c) continue;
      const double l = c->advance(dt);
      if (l < 0.0) {
        any = true;
        continue;
      }
      left = std::min(left, l);
      c.reset();
    }
    if (any) return kRunning;
    children_.clear();
    return left;
  }
  std::vector<std::unique_ptr<Running>> children_;
};

/// A Parameters event: its children side by side, with its parameters set.
Scheduler::Context withParameters(Scheduler::Context c, const Event& e) {
  for (const auto& [name, value] : e.parameters) c.parameters[name] = value;
  return c;
}

class StateMachine : public Running {
 public:
  StateMachine(Scheduler& s, const Event& e, Scheduler::Context c) : s_(s), e_(e), context_(std::move(c)) {
    enter(e.initial);
  }
  double advance(double dt) override {
    for (int round = 0;; ++round) {
      if (round > kMostZeroTimeRounds)
        throw Error::at(e_.where, "StateMachine: goes from state to state without taking time, for ever");
      const double left = running_->advance(dt);
      if (left < 0.0) return kRunning;
      const long next = e_.children[current_].next;
      if (next < 0) return left;
      enter(static_cast<std::size_t>(next));
      dt = left;
    }
  }
  void stop() override {
    if (running_) running_->stop();
  }
  /// At once: the state it names starts now (the scheduler sends events at a tick).
  void send(const std::string& event) override {
    const Event& state = e_.children[current_];
    const auto it = std::find(state.on.begin(), state.on.end(), event);
    if (it == state.on.end()) {
      if (running_) running_->send(event);  // for machines inside the state
      return;
    }
    const std::size_t to = state.to[static_cast<std::size_t>(it - state.on.begin())];
    spdlog::debug("{}: '{}' moves it from state '{}' to '{}'", e_.where.str(), event, state.name, e_.children[to].name);
    if (running_) running_->stop();
    enter(to);
  }

 private:
  void enter(std::size_t state) {
    current_ = state;
    running_ = s_.launch(e_.children[state], context_);
  }
  Scheduler& s_;
  const Event& e_;
  Scheduler::Context context_;
  std::size_t current_ = 0;
  std::unique_ptr<Running> running_;
};

class Condition : public Running {
 public:
  Condition(Scheduler& s, const Event& e, const Scheduler::Context& c) {
    const auto it = c.parameters.find(e.parameter);
    const bool holds =
        it != c.parameters.end() && std::find(e.equals.begin(), e.equals.end(), it->second) != e.equals.end();
    spdlog::debug("{}: {} is '{}': {}", e.where.str(), e.parameter, it == c.parameters.end() ? "(not set)" : it->second,
                  holds ? "then" : "otherwise");
    branch_ = s.launch(e.children[holds ? 0 : 1], c);
  }
  double advance(double dt) override { return branch_->advance(dt); }
  void stop() override { branch_->stop(); }
  void send(const std::string& event) override { branch_->send(event); }

 private:
  std::unique_ptr<Running> branch_;
};

// --- leaves ------------------------------------------------------------------------

class Wait : public Running {
 public:
  explicit Wait(const Event& e) : duration_(e.duration_s) {}
  double advance(double dt) override {
    elapsed_ += dt;
    return elapsed_ >= duration_ - kTimeEpsilon ? std::max(0.0, elapsed_ - duration_) : kRunning;
  }

 private:
  double duration_;
  double elapsed_ = 0.0;
};

class Wind : public Running {
 public:
  Wind(Scheduler& s, const Event& e) : s_(s), duration_(e.duration_s) {
    if (duration_ < 0.0) {
      s_.setBaseWind(e.velocity);  // from now on, whatever ends
    } else {
      id_ = s_.pushWind(e.velocity);
    }
  }
  ~Wind() override { stop(); }
  double advance(double dt) override {
    if (duration_ < 0.0) return dt;
    elapsed_ += dt;
    if (elapsed_ < duration_ - kTimeEpsilon) return kRunning;
    stop();
    return std::max(0.0, elapsed_ - duration_);
  }
  void stop() override {
    if (id_ != 0) s_.popWind(id_);
    id_ = 0;
  }

 private:
  Scheduler& s_;
  double duration_;
  double elapsed_ = 0.0;
  std::uint64_t id_ = 0;
};

class Play : public Running {
 public:
  Play(Scheduler& s, const Event& e, const Scheduler::Context& c)
      : s_(s),
        e_(e),
        actor_(s.actorFor(e.character.empty() ? c.character : e.character)),
        motion_(c.motions->of(e, *s.actors()[actor_].avatar)),
        pose_(motion_.jointCount()) {
    end_s_ = e.to_s < 0.0 ? motion_.duration() : std::min(e.to_s, motion_.duration());
    if (e.from_s > end_s_)
      throw Error::at(e.where, fmt::format("Play: from {:g} s is past the end of {} ({:g} s)", e.from_s, e.motion, end_s_));
    sample(e.from_s);
    // Anchored, its path goes on from where the character stands when the layer is first
    // composed: the motion's root at `from` is carried there.
    std::optional<RigidTransform> root;
    if (e.anchor) root = pose_.front();
    id_ = s_.addLayer(actor_, pose_, weight(), root);
  }
  double advance(double dt) override {
    if (id_ == 0) return dt;
    elapsed_ += dt;
    const double at = e_.from_s + elapsed_ * e_.speed;
    const bool over = at >= end_s_ - kTimeEpsilon;
    sample(over ? end_s_ : at);
    s_.setLayer(id_, pose_, weight());
    if (!over) return kRunning;
    id_ = 0;  // its last pose stays, as a layer, until a later one covers it
    return std::max(0.0, at - end_s_) / e_.speed;
  }
  void stop() override { id_ = 0; }

 private:
  [[nodiscard]] double weight() const {
    return e_.blend_s > 0.0 ? std::min(1.0, (elapsed_ + kTimeEpsilon) / e_.blend_s) : 1.0;
  }
  /// The motion at its time t (s). A time on a frame (give or take the rounding of summed
  /// ticks) is that frame, to the bit.
  void sample(double t) {
    double frames = t * motion_.rate();
    if (std::abs(frames - std::round(frames)) < 1e-6) frames = std::round(frames);
    const auto f = static_cast<std::size_t>(std::floor(frames));
    motion_.evaluate(f, frames - static_cast<double>(f), pose_);
  }
  Scheduler& s_;
  const Event& e_;
  std::size_t actor_;
  const motion::AvatarAnimation& motion_;
  std::vector<RigidTransform> pose_;
  double end_s_ = 0.0, elapsed_ = 0.0;
  std::uint64_t id_ = 0;
};

}  // namespace

PathCourse::PathCourse(const Event& e)
    : points_(e.points), speed_(e.pathSpeed_mps), ease_(e.ease_s), corner_(e.turn ? e.corner_m : 0.0) {
  lengths_.push_back(0.0);
  for (std::size_t k = 1; k < points_.size(); ++k) {
    const Vec3 d = points_[k] - points_[k - 1];
    lengths_.push_back(lengths_.back() + std::hypot(d.x(), d.z()));
  }
  turns_.assign(points_.size(), 0.0);
  if (!e.turn) return;
  for (std::size_t k = 1; k + 1 < points_.size(); ++k)
    turns_[k] = wrapped(headingOf(points_[k + 1] - points_[k]) - headingOf(points_[k] - points_[k - 1]));
}

Vec3 PathCourse::at(double s) const {
  s = std::clamp(s, 0.0, length());
  const auto k = static_cast<std::size_t>(std::upper_bound(lengths_.begin(), lengths_.end(), s) - lengths_.begin());
  if (k >= points_.size()) return points_.back();
  const double span = lengths_[k] - lengths_[k - 1];
  return points_[k - 1] + (points_[k] - points_[k - 1]) * ((s - lengths_[k - 1]) / span);
}

double PathCourse::turn(double s) const {
  double a = 0.0;
  for (std::size_t k = 1; k + 1 < points_.size(); ++k) {
    if (turns_[k] == 0.0) continue;
    const double w = std::min({corner_, lengths_[k] - lengths_[k - 1], lengths_[k + 1] - lengths_[k]});
    const double from = lengths_[k] - 0.5 * w;
    const double part = w > 0.0 ? std::clamp((s - from) / w, 0.0, 1.0) : (s >= lengths_[k] ? 1.0 : 0.0);
    a += turns_[k] * part;
  }
  return a;
}

double PathCourse::duration() const {
  if (!(speed_ > 0.0)) return -1.0;
  if (length() >= speed_ * ease_) return length() / speed_ + ease_;
  return 2.0 * ease_;
}

double PathCourse::travelled(double t) const {
  const double total = duration(), L = length();
  if (t >= total) return L;
  if (t <= 0.0) return 0.0;
  if (ease_ <= 0.0) return speed_ * t;
  // The speed reached: the path's own, or on a short path what half of it allows.
  const double top = L >= speed_ * ease_ ? speed_ : L / ease_;
  if (t < ease_) return 0.5 * top * t * t / ease_;
  if (t > total - ease_) {
    const double r = total - t;
    return L - 0.5 * top * r * r / ease_;
  }
  return 0.5 * top * ease_ + top * (t - ease_);
}

/// A Path as it runs: its course, how far along it the character is, and what the Path
/// event that runs it has seen of time. The scheduler holds the one it follows and moves
/// the character at each composition; the event may end before that last step is made.
struct PathState {
  explicit PathState(const Event& e) : course(e), carried(e.pathSpeed_mps > 0.0) {}

  /// The carrier after this tick, from the one before and the root as the layers put it
  /// at the last tick and now.
  RigidTransform carry(const RigidTransform& carrier, const RigidTransform& before, const RigidTransform& now) {
    if (!started) {
      start = carrier.rotation;
      started = true;
    }
    const Vec3 step = now.translation - before.translation;
    double next = s;
    if (carried) {
      next = course.travelled(elapsed);
    } else {
      // Steering: the path goes as far as the character walks forwards, its sway aside.
      Vec3 forward = now.rotation * Vec3::UnitZ();
      forward.y() = 0.0;
      if (forward.norm() > 1e-9) next = std::min(course.length(), s + std::max(0.0, Vec3(step.x(), 0.0, step.z()).dot(forward.normalized())));
    }
    const Quat rotation = (Quat(Eigen::AngleAxisd(course.turn(next), Vec3::UnitY())) * start).normalized();
    Vec3 root = carrier.apply(before.translation) + rotation * step;
    if (carried) root += course.at(next) - course.at(s);
    s = next;
    return {rotation, root - rotation * now.translation};
  }
  /// Whether it has done all it does: the course travelled, or its event stopped.
  [[nodiscard]] bool done() const { return stopped || s >= course.length() - 1e-12; }

  PathCourse course;
  bool carried;
  double s = 0.0;        ///< metres along the course
  double elapsed = 0.0;  ///< seconds of the event's time (carried: its place on the speed profile)
  bool stopped = false;
  bool ended = false;  ///< its event ran to its end (a carried one's last step still to make)
  bool started = false;
  Quat start = Quat::Identity();  ///< the carrier's rotation when the path started
};

namespace {

class Path : public Running {
 public:
  Path(Scheduler& s, const Event& e, const Scheduler::Context& c)
      : s_(s),
        actor_(s.actorFor(e.character.empty() ? c.character : e.character)),
        state_(std::make_shared<PathState>(e)) {
    s_.follow(actor_, state_);
  }
  ~Path() override { stop(); }
  double advance(double dt) override {
    if (s_.following(actor_) != state_.get()) return dt;  // a later Path took over
    if (state_->carried) {
      const double total = state_->course.duration();
      const double left = state_->elapsed + dt - total;
      state_->elapsed = std::min(total, state_->elapsed + dt);
      // Ends at its duration; the scheduler makes the last step at this tick's composition.
      if (left < -kTimeEpsilon) return kRunning;
      state_->ended = true;
      return std::max(0.0, left);
    }
    if (!state_->done()) return kRunning;
    state_->ended = true;
    return 0.0;
  }
  /// Cut before its end: the character stays where this tick moves it to.
  void stop() override {
    if (s_.following(actor_) == state_.get() && !state_->ended) state_->stopped = true;
  }

 private:
  Scheduler& s_;
  std::size_t actor_;
  std::shared_ptr<PathState> state_;
};

}  // namespace

int actorOf(const std::vector<Actor>& actors, const std::string& character) {
  if (character.empty()) return actors.size() == 1 ? 0 : -1;
  for (std::size_t a = 0; a < actors.size(); ++a) {
    const std::vector<std::string>& names = actors[a].names;
    if (std::find(names.begin(), names.end(), character) != names.end()) return static_cast<int>(a);
  }
  // Alone, an actor answers to its avatar's own name too.
  if (actors.size() == 1 && actors.front().avatar->name == character) return 0;
  return -1;
}

void Motions::load(const Graph& graph, const std::vector<Actor>& actors, const motion::MotionOptions& options) {
  load(graph.root, graph.root.character, actors, options);
}

void Motions::load(const Event& e, const std::string& inherited, const std::vector<Actor>& actors,
                   const motion::MotionOptions& options) {
  const std::string character = e.character.empty() ? inherited : e.character;
  if (e.kind == Kind::Play) {
    // A single avatar plays every Play; among several, the one the Play names (none: the
    // graph's start says what is wrong).
    const int a = actors.size() == 1 ? 0 : actorOf(actors, character);
    if (a >= 0) {
      const scene::Avatar* avatar = actors[static_cast<std::size_t>(a)].avatar;
      const auto key = std::make_tuple(avatar, e.motion, e.animation, e.jointMap);
      if (!loaded_.contains(key)) {
        motion::MotionOptions o = options;
        o.jointMapPath = e.jointMap;
        o.animation = e.animation;
        o.sampled = nullptr;
        motion::ClipLoadReport report;
        loaded_[key] = std::make_unique<motion::AvatarAnimation>(motion::loadAnimation(*avatar, e.motion, o, &report));
        spdlog::info("{}: {} frames at {:g} Hz, played by the event graph{}{}", e.motion, report.sourceFrames,
                     report.sourceRate, e.animation.empty() ? "" : fmt::format(" ('{}')", e.animation),
                     actors.size() > 1 ? fmt::format(" on {}", character) : "");
      }
    }
  }
  for (const Event& c : e.children) load(c, character, actors, options);
}

const motion::AvatarAnimation& Motions::of(const Event& play, const scene::Avatar& avatar) const {
  const auto it = loaded_.find(std::make_tuple(&avatar, play.motion, play.animation, play.jointMap));
  if (it == loaded_.end()) throw Error(play.where.str() + ": Play: its motion was not loaded", ExitCode::Internal);
  return *it->second;
}

Scheduler::Scheduler(std::vector<Actor> actors, double rate, std::vector<std::pair<std::string, std::string>> parameters)
    : actors_(std::move(actors)), rate_(rate) {
  if (!(rate > 0.0)) throw Error(fmt::format("the event graph's rate {} must be > 0", rate), ExitCode::Internal);
  if (actors_.empty()) throw Error("an event graph needs a character to move", ExitCode::Internal);
  for (auto& [name, value] : parameters) parameters_[name] = value;
  // Alone, the actor answers to its avatar's own name too.
  if (actors_.size() == 1) {
    std::vector<std::string>& names = actors_.front().names;
    if (std::find(names.begin(), names.end(), actors_.front().avatar->name) == names.end())
      names.push_back(actors_.front().avatar->name);
  }
  for (const Actor& a : actors_) {
    Figure& f = figures_.emplace_back();
    for (const scene::Joint& j : a.avatar->joints) f.composite.push_back(j.restWorld());
  }
}

Scheduler::Scheduler(const scene::Avatar& avatar, std::vector<std::string> names, double rate,
                     std::vector<std::pair<std::string, std::string>> parameters)
    : Scheduler({Actor{&avatar, std::move(names)}}, rate, std::move(parameters)) {}

Scheduler::~Scheduler() {
  // Events first: their destructors hand back what they hold (a wind).
  starting_.clear();
  graphs_.clear();
}

void Scheduler::checkCharacters(const Event& e, const std::string& inherited) const {
  const std::string character = e.character.empty() ? inherited : e.character;
  if ((e.kind == Kind::Play || e.kind == Kind::Path) && actorOf(actors_, character) < 0) {
    if (character.empty()) {
      std::vector<std::string> names;
      for (const Actor& a : actors_) names.push_back(a.names.empty() ? a.avatar->name : a.names.front());
      throw Error::at(e.where, fmt::format("{}: the scene has {} characters ({}): say which it moves (character "
                                           "\"NAME\", here or on an event above it)",
                                           kindName(e.kind), actors_.size(), fmt::join(names, ", ")));
    }
    if (actors_.size() == 1)
      throw Error::at(e.where, fmt::format("{}: character '{}' is not in the scene (its character answers to: {})",
                                           kindName(e.kind), character, fmt::join(actors_.front().names, ", ")));
    std::vector<std::string> names;
    for (const Actor& a : actors_) names.insert(names.end(), a.names.begin(), a.names.end());
    throw Error::at(e.where, fmt::format("{}: character '{}' is not in the scene (its characters: {})",
                                         kindName(e.kind), character, fmt::join(names, ", ")));
  }
  for (const Event& c : e.children) checkCharacters(c, character);
}

std::size_t Scheduler::actorFor(const std::string& character) const {
  const int a = actorOf(actors_, character);
  if (a < 0) throw Error(fmt::format("no actor answers to '{}'", character), ExitCode::Internal);
  return static_cast<std::size_t>(a);
}

void Scheduler::start(const Graph& graph, const Motions& motions) {
  checkCharacters(graph.root, "");
  Context c;
  c.parameters = parameters_;
  c.motions = &motions;
  c.character = graph.root.character;
  starting_.push_back(launch(graph.root, c));
}

void Scheduler::send(const std::string& event) { pending_.push_back(event); }

std::unique_ptr<Running> Scheduler::launch(const Event& e, const Context& context) {
  switch (e.kind) {
    case Kind::Sequence: return std::make_unique<Sequence>(*this, e, context, 1);
    case Kind::Loop: return std::make_unique<Sequence>(*this, e, context, e.count);
    case Kind::Parallel: return std::make_unique<Parallel>(*this, e, context);
    case Kind::Parameters: return std::make_unique<Parallel>(*this, e, withParameters(context, e));
    case Kind::Condition: return std::make_unique<Condition>(*this, e, context);
    case Kind::StateMachine: return std::make_unique<StateMachine>(*this, e, context);
    case Kind::Wait: return std::make_unique<Wait>(e);
    case Kind::Play: return std::make_unique<Play>(*this, e, context);
    case Kind::Wind: return std::make_unique<Wind>(*this, e);
    case Kind::Path: return std::make_unique<Path>(*this, e, context);
  }
  throw Error(e.where.str() + ": an event of no known kind", ExitCode::Internal);
}

std::uint64_t Scheduler::addLayer(std::size_t a, std::vector<RigidTransform> pose, double weight,
                                  std::optional<RigidTransform> root) {
  figures_[a].layers.push_back({nextId_, std::move(pose), weight, root, std::nullopt});
  return nextId_++;
}

void Scheduler::setLayer(std::uint64_t id, std::span<const RigidTransform> pose, double weight) {
  for (Figure& f : figures_)
    for (Layer& l : f.layers)
      if (l.id == id) {
        std::copy(pose.begin(), pose.end(), l.pose.begin());
        l.weight = weight;
      }
}

void Scheduler::follow(std::size_t a, std::shared_ptr<PathState> path) {
  Figure& f = figures_[a];
  if (f.path && !f.path->done()) f.leaving = std::move(f.path);
  f.path = std::move(path);
}

std::uint64_t Scheduler::pushWind(const Vec3& velocity) {
  winds_.emplace_back(nextId_, velocity);
  return nextId_++;
}

void Scheduler::popWind(std::uint64_t id) {
  std::erase_if(winds_, [id](const auto& w) { return w.first == id; });
}

void Scheduler::compose(const scene::Avatar& avatar, Figure& f) {
  // From the rest pose, each layer over what is below it; an anchored layer is carried, the
  // first time, onto where what is below it stands.
  std::vector<RigidTransform>& composite = f.composite;
  for (std::size_t j = 0; j < composite.size(); ++j) composite[j] = avatar.joints[j].restWorld();
  for (Layer& l : f.layers) {
    if (l.root && !l.anchor) l.anchor = anchorOnto(composite.front(), *l.root);
    for (std::size_t j = 0; j < composite.size(); ++j) {
      const RigidTransform joint = l.anchor ? *l.anchor * l.pose[j] : l.pose[j];
      composite[j] = l.weight >= 1.0 ? joint : motion::interpolate(composite[j], joint, l.weight);
    }
  }
  // The Path followed moves the character from where the last tick left it.
  const RigidTransform root = composite.front();
  if (f.leaving && f.lastRoot) f.carrier = f.leaving->carry(f.carrier, *f.lastRoot, *f.lastRoot);  // its course, up to now
  f.leaving.reset();
  if (f.path) {
    if (f.lastRoot) {  // a Path cut at this tick still makes the step up to the cut
      f.carrier = f.path->carry(f.carrier, *f.lastRoot, root);
      f.carried = true;
    }
    if (f.path->done()) f.path.reset();
  }
  f.lastRoot = root;
  // Layers a later one covers whole are gone: nothing of them shows any more.
  for (std::size_t k = f.layers.size(); k-- > 1;)
    if (f.layers[k].weight >= 1.0) {
      f.layers.erase(f.layers.begin(), f.layers.begin() + static_cast<long>(k));
      break;
    }
}

bool Scheduler::tick(Tick& out) {
  if (ticks_ > 0) {
    const double dt = 1.0 / rate_;
    for (auto& g : graphs_)
      if (g->advance(dt) >= 0.0) g.reset();
    std::erase(graphs_, nullptr);
  }
  // Events act at the tick: a state entered now starts at this tick's time, and what ends
  // at once because of it (a state with nothing in it) ends now too.
  if (!pending_.empty()) {
    for (const std::string& event : pending_)
      for (auto& g : graphs_) g->send(event);
    pending_.clear();
    for (auto& g : graphs_)
      if (g->advance(0.0) >= 0.0) g.reset();
    std::erase(graphs_, nullptr);
  }
  // Graphs started since the last tick start here, at their time 0.
  for (auto& g : starting_)
    if (g->advance(0.0) < 0.0) graphs_.push_back(std::move(g));
  starting_.clear();
  out.poses.resize(figures_.size());
  for (std::size_t a = 0; a < figures_.size(); ++a) {
    Figure& f = figures_[a];
    compose(*actors_[a].avatar, f);
    out.poses[a] = f.composite;
    if (f.carried)
      for (RigidTransform& j : out.poses[a]) j = f.carrier * j;
  }
  out.wind = !winds_.empty() ? std::optional<Vec3>(winds_.back().second) : baseWind_;
  ++ticks_;
  return !graphs_.empty();
}

RenderedCast render(const Graph& graph, const Motions& motions, const std::vector<Actor>& actors, double rate,
                    long maxFrames, const std::vector<TimedEvent>& events,
                    const std::vector<std::pair<std::string, std::string>>& parameters) {
  Scheduler scheduler(actors, rate, parameters);
  scheduler.start(graph, motions);
  RenderedCast r;
  for (const Actor& a : actors) {
    std::vector<int> driving(a.avatar->joints.size(), -1);
    r.animations.push_back(motion::AvatarAnimation::streamed(a.avatar->joints.size(), rate, TimeCode{0, rate}, driving));
  }
  std::vector<TimedEvent> toSend = events;
  std::sort(toSend.begin(), toSend.end(), [](const TimedEvent& a, const TimedEvent& b) { return a.at_s < b.at_s; });
  std::size_t sent = 0;
  // An endless graph needs a limit; one about an hour long is a mistake more likely than a take.
  const long most = maxFrames > 0 ? maxFrames : static_cast<long>(3600.0 * rate);
  Tick tick;
  for (long f = 0; f < most; ++f) {
    // An event at time t acts at the first tick at or after it.
    while (sent < toSend.size() && toSend[sent].at_s <= static_cast<double>(f) / rate) scheduler.send(toSend[sent++].name);
    const bool more = scheduler.tick(tick);
    for (std::size_t a = 0; a < actors.size(); ++a) r.animations[a].appendFrame(tick.poses[a]);
    r.wind.push_back(tick.wind);
    ++r.frames;
    if (!more) {
      r.ended = true;
      return r;
    }
  }
  if (maxFrames <= 0)
    throw Error(fmt::format("{}: the event graph runs on past an hour (a Loop for ever, a state machine that never "
                            "ends, or a steering Path longer than the walk it steers): give the frames to render",
                            graph.file.empty() ? "the graph" : graph.file));
  return r;
}

Rendered render(const Graph& graph, const Motions& motions, const scene::Avatar& avatar,
                const std::vector<std::string>& names, double rate, long maxFrames,
                const std::vector<TimedEvent>& events, const std::vector<std::pair<std::string, std::string>>& parameters) {
  RenderedCast cast = render(graph, motions, {Actor{&avatar, names}}, rate, maxFrames, events, parameters);
  return {std::move(cast.animations.front()), std::move(cast.wind), cast.frames, cast.ended};
}

}  // namespace drape::events
