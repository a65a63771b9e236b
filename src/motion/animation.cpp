#include "drape/motion/animation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/hanim_motion.hpp"
#include "drape/motion/interpolate.hpp"
#include "drape/motion/standing.hpp"
#include "drape/scene/humanoid.hpp"

namespace drape::motion {
namespace {

// For each avatar joint, the motion joint the map makes drive it (-1 if none).
std::vector<int> drivingJoints(const scene::Avatar& avatar, const Skeleton& skeleton, const JointMap& map) {
  std::vector<int> driving(avatar.joints.size(), -1);
  for (const JointMapEntry& e : map.entries) {
    const int a = avatar.findJoint(e.avatarJoint);
    const int m = skeleton.find(e.motionJoint);
    if (a >= 0 && m >= 0 && driving[static_cast<std::size_t>(a)] < 0) driving[static_cast<std::size_t>(a)] = m;
  }
  return driving;
}

// For each avatar joint, the head of its chain: the highest of the consecutive ancestors
// driven by the same motion joint (itself when its parent is driven by another, or none).
std::vector<std::size_t> chainHeads(const scene::Avatar& avatar, const std::vector<int>& driving) {
  std::vector<std::size_t> head(avatar.joints.size());
  for (std::size_t a = 0; a < head.size(); ++a) {
    const int p = avatar.joints[a].parent;
    head[a] = p >= 0 && driving[a] >= 0 && driving[a] == driving[static_cast<std::size_t>(p)]
                  ? head[static_cast<std::size_t>(p)]
                  : a;
  }
  return head;
}

struct Hub {
  int joint = -1;                   ///< the avatar joint the motion's root drives, under an undriven root
  std::vector<std::uint8_t> above;  ///< its ancestors, all undriven
};

// Where the avatar's root is not driven (a game rig's Root on the floor under the pelvis):
// the highest avatar joint that the motion's root joint drives, when everything above it
// is undriven. None (joint -1) otherwise.
Hub findHub(const scene::Avatar& avatar, const std::vector<int>& driving, const Skeleton& skeleton) {
  Hub hub;
  hub.above.assign(avatar.joints.size(), 0);
  for (std::size_t a = 0; a < avatar.joints.size(); ++a) {
    const int m = driving[a];
    if (m < 0 || skeleton.joints[static_cast<std::size_t>(m)].parent >= 0) continue;
    std::vector<std::size_t> path;
    int p = avatar.joints[a].parent;
    while (p >= 0 && driving[static_cast<std::size_t>(p)] < 0) {
      path.push_back(static_cast<std::size_t>(p));
      p = avatar.joints[static_cast<std::size_t>(p)].parent;
    }
    if (p >= 0 || path.empty()) return hub;  // a driven ancestor, or the root itself: no hub
    hub.joint = static_cast<int>(a);
    for (const std::size_t q : path) hub.above[q] = 1;
    return hub;
  }
  return hub;
}

// The driven bones of the avatar at rest, each as (avatar direction, motion direction): from
// the nearest driven ancestor (an undriven joint between is carried rigidly), a chain of
// joints one motion joint drives (twist joints) counting as one bone from its head, whose
// index comes first. What the rest corrections turn onto each other.
struct RestBone {
  std::size_t head, tail;     ///< the avatar joints it runs from and to
  Vec3 avatarDir, motionDir;  ///< unit vectors
};

std::vector<RestBone> restBones(const scene::Avatar& avatar, const std::vector<int>& driving,
                                const std::vector<Vec3>& motionRest) {
  const std::size_t n = avatar.joints.size();
  const std::vector<std::size_t> head = chainHeads(avatar, driving);
  std::vector<RestBone> bones;
  for (std::size_t c = 0; c < n; ++c) {
    if (driving[c] < 0) continue;
    // The nearest driven ancestor: an undriven joint between (a second neck joint, a hip
    // joint that the motion's naming style lacks) is carried rigidly, so the bone to turn
    // onto the motion's runs from that ancestor to this joint.
    int a = avatar.joints[c].parent;
    while (a >= 0 && driving[static_cast<std::size_t>(a)] < 0) a = avatar.joints[static_cast<std::size_t>(a)].parent;
    if (a < 0) continue;
    if (driving[c] == driving[static_cast<std::size_t>(a)]) continue;  // within one chain: one bone
    // A chain (twist joints) is one bone from its head: the direction is measured there.
    const std::size_t h = head[static_cast<std::size_t>(a)];
    const Vec3 da = avatar.joints[c].restCenter - avatar.joints[h].restCenter;
    const Vec3 dm = motionRest[static_cast<std::size_t>(driving[c])] -
                    motionRest[static_cast<std::size_t>(driving[static_cast<std::size_t>(a)])];
    if (da.norm() < 1e-9 || dm.norm() < 1e-9) continue;
    bones.push_back({h, c, da.normalized(), dm.normalized()});
  }
  return bones;
}

// The quarter turn about the vertical that best faces the avatar's rest pose the way the
// motion's faces, from the horizontal parts of every driven bone (the hips' and shoulders'
// spans decide it): identity where both face alike, as glTF characters and CMU captures
// (+Z) do; a half turn for a VRM 0.x character (-Z); a quarter for one facing along x.
// Rest poses differ by their axis conventions, in quarter turns; a smaller difference is
// pose, which the per-joint corrections take. None where no turn is needed, so that such an
// avatar's rotations are not renormalised and its results stay exactly as without this step.
std::optional<Quat> restFacingTurn(const std::vector<RestBone>& bones) {
  double cosine = 0.0, sine = 0.0;  // of the best turn about y, weighted by the bones' horizontal spans
  for (const RestBone& b : bones) {
    cosine += b.avatarDir.x() * b.motionDir.x() + b.avatarDir.z() * b.motionDir.z();
    sine += b.avatarDir.z() * b.motionDir.x() - b.avatarDir.x() * b.motionDir.z();
  }
  const double quarters = std::round(std::atan2(sine, cosine) / (std::numbers::pi / 2));
  if (quarters == 0.0 || !std::isfinite(quarters)) return std::nullopt;
  return Quat(Eigen::AngleAxisd(quarters * std::numbers::pi / 2, Vec3::UnitY()));
}

// The avatar's hip bones and clavicles (a humanoid's limb bases), which the rest
// corrections leave as the avatar's own; none for a body that is not humanoid.
std::vector<std::uint8_t> girdleJoints(const scene::Avatar& avatar) {
  std::vector<std::uint8_t> girdle(avatar.joints.size(), 0);
  const std::optional<scene::Humanoid> h = scene::findHumanoid(scene::jointsAt(avatar));
  if (!h) return girdle;
  for (const auto* limbs : {&h->legs, &h->arms})
    for (const scene::HumanoidLimb& limb : *limbs)
      for (const int j : limb.base) girdle[static_cast<std::size_t>(j)] = 1;
  return girdle;
}

// Rest-pose correction per avatar joint: the world rotation that turns the avatar's rest
// bone directions (towards its nearest driven descendants) onto the motion skeleton's rest
// bone directions towards the same joints. A T-pose motion then lifts an A-pose avatar's
// arms at its reference frame, and both skeletons agree wherever the motion goes. The
// avatar is first turned by `facing` (restFacingTurn), and every correction ends with that
// turn: roots take it alone (both then stand upright facing the same way); joints with no
// usable child share their parent's correction. So do the hip bones and clavicles
// (`girdle`): where they sit on the pelvis and chest is the avatar's build, not its pose, and
// turned onto the capture's they moved the joints they carry: a Daz capture's hip bone (2.8
// cm, pointing down and back) carried MakeHuman's thighs 15 cm on its hips; the CMU walk's
// turned its hip bones 34 degrees and its clavicles 21 (the thighs 7 cm and the shoulders 5 cm
// off their places), so that the thighs stood 48 mm inside each other through the whole
// walk. The Daz walk's clavicles tore a jacket's yoke from its skirt.
// The capture's own turns of those bones still reach them, from the avatar's rest.
std::vector<Quat> restCorrections(const scene::Avatar& avatar, const std::vector<int>& driving,
                                  const Skeleton& skeleton, const std::vector<RestBone>& bones,
                                  const std::optional<Quat>& facing, const std::vector<std::uint8_t>& girdle) {
  const std::size_t n = avatar.joints.size();
  const std::vector<std::size_t> head = chainHeads(avatar, driving);
  const auto turn = [&](const Vec3& v) { return facing ? Vec3(*facing * v) : v; };
  std::vector<Vec3> avatarDir(n, Vec3::Zero()), motionDir(n, Vec3::Zero());
  // The bones from the trunk to where a hip bone or clavicle starts are the avatar's
  // anatomy as well (MakeHuman's clavicles start in front of its chest joint, a Daz
  // capture's behind): where the trunk joint has another bone (the neck), they do not
  // turn it.
  std::vector<std::uint8_t> hasTrunkBone(n, 0);
  for (const RestBone& b : bones)
    if (!girdle[b.tail] || girdle[b.head]) hasTrunkBone[b.head] = 1;
  for (const RestBone& b : bones) {
    if (girdle[b.tail] && !girdle[b.head] && hasTrunkBone[b.head]) continue;
    avatarDir[b.head] += turn(b.avatarDir);
    motionDir[b.head] += b.motionDir;
  }
  // A driven joint with no driven child (a foot whose toes the motion lacks, a head):
  // its motion end site against the avatar's directions to all its children.
  for (std::size_t a = 0; a < n; ++a) {
    if (driving[a] < 0 || avatarDir[a].norm() > 1e-9) continue;
    const auto& endSite = skeleton.joints[static_cast<std::size_t>(driving[a])].endSite;
    if (!endSite || endSite->norm() < 1e-9) continue;
    Vec3 sum = Vec3::Zero();
    for (std::size_t c = 0; c < n; ++c) {
      if (avatar.joints[c].parent != static_cast<int>(a)) continue;
      const Vec3 d = avatar.joints[c].restCenter - avatar.joints[a].restCenter;
      if (d.norm() > 1e-9) sum += d.normalized();
    }
    if (sum.norm() < 1e-9) continue;
    avatarDir[a] = turn(sum);
    motionDir[a] = endSite->normalized();
  }
  std::vector<Quat> correction(n, Quat::Identity());
  for (std::size_t a = 0; a < n; ++a) {
    const int parent = avatar.joints[a].parent;
    if (parent < 0) continue;
    if (head[a] != a) {
      correction[a] = correction[head[a]];  // the rest of a chain turns with its head
    } else if (girdle[a]) {
      correction[a] = correction[static_cast<std::size_t>(parent)];  // kept as the avatar's own
    } else if (avatarDir[a].norm() > 1e-9 && motionDir[a].norm() > 1e-9) {
      correction[a] = Quat::FromTwoVectors(avatarDir[a], motionDir[a]);
    } else {
      correction[a] = correction[static_cast<std::size_t>(parent)];
    }
  }
  if (facing)
    for (Quat& c : correction) c = (c * *facing).normalized();
  return correction;
}

// Leg-length ratio avatar / motion over LeftUpLeg -> LeftLeg -> LeftFoot (or the right
// leg), found by drape's names on the avatar, or on the motion where the avatar names its
// joints in another style (a CMU capture on a Mixamo character or an H-Anim humanoid);
// for other names, the ratio of hip heights; else the ratio of overall extents.
double legLengthRatio(const scene::Avatar& avatar, const std::vector<int>& driving, const std::vector<Vec3>& motionRest,
                      const Skeleton& skeleton) {
  // The avatar joint named `name` and the motion joint driving it, else the motion joint
  // named `name` and the avatar joint it drives; {-1, -1} where neither is driven.
  const auto legJoint = [&](const std::string& name) -> std::pair<int, int> {
    if (const int a = avatar.findJoint(name); a >= 0 && driving[static_cast<std::size_t>(a)] >= 0)
      return {a, driving[static_cast<std::size_t>(a)]};
    const int m = skeleton.find(name);
    const auto a = std::find(driving.begin(), driving.end(), m);
    if (m < 0 || a == driving.end()) return {-1, -1};
    return {static_cast<int>(a - driving.begin()), m};
  };
  for (const char* side : {"Left", "Right"}) {
    const auto [up, mu] = legJoint(fmt::format("{}UpLeg", side));
    const auto [knee, mk] = legJoint(fmt::format("{}Leg", side));
    const auto [foot, mf] = legJoint(fmt::format("{}Foot", side));
    if (mu < 0 || mk < 0 || mf < 0) continue;
    auto centre = [&](int j) { return avatar.joints[static_cast<std::size_t>(j)].restCenter; };
    auto rest = [&](int j) { return motionRest[static_cast<std::size_t>(j)]; };
    const double a = (centre(knee) - centre(up)).norm() + (centre(foot) - centre(knee)).norm();
    const double m = (rest(mk) - rest(mu)).norm() + (rest(mf) - rest(mk)).norm();
    if (a > 1e-6 && m > 1e-6) return a / m;
  }
  // Other names (another rig): the height of the joint the motion's root drives above the
  // driven joint lowest in the motion, against the same two motion joints at rest.
  int hip = -1, low = -1;
  for (std::size_t a = 0; a < avatar.joints.size(); ++a) {
    const int m = driving[a];
    if (m < 0) continue;
    if (hip < 0 && skeleton.joints[static_cast<std::size_t>(m)].parent < 0) hip = static_cast<int>(a);
    if (low < 0 || motionRest[static_cast<std::size_t>(m)].y() <
                       motionRest[static_cast<std::size_t>(driving[static_cast<std::size_t>(low)])].y())
      low = static_cast<int>(a);
  }
  if (hip >= 0 && low >= 0) {
    const auto h = static_cast<std::size_t>(hip), l = static_cast<std::size_t>(low);
    const double a = avatar.joints[h].restCenter.y() - avatar.joints[l].restCenter.y();
    const double m = motionRest[static_cast<std::size_t>(driving[h])].y() - motionRest[static_cast<std::size_t>(driving[l])].y();
    if (a > 1e-6 && m > 1e-6) return a / m;
  }
  Aabb box;
  for (const scene::Joint& j : avatar.joints) box.extend(j.restCenter);
  const double extent = skeleton.restExtent();
  return extent > 1e-9 && !box.empty() && box.size().maxCoeff() > 1e-9 ? box.size().maxCoeff() / extent : 1.0;
}

// The avatar's floor: its lowest rest point (segments, else the skin, else joints).
double avatarFloor(const scene::Avatar& avatar) {
  double floor = std::numeric_limits<double>::infinity();
  for (const scene::Segment& s : avatar.segments) {
    const RigidTransform rest = avatar.joints[static_cast<std::size_t>(s.joint)].restWorld();
    for (const Vec3& v : s.mesh.positions) floor = std::min(floor, rest.apply(v).y());
  }
  if (std::isinf(floor) && avatar.skin)
    for (const Vec3& v : avatar.skin->mesh.positions) floor = std::min(floor, v.y());
  if (std::isinf(floor))
    for (const scene::Joint& j : avatar.joints) floor = std::min(floor, j.restCenter.y());
  return std::isinf(floor) ? 0.0 : floor;
}

// Up to 256 points per segment are plenty to find its lowest point.
std::vector<std::pair<int, Vec3>> groundSamples(const scene::Avatar& avatar) {
  std::vector<std::pair<int, Vec3>> samples;
  for (const scene::Segment& s : avatar.segments) {
    const std::size_t stride = std::max<std::size_t>(1, s.mesh.positions.size() / 256);
    for (std::size_t v = 0; v < s.mesh.positions.size(); v += stride) samples.emplace_back(s.joint, s.mesh.positions[v]);
  }
  return samples;
}

// The capture floor is seldom level over a take (the CMU walk in data/ rises about 7 cm
// in 3 s), so a fixed root height leaves the feet floating or sinking as the clip goes on.
// Grounding measures the avatar's own lowest point per frame, takes its minimum over each
// window of about one gait cycle (1 s) and smooths that over the same window: the result
// is the floor the motion walks on, subtracted from every joint's height.
std::vector<double> measureGround(const Retargeter& retargeter, const std::vector<RigidTransform>& world,
                                  std::size_t frames, double rate) {
  const std::size_t n = retargeter.jointCount();
  std::vector<double> lowest(frames, 0.0), window(frames, 0.0), correction(frames, 0.0);
  if (!retargeter.hasGroundSamples()) return correction;
  for (std::size_t f = 0; f < frames; ++f)
    lowest[f] = retargeter.lowestAboveFloor({world.data() + f * n, n});
  const std::size_t half = groundHalfWindow(rate);
  auto range = [&](std::size_t f) {
    return std::make_pair(f > half ? f - half : 0, std::min(frames - 1, f + half));
  };
  for (std::size_t f = 0; f < frames; ++f) {
    const auto [lo, hi] = range(f);
    window[f] = *std::min_element(lowest.begin() + static_cast<std::ptrdiff_t>(lo), lowest.begin() + static_cast<std::ptrdiff_t>(hi) + 1);
  }
  for (std::size_t f = 0; f < frames; ++f) {
    const auto [lo, hi] = range(f);
    double sum = 0.0;
    for (std::size_t k = lo; k <= hi; ++k) sum += window[k];
    correction[f] = sum / static_cast<double>(hi - lo + 1);
  }
  return correction;
}

}  // namespace

std::size_t groundHalfWindow(double rate) { return static_cast<std::size_t>(std::max(1.0, std::round(rate * 0.5))); }

Retargeter::Retargeter(const scene::Avatar& avatar, const Skeleton& skeleton, const JointMap& map,
                       const RetargetOptions& options, const std::string& source)
    : avatar_(&avatar), skeleton_(skeleton), options_(options) {
  const std::size_t n = avatar.joints.size();
  if (n == 0) throw Error(fmt::format("{}: the avatar has no joints to animate", avatar.source));
  driving_ = drivingJoints(avatar, skeleton, map);
  // An avatar root the motion does not drive (a game rig's Root on the floor under the
  // pelvis) carries the hub: the avatar joint the motion's root drives.
  const Hub hub = findHub(avatar, driving_, skeleton);
  hub_ = hub.joint;
  aboveHub_ = hub.above;
  for (std::size_t a = 0; a < n; ++a) {
    if (avatar.joints[a].parent >= 0 || driving_[a] >= 0 || aboveHub_[a]) continue;
    const auto paired = std::count_if(driving_.begin(), driving_.end(), [](int j) { return j >= 0; });
    throw Error(fmt::format("{}: no joint of the motion {} drives the avatar's root joint '{}' (joint map '{}' pairs "
                            "{} of the motion's {} joints with the avatar's); give a joint map naming the motion's "
                            "joints (--joint-map FILE, docs/MOTION.md)",
                            avatar.source.empty() ? avatar.name : avatar.source, source, avatar.joints[a].name,
                            map.name, paired, skeleton.size()));
  }
  const std::vector<Vec3> motionRest = skeleton.restPositions();
  const std::vector<RestBone> bones = restBones(avatar, driving_, motionRest);
  facing_ = restFacingTurn(bones);
  correction_ = restCorrections(avatar, driving_, skeleton, bones, facing_, girdleJoints(avatar));
  rootScale_ = options.rootScale > 0.0 ? options.rootScale : legLengthRatio(avatar, driving_, motionRest, skeleton);
  floor_ = avatarFloor(avatar);
  samples_ = groundSamples(avatar);
  motionWorld_.resize(skeleton.size());
  delta_.resize(n);
  position_.resize(n);
  firstRoot_.assign(n, Vec3::Zero());
}

void Retargeter::retarget(std::span<const Quat> local, const Vec3& root, std::span<RigidTransform> out) {
  const scene::Avatar& avatar = *avatar_;
  const std::size_t n = avatar.joints.size();
  const bool first = !started_;
  started_ = true;
  // The scaled motion root path from an avatar joint's rest position (the root's, or the hub's).
  const auto rootPathFrom = [&](const Vec3& rest, const Vec3& motionRoot, const Vec3& start) {
    Vec3 p = rootScale_ * motionRoot;
    if (options_.anchorRootAtRest) {
      p.x() = rest.x() + rootScale_ * (motionRoot.x() - start.x());
      p.z() = rest.z() + rootScale_ * (motionRoot.z() - start.z());
    }
    p.y() = floor_ + rootScale_ * motionRoot.y();
    return p;
  };
  // A root (or the hub) turns with its motion joint and moves along the scaled root path.
  const auto placeRoot = [&](std::size_t a) {
    const RigidTransform& motion = motionWorld_[static_cast<std::size_t>(driving_[a])];
    if (first) firstRoot_[a] = motion.translation;
    delta_[a] = facing_ ? Quat((motion.rotation * *facing_).normalized()) : motion.rotation;
    position_[a] = rootPathFrom(avatar.joints[a].restCenter, motion.translation, firstRoot_[a]);
  };
  forwardKinematics(skeleton_, local, root, motionWorld_);
  // The hub first: the joints above it, earlier in the order, move with it.
  Vec3 hubShift = Vec3::Zero();
  if (hub_ >= 0) {
    const auto h = static_cast<std::size_t>(hub_);
    placeRoot(h);
    hubShift = position_[h] - avatar.joints[h].restCenter;
    hubShift.y() = 0.0;
  }
  for (std::size_t a = 0; a < n; ++a) {
    const scene::Joint& joint = avatar.joints[a];
    const int m = driving_[a];
    const auto parent = static_cast<std::size_t>(joint.parent);
    if (aboveHub_[a]) {
      // Above the hub: upright, at rest height, moving with the hub across the floor.
      delta_[a] = facing_.value_or(Quat::Identity());
      position_[a] = joint.restCenter + hubShift;
    } else if (joint.parent < 0) {
      placeRoot(a);
    } else if (static_cast<int>(a) != hub_) {
      delta_[a] = m >= 0 ? Quat((motionWorld_[static_cast<std::size_t>(m)].rotation * correction_[a]).normalized())
                         : delta_[parent];
      position_[a] = position_[parent] + delta_[parent] * (joint.restCenter - avatar.joints[parent].restCenter);
    }
    out[a] = {(delta_[a] * joint.restOrientation).normalized(), position_[a]};
  }
}

double Retargeter::lowestAboveFloor(std::span<const RigidTransform> world) const {
  double low = std::numeric_limits<double>::infinity();
  for (const auto& [joint, p] : samples_) low = std::min(low, world[static_cast<std::size_t>(joint)].apply(p).y());
  return low - floor_;
}

AvatarAnimation AvatarAnimation::build(const scene::Avatar& avatar, const Clip& clip, const JointMap& map,
                                       const RetargetOptions& options) {
  const std::size_t n = avatar.joints.size();
  if (clip.frameCount() == 0) throw Error(fmt::format("{}: the motion has no frames", clip.source));
  Retargeter retargeter(avatar, clip.skeleton, map, options, clip.source);  // throws for an avatar without joints
  AvatarAnimation anim;
  anim.frames_ = clip.frameCount();
  anim.joints_ = n;
  anim.rate_ = clip.rate;
  anim.start_ = clip.start;
  anim.driving_.assign(retargeter.drivingJoint().begin(), retargeter.drivingJoint().end());
  anim.rootScale_ = retargeter.rootScale();
  anim.rootHeightOffset_ = retargeter.floor();  // the motion's y = 0 on the avatar's floor, before grounding
  anim.world_.resize(anim.frames_ * n);
  anim.inverse_.resize(anim.frames_ * n);
  anim.rootPath_.resize(anim.frames_);
  for (std::size_t f = 0; f < anim.frames_; ++f)
    retargeter.retarget(clip.frameRotations(f), clip.rootTranslations[f], {anim.world_.data() + f * n, n});
  anim.ground_.assign(anim.frames_, 0.0);
  if (options.groundFeet) anim.ground_ = measureGround(retargeter, anim.world_, anim.frames_, anim.rate_);
  for (std::size_t f = 0; f < anim.frames_; ++f) {
    for (std::size_t a = 0; a < n; ++a) {
      RigidTransform& t = anim.world_[f * n + a];
      t.translation.y() -= anim.ground_[f];
      anim.inverse_[f * n + a] = t.inverse();
    }
    anim.rootPath_[f] = anim.world_[f * n].translation;
  }
  return anim;
}

void AvatarAnimation::evaluate(std::size_t f, double s, std::span<RigidTransform> out) const {
  const std::size_t f0 = std::min(f, frames_ - 1);
  const std::size_t f1 = std::min(f0 + 1, frames_ - 1);
  const RigidTransform* a = world_.data() + f0 * joints_;
  const RigidTransform* b = world_.data() + f1 * joints_;
  for (std::size_t j = 0; j < joints_; ++j) out[j] = interpolate(a[j], b[j], s);
}

RigidTransform AvatarAnimation::evaluateJoint(std::size_t f, double s, std::size_t joint) const {
  const std::size_t f0 = std::min(f, frames_ - 1);
  const std::size_t f1 = std::min(f0 + 1, frames_ - 1);
  return interpolate(world_[f0 * joints_ + joint], world_[f1 * joints_ + joint], s);
}

void AvatarAnimation::evaluateInverse(std::size_t f, double s, std::span<RigidTransform> out) const {
  const std::size_t f0 = std::min(f, frames_ - 1);
  const std::size_t f1 = std::min(f0 + 1, frames_ - 1);
  const RigidTransform* a = inverse_.data() + f0 * joints_;
  const RigidTransform* b = inverse_.data() + f1 * joints_;
  for (std::size_t j = 0; j < joints_; ++j) out[j] = interpolate(a[j], b[j], s);
}

AvatarAnimation AvatarAnimation::streamed(std::size_t joints, double rate, TimeCode start, std::vector<int> driving) {
  if (joints == 0 || !(rate > 0.0) || driving.size() != joints)
    throw Error(fmt::format("a streamed animation needs joints ({}), a rate ({}) and a driving joint per joint ({})",
                            joints, rate, driving.size()),
                ExitCode::Internal);
  AvatarAnimation anim;
  anim.joints_ = joints;
  anim.rate_ = rate;
  anim.start_ = start;
  anim.driving_ = std::move(driving);
  return anim;
}

void AvatarAnimation::appendFrame(std::span<const RigidTransform> world) {
  if (world.size() != joints_)
    throw Error(fmt::format("a frame of {} joints for an animation of {}", world.size(), joints_), ExitCode::Internal);
  world_.insert(world_.end(), world.begin(), world.end());
  for (const RigidTransform& t : world) inverse_.push_back(t.inverse());
  rootPath_.push_back(world.front().translation);
  ground_.push_back(0.0);
  ++frames_;
}

void AvatarAnimation::setFrame(std::size_t f, std::span<const RigidTransform> world) {
  if (world.size() != joints_ || f >= frames_)
    throw Error(fmt::format("frame {} of {} joints for an animation of {} frames of {}", f, world.size(), frames_, joints_),
                ExitCode::Internal);
  for (std::size_t j = 0; j < joints_; ++j) {
    world_[f * joints_ + j] = world[j];
    inverse_[f * joints_ + j] = world[j].inverse();
  }
}

double maxJointSeparation(const AvatarAnimation& animation, const scene::Avatar& avatar, int substeps) {
  // Where each joint sits in its parent's frame (constant: bones are rigid).
  std::vector<Vec3> attach(avatar.joints.size(), Vec3::Zero());
  for (std::size_t a = 0; a < avatar.joints.size(); ++a) {
    const int p = avatar.joints[a].parent;
    if (p >= 0) attach[a] = avatar.joints[static_cast<std::size_t>(p)].restWorld().inverse().apply(avatar.joints[a].restCenter);
  }
  std::vector<RigidTransform> ltm(animation.jointCount());
  double largest = 0.0;
  for (std::size_t f = 0; f + 1 < animation.frameCount(); ++f) {
    for (int k = 1; k < substeps; ++k) {
      animation.evaluate(f, static_cast<double>(k) / substeps, ltm);
      for (std::size_t a = 0; a < avatar.joints.size(); ++a) {
        const int p = avatar.joints[a].parent;
        if (p < 0) continue;
        largest = std::max(largest, (ltm[a].translation - ltm[static_cast<std::size_t>(p)].apply(attach[a])).norm());
      }
    }
  }
  return largest;
}

namespace {

/// What the run's log calls an avatar file's format.
std::string formatLabel(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".dae") return "Collada";
  if (ext == ".fbx") return "FBX";
  if (formats::isVrmlPath(path)) return "VRML97 H-Anim";
  return "glTF";
}

/// Where a scene put the avatar of a file: world = rotation (scale x) + translation.
struct Placement {
  Quat rotation = Quat::Identity();
  double scale = 1.0;
  Vec3 translation = Vec3::Zero();
  [[nodiscard]] Vec3 apply(const Vec3& x) const { return rotation * (scale * x) + translation; }
};

/// The placement that takes the file's rest joint positions onto the avatar's: the
/// rotation the scene gave every joint frame (a skinned avatar's joints rest unrotated in its
/// file), the ratio of the two skeletons' spreads about their centroids, and the shift of
/// the centroids.
Placement placementOf(const scene::Avatar& avatar, const std::vector<int>& motionJoint,
                      const formats::SkinnedJointMotion& motion) {
  Placement p;
  p.rotation = avatar.joints.front().restOrientation;
  Vec3 meanAvatar = Vec3::Zero(), meanFile = Vec3::Zero();
  for (std::size_t a = 0; a < avatar.joints.size(); ++a) {
    meanAvatar += avatar.joints[a].restCenter;
    meanFile += motion.restCenters[static_cast<std::size_t>(motionJoint[a])];
  }
  const auto n = static_cast<double>(avatar.joints.size());
  meanAvatar /= n;
  meanFile /= n;
  double spreadAvatar = 0.0, spreadFile = 0.0;
  for (std::size_t a = 0; a < avatar.joints.size(); ++a) {
    spreadAvatar += (avatar.joints[a].restCenter - meanAvatar).norm();
    spreadFile += (motion.restCenters[static_cast<std::size_t>(motionJoint[a])] - meanFile).norm();
  }
  if (spreadFile > 0.0 && spreadAvatar > 0.0) p.scale = spreadAvatar / spreadFile;
  p.translation = meanAvatar - p.rotation * (p.scale * meanFile);
  return p;
}

}  // namespace

