#pragma once
// Pieces of the VRML97 scene files that `drape make-skirt` and `drape make-scene` write.

#include <filesystem>
#include <ostream>
#include <string>

#include <fmt/format.h>
#include <fmt/ostream.h>

#include "drape/cloth/material.hpp"
#include "drape/core/error.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::cli {

/// The coord and coordIndex fields of an IndexedFaceSet, one vertex or triangle per line.
inline void writeIndexedFaceSet(std::ostream& os, const mesh::TriMesh& m, const std::string& indent) {
  fmt::print(os, "{}coord Coordinate {{ point [\n", indent);
  for (const Vec3& p : m.positions) fmt::print(os, "{}  {:.5f} {:.5f} {:.5f},\n", indent, p.x(), p.y(), p.z());
  fmt::print(os, "{}] }}\n{}coordIndex [\n", indent, indent);
  for (const auto& t : m.triangles) fmt::print(os, "{}  {} {} {} -1,\n", indent, t[0], t[1], t[2]);
  fmt::print(os, "{}]\n", indent);
}

/// A ClothMaterial node named Knit with the material's values.
inline void writeMaterial(std::ostream& os, const cloth::Material& m) {
  fmt::print(os,
             "DEF Knit ClothMaterial {{\n  density {:g}\n  thickness {:g}\n  youngsModulus {:g}\n"
             "  poissonRatio {:g}\n  damping {:g}\n  staticFriction {:g}\n  dynamicFriction {:g}\n"
             "  compressionScale {:g}\n}}\n\n",
             m.density_kg_m3, m.thickness_m, m.youngsModulus_Pa, m.poissonRatio, m.damping_s, m.staticFriction,
             m.dynamicFriction, m.compressionScale);
}

/// Creates the scene's directory (`--out`) and returns the Avatar url to write: `avatarUrl`
/// if given, else the avatar's path relative to that directory.
inline std::string prepareSceneDir(const std::string& out, const std::string& avatar, const std::string& avatarUrl) {
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  if (ec) throw Error(fmt::format("--out {}: cannot create the directory ({})", out, ec.message()));
  if (!avatarUrl.empty()) return avatarUrl;
  return std::filesystem::relative(std::filesystem::absolute(avatar), std::filesystem::absolute(out)).string();
}

}  // namespace drape::cli
