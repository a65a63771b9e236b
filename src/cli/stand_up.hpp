#pragma once
// A new scene's avatar (`drape make-skirt`, `drape make-scene`) that its file stands along
// another axis than +y, as robots from Choreonoid and OpenHRP stand along +z: turned to
// stand along +y as drape's scenes do, the scene's Avatar node given that rotation. And
// which of its file's meshes made its body, where the file holds several.

#include <optional>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/scene/avatar.hpp"
#include "drape/scene/humanoid.hpp"

namespace drape::cli {

/// Turns `avatar` when it is a humanoid along another axis than +y and says so on standard
/// output; the turn, or nullopt where it stands along +y or is no humanoid at all (the
/// caller's own checks say why).
inline std::optional<scene::Upright> standUp(scene::Avatar& avatar, const std::string& whose) {
  std::optional<scene::Upright> u = scene::uprightAlongAnotherAxis(scene::jointsAt(avatar));
  if (!u) return std::nullopt;
  scene::placeAvatar(avatar, RigidTransform{u->turn, Vec3::Zero()});
  fmt::print("{} stands along {}: turned to stand along +y, as drape's scenes do (its Avatar node's rotation {})\n",
             whose, u->axis, u->rotationText());
  return u;
}

/// Says on standard output which of the avatar file's skinned meshes made the body the cloth
/// collides with, where the file holds more than one (a character shipped with its clothes
/// or hair): nothing for a file of one mesh.
inline void sayWhichMeshesMakeTheBody(const scene::Avatar& avatar, const std::string& whose) {
  if (avatar.fileMeshes.size() < 2) return;
  if (avatar.meshesRead.size() == avatar.fileMeshes.size())
    fmt::print("{}: the body is every mesh of its skin ({}); --avatar-meshes chooses those that make it, leaving out "
               "clothes or hair\n",
               whose, fmt::join(avatar.fileMeshes, ", "));
  else
    fmt::print("{}: the body is {} of its meshes {}\n", whose, fmt::join(avatar.meshesRead, ", "),
               fmt::join(avatar.fileMeshes, ", "));
  if (avatar.drawnSkin)
    fmt::print("{}: {} drawn with the body, not collided with\n", whose, fmt::join(avatar.drawnMeshesRead, ", "));
}

}  // namespace drape::cli