namespace {

/// How an avatar file's motion fits `avatar` as the avatar of that file: the motion joint
/// of each avatar joint (by name), the placement, and what does not fit ("" if it all does).
struct OwnFit {
  std::vector<int> motionJoint;
  Placement place;
  std::string mismatch;
};

OwnFit fitAsOwn(const scene::Avatar& avatar, const formats::SkinnedJointMotion& motion) {
  const std::size_t n = avatar.joints.size();
  OwnFit fit;
  fit.motionJoint.assign(n, -1);
  std::vector<std::string> missing;
  for (std::size_t a = 0; a < n; ++a) {
    const auto it = std::find(motion.joints.begin(), motion.joints.end(), avatar.joints[a].name);
    if (it == motion.joints.end()) missing.push_back(avatar.joints[a].name);
    else fit.motionJoint[a] = static_cast<int>(it - motion.joints.begin());
  }
  if (!missing.empty()) {
    fit.mismatch = fmt::format("its skin has no joint named {} of avatar '{}' ({} of {} missing)",
                               fmt::join(missing.begin(), missing.begin() + std::min<std::size_t>(missing.size(), 4), ", "),
                               avatar.name, missing.size(), n);
    return fit;
  }
  fit.place = placementOf(avatar, fit.motionJoint, motion);
  // The same skeleton at rest, or a different one with the same joint names.
  double spread = 0.0;
  for (const scene::Joint& j : avatar.joints) spread = std::max(spread, (j.restCenter - avatar.joints.front().restCenter).norm());
  const double tolerance = std::max(1e-3 * spread, 1e-6);
  for (std::size_t a = 0; a < n && fit.mismatch.empty(); ++a) {
    const double off =
        (fit.place.apply(motion.restCenters[static_cast<std::size_t>(fit.motionJoint[a])]) - avatar.joints[a].restCenter).norm();
    if (off > tolerance)
      fit.mismatch = fmt::format("the skeleton of its animation does not rest as avatar '{}' does (joint '{}' {:.1f} mm "
                                 "away once placed)",
                                 avatar.name, avatar.joints[a].name, 1e3 * off);
  }
  return fit;
}

}  // namespace

