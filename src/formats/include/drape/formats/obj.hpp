#pragma once
// Wavefront OBJ through tinyobjloader: garments, masks, body meshes in, frames out.

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

struct ObjReadOptions {
  double metresPerUnit = 1.0;       ///< scale applied to every position
  std::vector<std::string> groups;  ///< keep only faces of these g/o groups (empty: all)
  bool keepUnusedVertices = true;   ///< false: drop vertices no kept face uses (renumbers)
};

/// Parses OBJ text read from `name` (used in messages); polygons are triangulated as fans.
/// Throws drape::Error "name:line:column: what" for a vertex line without three finite
/// coordinates, "name: what" for other syntax errors (tinyobjloader's text, which names the
/// line), faces that refer to missing vertices, or an empty mesh. mtllib lines are ignored.
/// `groupsRead`, when given, receives the groups whose faces were kept, in the file's order
/// (those ObjReadOptions::groups' names and patterns matched).
[[nodiscard]] mesh::TriMesh parseObj(std::string_view text, const std::string& name, const ObjReadOptions& options = {},
                                     std::vector<std::string>* groupsRead = nullptr);
/// Reads and parses an OBJ file; "file: ..." also for a missing or unreadable file.
[[nodiscard]] mesh::TriMesh readObj(const std::string& path, const ObjReadOptions& options = {},
                                    std::vector<std::string>* groupsRead = nullptr);

/// Writes positions and triangles as OBJ (positions in metres, 1-based indices).
void writeObj(const std::string& path, std::span<const Vec3> positions,
              std::span<const mesh::Triangle> triangles, const std::string& comment = {});

}  // namespace drape::formats
