#include "drape/scene/humanoid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::scene {
namespace {

// The proportions the rules read, as fractions of the skeleton's height (its highest joint
// above its lowest) or of a limb's length; the human body's own are far from each edge.
constexpr double kFloorReach = 0.15;   // a leg's lowest joint lies this near the lowest of all
constexpr double kHipOut = 0.25;       // the hip: this far out of the middle, of the knee's distance
constexpr double kAnkleUp = 0.2;       // the ankle: this near the floor, of the pelvis's height over it
constexpr double kArmReach = 0.08;     // an arm reaches this far to the side (hanging at the side, 0.12)
constexpr double kWristOut = 0.6;      // the wrist lies at least this far along the arm's reach
constexpr double kElbowBack = 0.45;    // the elbow: this far back from the wrist, of the arm's span
constexpr double kShoulderBack = 0.85; // the shoulder: at least this far from the elbow, of the forearm
constexpr double kForearmOfItsHand = 0.57;  // a forearm, of the forearm and the hand together (25 cm of 44)
constexpr double kWaistAboveHips = 0.03;  // the waist: this far above the hip joints

struct Tree {
  std::span<const JointAt> joints;
  std::vector<std::vector<int>> children;
  std::vector<double> lowest;   // the lowest y of each joint's subtree
  std::vector<double> highest;  // the highest y of each joint's subtree

