#pragma once
// AvatarAnimation: a clip retargeted onto an avatar, ready for the simulation loop.
//
// THE INTERFACE sim/ consumes. Built once per (avatar, clip, map); then, for motion frame
// f and substep fraction s in [0, 1], it writes each avatar joint's world rigid transform
// (the paper's LTM, section 4.3.1) into a caller's span, allocating nothing:
//
//   motion::AvatarAnimation anim = motion::AvatarAnimation::build(avatar, clip, map);
//   std::vector<RigidTransform> ltm(anim.jointCount()), ltmInv(anim.jointCount());
//   for (std::size_t f = 0; f + 1 < anim.frameCount(); ++f)
//     for (int k = 0; k <= substeps; ++k) {
//       const double s = double(k) / substeps;
//       anim.evaluate(f, s, ltm);          // joint frame -> world
//       anim.evaluateInverse(f, s, ltmInv); // world -> joint frame
//       // segment i moves with ltm[avatar.segments[i].joint]:
//       //   world vertex = ltm[j].apply(segment vertex in its joint frame)
//     }
//
// Micro-interpolation (section 4.3.1): every joint's world transform and its inverse are
// stored per frame and interpolated separately per substep, translation linearly and
// rotation by SLERP; no forward kinematics runs per substep. s = 0 and s = 1 give frames f
// and f + 1 bit for bit. The paper's caveat holds: within a frame a child joint may drift
// from the point of its parent it is attached to (measured by maxJointSeparation; see
// docs/MOTION.md), and LTM(s) * LTMinv(s) is identity only at s = 0 and 1.
//
// Retargeting: each mapped avatar joint takes the world rotation of its motion joint,
// composed with a constant rest-pose correction (the rotation that turns the avatar's rest
// bone directions onto the motion skeleton's rest bone directions, so a T-pose motion
// drives an A-pose avatar); unmapped joints follow their parent rigidly. Joint positions
// come from the avatar's own bone lengths (forward kinematics at build time). The root
// follows the motion's root path scaled by the ratio of leg lengths (avatar / motion),
// with the motion's y = 0 on the avatar's floor (its lowest rest vertex); then, since
// capture floors are seldom level, the body is grounded: each frame is lowered by the
// smoothed per-gait-cycle minimum of the avatar's lowest point (groundCorrection()).

#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/core/timecode.hpp"
#include "drape/formats/avatar_motion.hpp"
#include "drape/motion/clip_io.hpp"
#include "drape/motion/jointmap.hpp"
#include "drape/motion/skeleton.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::motion {

struct RetargetOptions {
  /// Start the root at the avatar's rest position on the floor plane (x, z), instead of
  /// where the capture volume had it; heights always follow the motion.
  bool anchorRootAtRest = true;
  /// Multiplies the root path instead of the leg-length ratio, if > 0.
  double rootScale = 0.0;
  /// Follow the capture's floor: per frame, lower or raise the whole body so that its
  /// lowest point over each one-second window (about a gait cycle) meets the avatar's
  /// floor (see groundCorrection()).
  bool groundFeet = true;
};

/// Retargeting one pose at a time: what AvatarAnimation::build does for each frame of a
/// clip (the rest corrections, the scaled root path, the hub), for a motion that arrives
/// frame by frame (a live capture, live_motion.hpp). Grounding, a correction over a window of
/// frames, is the caller's: build() centres its window, a live motion trails it.
class Retargeter {
 public:
  /// `avatar` must outlive the retargeter. Throws drape::Error naming `source` when no
  /// motion joint drives the avatar's root.
  Retargeter(const scene::Avatar& avatar, const Skeleton& skeleton, const JointMap& map, const RetargetOptions& options,
             const std::string& source);

  /// The avatar joints' world transforms for one pose of the motion (its local rotations and
  /// root translation, m), before grounding. The first call fixes where the root path starts.
  /// `out` has jointCount() entries. Allocates nothing.
  void retarget(std::span<const Quat> local, const Vec3& root, std::span<RigidTransform> out);

  /// m, the avatar's lowest point above its floor in the pose `world` (sampled, up to 256
  /// points per segment); the quantity grounding follows.
  [[nodiscard]] double lowestAboveFloor(std::span<const RigidTransform> world) const;
  [[nodiscard]] bool hasGroundSamples() const { return !samples_.empty(); }