AvatarAnimation AvatarAnimation::fromJointMotion(const scene::Avatar& avatar, const formats::SkinnedJointMotion& motion,
                                                 const std::string& source) {
  const std::size_t n = avatar.joints.size();
  if (n == 0) throw Error(fmt::format("{}: the avatar has no joints to animate", avatar.source));
  if (motion.frameCount() == 0) throw Error(fmt::format("{}: the motion has no frames", source));
  const OwnFit fit = fitAsOwn(avatar, motion);
  if (!fit.mismatch.empty())
    throw Error(fmt::format("{}: {}: an avatar file's animation drives the avatar of its own file as it is; "
                            "loadAnimation retargets it onto any other",
                            source, fit.mismatch));
  const std::vector<int>& motionJoint = fit.motionJoint;
  const Placement& place = fit.place;

  AvatarAnimation anim;
  anim.frames_ = motion.frameCount();
  anim.joints_ = n;
  anim.rate_ = motion.rate;
  anim.rootScale_ = place.scale;
  anim.driving_ = motionJoint;
  anim.world_.resize(anim.frames_ * n);
  anim.inverse_.resize(anim.frames_ * n);
  anim.rootPath_.resize(anim.frames_);
  anim.ground_.assign(anim.frames_, 0.0);
  const Quat toScene = place.rotation, fromScene = place.rotation.conjugate();
  for (std::size_t f = 0; f < anim.frames_; ++f) {
    const RigidTransform* file = motion.frames.data() + f * motion.joints.size();
    for (std::size_t a = 0; a < n; ++a) {
      // The file's motion from rest, conjugated into the scene's axes and applied after the
      // joint's rest orientation; the joint's position is its file position placed.
      const RigidTransform& m = file[motionJoint[a]];
      RigidTransform& t = anim.world_[f * n + a];
      t.rotation = (toScene * m.rotation * fromScene * avatar.joints[a].restOrientation).normalized();
      t.translation = place.apply(m.translation);
      anim.inverse_[f * n + a] = t.inverse();
    }
    anim.rootPath_[f] = anim.world_[f * n].translation;
  }
  return anim;
}

