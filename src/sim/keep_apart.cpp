#include "drape/sim/keep_apart.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/sim/body_overlap.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {
namespace {

constexpr int kSolves = 2;            // one smoothed, then one that is not
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
  }

  [[nodiscard]] const std::vector<Pair>& pairs() const { return pairs_; }
  [[nodiscard]] std::size_t pivotCount() const { return pivots_.size(); }

  /// Where a pair is closest: the point (world) and the way the moved part must go there.
  struct Closest {
    Vec3 point = Vec3::Zero();
    Vec3 away = Vec3::Zero();
  };

  /// The most pair p lacks of its clearance in frame f of `animation` (<= 0: none): the
  /// moved part's vertices read in the other's field and, when the moved part collides
  /// too, the other's vertices in its field (a thin limb can take an edge of the other
  /// part inside it with none of its own vertices inside that part).
  [[nodiscard]] double lack(const motion::AvatarAnimation& animation, std::size_t f, const Pair& p,
                            Closest* where = nullptr) const {
    return lack(animation.frame(f), p, where);
  }
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

  /// Swings the pivots of frame f until every pair keeps its clearance, or no turn can help
  /// a pair (its deepest point in line with the pivot, or the pivot's correction at
  /// settings.maxTurn_deg), composing each turn into `turns` (per pivot, in its parent's
  /// frame).
  void solveFrame(motion::AvatarAnimation& animation, std::size_t f, std::vector<std::vector<Quat>>& turns) const {
    const double maxTurn = settings_.maxTurn_deg * std::numbers::pi / 180.0;
    std::vector<std::uint8_t> givenUp(pairs_.size(), 0);
    for (int t = 0; t < kTurnsPerFrame; ++t) {
      double worst = kTolerance_m;
      std::size_t chosenIndex = pairs_.size();
      Closest at;
      for (std::size_t pi = 0; pi < pairs_.size(); ++pi) {
        if (givenUp[pi]) continue;
        Closest c;
        const double l = lack(animation, f, pairs_[pi], &c);
        if (l > worst) {
          worst = l;
          chosenIndex = pi;
          at = c;
        }
      }
      if (chosenIndex == pairs_.size()) return;
      const Pair* chosen = &pairs_[chosenIndex];
      const Vec3 pivot = animation.frame(f)[static_cast<std::size_t>(chosen->pivot)].translation;
      const Vec3 axis = (at.point - pivot).cross(at.away);
      const double lever = axis.norm();
      const double room = maxTurn - angleOf(turns[chosen->pivotSlot][f]);
      if (lever < kMinLever_m || room <= 1e-6) {
        givenUp[chosenIndex] = 1;
        continue;
      }
      const double angle = std::min({worst / lever, kMaxTurn_rad, room});
      const Quat turn(Eigen::AngleAxisd(angle, axis / lever));
      animation.moveJoints(f, subtrees_[chosen->pivotSlot], {turn, pivot - turn * pivot});
      const Quat parent = parentRotation(animation, f, chosen->pivot);
      Quat& q = turns[chosen->pivotSlot][f];
      q = ((parent.conjugate() * turn * parent) * q).normalized();
    }
  }

  /// `original` with the turns applied, parents' before their children's.
  [[nodiscard]] motion::AvatarAnimation apply(const motion::AvatarAnimation& original,
                                              const std::vector<std::vector<Quat>>& turns) const {
    motion::AvatarAnimation out = original;
    std::vector<std::size_t> order(pivots_.size());
    for (std::size_t s = 0; s < order.size(); ++s) order[s] = s;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return pivots_[a] < pivots_[b]; });
    for (std::size_t f = 0; f < out.frameCount(); ++f)
      for (const std::size_t s : order) {
        const Quat& q = turns[s][f];
        if (q.vec().squaredNorm() == 0) continue;
        const Quat parent = parentRotation(out, f, pivots_[s]);
        const Quat turn = (parent * q * parent.conjugate()).normalized();
        const Vec3 pivot = out.frame(f)[static_cast<std::size_t>(pivots_[s])].translation;
        out.moveJoints(f, subtrees_[s], {turn, pivot - turn * pivot});
      }
    return out;
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

  [[nodiscard]] Quat parentRotation(const motion::AvatarAnimation& animation, std::size_t f, int pivot) const {
    const int parent = avatar_.joints[static_cast<std::size_t>(pivot)].parent;
    return parent < 0 ? Quat::Identity() : animation.frame(f)[static_cast<std::size_t>(parent)].rotation;
  }

  const scene::Avatar& avatar_;
  const std::vector<PartField>& fields_;
  const KeepApartSettings& settings_;
  std::vector<Pair> pairs_;
  std::vector<int> pivots_;
  std::vector<std::vector<int>> subtrees_;  // per pivot: it and every joint below it
};

