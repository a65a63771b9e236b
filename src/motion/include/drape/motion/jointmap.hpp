#pragma once
// Joint name maps: which motion joint drives which avatar joint. drape's avatars use the
// CMU MotionBuilder-style names of the cgspeed BVH conversions (Hips, LeftUpLeg, LeftLeg,
// ...); maps for the MotionBuilder, 3ds Max and Daz/Poser naming styles ship as JSON in
// share/drape/jointmaps/, and `--joint-map FILE` reads any other:
//
//   { "name": "daz", "description": "...", "joints": { "hip": "Hips", "lThigh": "LeftUpLeg" } }
//
// Keys are motion joints, values avatar joints, or lists of avatar joints (parent first)
// where a rig splits one motion bone into several (twist joints):
//
//   { "name": "makehuman_default", "joints": { "LeftUpLeg": ["upperleg01.L", "upperleg02.L"] } }
//
// A rig's map from drape's names onto its own composes with a naming style's map
// (chooseJointMap tries the pairs), and every map also serves the other way round
// (reverseJointMap): a naming style's map drives an avatar of that style from drape's
// names, so a CMU capture walks a Mixamo character or an H-Anim humanoid.

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drape/motion/skeleton.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::motion {

/// A 1-based line and column in a map's file; 0 where the entry was built in code.
struct TextPos {
  int line = 0;
  int column = 0;
};

struct JointMapEntry {
  std::string motionJoint;
  std::string avatarJoint;
  TextPos at;        ///< where the entry's key (the motion joint) is written
  TextPos avatarAt;  ///< where its avatar joint is written
};

struct JointMap {
  std::string name;
  std::string source;  ///< file it came from, for messages
  std::vector<JointMapEntry> entries;

  /// The avatar joint `motionJoint` drives, or nullptr.
  [[nodiscard]] const std::string* avatarJointFor(std::string_view motionJoint) const;
  /// A map that pairs every joint with the avatar joint of the same name.
  [[nodiscard]] static JointMap identity(const Skeleton& skeleton);
};

/// Parses a map; throws drape::Error "name:line:column: ..." on bad JSON or structure.
[[nodiscard]] JointMap parseJointMap(std::string_view json, const std::string& name);
[[nodiscard]] JointMap readJointMap(const std::string& path);
/// Every *.json map in `directory`, sorted by name (empty if the directory is missing).
[[nodiscard]] std::vector<JointMap> readJointMapDirectory(const std::string& directory);

/// Number of entries of `map` whose motion joint is in `skeleton` and avatar joint in `avatar`.
[[nodiscard]] std::size_t matchedJointCount(const JointMap& map, const Skeleton& skeleton, const scene::Avatar& avatar);

/// `first` then `second`: motion joint m drives r wherever `first` pairs m with a joint c
/// and `second` pairs c with r (a naming style's map, then a rig's map from drape's names).
[[nodiscard]] JointMap composeJointMaps(const JointMap& first, const JointMap& second);

/// `map` read the other way round, named "NAME (reversed)": each of its avatar joints, as a
/// motion joint, drives the motion joint it was driven by. One to one, the first written
/// entry kept: where two motion joints drove one avatar joint (a style's alternative names,
/// 3ds Max's Spine1 and Chest), or one drove a chain, the later ones are left out.
[[nodiscard]] JointMap reverseJointMap(const JointMap& map);

/// The candidate, a candidate reversed (reverseJointMap), an ordered pair of those composed
/// (composeJointMaps) or the identity map that pairs the most joints of `skeleton` with
/// `avatar`; a later one only where it pairs strictly more, so a reversed map or a pair is
/// chosen only where no candidate as written does as well.
[[nodiscard]] JointMap chooseJointMap(const std::vector<JointMap>& candidates, const Skeleton& skeleton,
                                      const scene::Avatar& avatar);

/// The motion's joints paired with the avatar's by both skeletons' humanoid shape
/// (scene::findHumanoid), whatever either calls its joints; named "by shape". The pelvis
/// drives the pelvis; each limb's bone (hip bone or clavicle, thigh or upper arm, shin or
/// forearm, foot or hand, toe) drives the same bone, a chain where the avatar splits it
/// (twist joints); each of the avatar's spine and neck joints is driven by the motion's
/// joint nearest its height between the pelvis and the chest, or between the chest and the
/// head, so chest drives chest and head drives head. The motion's joints left over (its
/// own twist joints, fingers) drive nothing: their turns reach the avatar through the
/// joints below them, which are paired by their world rotation. nullopt, with `whyNot`
/// saying which skeleton is no humanoid and why, where either is not.
[[nodiscard]] std::optional<JointMap> shapeJointMap(const Skeleton& skeleton, const scene::Avatar& avatar,
                                                    std::string* whyNot = nullptr);

/// Whether `map` drives the avatar's root, or the joint where its legs and spine part (the
/// pelvis under a floor root, which the retargeter carries): where no named map does, the
/// joints are paired by shape instead.
[[nodiscard]] bool drivesTheTrunk(const JointMap& map, const Skeleton& skeleton, const scene::Avatar& avatar);

/// A user's map must name only joints that exist: throws "file:line:column: unknown motion
/// joint 'X' ..." (at its key) or "... unknown avatar joint 'Y' ..." (at that joint's name).
void checkJointMap(const JointMap& map, const Skeleton& skeleton, const scene::Avatar& avatar);

}  // namespace drape::motion
