// `drape make-skirt AVATAR --out DIR`: a skirt fitted to an avatar's hips at rest, with its
// waistband constraint mask, written as a ready-to-run VRML97 scene (DIR/scene.wrl) and as
// OBJ meshes (DIR/skirt.obj, DIR/waistband.obj).

#include <filesystem>
#include <fstream>
#include <iostream>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fmt/ostream.h>

#include "command.hpp"
#include "run_setup.hpp"
#include "scene_text.hpp"
#include "drape/cloth/model.hpp"
#include "drape/core/error.hpp"
#include "drape/formats/obj.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/garment_fit.hpp"

namespace drape::cli {
namespace {

struct MakeSkirtOptions {
  std::string avatar;
  std::string avatarUrl;
  std::string out;
  scene::SkirtFit fit;
  double bindThreshold_m = 0.04;
};

/// The knit the scene gives the skirt (written below as the Knit material).
cloth::Material knit() {
  cloth::Material m;
  m.density_kg_m3 = 300;
  m.thickness_m = 0.0005;
  m.youngsModulus_Pa = 50000;
  m.poissonRatio = 0.3;
  m.damping_s = 0.002;
  m.staticFriction = 0.5;
  m.dynamicFriction = 0.3;
  m.compressionScale = 0.2;
  return m;
}

/// Writes the scene; returns its substeps per frame.
int writeScene(const std::string& path, const MakeSkirtOptions& o, const mesh::Skirt& skirt) {
  constexpr double kFrameRate = 30.0;
  const cloth::Material m = knit();
  // The paper's 33 substeps per frame, or as many more as this skirt's smallest elements and
  // the knit's damping need (a small avatar's skirt has smaller, stiffer triangles).
  const int kSubsteps =
      cloth::fewestStableSubsteps(skirt.mesh, mesh::Topology::build(skirt.mesh), m, kFrameRate, 0.0, 33).substepsPerFrame;
  const int bendEvery = cloth::suggestedBendEvery(
      *cloth::ClothModel::build(skirt.mesh, mesh::Topology::build(skirt.mesh), m), 1.0 / (kFrameRate * kSubsteps));
  std::ofstream os(path);
  fmt::print(os, "#VRML V2.0 utf8\n");
  fmt::print(os, "# The paper's walking scenario: a skirt of {} triangles bound at the waist, on a segmented\n"
                 "# avatar whose hips, thighs and shins collide. Made by `drape make-skirt`; run it with\n"
                 "#   drape run {} --motion walk.bvh --out out/walking_skirt\n"
                 "# Units: metres, kilograms, seconds; y is up.\n\n",
             skirt.mesh.triangleCount(), path);
  fmt::print(os, "WorldInfo {{ title \"drape: walking skirt\" }}\n\n");
  fmt::print(os, "DEF Simulation Simulation {{\n  gravity 0 -9.81 0\n  frameRate {:g}\n  stepsPerFrame {}\n"
                 "  airViscosity 0.5\n  offsets [ 0.005 0.010 0.015 0.030 ]\n  voxelSize 0.005\n"
                 "  integrator \"symplectic-euler\"\n  collisionEvery 1\n  bendEvery {}\n}}\n\n",
             kFrameRate, kSubsteps, bendEvery);
  writeMaterial(os, m);
  fmt::print(os, "DEF Body Avatar {{\n  url \"{}\"\n}}\n\n", o.avatarUrl);
  fmt::print(os, "DEF Skirt ClothSet {{\n  cloth Shape {{\n    appearance Appearance {{ material Material {{ diffuseColor 0.7 0.15 0.2 }} }}\n"
                 "    geometry DEF SkirtMesh IndexedFaceSet {{\n      solid FALSE\n");
  writeIndexedFaceSet(os, skirt.mesh, "      ");
  fmt::print(os, "    }}\n  }}\n  constraintMask IndexedFaceSet {{\n");
  writeIndexedFaceSet(os, skirt.waistband, "    ");
  fmt::print(os, "  }}\n  material USE Knit\n  avatar USE Body\n");
  fmt::print(os, "  collidesWith [ \"{}\"", o.fit.waistSegment);
  for (const std::string& s : o.fit.hipSegments) fmt::print(os, ", \"{}\"", s);
  for (const std::string& s : o.fit.legSegments) fmt::print(os, ", \"{}\"", s);
  fmt::print(os, " ]\n  maskTolerance 0.0005\n  bindThreshold {:.3f}\n}}\n", o.bindThreshold_m);
  if (!os) throw Error(fmt::format("{}: cannot be written", path));
  return kSubsteps;
}

/// Every segment the fit and the scene name must be the avatar's: the defaults are the
/// MakeHuman CMU rig's, and another rig's avatar names its own.
void checkSegments(const scene::Avatar& avatar, const MakeSkirtOptions& o) {
  const auto check = [&](const std::string& name, const char* option) {
    if (avatar.findSegment(name) >= 0) return;
    throw Error(fmt::format("{}: the avatar has no segment '{}'; name one of its own with {} (it has: {})", o.avatar,
                            name, option, fmt::join(avatar.segmentNames(), ", ")));
  };
  check(o.fit.waistSegment, "--waist-segment");
  for (const std::string& name : o.fit.hipSegments) check(name, "--hip-segments");
  for (const std::string& name : o.fit.legSegments) check(name, "--leg-segments");
}

RunFunction setupMakeSkirt(CLI::App& app) {
  static MakeSkirtOptions o;
  app.add_option("avatar", o.avatar, "Avatar file to fit the skirt to (.glb, .gltf, .dae, .fbx, MakeHuman .mhskel)")->required();
  app.add_option("--out", o.out, "Directory for scene.wrl, skirt.obj and waistband.obj")->required();
  app.add_option("--avatar-url", o.avatarUrl, "The Avatar url written into scene.wrl (default: the avatar's path relative to --out)");
  app.add_option("--length", o.fit.length_m, "Waist to hem, m (default: a little above the knees)");
  app.add_option("--clearance", o.fit.clearance_m, "Gap between body and skirt at rest, m")->capture_default_str();
  app.add_option("--flare", o.fit.flare, "Extra hem radius per metre of length")->capture_default_str();
  app.add_option("--around", o.fit.segments, "Vertices around")->capture_default_str()->check(CLI::Range(6, 1000));
  app.add_option("--rings", o.fit.rings, "Bands from waist to hem")->capture_default_str()->check(CLI::Range(2, 1000));
  app.add_option("--waist-segment", o.fit.waistSegment, "Segment at whose joint the waist sits")->capture_default_str();
  app.add_option("--hip-segments", o.fit.hipSegments, "Segments below the waist the skirt clears and collides with")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--leg-segments", o.fit.legSegments,
                 "Leg segments the skirt clears and collides with; its default length reaches a little above the "
                 "knees")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--bind-threshold", o.bindThreshold_m, "Written into the ClothSet, m")->capture_default_str();
  return [] {
    const scene::Avatar avatar = scene::loadAvatarFile(o.avatar);
    checkSegments(avatar, o);
    const mesh::Skirt skirt = scene::fitSkirt(avatar, o.fit);
    o.avatarUrl = prepareSceneDir(o.out, o.avatar, o.avatarUrl);
    const std::filesystem::path dir(o.out);
    formats::writeObj((dir / "skirt.obj").string(), skirt.mesh.positions, skirt.mesh.triangles, "drape make-skirt (m)");
    formats::writeObj((dir / "waistband.obj").string(), skirt.waistband.positions, skirt.waistband.triangles,
                      "drape make-skirt: constraint mask (m)");
    const int substeps = writeScene((dir / "scene.wrl").string(), o, skirt);
    const Aabb box = skirt.mesh.bounds();
    fmt::print("skirt: {} vertices, {} triangles, waist at y = {:.3f} m, hem at y = {:.3f} m; {} substeps per frame\n",
               skirt.mesh.vertexCount(), skirt.mesh.triangleCount(), box.max.y(), box.min.y(), substeps);
    fmt::print("wrote {}/scene.wrl, skirt.obj, waistband.obj\n", o.out);
    printHowToRun(o.out, avatar);
    return 0;
  };
}

const bool registered_cmd_make_skirt = registerCommand({"make-skirt", "Fit a skirt to an avatar and write a ready-to-run scene", "", 60, &setupMakeSkirt});

}  // namespace
}  // namespace drape::cli
