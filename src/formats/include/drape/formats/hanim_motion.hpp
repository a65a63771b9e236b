#pragma once
// H-Anim humanoids' motions from VRML97 files: the interpolators that ROUTEs feed into a
// Humanoid's Joints (their translation, rotation, scale, center and scaleOrientation, and
// those of the Transforms between them and of the Humanoid itself), driven by TimeSensors,
// sampled into the SkinnedJointMotion that the skinned-avatar readers give. drape then
// plays a VRML97 humanoid's motion as it plays a glTF file's: on the humanoid itself, or
// retargeted onto another avatar (`drape run --motion walker.wrl`).
//
// The motion starts at time 0 and lasts the longest cycleInterval of the TimeSensors that
// drive the humanoid; a shorter looping sensor repeats within it, a shorter one that does not
// loop holds its last key. Joint positions and rotations are in the Humanoid's own frame
// (the coordinates of its humanoidBody): where the humanoid stands in the file is the
// avatar's placement, not its motion. Fields fed by anything but an interpolator (a
// Script, another sensor) keep their written value.

#include <string>
#include <vector>

#include "drape/formats/skinned_model.hpp"
#include "drape/formats/vrml_tree.hpp"

namespace drape::formats {

/// True for VRML97 files (.wrl, .vrml; any case).
[[nodiscard]] bool isVrmlPath(const std::string& path);

/// The motions of the document's Humanoids that interpolators drive, in file order, each
/// named after its Humanoid (its name field, else its DEF), sampled at `rate` frames per
/// second. Joints are named as the scene reader names them (scene::loadScene), so a
/// humanoid's motion fits the avatar drape reads from the same Humanoid. `file` is used in
/// messages.
[[nodiscard]] std::vector<SkinnedJointMotion> hanimMotions(const vrml::Document& document, double rate,
                                                           const std::string& file);

/// Reads a VRML97 file (vrml::readFile) and samples the motion of the Humanoid `animation`
/// names (its name, or its index from 0 among the animated ones; "" for the first). Throws
/// drape::Error naming the file when it has no animated Humanoid, or not that one.
[[nodiscard]] SkinnedJointMotion readHanimMotion(const std::string& path, double rate, const std::string& animation = "");

/// Every animated Humanoid's motion in the file (none: an empty list).
[[nodiscard]] std::vector<SkinnedJointMotion> readHanimMotions(const std::string& path, double rate);

}  // namespace drape::formats
