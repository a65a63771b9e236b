#pragma once
// Skinned characters in Collada (.dae) and FBX (.fbx), read and written through Assimp.
// (glTF stays on drape's own reader, gltf_avatar.hpp: Assimp's glTF2 importer crashed on
// CesiumMan.)
//
// Safety rules for files from outside (Assimp is not safe on malformed input):
//   - the bytes must look like the format the extension names (Collada: XML whose root
//     element is <COLLADA>; FBX: "Kaydara FBX Binary" or a text file starting "; FBX");
//   - only the importer for that extension is registered, so nothing falls through to
//     another of Assimp's ~50 readers;
//   - Assimp sees the avatar's own bytes and nothing else: every other file it asks for
//     (textures, external references) is refused, so images are never read and nothing
//     outside the avatar's folder is ever opened;
//   - every import runs in a limited child process (core/isolate.hpp), so a crash, a hang
//     or a memory blow-up is an error message naming the file.
//
// Units and axes: Assimp applies Collada's <unit meter> and <up_axis> to the root node.
// Its FBX importer applies neither: it reports GlobalSettings' UnitScaleFactor
// (centimetres per unit, 1 by default) and UpAxis/CoordAxis in the scene metadata, and
// drape applies them. The result is in metres, Y up.

#include <string>
#include <string_view>
#include <vector>

#include "drape/core/isolate.hpp"
#include "drape/formats/skinned_model.hpp"

namespace drape::formats {

/// True for the extensions read and written here (".dae", ".fbx"; any case).
[[nodiscard]] bool isAssimpAvatarPath(const std::string& path);

/// Parses Collada or FBX bytes in this process (for the fuzz target and the child). The
/// extension of `name` picks the format; `name` is also what messages call the file.
/// `parts`, when given, names the skinned meshes to read by node or mesh name (the
/// skeleton is still every skinned mesh's); a name that matches none is an error listing them.
[[nodiscard]] SkinnedModel parseAssimpSkinnedModel(std::string_view bytes, const std::string& name,
                                                   const std::vector<std::string>& parts = {});

/// Reads a .dae/.fbx file in a limited child process. Throws drape::Error naming the file.
[[nodiscard]] SkinnedModel readAssimpSkinnedModel(const std::string& path, const std::vector<std::string>& parts = {},
                                                  const IsolationLimits& limits = {});

/// One animation of Collada or FBX bytes as the motion of the skin's joints (the skeleton
/// parseAssimpSkinnedModel reads), sampled at `rate` from its first key time to its last:
/// translation and scale keys linear, rotation keys by SLERP, each held before its first
/// key and after its last, each node's own transform where no key drives it; key times
/// in Assimp's ticks at the file's ticks per second (25 where it gives none). `animation`
/// is a name, an index from 0 in decimal digits, or "" for the first. Throws drape::Error
/// naming the file; a file without animations, or without the one asked for, is an error.
[[nodiscard]] SkinnedJointMotion parseAssimpJointMotion(std::string_view bytes, const std::string& name, double rate,
                                                        const std::string& animation = "");
/// Every animation of the bytes, sampled the same way (none: an empty list).
[[nodiscard]] std::vector<SkinnedJointMotion> parseAssimpJointMotions(std::string_view bytes, const std::string& name,
                                                                      double rate);

/// The same from a .dae/.fbx file, in a limited child process.
[[nodiscard]] SkinnedJointMotion readAssimpJointMotion(const std::string& path, double rate,
                                                       const std::string& animation = "",
                                                       const IsolationLimits& limits = {});
[[nodiscard]] std::vector<SkinnedJointMotion> readAssimpJointMotions(const std::string& path, double rate,
                                                                     const IsolationLimits& limits = {});

/// Writes `model` (metres, Y up) as Collada 1.4 (.dae, in metres) or as ASCII FBX 7.5
/// (.fbx, in centimetres as its UnitScaleFactor 1 says): the skeleton as a node tree, one
/// skinned mesh, one bone per weighted joint, and each of `animations` (motions of the
/// model's joints, every joint named in each) as keys of its joints' local translation,
/// rotation and scale at every sampled frame. Binary FBX is not written: what Assimp
/// 5.2's binary FBX exporter writes, its own FBX importer cannot read back. Throws
/// drape::Error naming the path.
void writeAssimpSkinnedModel(const std::string& path, const SkinnedModel& model,
                             const std::vector<SkinnedJointMotion>& animations = {});

}  // namespace drape::formats