  explicit Tree(std::span<const JointAt> j) : joints(j), children(j.size()), lowest(j.size()), highest(j.size()) {
    for (std::size_t i = 0; i < j.size(); ++i) {
      lowest[i] = highest[i] = j[i].rest.y();
      if (j[i].parent >= 0) children[static_cast<std::size_t>(j[i].parent)].push_back(static_cast<int>(i));
    }
    for (std::size_t i = j.size(); i-- > 0;) {
      const int p = j[i].parent;
      if (p < 0) continue;
      lowest[static_cast<std::size_t>(p)] = std::min(lowest[static_cast<std::size_t>(p)], lowest[i]);
      highest[static_cast<std::size_t>(p)] = std::max(highest[static_cast<std::size_t>(p)], highest[i]);
    }
  }
  [[nodiscard]] const Vec3& at(int j) const { return joints[static_cast<std::size_t>(j)].rest; }
  [[nodiscard]] const std::vector<int>& kids(int j) const { return children[static_cast<std::size_t>(j)]; }
  [[nodiscard]] double low(int j) const { return lowest[static_cast<std::size_t>(j)]; }
  [[nodiscard]] double high(int j) const { return highest[static_cast<std::size_t>(j)]; }
};

Vec3 horizontal(const Vec3& v) { return {v.x(), 0.0, v.z()}; }

/// From `from` to a leaf, each step through the child `better` prefers (whose subtree
/// reaches lowest, or highest).
template <typename Better>
JointChain pathThrough(const Tree& t, int from, Better better) {
  JointChain path{from};
  while (!t.kids(path.back()).empty()) {
    const std::vector<int>& k = t.kids(path.back());
    path.push_back(*std::min_element(k.begin(), k.end(), better));
  }
  return path;
}

/// From `from`, down to the lowest joint below it.
JointChain pathDown(const Tree& t, int from) {
  return pathThrough(t, from, [&](int a, int b) { return t.low(a) < t.low(b); });
}

/// From `from`, up to the highest joint above it.
JointChain pathUp(const Tree& t, int from) {
  return pathThrough(t, from, [&](int a, int b) { return t.high(a) > t.high(b); });
}

JointChain slice(const JointChain& path, std::size_t first, std::size_t last) {
  return {path.begin() + static_cast<std::ptrdiff_t>(first), path.begin() + static_cast<std::ptrdiff_t>(last)};
}

/// The leg down `path` (a child of `pelvis`, where the legs part, first), or nullopt. The ankle and the knee are
/// found by height alone, then the hip by how far out it is of the knee's way out: legs
/// standing apart (the Acclaim skeletons' do by 0.39 m at the feet) put the hip joint less
/// far out than the feet.
std::optional<HumanoidLimb> legOf(const Tree& t, const JointChain& path, int pelvis, const Vec3& side) {
  const double floorY = t.at(path.back()).y(), pelvisUp = t.at(pelvis).y() - floorY;
  std::size_t ankle = 1;
  while (ankle < path.size() && t.at(path[ankle]).y() - floorY >= kAnkleUp * pelvisUp) ++ankle;
  if (ankle >= path.size() || ankle < 2) return std::nullopt;
  const double midY = 0.5 * (t.at(pelvis).y() + t.at(path[ankle]).y());
  std::size_t knee = 1;
  for (std::size_t i = 1; i < ankle; ++i)
    if (std::abs(t.at(path[i]).y() - midY) < std::abs(t.at(path[knee]).y() - midY)) knee = i;
  const auto out = [&](std::size_t i) { return std::abs(side.dot(t.at(path[i]) - t.at(pelvis))); };
  if (out(knee) < 1e-3 * pelvisUp) return std::nullopt;
  std::size_t hip = 0;
  while (hip < knee && out(hip) < kHipOut * out(knee)) ++hip;
  if (hip >= knee) return std::nullopt;
  HumanoidLimb leg;
  leg.base = slice(path, 0, hip);
  leg.upper = slice(path, hip, knee);
  leg.lower = slice(path, knee, ankle);
  leg.end = {path[ankle]};
  if (ankle + 1 < path.size()) leg.tip = {path[ankle + 1]};
  return leg;
}

/// Every joint of `from`'s subtree, `from` first. Without recursion: a glTF skeleton may be
/// a chain of any length.
std::vector<int> subtree(const Tree& t, int from) {
  std::vector<int> all{from};
  for (std::size_t i = 0; i < all.size(); ++i)
    for (int k : t.kids(all[i])) all.push_back(k);
  return all;
}

/// The farthest any joint of `from`'s subtree lies along `side` from `origin`.
double sideReach(const Tree& t, int from, const Vec3& origin, const Vec3& side) {
  double reach = 0.0;
  for (int j : subtree(t, from)) reach = std::max(reach, std::abs(side.dot(t.at(j) - origin)));
  return reach;
}

/// The path from `from` to the joint of its subtree farthest from it.
JointChain pathOut(const Tree& t, int from) {
  int farthest = from;
  double distance = 0.0;
  for (int j : subtree(t, from))
    if ((t.at(j) - t.at(from)).norm() > distance) {
      distance = (t.at(j) - t.at(from)).norm();
      farthest = j;
    }
  JointChain path;
  for (int j = farthest; j != from; j = t.joints[static_cast<std::size_t>(j)].parent) path.push_back(j);
  path.push_back(from);
  std::reverse(path.begin(), path.end());
  return path;
}

/// The index on `path` of the arm's shoulder, the elbow being at `elbow`: the last joint
/// at least kShoulderBack forearms from the elbow, or the first of the joints in that place
/// (a robot's shoulder is a pitch, a roll and a yaw joint in one place).
std::size_t shoulderOf(const Tree& t, const JointChain& path, std::size_t elbow, double forearm) {
  std::size_t shoulder = 0;
  for (std::size_t i = 0; i < elbow; ++i)
    if ((t.at(path[elbow]) - t.at(path[i])).norm() >= kShoulderBack * forearm) shoulder = i;
  while (shoulder > 0 && (t.at(path[shoulder - 1]) - t.at(path[shoulder])).norm() < 1e-3 * forearm) --shoulder;
  return shoulder;
}

/// The arm along `path` if it ends at its elbow, or nullopt: a robot's arm (Choreonoid's
/// GR001) may have no wrist, its last joint the elbow, whose segment is the forearm and the
/// hand. The segment's far end then lies well past the joint: the joint short of
/// kWristOut of the way to it, where a hand's segment puts its wrist farther out.
std::optional<HumanoidLimb> armEndingAtItsElbow(const Tree& t, const JointChain& path) {
  const int last = path.back();
  const std::optional<Vec3>& tip = t.joints[static_cast<std::size_t>(last)].tip;
  if (path.size() < 2 || !tip) return std::nullopt;
  if ((t.at(last) - t.at(path.front())).norm() >= kWristOut * (*tip - t.at(path.front())).norm()) return std::nullopt;
  const std::size_t elbow = path.size() - 1;
  const std::size_t shoulder = shoulderOf(t, path, elbow, kForearmOfItsHand * (*tip - t.at(last)).norm());
  HumanoidLimb arm;
  arm.base = slice(path, 0, shoulder);
  arm.upper = slice(path, shoulder, elbow);
  arm.lower = {last};
  return arm;
}

/// The arm that leaves the spine at `from`, or nullopt.
std::optional<HumanoidLimb> armOf(const Tree& t, int from) {
  const JointChain path = pathOut(t, from);
  if (std::optional<HumanoidLimb> arm = armEndingAtItsElbow(t, path)) return arm;
  const double reach = (t.at(path.back()) - t.at(from)).norm();
  std::size_t wrist = 1;
  while (wrist + 1 < path.size() &&
         (t.kids(path[wrist]).size() == 1 || (t.at(path[wrist]) - t.at(from)).norm() < kWristOut * reach))
    ++wrist;
  if (wrist >= path.size()) return std::nullopt;
  const double span = (t.at(path[wrist]) - t.at(from)).norm();
  std::size_t elbow = 0;
  double elbowMiss = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < wrist; ++i) {
    const double miss = std::abs((t.at(path[wrist]) - t.at(path[i])).norm() - kElbowBack * span);
    if (miss < elbowMiss) {
      elbowMiss = miss;
      elbow = i;
    }
  }
  if (elbow == 0) return std::nullopt;
  const std::size_t shoulder = shoulderOf(t, path, elbow, (t.at(path[wrist]) - t.at(path[elbow])).norm());
  HumanoidLimb arm;
  arm.base = slice(path, 0, shoulder);
  arm.upper = slice(path, shoulder, elbow);
  arm.lower = slice(path, elbow, wrist);
  arm.end = {path[wrist]};
  return arm;
}

