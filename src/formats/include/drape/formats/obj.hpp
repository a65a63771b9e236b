#pragma once
// Wavefront OBJ through tinyobjloader: garments, masks, body meshes in, frames out.

#include <span>
#include <string>
#include <vector>

#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

struct ObjReadOptions {
  double metresPerUnit = 1.0;       ///< scale applied to every position
  std::vector<std::string> groups;  ///< keep only faces of these g/o groups (empty: all)
  bool keepUnusedVertices = true;   ///< false: drop vertices no kept face uses (renumbers)
};

/// Reads an OBJ file; polygons are triangulated as fans. Throws drape::Error with
/// "file:line: what" for syntax errors, "file: ..." for a missing file or an empty mesh.
[[nodiscard]] mesh::TriMesh readObj(const std::string& path, const ObjReadOptions& options = {});

/// Writes positions and triangles as OBJ (positions in metres, 1-based indices).
void writeObj(const std::string& path, std::span<const Vec3> positions,
              std::span<const mesh::Triangle> triangles, const std::string& comment = {});

}  // namespace drape::formats
