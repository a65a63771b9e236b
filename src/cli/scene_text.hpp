#pragma once
// Pieces of the VRML97 scene files that `drape make-skirt` and `drape make-scene` write.

#include <ostream>
#include <string>

#include <fmt/ostream.h>

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

}  // namespace drape::cli
