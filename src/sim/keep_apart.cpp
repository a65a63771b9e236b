#include "drape/sim/keep_apart.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/sim/body_overlap.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {
namespace {

constexpr int kTurnsPerFrame = 32;    // per frame and solve: enough for a limb against two parts
constexpr double kMaxTurn_rad = 0.1;  // per turn, so that the first-order lift stays close
constexpr double kMinLever_m = 0.01;  // a deepest vertex closer than this to the line of the lift cannot be swung

bool isAncestorOrSelf(const scene::Avatar& avatar, int above, int j) {
  for (; j >= 0; j = avatar.joints[static_cast<std::size_t>(j)].parent)
    if (j == above) return true;
  return false;
}

/// The least distance of a surface's vertices from a part (read from its field, vertices
/// in its grid only) and the vertex where it is least, in the part's frame.
struct Clearance {
  double distance_m = std::numeric_limits<double>::infinity();
  Vec3 at = Vec3::Zero();
};

Clearance clearance(const mesh::TriMesh& surface, const RigidTransform& pose, const field::DistanceField& into,
                    const RigidTransform& intoPose) {
  const RigidTransform toInto = intoPose.inverse() * pose;
  Clearance c;
  for (const Vec3& v : surface.positions) {
    const Vec3 p = toInto.apply(v);
    if (!into.containsPoint(p)) continue;
    const double d = into.distanceAt(p);
    if (d < c.distance_m) c = {d, p};
  }
  return c;
}

/// Unit gradient of the field's distance at a local point (central differences over half a
/// voxel), or zero where it is flat.
Vec3 gradient(const field::DistanceField& f, const Vec3& p) {
  const double h = 0.5 * f.voxelSize();
  Vec3 g;
  for (int a = 0; a < 3; ++a) {
    const Vec3 e = Vec3::Unit(a) * h;
    g[a] = f.distanceAt(p + e) - f.distanceAt(p - e);
  }
  const double n = g.norm();
  return n > 0 ? Vec3(g / n) : Vec3::Zero();
}

double angleOf(const Quat& q) { return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w())); }

/// A moved part and a part it must keep clear of.
struct Pair {
  int segment = -1;      // the moved part (avatar segment)
  std::size_t into = 0;  // index into the fields
  int pivot = -1;        // joint it is swung about
  std::size_t pivotSlot = 0;
  double target_m = 0;   // clearance to keep
  int ownField = -1;     // the moved part's own field, if it collides
  int intoSegment = -1;  // the other part's segment (its vertices, for the reverse read)
  Aabb box;              // the moved part's bounds in its joint frame
  Aabb intoBox;          // the other part's body bounds in its joint frame
};

