#include "drape/sim/scene_setup.hpp"

#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/avatar_segment.hpp"
#include "drape/scene/humanoid.hpp"

namespace drape::sim {
namespace {

/// Cuts the parts of the joints the Avatar node's cutAtJoints names across their joints
/// (scene::segmentSkinnedAvatar), after placing: the cut runs through the placed skin.
void cutAtJoints(scene::Avatar& avatar, const scene::ExternalAvatar& ext) {
  std::size_t moved = 0;
  scene::segmentSkinnedAvatar(avatar, ext.cutAtJoints, &moved);
  spdlog::info("avatar '{}': the parts of {} cut across their joints, {} triangles behind them given to their parents",
               ext.name.empty() ? avatar.name : ext.name, fmt::join(ext.cutAtJoints, ", "), moved);
}

}  // namespace

void warnOfLyingCharacters(const scene::Scene& scene, const std::vector<SceneCharacter>& characters) {
  for (const SceneCharacter& c : characters)
    if (const std::optional<scene::Upright> u = lyingAcrossGravity(scene, *c.avatar))
      spdlog::warn("{}: character '{}' stands along {}, where gravity pulls along -y: its garments would fall across "
                   "it; {}",
                   scene.source, c.name, u->axis, u->standUpAdvice());
}

std::optional<scene::Upright> lyingAcrossGravity(const scene::Scene& scene, const scene::Avatar& avatar) {
  const Vec3 g = scene.simulation.gravity;
  if (!(g.norm() > 0.0) || g.normalized().dot(-Vec3::UnitY()) < 0.999) return std::nullopt;  // the scene's own up: its choice
  return scene::uprightAlongAnotherAxis(scene::jointsAt(avatar));
}

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
  c.implicitTolerance = s.implicitTolerance;
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

namespace {

GarmentSpec garmentSpec(const scene::Scene& scene, const scene::Garment& g, const scene::Avatar* avatar) {
  GarmentSpec spec;
  spec.name = g.name;
  spec.mesh = g.mesh;
  if (g.material >= 0) spec.material = toClothMaterial(scene.materials[static_cast<std::size_t>(g.material)]);
  spec.bindThreshold_m = g.bindThreshold;
  spec.stitches = cloth::stitchesDrawnTogether(g.stitches);
  spec.selfCollision_m = g.selfCollision;
  spec.over = g.over;
  spec.overGap_m = g.overGap;
  if (avatar) {
    spec.bound = g.maskVertices;
    spec.collidesWith = g.collidesWith;
    spec.faceSamplesWith = g.faceSamplesWith;
    if (spec.collidesWith.empty())
      for (const scene::Segment& s : avatar->segments) spec.collidesWith.push_back(s.name);
  } else {
    spec.pinned = g.maskVertices;  // no body to bind to: the mask pins in place
  }
  // The garment's own offsets, else the Simulation node's, else (none given) the voxel size's.
  if (const std::optional<std::array<double, 4>>& o = g.offsets ? g.offsets : scene.simulation.offsets) {
    spec.offsets = {(*o)[0], (*o)[1], (*o)[2], (*o)[3]};
    spec.offsetsGiven = true;
  }
  spec.collisionEvery = scene.simulation.collisionEvery;
  spec.colour = g.colour;
  return spec;
}

/// A URL of the scene's, as a path: absolute as it is, else from the scene's directory.
std::string resolved(const scene::Scene& scene, const std::string& url) {
  const std::filesystem::path p(url);
  return p.is_absolute() ? url : (std::filesystem::path(scene.source).parent_path() / p).lexically_normal().string();
}

/// An Avatar node's file, loaded, placed and cut as the node says.
std::unique_ptr<scene::Avatar> loadExternal(const scene::Scene& scene, const scene::ExternalAvatar& ext) {
  if (ext.urls.empty()) throw Error(fmt::format("{}: Avatar '{}' has no url", ext.source.str(), ext.name));
  std::string lastError;
  for (const std::string& url : ext.urls) {
    const std::string path = resolved(scene, url);
    try {
      auto avatar = std::make_unique<scene::Avatar>(scene::loadAvatarFile(path, ext.meshes, ext.drawnMeshes));
      scene::placeAvatar(*avatar, ext.placement, ext.scale);
      if (!ext.cutAtJoints.empty()) cutAtJoints(*avatar, ext);
      return avatar;
    } catch (const Error& e) {
      lastError = e.what();
    }
  }
  throw Error(fmt::format("{}: Avatar '{}': {}", ext.source.str(), ext.name, lastError));
}

/// The first of an Avatar node's motion URLs that is a file, resolved against the scene's
/// directory; "" when it names none. Throws drape::Error at the node when none exists.
std::string motionFile(const scene::Scene& scene, const scene::ExternalAvatar& ext) {
  for (const std::string& url : ext.motion)
    if (const std::string path = resolved(scene, url); std::filesystem::is_regular_file(path)) return path;
  if (ext.motion.empty()) return "";
  throw Error::at(ext.source, fmt::format("Avatar {}: motion: no such file ({})", ext.name, fmt::join(ext.motion, ", ")));
}

}  // namespace

std::vector<GarmentSpec> garmentSpecs(const scene::Scene& scene, const scene::Avatar* avatar) {
  std::vector<GarmentSpec> specs;
  for (const scene::Garment& g : scene.garments) specs.push_back(garmentSpec(scene, g, avatar));
  return specs;
}

std::vector<GarmentSpec> garmentSpecs(const scene::Scene& scene, const std::vector<SceneCharacter>& characters) {
  std::vector<const scene::Avatar*> wornBy(scene.garments.size(), nullptr);
  for (const SceneCharacter& c : characters)
    for (const std::size_t g : c.garments) wornBy[g] = c.avatar.get();
  std::vector<GarmentSpec> specs;
  for (std::size_t g = 0; g < scene.garments.size(); ++g) specs.push_back(garmentSpec(scene, scene.garments[g], wornBy[g]));
  return specs;
}

std::vector<SceneCharacter> sceneCharacters(const scene::Scene& scene, Undressed undressed) {
  // Avatars numbered Humanoids first, then Avatar nodes.
  const std::size_t humanoids = scene.avatars.size(), avatars = humanoids + scene.externalAvatars.size();
  const auto nameOf = [&](std::size_t a) {
    return a < humanoids ? scene.avatars[a].name : scene.externalAvatars[a - humanoids].name;
  };
  std::vector<std::vector<std::size_t>> worn(avatars);
  for (std::size_t g = 0; g < scene.garments.size(); ++g) {
    const scene::Garment& garment = scene.garments[g];
    if (garment.avatar >= 0) {
      worn[static_cast<std::size_t>(garment.avatar)].push_back(g);
    } else if (garment.externalAvatar >= 0) {
      worn[humanoids + static_cast<std::size_t>(garment.externalAvatar)].push_back(g);
    } else if (avatars == 1) {
      worn[0].push_back(g);
    } else if (avatars > 1) {
      std::vector<std::string> names;
      for (std::size_t a = 0; a < avatars; ++a) names.push_back(nameOf(a));
      throw Error::at(garment.source,
                      fmt::format("ClothSet '{}': the scene has {} avatars ({}); say which wears it (avatar USE NAME)",
                                  garment.name, avatars, fmt::join(names, ", ")));
    }
  }
  std::vector<SceneCharacter> out;
  for (std::size_t a = 0; a < avatars; ++a) {
    if (worn[a].empty() && undressed == Undressed::leftOut) {
      if (avatars > 1) spdlog::warn("{}: avatar '{}' wears no garment; it is left out", scene.source, nameOf(a));
      continue;
    }
    SceneCharacter c;
    c.avatar = a < humanoids ? std::make_unique<scene::Avatar>(scene.avatars[a])
                             : loadExternal(scene, scene.externalAvatars[a - humanoids]);
    c.name = nameOf(a).empty() ? c.avatar->name : nameOf(a);
    c.external = a >= humanoids;
    if (c.external) c.motion = motionFile(scene, scene.externalAvatars[a - humanoids]);
    c.garments = std::move(worn[a]);
    for (const SceneCharacter& other : out)
      if (other.name == c.name)
        throw Error(fmt::format("{}: two characters are called '{}'; give their Avatar or Humanoid nodes different "
                                "names (DEF)",
                                scene.source, c.name));
    out.push_back(std::move(c));
  }
  return out;
}

std::unique_ptr<scene::Avatar> sceneAvatar(const scene::Scene& scene) {
  std::vector<SceneCharacter> characters = sceneCharacters(scene);
  if (characters.empty()) return nullptr;
  if (characters.size() > 1) {
    std::vector<std::string> names;
    for (const SceneCharacter& c : characters) names.push_back(c.name);
    throw Error(fmt::format("{}: garments are worn by {} characters ({}); this takes one", scene.source,
                            characters.size(), fmt::join(names, ", ")));
  }
  return std::move(characters.front().avatar);
}

}  // namespace drape::sim
