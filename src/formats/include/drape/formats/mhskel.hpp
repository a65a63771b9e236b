#pragma once
// MakeHuman rig files (JSON, version 110), read with nlohmann_json. Syntax only; the
// avatar builder (scene/avatar_makehuman.hpp) resolves joints against the base mesh.
//  - .mhskel: bones {name: {parent, head, tail, reference, weights_reference}} and joints
//    {name: [base-mesh vertex indices]}; a joint's position is the mean of its vertices.
//  - .mhw: skin weights {bone: [[vertex, weight], ...]}, not normalised.
// Vertex indices are 0-based into the base mesh's `v` lines, in file order.

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace drape::formats {

struct MhBone {
  std::string name;
  std::string parent;  ///< "" for the root
  std::string head;    ///< joint name
  std::string tail;    ///< joint name
  std::vector<std::string> reference;         ///< default-rig bones this bone stands for
  std::vector<std::string> weightsReference;  ///< if present, where its weights come from
};

struct MhSkeleton {
  std::string source;
  std::string name;
  std::vector<MhBone> bones;  ///< breadth-first from the one root (parents first)
  std::map<std::string, std::vector<std::uint32_t>> joints;

  [[nodiscard]] int find(std::string_view bone) const;
};

struct MhWeights {
  std::string source;
  std::map<std::string, std::vector<std::pair<std::uint32_t, float>>> weights;
};

/// Throws drape::Error "name:line:column: ..." on bad JSON, "name: ..." on a bad structure
/// (missing keys, two roots, a cycle, an unknown parent or joint).
[[nodiscard]] MhSkeleton parseMhskel(std::string_view json, const std::string& name);
[[nodiscard]] MhSkeleton readMhskel(const std::string& path);
[[nodiscard]] MhWeights parseMhw(std::string_view json, const std::string& name);
[[nodiscard]] MhWeights readMhw(const std::string& path);

/// From makehuman_to_cmu_joint_map.json: default-rig bone -> BVH joint that receives its
/// weights ("default_bone_weights_to_bvh", or the "_neck_fix" variant).
[[nodiscard]] std::map<std::string, std::string> readMakeHumanWeightFold(const std::string& path, bool neckFix = false);

}  // namespace drape::formats