class Solver {
 public:
  Solver(const scene::Avatar& avatar, const std::vector<PartField>& fields, const KeepApartSettings& settings)
      : avatar_(avatar), fields_(fields), settings_(settings) {
    for (const std::string& name : settings.parts) addPart(name);
    for (std::size_t s = 0; s < pivots_.size(); ++s)
      for (std::size_t j = 0; j < avatar.joints.size(); ++j)
        if (isAncestorOrSelf(avatar, pivots_[s], static_cast<int>(j))) subtrees_[s].push_back(static_cast<int>(j));
    order_.resize(pivots_.size());
    for (std::size_t s = 0; s < order_.size(); ++s) order_[s] = s;
    std::sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) { return pivots_[a] < pivots_[b]; });
    givenUp_.resize(pairs_.size());
  }

  [[nodiscard]] const std::vector<Pair>& pairs() const { return pairs_; }
  [[nodiscard]] std::size_t pivotCount() const { return pivots_.size(); }
  [[nodiscard]] const scene::Avatar& avatar() const { return avatar_; }
  [[nodiscard]] const std::vector<PartField>& fields() const { return fields_; }

  /// Where a pair is closest: the point (world) and the way the moved part must go there.
  struct Closest {
    Vec3 point = Vec3::Zero();
    Vec3 away = Vec3::Zero();
  };

  /// The most pair p lacks of its clearance in `pose` (every joint's world transform; <= 0:
  /// none): the moved part's vertices read in the other's field and, when the moved part
  /// collides too, the other's vertices in its field (a thin limb can take an edge of the
  /// other part inside it with none of its own vertices inside that part).
  [[nodiscard]] double lack(std::span<const RigidTransform> pose, const Pair& p, Closest* where = nullptr) const {
    const scene::Segment& seg = avatar_.segments[static_cast<std::size_t>(p.segment)];
    const PartField& into = fields_[p.into];
    const RigidTransform& a = pose[static_cast<std::size_t>(seg.joint)];
    const RigidTransform& b = pose[static_cast<std::size_t>(into.joint)];
    if (!moved(p.box, a).overlaps(moved(p.intoBox, b), p.target_m)) return -std::numeric_limits<double>::infinity();
    const Clearance c = clearance(seg.mesh, a, into.field, b);
    Clearance back;
    if (p.ownField >= 0) {
      const scene::Segment& other = avatar_.segments[static_cast<std::size_t>(p.intoSegment)];
      back = clearance(other.mesh, b, fields_[static_cast<std::size_t>(p.ownField)].field, a);
    }
    if (where) {
      if (c.distance_m <= back.distance_m)
        *where = {b.apply(c.at), b.applyVector(gradient(into.field, c.at))};
      else  // the other part's vertex must leave the moved part: the moved part goes against its gradient
        *where = {a.apply(back.at), -a.applyVector(gradient(fields_[static_cast<std::size_t>(p.ownField)].field, back.at))};
    }
    return p.target_m - std::min(c.distance_m, back.distance_m);
  }

  /// Swings the pivots of `pose` until every pair keeps its clearance, or no turn can help
  /// a pair (its deepest point in line with the pivot, or the pivot's correction at
  /// settings.maxTurn_deg), composing each turn into `turns` (the frame's, one per pivot, in
  /// its parent's frame).
  void solveFrame(std::span<RigidTransform> pose, std::span<Quat> turns) const {
    const double maxTurn = settings_.maxTurn_deg * std::numbers::pi / 180.0;
    std::fill(givenUp_.begin(), givenUp_.end(), std::uint8_t{0});
    for (int t = 0; t < kTurnsPerFrame; ++t) {
      double worst = kTolerance_m;
      std::size_t chosenIndex = pairs_.size();
      Closest at;
      for (std::size_t pi = 0; pi < pairs_.size(); ++pi) {
        if (givenUp_[pi]) continue;
        Closest c;
        const double l = lack(pose, pairs_[pi], &c);
        if (l > worst) {
          worst = l;
          chosenIndex = pi;
          at = c;
        }
      }
      if (chosenIndex == pairs_.size()) return;
      const Pair& chosen = pairs_[chosenIndex];
      const Vec3 pivot = pose[static_cast<std::size_t>(chosen.pivot)].translation;
      const Vec3 axis = (at.point - pivot).cross(at.away);
      const double lever = axis.norm();
      const double room = maxTurn - angleOf(turns[chosen.pivotSlot]);
      if (lever < kMinLever_m || room <= 1e-6) {
        givenUp_[chosenIndex] = 1;
        continue;
      }
      const double angle = std::min({worst / lever, kMaxTurn_rad, room});
      const Quat turn(Eigen::AngleAxisd(angle, axis / lever));
      moveJoints(pose, subtrees_[chosen.pivotSlot], {turn, pivot - turn * pivot});
      const Quat parent = parentRotation(pose, chosen.pivot);
      Quat& q = turns[chosen.pivotSlot];
      q = ((parent.conjugate() * turn * parent) * q).normalized();
    }
  }

  /// Applies a frame's turns (one per pivot, in its parent's frame) to `pose`, parents'
  /// before their children's.
  void applyFrame(std::span<RigidTransform> pose, std::span<const Quat> turns) const {
    for (const std::size_t s : order_) {
      const Quat& q = turns[s];
      if (q.vec().squaredNorm() == 0) continue;
      const Quat parent = parentRotation(pose, pivots_[s]);
      const Quat turn = (parent * q * parent.conjugate()).normalized();
      const Vec3 pivot = pose[static_cast<std::size_t>(pivots_[s])].translation;
      moveJoints(pose, subtrees_[s], {turn, pivot - turn * pivot});
    }
  }

  static constexpr double kTolerance_m = 1e-4;

 private:
  void addPart(const std::string& name) {
    const int segment = avatar_.findSegment(name);
    if (segment < 0)
      throw Error(fmt::format("keep apart: avatar '{}' has no part '{}' (it has: {})", avatar_.name, name,
                              fmt::join(avatar_.segmentNames(), ", ")));
    const scene::Segment& seg = avatar_.segments[static_cast<std::size_t>(segment)];
    const int joint = seg.joint;
    const int parent = avatar_.joints[static_cast<std::size_t>(joint)].parent;
    if (parent < 0)
      throw Error(fmt::format("keep apart: part '{}' moves with the avatar's root joint '{}', which has no joint above "
                              "it to swing it about",
                              name, avatar_.joints[static_cast<std::size_t>(joint)].name));
    const Aabb box = seg.mesh.bounds();
    std::vector<RigidTransform> rest;
    for (const scene::Joint& j : avatar_.joints) rest.push_back(j.restWorld());
    for (std::size_t k = 0; k < fields_.size(); ++k) {
      const int into = fields_[k].joint;
      if (fields_[k].segment == name || jointsMeet(avatar_, joint, into)) continue;
      // The joint above the part swings it, unless the other part hangs from that joint too
      // (thighs from the hips): then the part's own joint.
      const int pivot = !isAncestorOrSelf(avatar_, parent, into) ? parent : joint;
      if (isAncestorOrSelf(avatar_, pivot, into)) continue;  // the other part moves with it
      Pair p;
      p.segment = segment;
      p.into = k;
      p.pivot = pivot;
      p.pivotSlot = slotOf(pivot);
      p.box = box;
      p.intoBox = fields_[k].field.bodyBounds();
      p.intoSegment = avatar_.findSegment(fields_[k].segment);
      for (std::size_t own = 0; own < fields_.size(); ++own)
        if (fields_[own].segment == name) p.ownField = static_cast<int>(own);
      // At rest: the pair keeps the margin, or what it has there if less (lack() reads the
      // margin for its box test).
      p.target_m = settings_.margin_m;
      p.target_m = std::min(settings_.margin_m, settings_.margin_m - lack(rest, p));
      pairs_.push_back(p);
    }
  }

  std::size_t slotOf(int pivot) {
    const auto it = std::find(pivots_.begin(), pivots_.end(), pivot);
    if (it != pivots_.end()) return static_cast<std::size_t>(it - pivots_.begin());
    pivots_.push_back(pivot);
    subtrees_.emplace_back();
    return pivots_.size() - 1;
  }

  /// Moves `joints` of `pose` by `motion`, applied after their world transforms (as
  /// AvatarAnimation::moveJoints moves a frame's).
  static void moveJoints(std::span<RigidTransform> pose, std::span<const int> joints, const RigidTransform& motion) {
    for (const int j : joints) pose[static_cast<std::size_t>(j)] = motion * pose[static_cast<std::size_t>(j)];
  }

  [[nodiscard]] Quat parentRotation(std::span<const RigidTransform> pose, int pivot) const {
    const int parent = avatar_.joints[static_cast<std::size_t>(pivot)].parent;
    return parent < 0 ? Quat::Identity() : pose[static_cast<std::size_t>(parent)].rotation;
  }

  const scene::Avatar& avatar_;
  const std::vector<PartField>& fields_;
  const KeepApartSettings& settings_;
  std::vector<Pair> pairs_;
  std::vector<int> pivots_;
  std::vector<std::vector<int>> subtrees_;  // per pivot: it and every joint below it
  std::vector<std::size_t> order_;          // the pivots, parents before children
  mutable std::vector<std::uint8_t> givenUp_;  // solveFrame's, per pair: scratch kept from frame to frame
};

