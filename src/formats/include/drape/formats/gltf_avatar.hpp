#pragma once
// Skinned characters from glTF 2.0 (.gltf, .glb), read by drape's own reader (GLB chunks,
// then the JSON through nlohmann_json) inside a limited child process (core/isolate.hpp),
// handed back as plain data. Only the first skin and the triangle primitives of the nodes
// that use it are read. (Debian's compiled tinygltf did not match its own header's struct
// layout in our build: AddressSanitizer caught a bad free in Model's destructor.)
//
// Safety rules for files from outside: only glTF is parsed (no other importer to fall
// through to); buffer URIs may be base64 `data:` URIs or files inside the model's own
// folder (anything else is an error); images are never read; a skin without
// inverseBindMatrices gets identity matrices (the glTF spec's default); every accessor is
// bounds checked against its buffer view and buffer.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "drape/core/isolate.hpp"
#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

struct GltfJoint {
  std::string name;                          ///< the node's name, or "joint<i>" if it has none
  int parent = -1;                           ///< nearest ancestor that is a joint; parents come first
  Eigen::Matrix4d restWorld = Eigen::Matrix4d::Identity();  ///< node world transform in the file's rest pose
};

struct GltfSkinnedModel {
  std::string source;
  std::vector<GltfJoint> joints;
  std::vector<Vec3> positions;               ///< file units (glTF: m), skinned with the rest-pose nodes
  std::vector<mesh::Triangle> triangles;
  std::vector<std::array<std::uint16_t, 4>> vertexJoints;  ///< indices into joints
  std::vector<std::array<float, 4>> vertexWeights;         ///< normalised to sum 1
};

/// Parses glTF/GLB bytes in this process (for the fuzz target and the child). `baseDir` is
/// the folder external URIs must stay inside ("" allows data: URIs only).
[[nodiscard]] GltfSkinnedModel parseGltfSkinnedModel(std::string_view bytes, const std::string& name,
                                                     const std::string& baseDir);

/// Reads a .gltf/.glb file in a limited child process. Throws drape::Error naming the file.
[[nodiscard]] GltfSkinnedModel readGltfSkinnedModel(const std::string& path, const IsolationLimits& limits = {});

/// Plain-data round trip used across the process boundary.
[[nodiscard]] std::string serialise(const GltfSkinnedModel& model);
[[nodiscard]] GltfSkinnedModel deserialiseGltfSkinnedModel(std::string_view bytes, const std::string& name);

}  // namespace drape::formats
