// `drape make-skirt AVATAR --out DIR`: a skirt fitted to an avatar's hips at rest, with its
// waistband constraint mask, written as a ready-to-run VRML97 scene (DIR/scene.wrl) and as
// OBJ meshes (DIR/skirt.obj, DIR/waistband.obj). `drape make-skirt --add-to SCENE`: one more
// skirt for a character of that scene (over a petticoat it wears), appended to it.

#include <filesystem>
#include <fstream>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <utility>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fmt/ostream.h>
#include <spdlog/spdlog.h>

#include "avatar_scale.hpp"
#include "command.hpp"
#include "run_setup.hpp"
#include "scene_add.hpp"
#include "scene_text.hpp"
#include "stand_up.hpp"
#include "drape/cloth/model.hpp"
#include "drape/core/error.hpp"
#include "drape/formats/obj.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/garment_fit.hpp"
#include "drape/scene/humanoid.hpp"
#include "drape/sim/garment_layers.hpp"

namespace drape::cli {
namespace {

struct MakeSkirtOptions {
  std::string avatar;
  std::string avatarUrl;
  std::string out;
  std::string name;  ///< --name: the ClothSet's name ("" : Skirt)
  AddToOptions add;  ///< --add-to, --character, --over, --over-gap, --colour
  scene::SkirtFit fit;
  double bindThreshold_m = 0.04;
  bool clearanceGiven = false;      ///< --clearance given (else 2 cm, less for an avatar under 1 m tall)
  double voxel_m = kPersonsVoxel_m;  ///< the scene's voxel: a person's, less for a small avatar (sceneScaleOf)
  bool bindThresholdGiven = false;  ///< --bind-threshold given (else: as far as the waistband needs, at least 0.04 m)
  bool waistGiven = false, hipsGiven = false, legsGiven = false;  ///< --waist-segment, --hip-segments, --leg-segments
  bool withArms = false;                  ///< --with-arms
  SceneIntegrator integrator;  ///< --integrator, --implicit-tolerance
  std::vector<std::string> armSegments;   ///< with --with-arms: the forearms, hands and fingers, collidable too
  std::vector<std::string> keptApart;     ///< with --with-arms: the upper arms and forearms, the scene's keepApart
  std::string avatarRotation;             ///< the Avatar node's rotation that stands a body up along +y; "" : none
  std::vector<std::string> avatarMeshes;  ///< --avatar-meshes: the Avatar node's meshes
  std::vector<std::string> drawnMeshes;   ///< --avatar-drawn-meshes: the Avatar node's drawnMeshes
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

/// The skirt's ClothSet, without its material and avatar.
ClothSetText clothSetOf(const MakeSkirtOptions& o, const mesh::TriMesh& cloth, const mesh::TriMesh& mask) {
  ClothSetText c;
  c.cloth = &cloth;
  c.mask = &mask;
  c.collidesWith.push_back(o.fit.waistSegment);
  c.collidesWith.insert(c.collidesWith.end(), o.fit.hipSegments.begin(), o.fit.hipSegments.end());
  c.collidesWith.insert(c.collidesWith.end(), o.fit.legSegments.begin(), o.fit.legSegments.end());
  c.collidesWith.insert(c.collidesWith.end(), o.armSegments.begin(), o.armSegments.end());
  if (!o.add.colour.empty()) c.colour = Vec3(o.add.colour[0], o.add.colour[1], o.add.colour[2]);
  c.bindThreshold_m = o.bindThreshold_m;
  return c;
}

/// Writes the scene; returns its substeps per frame.
int writeScene(const std::string& path, const MakeSkirtOptions& o, const mesh::Skirt& skirt, const scene::Avatar& avatar) {
  constexpr double kFrameRate = 30.0;
  const cloth::Material m = knit();
  // The paper's 33 substeps per frame, or as many more as this skirt's smallest elements and
  // the knit's damping need (a small avatar's skirt has smaller, stiffer triangles).
  const int explicitSubsteps =
      cloth::fewestStableSubsteps(skirt.mesh, mesh::Topology::build(skirt.mesh), m, kFrameRate, 0.0, 33).substepsPerFrame;
  // Backward Euler: an eighth of those, bending in every solve.
  const bool implicit = o.integrator.implicit();
  const auto model = cloth::ClothModel::build(skirt.mesh, mesh::Topology::build(skirt.mesh), m);
  // Runge-Kutta: as few as its bound on the membrane's stiffest mode allows.
  const int kSubsteps = implicit ? cloth::implicitSubstepsFor(explicitSubsteps)
                        : o.integrator.kind == cloth::IntegratorKind::RungeKutta4
                            ? std::min(explicitSubsteps, cloth::rungeKuttaSubsteps(*model, kFrameRate))
                            : explicitSubsteps;
  // Bending as an impulse suits the one-stage explicit steps alone.
  const int bendEvery = !cloth::StepSettings::oneStageExplicit(o.integrator.kind)
                            ? 1
                            : cloth::suggestedBendEvery(*model, 1.0 / (kFrameRate * kSubsteps));
  std::ofstream os(path);
  fmt::print(os, "#VRML V2.0 utf8\n");
  const std::string own = ownMotionText(avatar);
  fmt::print(os, "# The paper's walking scenario: a skirt of {} triangles bound at the waist, on a segmented\n"
                 "# avatar whose hips, thighs and shins collide. Made by `drape make-skirt`; run it with\n"
                 "#   drape run {}{}\n"
                 "# Units: metres, kilograms, seconds; y is up.\n\n",
             skirt.mesh.triangleCount(), path,
             !own.empty() ? fmt::format(" --out out/skirt\n# (the avatar plays {}; --motion FILE plays another)", own)
             // The bundled walking skirt keeps its walk beside its scene; elsewhere any capture.
             : std::filesystem::exists(std::filesystem::path(path).parent_path() / "walk.bvh")
                 ? " --motion walk.bvh --out out/walking_skirt"
                 : " --motion CAPTURE.bvh --out out/skirt");
  fmt::print(os, "WorldInfo {{ title \"drape: walking skirt\" }}\n\n");
  const double voxel = o.voxel_m;
  const int digits = voxel >= 0.001 ? 3 : 5;  // whole millimetres, or a small avatar's hundredths
  fmt::print(os, "DEF Simulation Simulation {{\n  gravity 0 -9.81 0\n  frameRate {:g}\n  stepsPerFrame {}\n"
                 "  airViscosity 0.5\n  offsets [ {:.{}f} {:.{}f} {:.{}f} {:.{}f} ]\n  voxelSize {:.{}f}\n"
                 "{}  collisionEvery 1\n  bendEvery {}\n{}}}\n\n",
             kFrameRate, kSubsteps, voxel, digits, 2 * voxel, digits, 3 * voxel, digits, 6 * voxel, digits, voxel,
             digits, o.integrator.fields(), bendEvery, stringsField("keepApart", o.keptApart));
  writeMaterial(os, m);
  fmt::print(os, "DEF Body Avatar {{\n  url \"{}\"\n{}{}{}}}\n\n", o.avatarUrl,
             o.avatarRotation.empty() ? "" : fmt::format("  rotation {}\n", o.avatarRotation),
             stringsField("meshes", o.avatarMeshes), stringsField("drawnMeshes", o.drawnMeshes));
  ClothSetText c = clothSetOf(o, skirt.mesh, skirt.waistband);
  c.def = "Skirt";
  c.name = o.name == "Skirt" ? "" : o.name;
  c.meshDef = "SkirtMesh";
  writeClothSet(os, c);
  if (!os) throw Error(fmt::format("{}: cannot be written", path));
  return kSubsteps;
}

/// Every segment the fit and the scene name must be the avatar's: the defaults are the
/// MakeHuman CMU rig's, and another rig's avatar names its own.
void checkSegments(const scene::Avatar& avatar, const MakeSkirtOptions& o, const std::string& whose) {
  const auto check = [&](const std::string& name, const char* option) {
    if (avatar.findSegment(name) >= 0) return;
    throw Error(fmt::format("{}: the avatar has no segment '{}'; name one of its own with {} (it has: {})", whose,
                            name, option, fmt::join(avatar.segmentNames(), ", ")));
  };
  check(o.fit.waistSegment, "--waist-segment");
  for (const std::string& name : o.fit.hipSegments) check(name, "--hip-segments");
  for (const std::string& name : o.fit.legSegments) check(name, "--leg-segments");
}

/// The segments the command line leaves to make-skirt: the defaults (the MakeHuman CMU rig's
/// names) where the avatar has them all, else those its skeleton's shape shows
/// (scene::findLowerBody), said on standard output.
void chooseSegments(const scene::Avatar& avatar, MakeSkirtOptions& o, const std::string& whose) {
  const scene::SkirtFit defaults;
  const auto has = [&](const std::string& name) { return avatar.findSegment(name) >= 0; };
  const bool namedAsDefaults = has(defaults.waistSegment) && std::all_of(defaults.hipSegments.begin(), defaults.hipSegments.end(), has) &&
                               std::all_of(defaults.legSegments.begin(), defaults.legSegments.end(), has);
  if (namedAsDefaults || (o.waistGiven && o.hipsGiven && o.legsGiven)) return;
  std::string whyNot;
  if (!scene::findHumanoid(scene::jointsAt(avatar), &whyNot)) {
    if (o.waistGiven || o.hipsGiven || o.legsGiven) return;  // checkSegments names what is missing
    // Lying in its scene, it needs turning, not naming its segments.
    if (const std::optional<scene::Upright> u = scene::uprightAlongAnotherAxis(scene::jointsAt(avatar)))
      throw Error(fmt::format("{}: it stands along {}, not along +y as drape's scenes do; {}, and the skirt is fitted to "
                              "it standing",
                              whose, u->axis, u->standUpAdvice()));
    throw Error(fmt::format("{} has none of the MakeHuman CMU rig's segment names make-skirt knows ({}, {}, {}), and its "
                            "lower body cannot be found by the skeleton's shape: {}; name its own with --waist-segment, "
                            "--hip-segments and --leg-segments (it has: {})",
                            whose, defaults.waistSegment, fmt::join(defaults.hipSegments, ", "),
                            fmt::join(defaults.legSegments, ", "), whyNot, fmt::join(avatar.segmentNames(), ", ")));
  }
  const scene::LowerBody found = scene::findLowerBody(avatar);
  if (!o.waistGiven) o.fit.waistSegment = found.waist;
  if (!o.hipsGiven) o.fit.hipSegments = found.hips;
  if (!o.legsGiven) o.fit.legSegments = found.legs;
  fmt::print("found by the skeleton's shape: waist {}; hips {}; legs {}\n", o.fit.waistSegment,
             fmt::join(o.fit.hipSegments, ", "), fmt::join(o.fit.legSegments, ", "));
}

/// --with-arms: the forearms, hands and fingers the skirt collides with too, found by shape
/// and said on standard output; and the arms a new scene keeps out of the body.
void chooseArmSegments(const scene::Avatar& avatar, MakeSkirtOptions& o) {
  if (!o.withArms) return;
  o.armSegments = scene::findForearmsAndHands(avatar);
  fmt::print("collides with the forearms and hands too: {}\n", fmt::join(o.armSegments, ", "));
  // A walk swings the forearms into the hips, where the skirt's waistband, bound there,
  // cannot give way (on the MakeHuman body and CMU walk, 26 mm deep): once they collide,
  // the scene turns them out of the body as the walking dress's does.
  o.keptApart = scene::findUpperArmsAndForearms(avatar);
}

/// --add-to --with-arms: the scene's Simulation is its own, so where its keepApart leaves out
/// arms the skirt now collides with, the user is warned and told how to keep them out of the body.
void sayWhichArmsTheSceneLetsIn(const std::vector<std::string>& keptApart, const std::vector<std::string>& arms,
                                const std::string& scene) {
  std::vector<std::string> missing;
  for (const std::string& a : arms)
    if (std::find(keptApart.begin(), keptApart.end(), a) == keptApart.end()) missing.push_back(a);
  if (missing.empty()) return;
  std::vector<std::string> wanted = keptApart;
  wanted.insert(wanted.end(), missing.begin(), missing.end());
  spdlog::warn("{} keeps {} out of the body; a walk swings the arms into the hips, through the waistband, which "
               "cannot give way: add {} to its Simulation node's keepApart, or run it with --keep-apart {}",
               scene, keptApart.empty() ? "no parts" : "only " + fmt::format("{}", fmt::join(keptApart, ", ")),
               fmt::join(missing, ", "), fmt::join(wanted, ","));
}

/// The OBJ files' stems: skirt and waistband for the default name, else NAME and NAME_waistband.
std::pair<std::string, std::string> objStems(const std::string& name) {
  if (name == "Skirt") return {"skirt", "waistband"};
  return {name, name + "_waistband"};
}

/// The bindThreshold the skirt's waistband needs on `avatar`: the default 0.04 m, or a little
/// more than the farthest waistband vertex lies from its collidable parts' vertices (which is
/// no nearer than their surfaces, where drape run measures it) when a wide --clearance sets
/// the band farther out.
double waistbandReach(const scene::Avatar& avatar, const MakeSkirtOptions& o, const mesh::Skirt& skirt) {
  std::vector<std::string> parts{o.fit.waistSegment};
  parts.insert(parts.end(), o.fit.hipSegments.begin(), o.fit.hipSegments.end());
  parts.insert(parts.end(), o.fit.legSegments.begin(), o.fit.legSegments.end());
  const std::vector<Vec3> body = sim::restBodyPoints(avatar, parts);
  double farthest = 0.0;
  for (const Vec3& p : skirt.waistband.positions) {
    double nearest = std::numeric_limits<double>::infinity();
    for (const Vec3& q : body) nearest = std::min(nearest, (p - q).norm());
    farthest = std::max(farthest, nearest);
  }
  return std::max(0.04, std::ceil((farthest + 0.005) * 1e3) / 1e3);
}

/// What a small avatar's default clearance was scaled to, against a person's.
std::string scaledClearance(double clearance_m) {
  return fmt::format("clearance {:.1f} mm (a person's: {:g} mm)", 1e3 * clearance_m, 1e3 * scene::SkirtFit{}.clearance_m);
}

void printSkirt(const std::string& name, const mesh::Skirt& skirt) {
  const Aabb box = skirt.mesh.bounds();
  fmt::print("{}: {} vertices, {} triangles, waist at y = {:.3f} m, hem at y = {:.3f} m", name,
             skirt.mesh.vertexCount(), skirt.mesh.triangleCount(), box.max.y(), box.min.y());
}

int makeSkirt(MakeSkirtOptions o) {
  scene::Avatar avatar = scene::loadAvatarFile(o.avatar, o.avatarMeshes, o.drawnMeshes);
  sayWhichMeshesMakeTheBody(avatar, o.avatar);
  if (const std::optional<scene::Upright> u = standUp(avatar, o.avatar)) o.avatarRotation = u->rotationText();
  chooseSegments(avatar, o, o.avatar);
  checkSegments(avatar, o, o.avatar);
  chooseArmSegments(avatar, o);
  if (!o.keptApart.empty())
    fmt::print("keeps the arms out of the body as they swing (the scene's keepApart): {}\n", fmt::join(o.keptApart, ", "));
  // A small avatar's skirt sits as near its body as a person's does, for its size.
  const SceneScale scale = sceneScaleOf(avatar);
  o.voxel_m = scale.voxel_m;
  if (!o.clearanceGiven) o.fit.clearance_m *= scale.factor();
  const mesh::Skirt skirt = scene::fitSkirt(avatar, o.fit);
  MakeSkirtOptions written = o;
  if (!o.bindThresholdGiven) written.bindThreshold_m = waistbandReach(avatar, o, skirt);
  written.avatarUrl = prepareSceneDir(o.out, o.avatar, o.avatarUrl);
  const std::filesystem::path dir(o.out);
  const auto [stem, maskStem] = objStems(o.name);
  formats::writeObj((dir / (stem + ".obj")).string(), skirt.mesh.positions, skirt.mesh.triangles, "drape make-skirt (m)");
  formats::writeObj((dir / (maskStem + ".obj")).string(), skirt.waistband.positions, skirt.waistband.triangles,
                    "drape make-skirt: constraint mask (m)");
  const int substeps = writeScene((dir / "scene.wrl").string(), written, skirt, avatar);
  printSkirt(o.name == "Skirt" ? "skirt" : o.name, skirt);
  const char* each = o.integrator.implicit() ? ", each a backward-Euler solve"
                     : o.integrator.kind == cloth::IntegratorKind::RungeKutta4 ? ", each a fourth-order Runge-Kutta step"
                                                                              : "";
  fmt::print("; {} substeps per frame{}\n", substeps, each);
  sayWhereTheVoxelIsScaled(
      scale, o.avatar,
      o.clearanceGiven ? "" : "; " + scaledClearance(o.fit.clearance_m));
  fmt::print("wrote {}/scene.wrl, {}.obj, {}.obj\n", o.out, stem, maskStem);
  printHowToRun((dir / "scene.wrl").string(), avatar);
  return 0;
}

/// --add-to: the skirt fitted to the scene's character as the scene places it, and appended.
int addSkirt(MakeSkirtOptions o) {
  const SceneToDress dress = openSceneToDress(o.add.scene, o.add.character);
  const scene::Avatar& avatar = *dress.character.avatar;
  const std::string whose = fmt::format("{} ('{}')", o.add.scene, dress.character.name);
  chooseSegments(avatar, o, whose);
  checkSegments(avatar, o, whose);
  chooseArmSegments(avatar, o);
  sayWhichArmsTheSceneLetsIn(dress.scene.simulation.keepApart, o.keptApart, o.add.scene);
  checkNewGarment(dress, o.name, o.add.over);
  // A small character's skirt sits as near its body, and as near the skirt under it, as a
  // person's does, for its size; the scene's voxel and offsets are its own.
  const SceneScale scale = sceneScaleOf(avatar);
  std::vector<std::string> scaled;
  if (!o.clearanceGiven && scale.factor() != 1.0) {
    o.fit.clearance_m *= scale.factor();
    scaled.push_back(scaledClearance(o.fit.clearance_m));
  }
  if (const std::string gap = fitToASmallCharacter(o.add, dress, scale); !gap.empty()) scaled.push_back(gap);
  for (const scene::Garment& g : dress.scene.garments)
    if (std::find(o.add.over.begin(), o.add.over.end(), g.name) != o.add.over.end())
      o.fit.wornOver.insert(o.fit.wornOver.end(), g.mesh.positions.begin(), g.mesh.positions.end());
  o.fit.wornOverGap_m = o.add.overGap_m;
  const mesh::Skirt skirt = scene::fitSkirt(avatar, o.fit);
  const double added = checkSceneSteps(dress, skirt.mesh, knit(), o.name);

  const mesh::TriMesh cloth = inFileUnits(dress, skirt.mesh), mask = inFileUnits(dress, skirt.waistband);
  ClothSetText c = clothSetOf(o, cloth, mask);
  if (!o.bindThresholdGiven) c.bindThreshold_m = waistbandReach(avatar, o, skirt);
  c.name = o.name;
  dressFor(c, dress, o.add, materialNode(knit(), "  ", o.name + " knit"));
  std::ostringstream text;
  text << addedComment("make-skirt", o.name, dress, o.add);
  writeClothSet(text, c);
  appendToScene(dress, text.str());

  const std::filesystem::path dir = std::filesystem::path(o.add.scene).parent_path();
  const auto [stem, maskStem] = objStems(o.name);
  formats::writeObj((dir / (stem + ".obj")).string(), skirt.mesh.positions, skirt.mesh.triangles,
                    "drape make-skirt: " + o.name + " (m, world)");
  formats::writeObj((dir / (maskStem + ".obj")).string(), skirt.waistband.positions, skirt.waistband.triangles,
                    "drape make-skirt: constraint mask of " + o.name + " (m, world)");
  printSkirt(o.name, skirt);
  fmt::print("; {}\n", wornText(dress, o.add));
  if (!scaled.empty())
    fmt::print("{} is {:.2f} m tall: {}\n", dress.character.name, scale.height_m, fmt::join(scaled, ", "));
  printSceneSteps(dress, added);
  fmt::print("added it to {}; wrote {}.obj, {}.obj beside it\n", o.add.scene, stem, maskStem);
  printHowToRun(o.add.scene, avatar, dress.character.motion);
  return 0;
}

RunFunction setupMakeSkirt(CLI::App& app) {
  static MakeSkirtOptions o;
  app.add_option("avatar", o.avatar, "Avatar file to fit the skirt to (.glb, .gltf, .vrm, .dae, .fbx, MakeHuman .mhskel, or a VRML97 "
                 "H-Anim humanoid .wrl; one standing along +z is stood up); not with --add-to");
  app.add_option("--out", o.out,
                 "Directory for scene.wrl, skirt.obj and waistband.obj (with --name, NAME.obj and NAME_waistband.obj; "
                 "required without --add-to)");
  addAddToOptions(app, o.add,
                  "Add the skirt to this scene instead, fitted to its character (a second skirt over a petticoat): "
                  "appended to the file as a ClothSet, once the scene with it loads; its OBJs are written beside it",
                  "red");
  app.add_option("--name", o.name, "The skirt's name (the ClothSet's; default Skirt)");
  app.add_option("--avatar-url", o.avatarUrl, "The Avatar url written into scene.wrl (default: the avatar's path relative to --out)");
  app.add_option("--avatar-meshes", o.avatarMeshes,
                 "The avatar file's skinned meshes that make the body, by node or mesh name or shell pattern (a "
                 "character file that holds its clothes or hair too), written as the Avatar node's meshes; default: "
                 "every mesh of its skin")
      ->delimiter(',');
  app.add_option("--avatar-drawn-meshes", o.drawnMeshes,
                 "Of the avatar file's skinned meshes, those drawn with the body but not collided with (hair, eyes, "
                 "accessories), by node or mesh name or shell pattern (*: every mesh the body leaves out), written as "
                 "the Avatar node's drawnMeshes; default: none")
      ->delimiter(',');
  app.add_option("--length", o.fit.length_m, "Waist to hem, m (default: a little above the knees)");
  app.add_option("--clearance", o.fit.clearance_m,
                 "Gap between body and skirt at rest, m (default: 0.02, less for an avatar under 1 m tall, by its "
                 "height against a person's 1.7 m); with --over, the skirt also clears the garments it is worn over by "
                 "twice --over-gap");
  app.add_option("--flare", o.fit.flare, "Extra hem radius per metre of length")->capture_default_str();
  app.add_option("--around", o.fit.segments, "Vertices around")->capture_default_str()->check(CLI::Range(6, 1000));
  app.add_option("--rings", o.fit.rings, "Bands from waist to hem")->capture_default_str()->check(CLI::Range(2, 1000));
  app.add_option("--waist-segment", o.fit.waistSegment,
                 "Segment at whose joint the waist sits (default: LowerBack, or where an avatar without the "
                 "MakeHuman CMU rig's names has its waist by its skeleton's shape)")
      ->capture_default_str();
  app.add_option("--hip-segments", o.fit.hipSegments,
                 "Segments below the waist the skirt clears and collides with (default: Hips, or found as the waist is)")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--leg-segments", o.fit.legSegments,
                 "Leg segments the skirt clears and collides with (default: the thighs and shins, by the CMU rig's names "
                 "or found as the waist is); its default length reaches a little above the knees")
      ->delimiter(',')
      ->capture_default_str();
  o.integrator.addOptions(app, "an eighth of the explicit steps' substeps");
  app.add_flag("--with-arms", o.withArms,
               "Collide with the forearms, hands and fingers too (found by the skeleton's shape), so that swinging "
               "arms push the skirt instead of sinking into it; costs a collision test per part");
  app.add_option("--bind-threshold", o.bindThreshold_m,
                 "Written into the ClothSet, m (default: 0.04, or as far as a wide --clearance sets the waistband "
                 "from the body)");
  return [&app] {
    if (o.name.empty()) o.name = "Skirt";
    o.bindThresholdGiven = app.count("--bind-threshold") > 0;
    o.clearanceGiven = app.count("--clearance") > 0;
    o.add.overGapGiven = app.count("--over-gap") > 0;
    o.integrator.check(app);
    o.waistGiven = app.count("--waist-segment") > 0;
    o.hipsGiven = app.count("--hip-segments") > 0;
    o.legsGiven = app.count("--leg-segments") > 0;
    if (!addingToScene(app, o.add, "make-skirt", o.avatar, o.out,
                       {"--out", "--avatar-url", "--avatar-meshes", "--avatar-drawn-meshes", "--integrator",
                        "--implicit-tolerance"}))
      return makeSkirt(o);
    return addSkirt(o);
  };
}

const bool registered_cmd_make_skirt = registerCommand({"make-skirt", "Fit a skirt to an avatar and write a ready-to-run scene", "", 60, &setupMakeSkirt});

}  // namespace
}  // namespace drape::cli