formats::SkinnedJointMotion AvatarAnimation::toJointMotion(const scene::Avatar& avatar, const std::string& name) const {
  if (avatar.joints.size() != joints_)
    throw Error(fmt::format("{}: the animation has {} joints, the avatar {}", avatar.source, joints_, avatar.joints.size()),
                ExitCode::Internal);
  formats::SkinnedJointMotion out;
  out.animation = name;
  out.animationNames = {name};
  out.rate = rate_;
  out.start_s = 0.0;
  out.end_s = duration();
  out.floor_m = avatarFloor(avatar);
  for (const scene::Joint& j : avatar.joints) {
    out.joints.push_back(j.name);
    out.parents.push_back(j.parent);
    out.restCenters.push_back(j.restCenter);
  }
  out.frames.reserve(world_.size());
  for (std::size_t f = 0; f < frames_; ++f)
    for (std::size_t a = 0; a < joints_; ++a) {
      const RigidTransform& w = world_[f * joints_ + a];
      out.frames.push_back({(w.rotation * avatar.joints[a].restOrientation.conjugate()).normalized(), w.translation});
    }
  return out;
}

namespace {

/// A skinned file's joint motion as a clip of its skeleton, for retargeting onto another
/// avatar. The file's rest pose with every joint frame turned to the world's axes is the
/// clip's rest (all its rotations identity): the offsets are the rest positions'
/// differences, a joint's local rotation is its parent's motion undone from its own, and the
/// root's path is its world position, its height taken from the file's floor (the lowest
/// point of its skin at rest), as a BVH's from the capture's floor.
Clip clipOfJointMotion(const formats::SkinnedJointMotion& m, const std::string& source) {
  const std::size_t n = m.joints.size();
  if (m.parents.size() != n || m.restCenters.size() != n || n == 0)
    throw Error(fmt::format("{}: the motion's skeleton is incomplete", source), ExitCode::Internal);
  for (std::size_t k = 1; k < n; ++k)
    if (m.parents[k] < 0)
      throw Error(fmt::format("{}: its skin's skeleton has more than one root ('{}' and '{}'); drape retargets a "
                              "skeleton with one",
                              source, m.joints.front(), m.joints[k]));
  Clip clip;
  clip.name = m.animation;
  clip.source = source;
  clip.rate = m.rate;
  for (std::size_t k = 0; k < n; ++k) {
    const int p = m.parents[k];
    clip.skeleton.joints.push_back(
        {m.joints[k], p, p < 0 ? Vec3::Zero() : Vec3(m.restCenters[k] - m.restCenters[static_cast<std::size_t>(p)]), {}});
  }
  const std::size_t frames = m.frameCount();
  clip.rotations.reserve(frames * n);
  clip.rootTranslations.reserve(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    const RigidTransform* frame = m.frames.data() + f * n;
    for (std::size_t k = 0; k < n; ++k) {
      const int p = m.parents[k];
      clip.rotations.push_back(p < 0 ? frame[k].rotation
                                     : (frame[static_cast<std::size_t>(p)].rotation.conjugate() * frame[k].rotation).normalized());
    }
    clip.rootTranslations.push_back(frame[0].translation - Vec3(0, m.floor_m, 0));
  }
  return clip;
}

}  // namespace

