#include "drape/render/frame.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::render {

MeshRole parseMeshRole(const std::string& role) {
  if (role == "garment") return MeshRole::Garment;
  if (role == "segment") return MeshRole::Segment;
  if (role == "skin") return MeshRole::Skin;
  if (role == "drawn") return MeshRole::Drawn;
  throw Error(fmt::format("mesh role '{}' is not one of: garment, segment, skin, drawn", role));
}

bool hasSkin(const std::vector<MeshInfo>& meshes, const std::string& character) {
  return std::any_of(meshes.begin(), meshes.end(),
                     [&](const MeshInfo& m) { return m.role == MeshRole::Skin && m.character == character; });
}

bool hasSkin(const std::vector<MeshInfo>& meshes) {
  return std::any_of(meshes.begin(), meshes.end(), [](const MeshInfo& m) { return m.role == MeshRole::Skin; });
}

Aabb frameBounds(const Frame& frame) {
  Aabb box;
  for (const std::vector<Vec3>& mesh : frame.positions)
    for (const Vec3& p : mesh) box.extend(p);
  return box;
}

}  // namespace drape::render
