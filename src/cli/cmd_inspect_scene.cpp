// `drape inspect SCENE.wrl`: avatars (joint tree with segment triangle counts, the motion
// of an animated humanoid), garments (vertices, triangles, boundary loops, mask size),
// materials with units, simulation settings and warnings of a VRML97 scene.

#include <algorithm>

#include <fmt/ostream.h>

#include "command.hpp"
#include "inspect_humanoid.hpp"
#include "run_setup.hpp"
#include "stitch_gaps.hpp"
#include "drape/cloth/field_collider.hpp"
#include "drape/formats/hanim_motion.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/scene_setup.hpp"

namespace drape::cli {
namespace {

/// What the scene's strain limit does, as the end of a sentence.
std::string strainLimitText(const scene::SimulationSettings& sim) {
  const auto times = [](double stretch) { return fmt::format("{:g} times their rest length", 1.0 + stretch); };
  if (sim.strainLimit > 0.0) return fmt::format("; edges are held to {} from the first frame", times(sim.strainLimit));
  if (sim.rescueStrainLimit > 0.0)
    return fmt::format(", then edges are held to {} from a frame that still goes unstable",
                       times(sim.rescueStrainLimit));
  return ", then the run stops on it";
}

void printJoint(std::ostream& out, const scene::Avatar& a, int joint, int depth) {
  const scene::Joint& j = a.joints[static_cast<std::size_t>(joint)];
  std::size_t triangles = 0;
  int segments = 0;
  for (const scene::Segment& s : a.segments)
    if (s.joint == joint) {
      triangles += s.mesh.triangleCount();
      ++segments;
    }
  fmt::print(out, "    {:{}}{}  at ({:.3f} {:.3f} {:.3f}) m", "", depth * 2, j.name, j.restCenter.x(), j.restCenter.y(),
             j.restCenter.z());
  if (segments > 0) fmt::print(out, "  [{} segment{}, {} triangles]", segments, segments == 1 ? "" : "s", triangles);
  fmt::print(out, "\n");
  for (std::size_t c = 0; c < a.joints.size(); ++c)
    if (a.joints[c].parent == joint) printJoint(out, a, static_cast<int>(c), depth + 1);
}

void printGarment(std::ostream& out, const scene::Scene& s, const scene::Garment& g) {
  fmt::print(out, "  {}: {} vertices, {} triangles", g.name, g.mesh.vertexCount(), g.mesh.triangleCount());
  const std::size_t nonManifold = mesh::countNonManifoldEdges(g.mesh);
  if (nonManifold > 0) {
    fmt::print(out, ", {} non-manifold edges (cannot be simulated as cloth)\n", nonManifold);
  } else {
    const mesh::Topology t = mesh::Topology::build(g.mesh);
    fmt::print(out, ", {} edges, {} boundary loop{}\n", t.edges.size(), t.boundaryLoops.size(),
               t.boundaryLoops.size() == 1 ? "" : "s");
  }
  const Aabb box = g.mesh.bounds();
  fmt::print(out, "    bounds [{:.3f} {:.3f} {:.3f}] .. [{:.3f} {:.3f} {:.3f}] m\n", box.min.x(), box.min.y(),
             box.min.z(), box.max.x(), box.max.y(), box.max.z());
  fmt::print(out, "    material {}, constraint mask {} vertices (tolerance {:g} m, bind threshold {:g} m)\n",
             s.materials[static_cast<std::size_t>(g.material)].name, g.maskVertices.size(), g.maskTolerance,
             g.bindThreshold);
  if (g.avatar >= 0) fmt::print(out, "    worn by {}\n", s.avatars[static_cast<std::size_t>(g.avatar)].name);
  if (g.externalAvatar >= 0)
    fmt::print(out, "    worn by {}\n", s.externalAvatars[static_cast<std::size_t>(g.externalAvatar)].name);
  fmt::print(
      out, "    collides with {}\n",
      g.collidesWith.empty() ? std::string("every segment") : fmt::format("{}", fmt::join(g.collidesWith, ", ")));
  if (!g.faceSamplesWith.empty())
    fmt::print(out, "    triangle centroids collide too with {}\n", fmt::join(g.faceSamplesWith, ", "));
  if (g.offsets)
    fmt::print(out, "    its own offset surfaces T0..T3 {:.4g}, {:.4g}, {:.4g}, {:.4g} mm\n", 1e3 * (*g.offsets)[0],
               1e3 * (*g.offsets)[1], 1e3 * (*g.offsets)[2], 1e3 * (*g.offsets)[3]);
  if (g.selfCollision > 0)
    fmt::print(out, "    its own layers kept {:.4g} mm apart (selfCollision)\n", 1e3 * g.selfCollision);
  if (!g.over.empty())
    fmt::print(out, "    worn {:.4g} mm over {} (over, overGap; stepped after {})\n", 1e3 * g.overGap,
               fmt::join(g.over, ", "), g.over.size() == 1 ? "it" : "them");
  if (!g.stitches.empty())
    fmt::print(out, "    {} stitches, drawing together vertices up to {:.1f} mm apart\n", g.stitches.size(),
               1e3 * widestStitch_m(g.mesh, g.stitches));
}

/// The interpolators that animate the file's humanoids: what `--motion FILE` plays, and what
/// `drape run FILE` plays by itself on the humanoid the file's garments wear.
void printHumanoidMotions(const std::string& path, const scene::Scene& s, std::ostream& out) {
  const std::vector<formats::SkinnedJointMotion> motions = formats::readHanimMotions(path, 30.0);
  for (const formats::SkinnedJointMotion& m : motions) {
    const bool worn = std::any_of(s.garments.begin(), s.garments.end(), [&](const scene::Garment& g) {
      return g.avatar >= 0 && s.avatars[static_cast<std::size_t>(g.avatar)].name == m.animation;
    });
    const std::string plays =
        worn ? fmt::format("drape run {} plays it by itself (--motion none: at rest)", path)
             : fmt::format("drape run ... --motion {}{} plays it", path,
                           motions.size() > 1 ? fmt::format(" --animation '{}'", m.animation) : std::string());
    fmt::print(out, "  {} moves: {:.3f} s of interpolators, {} frames at 30 Hz; {}\n", m.animation, m.end_s - m.start_s,
               m.frameCount(), plays);
  }
}

/// A worn avatar of an `Avatar` node, loaded as `drape run` loads it: what its file is, and
/// the animations it carries, which `drape run FILE` plays by itself.
void printAvatarFile(const std::string& path, const scene::Avatar& avatar, std::ostream& out) {
  fmt::print(out, "    {}: {} joints, {} segments{}\n", avatar.source, avatar.joints.size(), avatar.segments.size(),
             avatar.skin ? fmt::format(", a skin of {} triangles", avatar.skin->mesh.triangleCount()) : "");
  if (avatar.fileMeshes.size() > 1)
    fmt::print(out, "    its skin moves {} meshes ({}); the body is {}\n", avatar.fileMeshes.size(),
               fmt::join(avatar.fileMeshes, ", "),
               avatar.meshesRead.size() == avatar.fileMeshes.size() ? std::string("every one")
                                                                   : fmt::format("{}", fmt::join(avatar.meshesRead, ", ")));
  if (avatar.drawnSkin)
    fmt::print(out, "    drawn with it, not collided with: {} ({} triangles)\n", fmt::join(avatar.drawnMeshesRead, ", "),
               avatar.drawnSkin->mesh.triangleCount());
  if (!avatar.animations.empty())
    fmt::print(out, "    its file carries {} animation{} ('{}')\n", avatar.animations.size(),
               avatar.animations.size() == 1 ? "" : "s", fmt::join(avatar.animations, "', '"));
  if (const std::string own = ownMotionText(avatar); !own.empty())
    fmt::print(out, "    drape run {} plays {} by itself (--motion none: at rest)\n", path, own);
}

/// The scene's characters as `drape run` loads them: with several, who wears what; the files
/// of the Avatar nodes worn.
void printCharacters(const std::string& path, const scene::Scene& s, std::ostream& out) {
  std::vector<sim::SceneCharacter> characters;
  try {
    characters = sim::sceneCharacters(s);
    sim::warnOfLyingCharacters(s, characters);
  } catch (const Error& e) {
    fmt::print(out, "    not loaded: {}\n", e.what());
    return;
  }
  const bool several = characters.size() > 1;
  if (several) fmt::print(out, "characters: {}\n", characters.size());
  for (const sim::SceneCharacter& c : characters) {
    if (several) {
      std::vector<std::string> worn;
      for (const std::size_t g : c.garments) worn.push_back(s.garments[g].name);
      fmt::print(out, "  {} wears {}{}\n", c.name, fmt::join(worn, ", "),
                 fmt::format(" (drape run --motion {}=FILE moves it)", c.name));
    }
    if (c.external) printAvatarFile(path, *c.avatar, out);
  }
}

void inspectScene(const std::string& path, std::ostream& out) {
  const scene::Scene s = scene::loadScene(path);
  fmt::print(out, "{}: VRML97 scene\n", path);
  fmt::print(out, "avatars: {}\n", s.avatars.size() + s.externalAvatars.size());
  for (const scene::Avatar& a : s.avatars) {
    std::size_t triangles = 0;
    for (const scene::Segment& seg : a.segments) triangles += seg.mesh.triangleCount();
    fmt::print(out, "  {} (H-Anim): {} joints, {} segments, {} triangles\n", a.name, a.joints.size(), a.segments.size(),
               triangles);
    for (std::size_t j = 0; j < a.joints.size(); ++j)
      if (a.joints[j].parent < 0) printJoint(out, a, static_cast<int>(j), 0);
    std::vector<std::string> names;
    for (const scene::Joint& j : a.joints) names.push_back(j.name);
    printHumanoid(out, names, scene::jointsAt(a));
  }
  if (!s.avatars.empty()) printHumanoidMotions(path, s, out);
  for (const scene::ExternalAvatar& a : s.externalAvatars)
    fmt::print(out, "  {} (from {}){}{}{}{}\n", a.name, fmt::join(a.urls, ", "),
               a.meshes.empty() ? "" : fmt::format(", its body the meshes {}", fmt::join(a.meshes, ", ")),
               a.drawnMeshes.empty() ? "" : fmt::format(", drawn with it the meshes {}", fmt::join(a.drawnMeshes, ", ")),
               a.jointMap.empty() ? "" : fmt::format(", joint map {}", fmt::join(a.jointMap, ", ")),
               a.cutAtJoints.empty() ? "" : fmt::format(", parts cut across joints {}", fmt::join(a.cutAtJoints, ", ")));
  if (!s.externalAvatars.empty() || s.avatars.size() > 1) printCharacters(path, s, out);
  fmt::print(out, "garments: {}\n", s.garments.size());
  for (const scene::Garment& g : s.garments) printGarment(out, s, g);
  fmt::print(out, "materials: {}\n", s.materials.size());
  for (const scene::ClothMaterial& m : s.materials) {
    fmt::print(
        out,
        "  {}: density {:g} kg/m^3, thickness {:g} m ({:.4g} kg/m^2), Young's modulus {:g} Pa, Poisson ratio {:g}\n",
        m.name, m.density, m.thickness, m.arealDensity(), m.youngsModulus, m.poissonRatio);
    fmt::print(out,
               "    bending stiffness {:.4g} N m{}, damping {:g}, friction {:g} static / {:g} dynamic, compression "
               "scale {:g}\n",
               m.bendingStiffnessOrDerived(), m.bendingStiffness < 0 ? " (from E, t, nu)" : "", m.damping,
               m.staticFriction, m.dynamicFriction, m.compressionScale);
  }
  const scene::SimulationSettings& sim = s.simulation;
  fmt::print(out, "simulation{}:\n", s.hasSimulationNode ? "" : " (defaults: no Simulation node)");
  fmt::print(out, "  gravity ({:g} {:g} {:g}) m/s^2, wind ({:g} {:g} {:g}) m/s, air viscosity {:g}\n", sim.gravity.x(),
             sim.gravity.y(), sim.gravity.z(), sim.wind.x(), sim.wind.y(), sim.wind.z(), sim.airViscosity);
  fmt::print(out, "  {:g} frames/s x {} steps/frame ({}{}), collisions every {} step{}, bending every {} step{}\n",
             sim.frameRate, sim.stepsPerFrame, sim.integrator,
             sim.integrator == "backward-euler" ? fmt::format(", solves to {:g}", sim.implicitTolerance) : "",
             sim.collisionEvery, sim.collisionEvery == 1 ? "" : "s", sim.bendEvery, sim.bendEvery == 1 ? "" : "s");
  const cloth::OffsetSurfaces t =
      sim.offsets ? cloth::OffsetSurfaces{(*sim.offsets)[0], (*sim.offsets)[1], (*sim.offsets)[2], (*sim.offsets)[3]}
                  : cloth::OffsetSurfaces::fromVoxelSize(sim.voxelSize);
  fmt::print(out, "  offsets T0..T3 {:g} {:g} {:g} {:g} m{}, voxel size {:g} m, unit scale {:g} m per file unit\n",
             t.t0_m, t.t1_m, t.t2_m, t.t3_m, sim.offsets ? "" : " (1, 2, 3 and 6 voxels: none written)",
             sim.voxelSize, sim.unitScale);
  fmt::print(out, "  an unstable frame is computed again with up to {} times the steps{}\n", sim.maxRefinement,
             strainLimitText(sim));
  if (!sim.keepApart.empty())
    fmt::print(out, "  the motion is corrected to keep {} out of the collidable parts\n", fmt::join(sim.keepApart, ", "));
  if (!s.scenery.empty()) {
    std::size_t triangles = 0;
    for (const scene::Scenery& m : s.scenery) triangles += m.mesh.triangleCount();
    fmt::print(out, "scenery: {} shape{}, {} triangles\n", s.scenery.size(), s.scenery.size() == 1 ? "" : "s",
               triangles);
  }
  for (const std::string& w : s.warnings) fmt::print(out, "warning: {}\n", w);
}

const bool registered_cmd_inspect_scene =
    registerInspector({".wrl", ".vrml"}, "VRML97 scenes: avatars, garments, materials, simulation", &inspectScene);

}  // namespace
}  // namespace drape::cli