/// The user's joint map (checked strictly), or the shipped map that pairs the most joints.
JointMap jointMapFor(const Clip& clip, const scene::Avatar& avatar, const MotionOptions& options) {
  if (options.jointMapPath.empty()) {
    JointMap named = chooseJointMap(readJointMapDirectory(options.jointMapDirectory), clip.skeleton, avatar);
    if (drivesTheTrunk(named, clip.skeleton, avatar)) return named;
    // No shipped map knows both skeletons' names (CesiumMan's joint0 .. joint18): paired by
    // their shapes, or refused with what the shape lacks.
    std::string whyNot;
    if (std::optional<JointMap> byShape = shapeJointMap(clip.skeleton, avatar, &whyNot)) return std::move(*byShape);
    // Lying, the avatar needs turning, not a joint map.
    if (const std::optional<scene::Upright> u = scene::uprightAlongAnotherAxis(scene::jointsAt(avatar)))
      throw Error(fmt::format("{}: it stands along {}, not along +y as drape's scenes do, and the motion {} is paired with "
                              "its joints by shape only once it stands (no shipped joint map pairs them: the best, '{}', "
                              "pairs {} and misses its root); {}",
                              avatar.source.empty() ? avatar.name : avatar.source, u->axis, clip.source, named.name,
                              matchedJointCount(named, clip.skeleton, avatar), u->standUpAdvice()));
    throw Error(fmt::format("{}: no shipped joint map pairs the joints of the motion {} with the avatar's (the best, '{}', "
                            "pairs {} and misses its root), and they cannot be paired by shape: {}; give a joint map "
                            "naming the motion's joints (--joint-map FILE, docs/MOTION.md)",
                            avatar.source.empty() ? avatar.name : avatar.source, clip.source, named.name,
                            matchedJointCount(named, clip.skeleton, avatar), whyNot));
  }
  JointMap map = readJointMap(options.jointMapPath);
  checkJointMap(map, clip.skeleton, avatar);
  return map;
}