template <typename T = Humanoid>
std::optional<T> fail(std::string* whyNot, std::string why) {
  if (whyNot != nullptr) *whyNot = std::move(why);
  return std::nullopt;
}

}  // namespace

std::optional<Humanoid> findHumanoid(std::span<const JointAt> joints, std::string* whyNot) {
  if (joints.size() < 8) return fail(whyNot, fmt::format("{} joints are too few for legs, a spine and arms", joints.size()));
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (joints[i].parent >= static_cast<int>(i))
      return fail(whyNot, fmt::format("joint {} comes before its parent {}", i, joints[i].parent));
  const Tree t(joints);
  double lowestY = std::numeric_limits<double>::infinity(), highestY = -lowestY;
  for (const JointAt& j : joints) {
    lowestY = std::min(lowestY, j.rest.y());
    highestY = std::max(highestY, j.rest.y());
  }
  const double height = highestY - lowestY;
  if (!(height > 0)) return fail(whyNot, "its joints stand no higher than each other");

  // Where the legs part: the shallowest joint (parents come first) with two children
  // reaching the floor. The pelvis: it, or the first joint above it that a spine leaves
  // (H-Anim hangs the legs from a sacroiliac and the spine from the HumanoidRoot above it).
  Humanoid h;
  int parting = -1;
  std::vector<int> legChildren;
  for (std::size_t i = 0; i < joints.size() && parting < 0; ++i) {
    std::vector<int> reaching;
    for (int k : t.kids(static_cast<int>(i)))
      if (t.low(k) < lowestY + kFloorReach * height) reaching.push_back(k);
    if (reaching.size() == 2) {
      parting = static_cast<int>(i);
      legChildren = reaching;
    }
  }
  if (parting < 0) return fail(whyNot, "no joint has two children reaching the floor (the legs)");
  int spineChild = -1;
  for (int j = parting, below = -1; j >= 0 && spineChild < 0; below = j, j = joints[static_cast<std::size_t>(j)].parent) {
    for (int k : t.kids(j)) {
      const bool towardLegs = k == below || (j == parting && (k == legChildren[0] || k == legChildren[1]));
      if (!towardLegs && t.high(k) >= t.at(parting).y() + 0.25 * height && (spineChild < 0 || t.high(k) > t.high(spineChild)))
        spineChild = k;
    }
    if (spineChild >= 0) h.pelvis = j;
  }
  if (spineChild < 0) return fail(whyNot, "no joint above the legs' parting reaches up (the spine)");
  for (int j = parting; j != h.pelvis; j = joints[static_cast<std::size_t>(j)].parent) h.hips.insert(h.hips.begin(), j);
  for (int a = joints[static_cast<std::size_t>(h.pelvis)].parent; a >= 0; a = joints[static_cast<std::size_t>(a)].parent)
    h.abovePelvis.insert(h.abovePelvis.begin(), a);

  // Forward from the toes where the legs have joints past the ankle, else +z (glTF's and
  // BVH's facing); left is up x forward.
  const std::array<JointChain, 2> legPaths{pathDown(t, legChildren[0]), pathDown(t, legChildren[1])};
  const Vec3 across = horizontal(t.at(legPaths[0].back()) - t.at(legPaths[1].back()));
  if (across.norm() < 1e-6) return fail(whyNot, "the two legs end in the same place");
  std::array<std::optional<HumanoidLimb>, 2> legs{legOf(t, legPaths[0], parting, across.normalized()),
                                                   legOf(t, legPaths[1], parting, across.normalized())};
  if (!legs[0] || !legs[1]) return fail(whyNot, "a leg has no hip, knee and ankle one above the other");
  Vec3 toes = Vec3::Zero();
  for (const auto& leg : legs)
    if (!leg->tip.empty()) toes += horizontal(t.at(leg->tip[0]) - t.at(leg->end[0]));
  const Vec3 side0 = horizontal(t.at(legs[0]->upper[0]) - t.at(parting));
  if (toes.norm() > 0.01 * height) {
    // The toes' direction, made square to the legs' parting: feet turn out.
    const Vec3 a = across.normalized();
    h.forward = (toes - a * a.dot(toes)).normalized();
  } else {
    // No toes: square to the legs' parting, towards +z (or +x), as glTF and BVH characters face.
    h.forward = Vec3(-across.z(), 0.0, across.x()).normalized();
    if (h.forward.z() < -1e-9 || (std::abs(h.forward.z()) <= 1e-9 && h.forward.x() < 0)) h.forward = -h.forward;
  }
  const Vec3 left = Vec3::UnitY().cross(h.forward);
  const bool firstIsLeft = left.dot(side0) > 0;
  h.legs[0] = *legs[firstIsLeft ? 0 : 1];
  h.legs[1] = *legs[firstIsLeft ? 1 : 0];

  // The spine up to the chest: where the two branches reaching farthest to the sides leave it.
  // The way up ends where it turns to a side: a body without a head (a robot's) has its
  // highest joints in an arm, and the spine must not run out along it.
  JointChain up = pathUp(t, spineChild);
  const auto sideways = [&](int j) { return std::abs(left.dot(t.at(j) - t.at(h.pelvis))) > kArmReach * height; };
  up.erase(std::find_if(up.begin() + 1, up.end(), sideways), up.end());
  std::array<int, 2> arms{-1, -1};            // the branches' first joints, left and right
  std::array<std::size_t, 2> armAt{0, 0};     // where on the way up they leave it
  std::array<double, 2> reach{0.0, 0.0};
  for (std::size_t i = 0; i < up.size(); ++i)
    for (int k : t.kids(up[i])) {
      if (i + 1 < up.size() && k == up[i + 1]) continue;
      const double r = sideReach(t, k, t.at(up[i]), left);
      const std::size_t s = left.dot(t.at(pathOut(t, k).back()) - t.at(up[i])) > 0 ? 0 : 1;
      if (r > reach[s] && r > kArmReach * height) {
        reach[s] = r;
        arms[s] = k;
        armAt[s] = i;
      }
    }
  if (arms[0] < 0 || arms[1] < 0) return fail(whyNot, "the spine has no two branches reaching out to the sides (the arms)");
  const std::size_t chestAt = std::min(armAt[0], armAt[1]);
  h.spine = slice(up, 0, chestAt + 1);
  // The neck up to the head: from the chest's highest child that is no arm, to the first
  // joint where the way up branches or ends. None: a body without a head.
  int neckChild = -1;
  for (int k : t.kids(h.chest()))
    if (k != arms[0] && k != arms[1] && (neckChild < 0 || t.high(k) > t.high(neckChild))) neckChild = k;
  if (neckChild >= 0) {
    const JointChain neckUp = pathUp(t, neckChild);
    std::size_t headAt = 0;
    while (headAt + 1 < neckUp.size() && t.kids(neckUp[headAt]).size() == 1) ++headAt;
    // A rig's marker at the top of the head (Mixamo's HeadTop_End) ends the way up, but the
    // head's bone starts below it, at the joint the head moves with.
    const auto carries = [&](int j) { return t.joints[static_cast<std::size_t>(j)].carries; };
    if (headAt > 0 && t.kids(neckUp[headAt]).empty() && !carries(neckUp[headAt]) && carries(neckUp[headAt - 1]))
      --headAt;
    h.neck = slice(neckUp, 0, headAt + 1);
  }
  for (std::size_t s = 0; s < 2; ++s) {
    const std::optional<HumanoidLimb> arm = armOf(t, arms[s]);
    if (!arm) return fail(whyNot, "an arm has no shoulder, elbow and wrist along it");
    h.arms[s] = *arm;
  }
  return h;
}