// The smoothing of the first solve's turns, a frame at a time: a frame's widened turns read
// the first solve's within `reach` frames of it, its blended turns the widened ones within
// the Gaussian's reach. Frames before the first and after the last (n - 1) are the first's and
// the last's (the motion holds them beyond its ends). `at(k)` gives frame k's turns, one per
// pivot, for both: the whole motion's series, or a live motion's window of frames.

/// Each pivot's largest turn within `reach` frames of f: smoothed afterwards, a turn then
/// stays about as large as each frame needed (a plain average would take the peaks off, and
/// the last solve would put them back as kinks).
template <class At>
void widened(const At& at, std::size_t f, std::size_t n, std::size_t reach, std::span<Quat> out) {
  const std::size_t first = f > reach ? f - reach : 0, last = std::min(n - 1, f + reach);
  const std::span<const Quat> own = at(f);
  for (std::size_t s = 0; s < out.size(); ++s) {
    Quat widest = own[s];
    for (std::size_t k = first; k <= last; ++k)
      if (angleOf(at(k)[s]) > angleOf(widest)) widest = at(k)[s];
    out[s] = widest;
  }
}

/// The Gaussian blend at frame f of the widened turns: `weights` over frames f - reach to
/// f + reach (2 reach + 1 of them).
template <class At>
void blended(const At& at, std::size_t f, std::size_t n, std::span<const double> weights, std::span<Quat> out) {
  const long reach = static_cast<long>(weights.size() / 2), last = static_cast<long>(n) - 1;
  for (std::size_t s = 0; s < out.size(); ++s) {
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    double total = 0;
    for (long k = -reach; k <= reach; ++k) {
      const Quat& q = at(static_cast<std::size_t>(std::clamp(static_cast<long>(f) + k, 0L, last)))[s];
      const double wk = weights[static_cast<std::size_t>(k + reach)];
      sum += wk * (q.w() < 0 ? -q.coeffs() : q.coeffs());  // one hemisphere: the turns are small
      total += wk;
    }
    Quat q;
    q.coeffs() = sum / total;
    out[s] = q.normalized();
  }
}

