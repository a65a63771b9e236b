#pragma once
// The bundled MakeHuman body (CMU-named rig), loaded once per test process: the avatar the
// motion tests retarget, skin and write.

#include <string>

#include "drape/scene/avatar_gltf.hpp"

namespace drape::motion {

inline const scene::Avatar& makeHuman() {
  static const scene::Avatar avatar =
      scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  return avatar;
}

}  // namespace drape::motion
