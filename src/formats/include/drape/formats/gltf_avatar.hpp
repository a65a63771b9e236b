#pragma once
// Skinned characters from glTF 2.0 (.gltf, .glb), read by drape's own reader (GLB chunks,
// then the JSON through nlohmann_json) inside a limited child process (core/isolate.hpp),
// handed back as plain data. The skeleton is the first skin's joints and those of every
// skin that shares joints with it (exporters that write one skin per mesh list one
// skeleton's joints several times over); the triangle primitives of the nodes those skins
// move are read, and on request one animation as the motion of the skeleton's joints.
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

/// True for the extensions of glTF files (".gltf", ".glb", and ".vrm": VRoid Studio's and
/// UniVRM's avatars, binary glTF with VRM's extensions, which drape does not need; any case).
[[nodiscard]] bool isGltfPath(const std::string& path);

// The glTF reader's result is the neutral plain data every skinned reader returns.
using GltfJoint = SkinnedJoint;
using GltfSkinnedModel = SkinnedModel;

/// Parses glTF/GLB bytes in this process (for the fuzz target and the child). `baseDir` is
/// the folder external URIs must stay inside ("" allows data: URIs only). `parts`, when
/// given, names the skinned meshes to read by node or mesh name (the body of a character
/// whose file holds its clothes too); a name that matches none, or a mesh of another
/// skin, is an error listing the skin's meshes.
[[nodiscard]] GltfSkinnedModel parseGltfSkinnedModel(std::string_view bytes, const std::string& name,
                                                     const std::string& baseDir, const std::vector<std::string>& parts = {});

/// Reads a .gltf/.glb file in a limited child process. Throws drape::Error naming the file.
[[nodiscard]] GltfSkinnedModel readGltfSkinnedModel(const std::string& path, const std::vector<std::string>& parts = {},
                                                    const IsolationLimits& limits = {});

/// One of a glTF file's animations: channels follow the glTF 2.0 rules (translation,
/// rotation and scale of nodes, LINEAR with rotations by SLERP, STEP and CUBICSPLINE
/// samplers, each node's own transform where no channel drives it); morph target weights
/// are ignored.
using GltfJointMotion = SkinnedJointMotion;

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

/// Every animation of a glTF file, sampled the same way (none: an empty list).
[[nodiscard]] std::vector<GltfJointMotion> parseGltfJointMotions(std::string_view bytes, const std::string& name,
                                                                 const std::string& baseDir, double rate);
[[nodiscard]] std::vector<GltfJointMotion> readGltfJointMotions(const std::string& path, double rate,
                                                                const IsolationLimits& limits = {});

}  // namespace drape::formats
