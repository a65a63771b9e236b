#pragma once
// The bundled examples' files, as the tests that run them name them.

#include <string>

namespace drape::testing {

inline const std::string kSkirtScene = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/scene.wrl";
inline const std::string kSkirtWalk = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh";
inline const std::string kDressScene = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_dress/scene.wrl";

}  // namespace drape::testing
