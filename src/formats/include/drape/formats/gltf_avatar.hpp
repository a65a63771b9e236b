#pragma once
// Skinned characters from glTF 2.0 (.gltf, .glb), read by drape's own reader (GLB chunks,
// then the JSON through nlohmann_json) inside a limited child process (core/isolate.hpp),
// handed back as plain data. Only the first skin and the triangle primitives of the nodes
// that use it are read, and on request one animation as the motion of that skin's joints.
// (Debian's compiled tinygltf did not match its own header's struct layout in our build:
// AddressSanitizer caught a bad free in Model's destructor.)
//
// Safety rules for files from outside: only glTF is parsed (no other importer to fall
// through to); buffer URIs may be base64 `data:` URIs or files inside the model's own
// folder (anything else is an error); images are never read; a skin without
// inverseBindMatrices gets identity matrices (the glTF spec's default); every accessor is
// bounds checked against its buffer view and buffer.

#include <string>
#include <string_view>
#include <vector>

#include "drape/core/isolate.hpp"
#include "drape/formats/skinned_model.hpp"

namespace drape::formats {

// The glTF reader's result is the neutral plain data every skinned reader returns.
using GltfJoint = SkinnedJoint;
using GltfSkinnedModel = SkinnedModel;

/// Parses glTF/GLB bytes in this process (for the fuzz target and the child). `baseDir` is
/// the folder external URIs must stay inside ("" allows data: URIs only).
[[nodiscard]] GltfSkinnedModel parseGltfSkinnedModel(std::string_view bytes, const std::string& name,
                                                     const std::string& baseDir);

/// Reads a .gltf/.glb file in a limited child process. Throws drape::Error naming the file.
[[nodiscard]] GltfSkinnedModel readGltfSkinnedModel(const std::string& path, const IsolationLimits& limits = {});

/// One of a glTF file's animations as the motion of its first skin's joints, sampled at a
/// fixed rate from the animation's first key time to its last. Channels follow the glTF
/// 2.0 rules: translation, rotation and scale of nodes, LINEAR (rotations by SLERP), STEP
/// and CUBICSPLINE samplers, each node's own transform where no channel drives it; morph
/// target weights are ignored.
struct GltfJointMotion {
  std::string animation;                  ///< its name, or "animation <index>"
  std::vector<std::string> animationNames;  ///< every animation's name ("animation <index>" if it has none)
  double rate = 30.0;                     ///< frames per second
  double start_s = 0.0, end_s = 0.0;      ///< the animation's first and last key times
  std::vector<std::string> joints;        ///< the skin's joints, parent-first and named as in GltfSkinnedModel
  std::vector<Vec3> restCenters;          ///< m, each joint's world position in the file's rest pose
  /// Frame-major, joint j of frame f at [f * joints.size() + j]: `rotation` turns the joint
  /// from its rest orientation (the rotation of W(t) W_rest^-1, W its node's world
  /// matrix), `translation` is its world position.
  std::vector<RigidTransform> frames;
  [[nodiscard]] std::size_t frameCount() const { return joints.empty() ? 0 : frames.size() / joints.size(); }
};

/// Samples one animation of glTF/GLB bytes in this process (for the fuzz target and the
/// child): `animation` is its name, or its index from 0 in decimal digits, or "" for the
/// first. Throws drape::Error naming the file and what is wrong; a file without
/// animations, or without the one asked for, is an error.
[[nodiscard]] GltfJointMotion parseGltfJointMotion(std::string_view bytes, const std::string& name,
                                                   const std::string& baseDir, double rate,
                                                   const std::string& animation = "");

/// Reads and samples one animation of a .gltf/.glb file in a limited child process.
[[nodiscard]] GltfJointMotion readGltfJointMotion(const std::string& path, double rate,
                                                  const std::string& animation = "",
                                                  const IsolationLimits& limits = {});

}  // namespace drape::formats
