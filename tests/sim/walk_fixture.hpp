#pragma once
// A walk on the MakeHuman body for the sim tests: the avatar, a motion retargeted onto it
// at 30 Hz, and distance fields of the parts a test looks at (5 mm voxels).

#include <string>
#include <vector>

#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim::fixture {

struct Walk {
  scene::Avatar avatar;
  motion::AvatarAnimation animation;
  std::vector<PartField> fields;
};

/// `motionPath` onto data/avatars/makehuman_rig_cmu_mb.mhskel; fields of `parts` with
/// shells of `shell_m`.
inline Walk loadWalk(const std::string& motionPath, const std::vector<std::string>& parts, double shell_m) {
  scene::Avatar avatar = scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  motion::MotionOptions mo;
  mo.clip.rate = 30.0;
  mo.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  motion::AvatarAnimation animation = motion::loadAnimation(avatar, motionPath, mo);
  field::FieldSettings fs;
  fs.voxelSize_m = 0.005;
  fs.shell_m = shell_m;
  std::vector<PartField> fields;
  for (const std::string& name : parts) {
    const scene::Segment& s = avatar.segments[static_cast<std::size_t>(avatar.findSegment(name))];
    fields.push_back({name, s.joint, field::DistanceField::build(s.mesh, fs)});
  }
  return Walk{std::move(avatar), std::move(animation), std::move(fields)};
}

}  // namespace drape::sim::fixture