AvatarAnimation loadAnimation(const scene::Avatar& avatar, const std::string& motionPath, const MotionOptions& options,
                              ClipLoadReport* report, JointMap* chosenMap) {
  if (formats::isAvatarMotionPath(motionPath)) {
    const double rate = options.clip.rate > 0 ? options.clip.rate : 30.0;
    const formats::SkinnedJointMotion motion =
        options.sampled != nullptr ? *options.sampled : formats::readAvatarMotion(motionPath, rate, options.animation);
    if (report) {
      ClipLoadReport r;
      r.units.metresPerUnit = 1.0;
      r.units.name = fmt::format("m ({})", formatLabel(motionPath));
      r.sourceFrames = motion.frameCount();
      r.sourceRate = rate;
      *report = std::move(r);
    }
    // The avatar of the file itself (every joint of it named in the skin, resting where the
    // skin's does): its own motion, no retargeting. Any other avatar, a skeleton of the same
    // names and other proportions too: the file's skeleton retargeted like a BVH's.
    if (options.jointMapPath.empty() && fitAsOwn(avatar, motion).mismatch.empty()) {
      if (chosenMap) {
        *chosenMap = {};
        chosenMap->name = fmt::format("its own {}joints ({})", formats::isVrmlPath(motionPath) ? "" : "skin's ",
                                      motion.animation);
      }
      return AvatarAnimation::fromJointMotion(avatar, motion, motionPath);
    }
    // Retargeted like a capture, stood up like one: a file that stands its skeleton along +z
    // (an FBX from a Z-up tool, a robot's H-Anim) would lay the avatar down.
    Clip clip = clipOfJointMotion(motion, motionPath);
    const Standing standing = standUp(clip);
    if (report) {
      report->standingAxis = standing.axis;
      report->standingTurn = standing.turn;
    }
    const JointMap map = jointMapFor(clip, avatar, options);
    if (chosenMap) *chosenMap = map;
    return AvatarAnimation::build(avatar, clip, map, options.retarget);
  }
  if (!options.animation.empty())
    throw Error(fmt::format("--animation: {} is not an avatar file (.glb, .gltf, .vrm, .dae, .fbx, .wrl); animations are chosen "
                            "from an avatar's own file",
                            motionPath));
  const Clip clip = loadClip(motionPath, options.clip, report);
  const JointMap map = jointMapFor(clip, avatar, options);
  if (chosenMap) *chosenMap = map;
  return AvatarAnimation::build(avatar, clip, map, options.retarget);
}

}  // namespace drape::motion