/// The frames a smoothing over `sigma_frames` reaches on either side: the widening's, and the
/// Gaussian's, whose weights are returned. None when it is off (sigma_frames <= 0).
struct Reach {
  std::size_t widen = 0, blend = 0;
  std::vector<double> weights;

  explicit Reach(double sigma_frames) {
    if (sigma_frames <= 0) return;
    widen = static_cast<std::size_t>(std::ceil(2 * sigma_frames));
    blend = static_cast<std::size_t>(std::ceil(3 * sigma_frames));
    const int r = static_cast<int>(blend);
    for (int k = -r; k <= r; ++k) weights.push_back(std::exp(-0.5 * k * k / (sigma_frames * sigma_frames)));
  }
  [[nodiscard]] bool smooths() const { return !weights.empty(); }
  [[nodiscard]] std::size_t frames() const { return widen + blend; }  ///< how far ahead a frame's correction reads
};

/// Per pair: the most it lacks, in which frame, and in how many frames more than a bound.
struct Lack {
  double most_m = 0;
  long frame = 0, frames = 0;
};

/// What a correction found and left, counted frame by frame: each pair's lack before it (over
/// the solver's tolerance) and after it (over a tenth of a voxel), and the turns it made.
class Tally {
 public:
  Tally(const Solver& solver, double voxel_m)
      : solver_(solver), after_over_m_(0.1 * voxel_m), before_(solver.pairs().size()), after_(solver.pairs().size()) {}

  void before(std::span<const RigidTransform> pose, long frame) { count(before_, pose, frame, Solver::kTolerance_m); }
  void after(std::span<const RigidTransform> pose, std::span<const Quat> turns, long frame) {
    count(after_, pose, frame, after_over_m_);
    bool changed = false;
    for (const Quat& q : turns) {
      const double a = angleOf(q);
      changed = changed || a > 1e-6;
      largestAngle_deg_ = std::max(largestAngle_deg_, a * 180.0 / std::numbers::pi);
    }
    framesChanged_ += changed ? 1 : 0;
  }

  [[nodiscard]] KeepApartReport report(const scene::Avatar& avatar, const std::vector<PartField>& fields,
                                       const KeepApartSettings& settings) const {
    KeepApartReport report;
    report.parts = settings.parts;
    report.maxTurn_deg = settings.maxTurn_deg;
    for (std::size_t i = 0; i < before_.size(); ++i) {
      if (before_[i].frames == 0) continue;
      const Pair& p = solver_.pairs()[i];
      KeptApart k;
      k.part = avatar.segments[static_cast<std::size_t>(p.segment)].name;
      k.from = fields[p.into].segment;
      k.pivot = avatar.joints[static_cast<std::size_t>(p.pivot)].name;
      k.target_m = p.target_m;
      k.deepest_m = before_[i].most_m;
      k.deepestFrame = before_[i].frame;
      k.frames = before_[i].frames;
      k.remaining_m = std::max(0.0, after_[i].most_m);
      k.framesRemaining = after_[i].frames;
      report.pairs.push_back(k);
    }
    std::sort(report.pairs.begin(), report.pairs.end(),
              [](const KeptApart& a, const KeptApart& b) { return a.deepest_m > b.deepest_m; });
    report.largestAngle_deg = largestAngle_deg_;
    report.framesChanged = framesChanged_;
    return report;
  }

