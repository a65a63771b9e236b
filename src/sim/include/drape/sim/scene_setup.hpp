#pragma once
// From the scene model (scene/, what the file says) to the simulation's parameters
// (cloth/, what the solver needs). scene/ and cloth/ do not know each other; this is where
// they meet.

#include <string>
#include <vector>

#include "drape/cloth/material.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {

[[nodiscard]] cloth::Material toClothMaterial(const scene::ClothMaterial& material);
[[nodiscard]] cloth::StepSettings toStepSettings(const scene::SimulationSettings& settings);
[[nodiscard]] WorldSettings toWorldSettings(const scene::SimulationSettings& settings);

/// The garments of `scene` as simulation specs: collidesWith empty in the file means every
/// segment of `avatar`; offsets from the Simulation node.
[[nodiscard]] std::vector<GarmentSpec> garmentSpecs(const scene::Scene& scene, const scene::Avatar* avatar);

/// The avatar the scene's garments are worn by: its H-Anim Humanoid, or the file an Avatar
/// node names (glTF, MakeHuman), loaded and placed. Null when the scene has no avatar.
/// Throws drape::Error when garments name different avatars (one character per run).
[[nodiscard]] std::unique_ptr<scene::Avatar> sceneAvatar(const scene::Scene& scene);

}  // namespace drape::sim
