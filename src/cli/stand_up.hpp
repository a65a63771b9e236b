#pragma once
// A new scene's avatar (`drape make-skirt`, `drape make-scene`) that its file stands along
// another axis than +y, as robots from Choreonoid and OpenHRP stand along +z: turned to
// stand along +y as drape's scenes do, the scene's Avatar node given that rotation.

#include <optional>
#include <string>

#include <fmt/format.h>

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

}  // namespace drape::cli