 private:
  void count(std::vector<Lack>& lacks, std::span<const RigidTransform> pose, long frame, double over) const {
    for (std::size_t i = 0; i < lacks.size(); ++i) {
      const double l = solver_.lack(pose, solver_.pairs()[i]);
      if (l > over) ++lacks[i].frames;
      if (l > lacks[i].most_m) lacks[i] = {l, frame, lacks[i].frames};
    }
  }

  const Solver& solver_;
  double after_over_m_;
  std::vector<Lack> before_, after_;
  double largestAngle_deg_ = 0;
  long framesChanged_ = 0;
};

double voxelOf(const std::vector<PartField>& fields) {
  return fields.empty() ? 0.005 : fields.front().field.voxelSize();
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

KeepApartReport keepBodyApart(const scene::Avatar& avatar, motion::AvatarAnimation& animation,
                              const std::vector<PartField>& fields, const KeepApartSettings& settings) {
  if (settings.parts.empty()) {
    KeepApartReport report;
    report.maxTurn_deg = settings.maxTurn_deg;
    return report;
  }
  const auto start = std::chrono::steady_clock::now();
  const Solver solver(avatar, fields, settings);
  Tally tally(solver, voxelOf(fields));
  const std::size_t n = animation.frameCount(), pivots = solver.pivotCount();
  // Turns laid out [frame][pivot]: the first solve's, then the smoothed ones the last solve
  // starts from and adds to.
  std::vector<Quat> turns(n * pivots, Quat::Identity());
  const auto turnsOf = [&](std::vector<Quat>& series, std::size_t f) { return std::span<Quat>(series).subspan(f * pivots, pivots); };
  std::vector<RigidTransform> pose(animation.jointCount());
  const auto copyFrame = [&](std::size_t f) {
    const std::span<const RigidTransform> from = animation.frame(f);
    std::copy(from.begin(), from.end(), pose.begin());
  };

  for (std::size_t f = 0; f < n; ++f) {
    tally.before(animation.frame(f), static_cast<long>(f));
    copyFrame(f);
    solver.solveFrame(pose, turnsOf(turns, f));
  }
  const Reach reach(settings.smoothing_s * animation.rate());
  if (reach.smooths()) {
    const auto firstAt = [&](std::size_t k) { return std::span<const Quat>(turnsOf(turns, k)); };
    std::vector<Quat> wide(turns.size());
    for (std::size_t f = 0; f < n; ++f) widened(firstAt, f, n, reach.widen, turnsOf(wide, f));
    const auto wideAt = [&](std::size_t k) { return std::span<const Quat>(turnsOf(wide, k)); };
    for (std::size_t f = 0; f < n; ++f) blended(wideAt, f, n, reach.weights, turnsOf(turns, f));
  }
  for (std::size_t f = 0; f < n; ++f) {
    copyFrame(f);
    solver.applyFrame(pose, turnsOf(turns, f));
    solver.solveFrame(pose, turnsOf(turns, f));
    tally.after(pose, turnsOf(turns, f), static_cast<long>(f));
    animation.setFrame(f, pose);
  }
  KeepApartReport report = tally.report(avatar, fields, settings);
  report.seconds = seconds(start);
  return report;
}

// A live motion's frames are kept in rings of ring_ slots, frame f in slot f % ring_: its pose
// until it is out, its first solve's turns until the frames around it are widened, its
// widened turns until the frames around it are blended.
struct LiveKeepApart::State {
  State(const scene::Avatar& avatar, const std::vector<PartField>& fields, const KeepApartSettings& keep, double rate)
      : settings(keep),
        solver(avatar, fields, settings),
        tally(solver, voxelOf(fields)),
        reach(settings.smoothing_s * rate),
        joints(avatar.joints.size()),
        pivots(solver.pivotCount()),
        ring(2 * reach.frames() + 2),
        poses(ring * joints),
        first(ring * pivots),
        wide(ring * pivots),
        pose(joints),
        turns(pivots) {}

  [[nodiscard]] std::span<RigidTransform> poseOf(std::size_t f) {
    return std::span<RigidTransform>(poses).subspan((f % ring) * joints, joints);
  }
  [[nodiscard]] std::span<Quat> of(std::vector<Quat>& series, std::size_t f) const {
    return std::span<Quat>(series).subspan((f % ring) * pivots, pivots);
  }

  /// Widens every frame whose widening has all it reads.
  void widen() {
    if (!reach.smooths()) {
      widenedCount = pushed;
      return;
    }
    const auto firstAt = [this](std::size_t k) { return std::span<const Quat>(of(first, k)); };
    for (; widenedCount < pushed && (finished || widenedCount + reach.widen < pushed); ++widenedCount)
      widened(firstAt, widenedCount, pushed, reach.widen, of(wide, widenedCount));
  }

  [[nodiscard]] bool ready() const {
    return emitted < widenedCount && (finished || !reach.smooths() || emitted + reach.blend < widenedCount);
  }

  KeepApartSettings settings;
  Solver solver;
  Tally tally;
  Reach reach;
  std::size_t joints, pivots, ring;
  std::vector<RigidTransform> poses;
  std::vector<Quat> first, wide;
  std::vector<RigidTransform> pose;  // scratch: the frame being corrected
  std::vector<Quat> turns;           // scratch: its turns
  std::size_t pushed = 0, widenedCount = 0, emitted = 0;
  bool finished = false;
  double seconds = 0;
};

LiveKeepApart::LiveKeepApart(const scene::Avatar& avatar, const std::vector<PartField>& fields,
                             const KeepApartSettings& settings, double rate)
    : state_(std::make_unique<State>(avatar, fields, settings, rate)) {}

LiveKeepApart::~LiveKeepApart() = default;

std::size_t LiveKeepApart::delay() const { return state_->reach.frames(); }

void LiveKeepApart::push(std::span<const RigidTransform> pose) {
  State& s = *state_;
  if (pose.size() != s.joints)
    throw Error(fmt::format("keep apart: a frame of {} joints for an avatar of {}", pose.size(), s.joints),
                ExitCode::Internal);
  if (s.finished) throw Error("keep apart: a frame after the motion's end", ExitCode::Internal);
  if (s.pushed - s.emitted > delay())
    throw Error(fmt::format("keep apart: {} frames waiting to be taken, {} at most", s.pushed - s.emitted, delay() + 1),
                ExitCode::Internal);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t f = s.pushed;
  std::copy(pose.begin(), pose.end(), s.poseOf(f).begin());
  s.tally.before(pose, static_cast<long>(f));
  std::copy(pose.begin(), pose.end(), s.pose.begin());
  const std::span<Quat> turns = s.of(s.first, f);
  std::fill(turns.begin(), turns.end(), Quat::Identity());
  s.solver.solveFrame(s.pose, turns);
  ++s.pushed;
  s.widen();
  s.seconds += seconds(start);
}

void LiveKeepApart::finish() {
  state_->finished = true;
  state_->widen();
}

bool LiveKeepApart::next(std::span<RigidTransform> out) {
  State& s = *state_;
  if (!s.ready()) return false;
  const auto start = std::chrono::steady_clock::now();
  const std::size_t f = s.emitted;
  if (s.reach.smooths()) {
    const auto wideAt = [&s](std::size_t k) { return std::span<const Quat>(s.of(s.wide, k)); };
    blended(wideAt, f, s.widenedCount, s.reach.weights, s.turns);
  } else {
    const std::span<const Quat> first = s.of(s.first, f);
    std::copy(first.begin(), first.end(), s.turns.begin());
  }
  const std::span<const RigidTransform> original = s.poseOf(f);
  std::copy(original.begin(), original.end(), s.pose.begin());
  s.solver.applyFrame(s.pose, s.turns);
  s.solver.solveFrame(s.pose, s.turns);
  s.tally.after(s.pose, s.turns, static_cast<long>(f));
  std::copy(s.pose.begin(), s.pose.end(), out.begin());
  ++s.emitted;
  s.seconds += seconds(start);
  return true;
}

std::size_t LiveKeepApart::framesOut() const { return state_->emitted; }

KeepApartReport LiveKeepApart::report() const {
  KeepApartReport report = state_->tally.report(state_->solver.avatar(), state_->solver.fields(), state_->settings);
  report.seconds = state_->seconds;
  return report;
}

std::string describe(const KeptApart& k) {
  return fmt::format("{} out of {} about {}: {:.1f} mm short of its {:.0f} mm clearance at most, in {} frames (most "
                     "in frame {}); {:.1f} mm after{}",
                     k.part, k.from, k.pivot, 1e3 * k.deepest_m, std::round(1e3 * k.target_m) + 0.0, k.frames,
                     k.deepestFrame, 1e3 * k.remaining_m,
                     k.framesRemaining > 0 ? fmt::format(", in {} frames", k.framesRemaining) : "");
}

}  // namespace drape::sim
