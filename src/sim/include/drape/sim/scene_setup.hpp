#pragma once
// From the scene model (scene/, what the file says) to the simulation's parameters
// (cloth/, what the solver needs). scene/ and cloth/ do not know each other; this is where
// they meet.

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drape/cloth/material.hpp"
#include "drape/scene/humanoid.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {

[[nodiscard]] cloth::Material toClothMaterial(const scene::ClothMaterial& material);
[[nodiscard]] cloth::StepSettings toStepSettings(const scene::SimulationSettings& settings);
[[nodiscard]] WorldSettings toWorldSettings(const scene::SimulationSettings& settings);

/// A character of the scene: an avatar and the garments it wears.
struct SceneCharacter {
  std::unique_ptr<scene::Avatar> avatar;  ///< loaded and placed where the scene puts it
  /// What the scene calls it: its Avatar node's or Humanoid's name (DEF or name field),
  /// unique among the scene's characters.
  std::string name;
  std::vector<std::size_t> garments;  ///< indices into Scene::garments, ascending
  bool external = false;              ///< from an Avatar node's file (else an H-Anim Humanoid of the scene)
  /// The motion file its Avatar node's `motion` names (the first of its URLs that exists),
  /// which it plays when a command gives it none; "" when the node names none.
  std::string motion;
};

/// The garments of `scene` as simulation specs: collidesWith empty in the file means every
/// segment of `avatar`; offsets from the Simulation node.
[[nodiscard]] std::vector<GarmentSpec> garmentSpecs(const scene::Scene& scene, const scene::Avatar* avatar);
/// The same with each garment on the avatar of the character that wears it (none: pinned
/// where its mask is, as without an avatar).
[[nodiscard]] std::vector<GarmentSpec> garmentSpecs(const scene::Scene& scene, const std::vector<SceneCharacter>& characters);

/// Whether sceneCharacters lists avatars that wear nothing (`drape make-skirt --add-to`
/// dresses them; a run leaves them out, saying so).
enum class Undressed { leftOut, included };

/// The scene's characters: each avatar (an H-Anim Humanoid, or the file an Avatar node names,
/// loaded and placed) that wears a garment, or every avatar with `Undressed::included`, with
/// its garments, Humanoids first, each kind in file order. A garment that names no avatar is
/// worn by the scene's only one. Empty when the scene has no avatar. Throws drape::Error
/// naming the garment when the scene has several avatars and a garment does not say which
/// wears it, or two characters share a name.
[[nodiscard]] std::vector<SceneCharacter> sceneCharacters(const scene::Scene& scene,
                                                          Undressed undressed = Undressed::leftOut);

/// How `avatar`, placed in `scene`, stands where it lies across the scene's gravity: a
/// humanoid along another axis than +y (a robot placed as its file stands it, along +z) in a
/// scene whose gravity pulls along -y, its garments would fall across it. nullopt where it
/// stands along +y, is no humanoid, or the scene's gravity pulls along another axis (the
/// scene's own up).
[[nodiscard]] std::optional<scene::Upright> lyingAcrossGravity(const scene::Scene& scene, const scene::Avatar& avatar);

/// Warns of each of `characters` (sceneCharacters') lying across the scene's gravity, with
/// the rotation that stands it up: what a run or `drape inspect` goes on with, and a command
/// that dresses it refuses.
void warnOfLyingCharacters(const scene::Scene& scene, const std::vector<SceneCharacter>& characters);

/// The avatar the scene's garments are worn by (sceneCharacters' only one); null when the
/// scene has none. Throws drape::Error when its garments are worn by several characters.
[[nodiscard]] std::unique_ptr<scene::Avatar> sceneAvatar(const scene::Scene& scene);

}  // namespace drape::sim