std::optional<Upright> findUpright(std::span<const JointAt> joints, std::string* whyNot) {
  // +y first, so that a body standing as drape's scenes do is never turned; then the other
  // axes files stand their bodies along (robotics' and CAD's +z first).
  const double quarter = 0.5 * std::numbers::pi;
  const std::array<std::pair<const char*, Quat>, 6> axes{{
      {"+y", Quat::Identity()},
      {"+z", Quat(Eigen::AngleAxisd(-quarter, Vec3::UnitX()))},
      {"-z", Quat(Eigen::AngleAxisd(quarter, Vec3::UnitX()))},
      {"+x", Quat(Eigen::AngleAxisd(quarter, Vec3::UnitZ()))},
      {"-x", Quat(Eigen::AngleAxisd(-quarter, Vec3::UnitZ()))},
      {"-y", Quat(Eigen::AngleAxisd(2.0 * quarter, Vec3::UnitX()))},
  }};
  std::string whyNotUp;
  bool sameEverywhere = true;  // too few joints, or out of order: nothing to do with the axis
  std::vector<JointAt> turned(joints.begin(), joints.end());
  for (const auto& [axis, turn] : axes) {
    for (std::size_t i = 0; i < joints.size(); ++i) {
      turned[i].rest = turn * joints[i].rest;
      if (joints[i].tip) turned[i].tip = turn * *joints[i].tip;
    }
    std::string why;
    if (std::optional<Humanoid> h = findHumanoid(turned, &why)) return Upright{axis, turn, std::move(*h)};
    if (whyNotUp.empty()) whyNotUp = why;
    sameEverywhere = sameEverywhere && why == whyNotUp;
  }
  return fail<Upright>(whyNot, sameEverywhere ? whyNotUp
                                              : whyNotUp + " (and turned to stand along x or z, it is no humanoid either)");
}