  [[nodiscard]] std::size_t jointCount() const { return driving_.size(); }
  [[nodiscard]] std::span<const int> drivingJoint() const { return driving_; }
  [[nodiscard]] double rootScale() const { return rootScale_; }
  [[nodiscard]] double floor() const { return floor_; }  ///< m, the avatar's lowest rest point

 private:
  const scene::Avatar* avatar_;
  Skeleton skeleton_;
  RetargetOptions options_;
  std::vector<int> driving_;
  int hub_ = -1;
  std::vector<std::uint8_t> aboveHub_;
  std::optional<Quat> facing_;
  std::vector<Quat> correction_;
  double rootScale_ = 1.0, floor_ = 0.0;
  std::vector<std::pair<int, Vec3>> samples_;
  bool started_ = false;
  std::vector<RigidTransform> motionWorld_;
  std::vector<Quat> delta_;
  std::vector<Vec3> position_, firstRoot_;
};

/// Frames on either side of a frame in grounding's windows at `rate` (half a second).
[[nodiscard]] std::size_t groundHalfWindow(double rate);

class AvatarAnimation {
 public:
  /// Retargets `clip` onto `avatar` through `map` (motion joint -> avatar joint).
  /// Throws drape::Error if the avatar's root joint is driven by no motion joint.
  [[nodiscard]] static AvatarAnimation build(const scene::Avatar& avatar, const Clip& clip, const JointMap& map,
                                             const RetargetOptions& options = {});

  /// The avatar's own motion from the file it was loaded from (a glTF, Collada or FBX
  /// animation of its skin): each avatar joint follows the joint of the same name, no retargeting. The
  /// file's rest pose must be the avatar's, up to the placement and uniform scale a scene
  /// gives the avatar (found from the joints' rest positions and applied to the motion).
  /// Throws drape::Error naming `source` when a joint is missing or rests elsewhere.
  [[nodiscard]] static AvatarAnimation fromJointMotion(const scene::Avatar& avatar,
                                                       const formats::SkinnedJointMotion& motion,
                                                       const std::string& source);

  /// The other way: this animation of `avatar` (the one it was built for) as the motion of
  /// its joints, each frame's rotations from the joints' rest orientations and their world
  /// positions, named `name`: what a skinned-avatar writer takes to write the avatar with
  /// its motion (`drape convert --motion`).
  [[nodiscard]] formats::SkinnedJointMotion toJointMotion(const scene::Avatar& avatar, const std::string& name) const;

  /// An animation that arrives frame by frame (a studio pose stream, studio/): `joints`
  /// joints at `rate` frames per second, frame 0 at time code `start`, no frames yet;
  /// appendFrame adds them. `driving` is what drivingJoint() reports (the sender's).
  [[nodiscard]] static AvatarAnimation streamed(std::size_t joints, double rate, TimeCode start,
                                                std::vector<int> driving);
  /// Adds frame frameCount(): every joint's world transform, exactly as sent; its inverse is
  /// computed as build() computes it, so a streamed copy of an animation evaluates to the
  /// same bits. Throws drape::Error (Internal) on a frame of the wrong size.
  void appendFrame(std::span<const RigidTransform> world);

  [[nodiscard]] std::size_t frameCount() const { return frames_; }
  [[nodiscard]] std::size_t jointCount() const { return joints_; }
  [[nodiscard]] double rate() const { return rate_; }          ///< frames per second
  [[nodiscard]] TimeCode start() const { return start_; }      ///< time code of frame 0
  [[nodiscard]] double duration() const { return frames_ > 1 ? static_cast<double>(frames_ - 1) / rate_ : 0.0; }

  /// Exact joint world transforms of frame f (< frameCount()).
  [[nodiscard]] std::span<const RigidTransform> frame(std::size_t f) const {
    return {world_.data() + f * joints_, joints_};
  }
  /// Joint world transforms at time (f + s) / rate(), s in [0, 1]; f + 1 is clamped to the
  /// last frame. out.size() must be jointCount(). Allocates nothing.
  void evaluate(std::size_t f, double s, std::span<RigidTransform> out) const;
  /// One joint of evaluate(): each joint is interpolated on its own (section 4.3.1), so a
  /// caller that needs a few joints per substep pays for those only.
  [[nodiscard]] RigidTransform evaluateJoint(std::size_t f, double s, std::size_t joint) const;
  /// The interpolated inverses (world -> joint frame), interpolated on their own as the
  /// paper does. Allocates nothing.
  void evaluateInverse(std::size_t f, double s, std::span<RigidTransform> out) const;

