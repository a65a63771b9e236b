#include "drape/sim/scene_setup.hpp"

#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/avatar_segment.hpp"

namespace drape::sim {
namespace {

/// Places an avatar loaded in its own frame where the scene's Avatar node puts it.
void place(scene::Avatar& avatar, const RigidTransform& placement, double scale) {
  for (scene::Joint& j : avatar.joints) {
    j.restCenter = placement.apply(scale * j.restCenter);
    j.restOrientation = (placement.rotation * j.restOrientation).normalized();
  }
  for (scene::Segment& s : avatar.segments) s.mesh.scale(scale);
  if (avatar.skin) {
    avatar.skin->mesh.scale(scale);
    avatar.skin->mesh.transform(placement);
  }
}

/// Cuts the parts of the joints the Avatar node's cutAtJoints names across their joints
/// (scene::segmentSkinnedAvatar), after placing: the cut runs through the placed skin.
void cutAtJoints(scene::Avatar& avatar, const scene::ExternalAvatar& ext) {
  std::size_t moved = 0;
  scene::segmentSkinnedAvatar(avatar, ext.cutAtJoints, &moved);
  spdlog::info("avatar '{}': the parts of {} cut across their joints, {} triangles behind them given to their parents",
               ext.name.empty() ? avatar.name : ext.name, fmt::join(ext.cutAtJoints, ", "), moved);
}

}  // namespace

cloth::Material toClothMaterial(const scene::ClothMaterial& m) {
  cloth::Material c;
  c.density_kg_m3 = m.density;
  c.thickness_m = m.thickness;
  c.youngsModulus_Pa = m.youngsModulus;
  c.poissonRatio = m.poissonRatio;
  c.bendingStiffness_Nm = m.bendingStiffness;
  c.damping_s = m.damping;
  c.staticFriction = m.staticFriction;
  c.dynamicFriction = m.dynamicFriction;
  c.compressionScale = m.compressionScale;
  return c;
}

cloth::StepSettings toStepSettings(const scene::SimulationSettings& s) {
  cloth::StepSettings c;
  c.gravity_m_s2 = s.gravity;
  c.frameRate_hz = s.frameRate;
  c.substepsPerFrame = s.stepsPerFrame;
  c.airViscosity_Ns_m3 = s.airViscosity;
  c.wind_m_s = s.wind;
  c.maxAddedMass = s.maxAddedMass;
  c.bendEvery = s.bendEvery;
  c.maxRefinement = s.maxRefinement;
  c.strainLimit = s.strainLimit;
  c.rescueStrainLimit = s.rescueStrainLimit;
  c.integrator = cloth::parseIntegrator(s.integrator, "Simulation.integrator");
  return c;
}

WorldSettings toWorldSettings(const scene::SimulationSettings& s) {
  WorldSettings w;
  w.step = toStepSettings(s);
  w.voxel_m = s.voxelSize;
  w.keepApart.parts = s.keepApart;
  return w;
}

std::vector<GarmentSpec> garmentSpecs(const scene::Scene& scene, const scene::Avatar* avatar) {
  std::vector<GarmentSpec> specs;
  for (const scene::Garment& g : scene.garments) {
    GarmentSpec spec;
    spec.name = g.name;
    spec.mesh = g.mesh;
    if (g.material >= 0) spec.material = toClothMaterial(scene.materials[static_cast<std::size_t>(g.material)]);
    spec.bindThreshold_m = g.bindThreshold;
    spec.stitches = cloth::stitchesDrawnTogether(g.stitches);
    if (avatar) {
      spec.bound = g.maskVertices;
      spec.collidesWith = g.collidesWith;
      spec.faceSamplesWith = g.faceSamplesWith;
      if (spec.collidesWith.empty())
        for (const scene::Segment& s : avatar->segments) spec.collidesWith.push_back(s.name);
    } else {
      spec.pinned = g.maskVertices;  // no body to bind to: the mask pins in place
    }
    const auto& o = scene.simulation.offsets;
    spec.offsets = {o[0], o[1], o[2], o[3]};
    spec.offsetsGiven = scene.simulation.source.line > 0;
    spec.collisionEvery = scene.simulation.collisionEvery;
    specs.push_back(std::move(spec));
  }
  return specs;
}

std::unique_ptr<scene::Avatar> sceneAvatar(const scene::Scene& scene) {
  int humanoid = -1, external = -1;
  for (const scene::Garment& g : scene.garments) {
    if ((g.avatar >= 0 && humanoid >= 0 && g.avatar != humanoid) ||
        (g.externalAvatar >= 0 && external >= 0 && g.externalAvatar != external) ||
        (g.avatar >= 0 && external >= 0) || (g.externalAvatar >= 0 && humanoid >= 0)) {
      throw Error(fmt::format("{}: garments are worn by different avatars; drape run simulates one character", scene.source));
    }
    if (g.avatar >= 0) humanoid = g.avatar;
    if (g.externalAvatar >= 0) external = g.externalAvatar;
  }
  if (humanoid < 0 && external < 0) {
    if (scene.avatars.size() == 1) humanoid = 0;
    else if (scene.externalAvatars.size() == 1 && scene.avatars.empty()) external = 0;
  }
  if (humanoid >= 0) return std::make_unique<scene::Avatar>(scene.avatars[static_cast<std::size_t>(humanoid)]);
  if (external < 0) return nullptr;
  const scene::ExternalAvatar& ext = scene.externalAvatars[static_cast<std::size_t>(external)];
  if (ext.urls.empty()) throw Error(fmt::format("{}: Avatar '{}' has no url", ext.source.str(), ext.name));
  std::string lastError;
  const std::filesystem::path base = std::filesystem::path(scene.source).parent_path();
  for (const std::string& url : ext.urls) {
    const std::filesystem::path p(url);
    const std::string path = p.is_absolute() ? url : (base / p).lexically_normal().string();
    try {
      auto avatar = std::make_unique<scene::Avatar>(scene::loadAvatarFile(path));
      place(*avatar, ext.placement, ext.scale);
      if (!ext.cutAtJoints.empty()) cutAtJoints(*avatar, ext);
      return avatar;
    } catch (const Error& e) {
      lastError = e.what();
    }
  }
  throw Error(fmt::format("{}: Avatar '{}': {}", ext.source.str(), ext.name, lastError));
}

}  // namespace drape::sim