/// Each frame takes the largest turn within `reach` frames of it: smoothed afterwards, a
/// turn then stays about as large as each frame needed (a plain average would take the
/// peaks off, and the last solve would put them back as kinks).
void widen(std::vector<std::vector<Quat>>& turns, int reach) {
  for (std::vector<Quat>& series : turns) {
    const std::vector<Quat> in = series;
    const int n = static_cast<int>(in.size());
    for (int f = 0; f < n; ++f)
      for (int k = std::max(0, f - reach); k <= std::min(n - 1, f + reach); ++k)
        if (angleOf(in[static_cast<std::size_t>(k)]) > angleOf(series[static_cast<std::size_t>(f)]))
          series[static_cast<std::size_t>(f)] = in[static_cast<std::size_t>(k)];
  }
}

/// Gaussian smoothing over frames of each pivot's turns (the motion holds its first and
/// last frames beyond its ends).
void smooth(std::vector<std::vector<Quat>>& turns, double sigma_frames) {
  if (sigma_frames <= 0) return;
  const int reach = static_cast<int>(std::ceil(3 * sigma_frames));
  widen(turns, static_cast<int>(std::ceil(2 * sigma_frames)));
  std::vector<double> w(static_cast<std::size_t>(2 * reach + 1));
  for (int k = -reach; k <= reach; ++k)
    w[static_cast<std::size_t>(k + reach)] = std::exp(-0.5 * k * k / (sigma_frames * sigma_frames));
  for (std::vector<Quat>& series : turns) {
    const std::vector<Quat> in = series;
    const int n = static_cast<int>(in.size());
    for (int f = 0; f < n; ++f) {
      Eigen::Vector4d sum = Eigen::Vector4d::Zero();
      double total = 0;
      for (int k = -reach; k <= reach; ++k) {
        const Quat& q = in[static_cast<std::size_t>(std::clamp(f + k, 0, n - 1))];
        const double wk = w[static_cast<std::size_t>(k + reach)];
        sum += wk * (q.w() < 0 ? -q.coeffs() : q.coeffs());  // one hemisphere: the turns are small
        total += wk;
      }
      Quat q;
      q.coeffs() = sum / total;
      series[static_cast<std::size_t>(f)] = q.normalized();
    }
  }
}

/// Per pair: the most it lacks, in which frame, and in how many frames more than `over`.
struct Lack {
  double most_m = 0;
  long frame = 0, frames = 0;
};

std::vector<Lack> measure(const Solver& solver, const motion::AvatarAnimation& animation, double over) {
  std::vector<Lack> out(solver.pairs().size());
  for (std::size_t f = 0; f < animation.frameCount(); ++f)
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double l = solver.lack(animation, f, solver.pairs()[i]);
      if (l > over) ++out[i].frames;
      if (l > out[i].most_m) out[i] = {l, static_cast<long>(f), out[i].frames};
    }
  return out;
}

}  // namespace

KeepApartReport keepBodyApart(const scene::Avatar& avatar, motion::AvatarAnimation& animation,
                              const std::vector<PartField>& fields, const KeepApartSettings& settings) {
  KeepApartReport report;
  report.parts = settings.parts;
  report.maxTurn_deg = settings.maxTurn_deg;
  if (settings.parts.empty()) return report;
  const auto start = std::chrono::steady_clock::now();
  const Solver solver(avatar, fields, settings);
  const double voxel = fields.empty() ? 0.005 : fields.front().field.voxelSize();
  const std::vector<Lack> before = measure(solver, animation, Solver::kTolerance_m);

  const motion::AvatarAnimation original = animation;
  std::vector<std::vector<Quat>> turns(solver.pivotCount(), std::vector<Quat>(animation.frameCount(), Quat::Identity()));
  for (int solve = 0; solve < kSolves; ++solve) {
    // Each solve turns the joints of its copy as it records the turns: the last copy is the
    // corrected motion.
    animation = solver.apply(original, turns);
    for (std::size_t f = 0; f < animation.frameCount(); ++f) solver.solveFrame(animation, f, turns);
    if (solve + 1 < kSolves) smooth(turns, settings.smoothing_s * animation.rate());
  }

  const std::vector<Lack> after = measure(solver, animation, 0.1 * voxel);
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (before[i].frames == 0) continue;
    const Pair& p = solver.pairs()[i];
    KeptApart k;
    k.part = avatar.segments[static_cast<std::size_t>(p.segment)].name;
    k.from = fields[p.into].segment;
    k.pivot = avatar.joints[static_cast<std::size_t>(p.pivot)].name;
    k.target_m = p.target_m;
    k.deepest_m = before[i].most_m;
    k.deepestFrame = before[i].frame;
    k.frames = before[i].frames;
    k.remaining_m = std::max(0.0, after[i].most_m);
    k.framesRemaining = after[i].frames;
    report.pairs.push_back(k);
  }
  std::sort(report.pairs.begin(), report.pairs.end(),
            [](const KeptApart& a, const KeptApart& b) { return a.deepest_m > b.deepest_m; });
  for (std::size_t f = 0; f < animation.frameCount(); ++f) {
    bool changed = false;
    for (const std::vector<Quat>& series : turns) {
      const double a = angleOf(series[f]);
      changed = changed || a > 1e-6;
      report.largestAngle_deg = std::max(report.largestAngle_deg, a * 180.0 / std::numbers::pi);
    }
    report.framesChanged += changed ? 1 : 0;
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