std::optional<Upright> uprightAlongAnotherAxis(std::span<const JointAt> joints) {
  std::optional<Upright> u = findUpright(joints);
  if (u && u->axis == "+y") return std::nullopt;
  return u;
}

std::string Upright::rotationText() const {
  const Eigen::AngleAxisd a(turn);
  // About a positive axis, as people write them: 1 0 0 -1.5708 rather than -1 0 0 1.5708.
  Eigen::Index major = 0;
  a.axis().cwiseAbs().maxCoeff(&major);
  const double sign = a.axis()[major] < 0 ? -1.0 : 1.0;
  const auto round = [](double v) { return std::abs(v) < 1e-9 ? 0.0 : v; };
  return fmt::format("{:g} {:g} {:g} {:.4f}", round(sign * a.axis().x()), round(sign * a.axis().y()),
                     round(sign * a.axis().z()), sign * a.angle());
}

std::string Upright::standUpAdvice() const {
  return fmt::format("give its Avatar node (or a Transform around its Humanoid) rotation {} to stand it up",
                     rotationText());
}

std::vector<JointAt> jointsAt(const Avatar& avatar) {
  std::vector<JointAt> out;
  out.reserve(avatar.joints.size());
  for (const Joint& j : avatar.joints) out.push_back({j.parent, j.restCenter});
  // Joints without a segment carry nothing, where the avatar has segments at all.
  if (avatar.segments.empty()) return out;
  std::vector<bool> hasChildren(out.size(), false);
  for (const JointAt& j : out)
    if (j.parent >= 0) hasChildren[static_cast<std::size_t>(j.parent)] = true;
  for (JointAt& j : out) j.carries = false;
  for (const Segment& s : avatar.segments) {
    if (s.joint < 0 || static_cast<std::size_t>(s.joint) >= out.size() || s.mesh.triangles.empty()) continue;
    const auto i = static_cast<std::size_t>(s.joint);
    out[i].carries = true;
    if (hasChildren[i]) continue;
    // The farthest point of the joint's segments from it (a joint may carry several).
    const RigidTransform rest = avatar.joints[i].restWorld();
    double reach = out[i].tip ? (*out[i].tip - out[i].rest).norm() : 0.0;
    for (const Vec3& v : s.mesh.positions) {
      const Vec3 p = rest.apply(v);
      if ((p - out[i].rest).norm() > reach) {
        reach = (p - out[i].rest).norm();
        out[i].tip = p;
      }
    }
  }
  return out;
}

