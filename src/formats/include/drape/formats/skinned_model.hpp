#pragma once
// A skinned character as plain data: what every skinned-avatar reader (glTF through
// drape's own reader, Collada and FBX through Assimp) hands back across the isolation
// child's pipe, and what the avatar writers take.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

struct SkinnedJoint {
  std::string name;                          ///< the node's name, or "joint<i>" if it has none
  int parent = -1;                           ///< nearest ancestor that is a joint; parents come first
  Eigen::Matrix4d restWorld = Eigen::Matrix4d::Identity();  ///< node world transform in the file's rest pose
};

struct SkinnedModel {
  std::string source;
  std::vector<SkinnedJoint> joints;
  std::vector<Vec3> positions;               ///< m, Y up, skinned with the rest-pose nodes
  std::vector<mesh::Triangle> triangles;
  std::vector<std::array<std::uint16_t, 4>> vertexJoints;  ///< indices into joints
  std::vector<std::array<float, 4>> vertexWeights;         ///< normalised to sum 1
};

/// Plain-data round trip used across the process boundary. `name` is the file the bytes
/// came from, for messages.
[[nodiscard]] std::string serialise(const SkinnedModel& model);
[[nodiscard]] SkinnedModel deserialiseSkinnedModel(std::string_view bytes, const std::string& name);

}  // namespace drape::formats