  /// Replaces frame f's joint world transforms by `world` (their inverses follow): a
  /// correction of the retargeted pose, such as limbs swung about their joints out of the
  /// body (sim/keep_apart.hpp). The root's path is not changed. Throws drape::Error
  /// (Internal) on a frame of the wrong size.
  void setFrame(std::size_t f, std::span<const RigidTransform> world);

  /// m, world position of the root joint per frame (the path the character travels).
  [[nodiscard]] std::span<const Vec3> rootPath() const { return rootPath_; }
  /// The ratio applied to the motion's root path (leg-length ratio unless overridden).
  [[nodiscard]] double rootScale() const { return rootScale_; }
  /// m, root height for a motion root height of 0 before grounding: the avatar's floor
  /// (its lowest rest vertex); root y = rootHeightOffset() + rootScale() * motion root y
  /// - groundCorrection()[f].
  [[nodiscard]] double rootHeightOffset() const { return rootHeightOffset_; }
  /// m per frame, how far the whole body was lowered to follow the capture's floor
  /// (zeros when RetargetOptions::groundFeet is off).
  [[nodiscard]] std::span<const double> groundCorrection() const { return ground_; }
  /// For each avatar joint, the motion joint driving it (-1: follows its parent).
  [[nodiscard]] std::span<const int> drivingJoint() const { return driving_; }

 private:
  std::size_t frames_ = 0;
  std::size_t joints_ = 0;
  double rate_ = 30.0;
  TimeCode start_;
  double rootScale_ = 1.0;
  double rootHeightOffset_ = 0.0;
  std::vector<RigidTransform> world_;     ///< frame-major frames_ x joints_
  std::vector<RigidTransform> inverse_;   ///< same layout, world_[i].inverse()
  std::vector<Vec3> rootPath_;
  std::vector<double> ground_;
  std::vector<int> driving_;
};

/// What `drape run --motion FILE` needs in one call.
struct MotionOptions {
  ClipLoadOptions clip;            ///< rate (default 30 Hz), --motion-scale, ASF path
  std::string jointMapPath;        ///< --joint-map FILE (checked strictly); "" = choose
  std::string jointMapDirectory;   ///< the shipped maps (share/drape/jointmaps)
  std::string animation;           ///< --animation: which of an avatar file's animations ("" the first)
  RetargetOptions retarget;
  /// The avatar file's animation already sampled at clip.rate (by a caller that read the
  /// file to find it): taken instead of reading the file again. Null: read it.
  const formats::SkinnedJointMotion* sampled = nullptr;
};

/// The joint map for `clip` on `avatar`: options.jointMapPath's (checked strictly), or the
/// shipped map of options.jointMapDirectory that pairs the most joints.
[[nodiscard]] JointMap jointMapFor(const Clip& clip, const scene::Avatar& avatar, const MotionOptions& options);

/// Loads FILE.bvh / FILE.amc, picks or reads the joint map, and retargets onto `avatar`;
/// or takes one of FILE.glb / .gltf / .dae / .fbx's animations, or of FILE.wrl's animated
/// H-Anim Humanoids (options.animation, by default the first), as the avatar's own motion
/// when the avatar is that file's (AvatarAnimation::fromJointMotion), retargeted like a
/// BVH's onto any other; `report` then gives the frames as sampled. Throws drape::Error
/// (exit code 2) naming the file, line and problem.
[[nodiscard]] AvatarAnimation loadAnimation(const scene::Avatar& avatar, const std::string& motionPath,
                                            const MotionOptions& options, ClipLoadReport* report = nullptr,
                                            JointMap* chosenMap = nullptr);

/// The paper's caveat, measured: over every frame and `substeps` substeps, the largest
/// distance (m) between an interpolated joint's origin and the point of its interpolated
/// parent it is attached to.
[[nodiscard]] double maxJointSeparation(const AvatarAnimation& animation, const scene::Avatar& avatar, int substeps);

}  // namespace drape::motion
