#pragma once
// A humanoid skeleton's parts found by its shape alone: which joints are the pelvis, the
// spine, the neck and head, and each leg's and arm's bones, from the joint tree and the
// joints' rest positions (y up), whatever the joints are called. CesiumMan's glTF names
// its joints joint0 .. joint18; a capture or a rig in another language names them in
// words no shipped map knows. `drape make-skirt` finds the lower body it fits a skirt to
// this way, and motion's `shapeJointMap` pairs two skeletons' joints bone for bone.
//
// The rules, for a standing rest pose (T or A), in docs/MOTION.md ("Joint maps by shape"):
// the legs part at the shallowest joint with two children reaching the floor, and the
// pelvis is that joint or the first above it that a spine leaves; the leg is the path from
// such a child down to its lowest joint, the ankle its first joint near the
// floor, the knee the joint before it nearest the mid-height of the pelvis and the ankle,
// the hip the first joint a quarter as far out of the body's middle as the knee is; the
// spine runs from the pelvis towards the highest joint until it turns to a side, the chest
// where the two branches reaching farthest to the sides leave it, the head where the way up
// from the chest's other child branches or ends (a robot may have none); an arm's wrist is where its path branches (the fingers) or ends, the
// elbow the joint nearest 45 % of the way from the wrist back to the arm's start, the
// shoulder the last joint before it at least 0.85 forearms from the elbow.

#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::scene {

/// A joint of a tree, as the shape sees it.
struct JointAt {
  int parent = -1;           ///< parents come first
  Vec3 rest = Vec3::Zero();  ///< world position at rest, y up
  /// Whether any of the body moves with it. False for an avatar's joint without a segment:
  /// the end markers rigs carry at their tips (Mixamo's HeadTop_End), which no bone starts.
  bool carries = true;
  /// For a joint without children whose segment reaches on past it: the segment's point
  /// farthest from the joint, at rest. A robot's arm may end at its elbow, whose segment is
  /// the forearm and the hand; the arm's shape is read to there.
  std::optional<Vec3> tip = std::nullopt;
};

/// Joints in order from parent to child; empty where the skeleton has no such bone.
using JointChain = std::vector<int>;

/// A limb's bones, each the chain of joints that moves as one bone (a twist joint after
/// its bone's first joint).
struct HumanoidLimb {
  JointChain base;   ///< between the trunk and the limb: a hip bone (LHipJoint), a clavicle
  JointChain upper;  ///< thigh, upper arm: from the hip or shoulder joint
  JointChain lower;  ///< shin, forearm: from the knee or elbow
  JointChain end;    ///< foot, hand: from the ankle or wrist
  JointChain tip;    ///< the toe (the joint after the ankle on the way down); empty for an arm
};

struct Humanoid {
  int pelvis = -1;               ///< where the spine leaves the legs' way
  JointChain abovePelvis;        ///< the pelvis's ancestors (a floor root), root first
  JointChain hips;               ///< below the pelvis down to where the legs part (H-Anim's sacroiliac); mostly empty
  JointChain spine;              ///< the pelvis's child up to the chest, which the arms leave
  JointChain neck;               ///< the chest's child up to the head (its last joint); empty without a head
  std::array<HumanoidLimb, 2> legs;  ///< [0] left, [1] right
  std::array<HumanoidLimb, 2> arms;  ///< [0] left, [1] right
  Vec3 forward = Vec3::UnitZ();  ///< the way the toes point, horizontal, unit

  /// The joint the head's last bone starts at.
  [[nodiscard]] int head() const { return neck.empty() ? -1 : neck.back(); }
  /// The chest: the spine's last joint.
  [[nodiscard]] int chest() const { return spine.empty() ? -1 : spine.back(); }
};

/// The humanoid in `joints`, or nullopt with `whyNot` (when given) saying what was not
/// found ("no joint has two children reaching the floor (the legs)", ...).
[[nodiscard]] std::optional<Humanoid> findHumanoid(std::span<const JointAt> joints, std::string* whyNot = nullptr);

/// How a skeleton stands at rest: its head's axis in its own frame, and the quarter turn
/// that stands it up along +y as drape's scenes are. Robots from Choreonoid and OpenHRP,
/// and files from CAD and robotics tools, stand their bodies along +z.
struct Upright {
  std::string axis = "+y";       ///< "+y", "+z", "-z", "+x", "-x" or "-y"
  Quat turn = Quat::Identity();  ///< takes `axis` onto +y (a quarter or half turn)
  Humanoid humanoid;             ///< found in the turned frame

  /// The turn as a VRML97 SFRotation ("1 0 0 -1.5708"): the rotation of an Avatar node or
  /// Transform that stands the body up.
  [[nodiscard]] std::string rotationText() const;
  /// What a scene that leaves the body lying is to do: "give its Avatar node (or a Transform
  /// around its Humanoid) rotation 1 0 0 -1.5708 to stand it up".
  [[nodiscard]] std::string standUpAdvice() const;
};

/// The humanoid standing along +y, or along the first other axis that shows one; nullopt
/// with `whyNot` saying what is missing standing along +y.
[[nodiscard]] std::optional<Upright> findUpright(std::span<const JointAt> joints, std::string* whyNot = nullptr);

/// findUpright's answer for a body that stands along another axis than +y (what a scene
/// must turn to stand it up); nullopt where it stands along +y or is no humanoid at all.
[[nodiscard]] std::optional<Upright> uprightAlongAnotherAxis(std::span<const JointAt> joints);

/// The avatar's joints at rest, as findHumanoid reads them.
[[nodiscard]] std::vector<JointAt> jointsAt(const Avatar& avatar);

/// The segments a skirt is fitted to and collides with, found by the avatar's shape: the
/// waist at the first spine joint a little above the hips, the segments below it (the
/// pelvis's, the spine's below the waist, the hip bones') as hips, the thighs and shins as
/// legs; each only where the avatar has a segment of that joint.
struct LowerBody {
  std::string waist;
  std::vector<std::string> hips;
  std::vector<std::string> legs;
};

/// Throws drape::Error naming the avatar and what was not found when it is not humanoid
/// or has no segment at its waist.
[[nodiscard]] LowerBody findLowerBody(const Avatar& avatar);

/// The segments of the forearms, the hands and everything the hands carry (fingers), found
/// by the avatar's shape: what swings against a skirt as the arms walk. Throws
/// drape::Error naming the avatar when it is not humanoid.
[[nodiscard]] std::vector<std::string> findForearmsAndHands(const Avatar& avatar);

/// The segments of the upper arms and forearms, found by the avatar's shape: the parts a
/// walk swings into the hips, which a scene's keepApart turns out of them. Throws
/// drape::Error naming the avatar when it is not humanoid.
[[nodiscard]] std::vector<std::string> findUpperArmsAndForearms(const Avatar& avatar);

}  // namespace drape::scene
