#pragma once
// The MakeHuman body as a segmented avatar: the hm08 base mesh (`g body`, 13380 vertices),
// the cmu_mb skeleton (31 bones named like the CMU MotionBuilder-style BVH joints, so CMU
// BVH files drive it directly), and the default skin weights folded onto the cmu_mb bones
// through makehuman_to_cmu_joint_map.json. Segments come from dominant weights, capped
// closed. Files are in decimetres; the avatar is in metres, Y up, facing +Z, in the
// space the MakeHuman garments are modelled in (so a dress fits it with the same scale).

#include <string>
#include <vector>

#include "drape/scene/avatar.hpp"

namespace drape::scene {

struct MakeHumanAvatarOptions {
  std::string directory;  ///< folder holding the files below
  std::string meshFile = "makehuman_base_hm08.obj";
  std::string meshGroup = "body";
  std::string skeletonFile = "makehuman_rig_cmu_mb.mhskel";
  std::string weightsFile = "makehuman_rig_default_weights.mhw";
  std::string weightFoldFile = "makehuman_to_cmu_joint_map.json";
  bool neckFix = false;          ///< use the geometric neck weight fold instead of MakeHuman's
  double metresPerUnit = 0.1;    ///< the files are in decimetres
};

/// Builds the avatar; throws drape::Error naming the file on any bad input.
[[nodiscard]] Avatar buildMakeHumanAvatar(const MakeHumanAvatarOptions& options);

/// Builds the avatar from a .mhskel path (the other files are looked up next to it; a
/// skeleton other than cmu_mb still uses the default weights folded by bone name through
/// its bones' "reference" lists).
[[nodiscard]] Avatar loadMakeHumanAvatar(const std::string& mhskelPath);

/// Every vertex of the base mesh next to a .mhskel (body, helpers and joint cubes, in file
/// order, as the rig and .mhclo files index them), in metres.
[[nodiscard]] std::vector<Vec3> loadMakeHumanBaseVertices(const std::string& mhskelPath);

}  // namespace drape::scene
