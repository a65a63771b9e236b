#pragma once
// Static triangle meshes (a garment, its constraint mask) from the files modelling tools
// export: Wavefront OBJ, glTF 2.0 (.gltf, .glb), Collada (.dae) and FBX (.fbx).
//
// glTF goes through drape's own glTF reader, Collada and FBX through Assimp, each in a
// limited child process and under the safety rules of gltf_avatar.hpp and
// assimp_avatar.hpp. Every triangle of every mesh the file's scene shows is read, at
// the nodes' rest transforms (a skinned mesh skinned with its skeleton at rest), in metres
// with y up (glTF is in metres; Collada's <unit> and <up_axis>, FBX's UnitScaleFactor and
// axes are applied). Those files split a vertex wherever its texture coordinates or
// normals change, and may hold a garment's pieces as separate meshes whose seams
// coincide: the vertices are welded by position (mesh/weld.hpp) into the one surface the
// cloth simulates. An OBJ is read as it is (its vertices are already shared).

#include <string>
#include <string_view>
#include <vector>

#include "drape/core/isolate.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

struct MeshFileOptions {
  double metresPerUnit = 1.0;      ///< OBJ only: the other formats state their own unit
  /// Keep only these parts (empty: all): OBJ g/o groups; glTF, Collada and FBX nodes or
  /// meshes by name. A name that matches nothing is an error that lists the file's parts.
  std::vector<std::string> parts;
  double weldTolerance_m = 1e-6;   ///< positions this close are one vertex (not for OBJ)
  /// Keep the vertices no triangle uses (a mask: a vertex selection may be loose points, or
  /// lines); a garment leaves them out. An OBJ keeps every vertex it lists either way.
  bool looseVertices = false;
};

struct MeshFile {
  mesh::TriMesh mesh;                   ///< metres, y up; named after the file
  std::vector<std::string> partsRead;   ///< the nodes (an OBJ's groups) whose meshes were read, in the file's order; an OBJ read whole names none
  std::size_t welded = 0;               ///< vertices merged into another at the same position
  std::size_t droppedTriangles = 0;     ///< triangles welding collapsed or repeated (a two-sided copy)
};

/// What was read, for a log line after the file's name: "mesh Dress (2205 vertices, 4192
/// triangles; 10371 split vertices welded)", or "" for a file of one part read as it is
/// (an OBJ, nothing welded or dropped).
[[nodiscard]] std::string describeRead(const MeshFile& file);

/// True for the extensions readMeshFile takes (".obj", ".gltf", ".glb", ".vrm", ".dae", ".fbx"; any case).
[[nodiscard]] bool isMeshFilePath(const std::string& path);

/// Reads a mesh file of any of those formats. Throws drape::Error naming the file: an
/// unknown extension, a file without triangles, parts that match nothing.
[[nodiscard]] MeshFile readMeshFile(const std::string& path, const MeshFileOptions& options = {},
                                    const IsolationLimits& limits = {});

/// What a reader hands back before welding: every triangle of the parts asked for (with
/// `loose`, the vertices of their points and lines too), and the names of every part the
/// file has (for messages).
struct MeshParts {
  mesh::TriMesh mesh;
  std::vector<std::string> read, all;
};

/// Whether a mesh placed by a node called `part` (its node's name, or its mesh's where the
/// node has none) is one of `parts`, by that name or its mesh's `meshName`, each of `parts`
/// a name or a shell pattern (part_names.hpp); every mesh is when `parts` is empty. Marks
/// in `matched` (as long as `parts`) the names it answers.
[[nodiscard]] bool partWanted(const std::vector<std::string>& parts, std::vector<bool>& matched, const std::string& part,
                              const std::string& meshName);

/// Throws drape::Error naming the file `name` when a name in `parts` matched no mesh
/// (`matched`, in the same order), listing the file's meshes `all` (`what` says which kind).
void checkPartsMatched(const std::vector<std::string>& parts, const std::vector<bool>& matched,
                       const std::vector<std::string>& all, const std::string& name, const std::string& what = "meshes");

/// A reader's last check: every name in `parts` matched (`matched`, in the same order) and
/// something was read. Throws drape::Error naming the file `name` and listing its meshes.
void checkMeshParts(const MeshParts& read, const std::vector<std::string>& parts, const std::vector<bool>& matched,
                    bool loose, const std::string& name);

/// glTF/GLB bytes in this process (for the fuzz target and the child); `baseDir` as in
/// parseGltfSkinnedModel.
[[nodiscard]] MeshParts parseGltfMesh(std::string_view bytes, const std::string& name, const std::string& baseDir,
                                      const std::vector<std::string>& parts = {}, bool loose = false);
/// Collada or FBX bytes in this process (the extension of `name` picks the format).
[[nodiscard]] MeshParts parseAssimpMesh(std::string_view bytes, const std::string& name,
                                        const std::vector<std::string>& parts = {}, bool loose = false);

}  // namespace drape::formats