namespace {

/// The names of the avatar's segments that move with `joint`.
std::vector<std::string> segmentsOf(const Avatar& avatar, int joint) {
  std::vector<std::string> names;
  for (const Segment& s : avatar.segments)
    if (s.joint == joint && !s.mesh.triangles.empty()) names.push_back(s.name);
  return names;
}

void addSegments(const Avatar& avatar, const JointChain& chain, std::vector<std::string>& into) {
  for (int j : chain)
    for (std::string& name : segmentsOf(avatar, j)) into.push_back(std::move(name));
}


/// The avatar's humanoid, or drape::Error saying that `what` cannot be found and why.
Humanoid humanoidOf(const Avatar& avatar, const char* what) {
  std::string whyNot;
  const std::optional<Humanoid> h = findHumanoid(jointsAt(avatar), &whyNot);
  if (!h)
    throw Error(fmt::format("{}: {} cannot be found by the skeleton's shape: {}",
                            avatar.source.empty() ? avatar.name : avatar.source, what, whyNot));
  return *h;
}

}  // namespace

std::vector<std::string> findForearmsAndHands(const Avatar& avatar) {
  const Humanoid h = humanoidOf(avatar, "its forearms and hands");
  std::vector<std::string> names;
  for (const HumanoidLimb& arm : h.arms) {
    addSegments(avatar, arm.lower, names);
    if (arm.end.empty()) continue;  // an arm ending at its elbow: the forearm's segment is the hand too
    // The hand and every joint below it, in order (parents come first).
    std::vector<bool> carried(avatar.joints.size(), false);
    carried[static_cast<std::size_t>(arm.end.front())] = true;
    JointChain hand;
    for (std::size_t j = 0; j < avatar.joints.size(); ++j) {
      const int p = avatar.joints[j].parent;
      if (p >= 0 && carried[static_cast<std::size_t>(p)]) carried[j] = true;
      if (carried[j]) hand.push_back(static_cast<int>(j));
    }
    addSegments(avatar, hand, names);
  }
  return names;
}

std::vector<std::string> findUpperArmsAndForearms(const Avatar& avatar) {
  const Humanoid h = humanoidOf(avatar, "its arms");
  std::vector<std::string> names;
  for (const HumanoidLimb& arm : h.arms) {
    addSegments(avatar, arm.upper, names);
    addSegments(avatar, arm.lower, names);
  }
  return names;
}

LowerBody findLowerBody(const Avatar& avatar) {
  const Humanoid h = humanoidOf(avatar, "its lower body");
  const std::string whose = avatar.source.empty() ? avatar.name : avatar.source;
  double height = -std::numeric_limits<double>::infinity(), lowest = std::numeric_limits<double>::infinity();
  for (const Joint& j : avatar.joints) {
    height = std::max(height, j.restCenter.y());
    lowest = std::min(lowest, j.restCenter.y());
  }
  height -= lowest;
  const double hipsY = 0.5 * (avatar.joints[static_cast<std::size_t>(h.legs[0].upper[0])].restCenter.y() +
                              avatar.joints[static_cast<std::size_t>(h.legs[1].upper[0])].restCenter.y());
  LowerBody body;
  addSegments(avatar, {h.pelvis}, body.hips);
  addSegments(avatar, h.hips, body.hips);
  for (int j : h.spine) {
    std::vector<std::string> names = segmentsOf(avatar, j);
    if (avatar.joints[static_cast<std::size_t>(j)].restCenter.y() >= hipsY + kWaistAboveHips * height && !names.empty()) {
      body.waist = names.front();
      break;
    }
    body.hips.insert(body.hips.end(), names.begin(), names.end());
  }
  if (body.waist.empty())
    throw Error(fmt::format("{}: no spine joint above the hips has a segment to fit a waist to; name one with "
                            "--waist-segment",
                            whose));
  for (const HumanoidLimb& leg : h.legs) addSegments(avatar, leg.base, body.hips);
  for (const HumanoidLimb& leg : h.legs) addSegments(avatar, leg.upper, body.legs);
  for (const HumanoidLimb& leg : h.legs) addSegments(avatar, leg.lower, body.legs);
  return body;
}

}  // namespace drape::scene
