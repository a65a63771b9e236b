// `drape make-scene AVATAR --garment FILE.obj --mask MASK.obj --out DIR`: a ready-to-run
// VRML97 scene (DIR/scene.wrl) that dresses an avatar in a garment modelled for it, such as
// a MakeHuman garment on the MakeHuman body. The garment and its constraint mask are written
// inline in metres; the collidable segments are those the garment lies near at rest; the
// substeps per frame are the fewest that mass scaling keeps stable within --max-added-mass.
// `--add-to SCENE` puts one more garment on a character of a scene already written.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <fmt/ostream.h>
#include <fmt/ranges.h>

#include "avatar_scale.hpp"
#include "command.hpp"
#include "stand_up.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/solver.hpp"
#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/units.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/avatar_segment.hpp"
#include "drape/scene/garment_fit.hpp"
#include "run_setup.hpp"
#include "scene_add.hpp"
#include "scene_text.hpp"
#include "stitch_gaps.hpp"

namespace drape::cli {
namespace {

struct MakeSceneOptions {
  std::string avatar;
  std::string avatarUrl;
  std::string garment;
  std::vector<std::string> garmentParts;  ///< --garment-parts: the meshes (OBJ groups) that are the garment
  std::string mask;
  std::string units = "m";
  std::string out;
  std::string name;
  std::string title;
  AddToOptions add;  ///< --add-to, --character, --over, --over-gap, --colour
  std::vector<std::string> collidesWith;
  std::vector<std::string> faceSamplesWith;
  std::vector<std::string> keepApart;  ///< --keep-apart: the scene's Simulation keepApart
  std::vector<std::string> cutAtJoints;  ///< --cut-at-joints: the Avatar node's cutAtJoints
  std::vector<std::string> avatarMeshes;  ///< --avatar-meshes: the Avatar node's meshes
  std::vector<std::string> drawnMeshes;   ///< --avatar-drawn-meshes: the Avatar node's drawnMeshes
  std::string avatarRotation;            ///< the Avatar node's rotation that stands a body up along +y; "" : none
  double reach_m = 0.03;
  double voxel_m = 0.005;
  bool voxelGiven = false;  ///< else sceneScaleOf's: a person's 5 mm, less for a small avatar
  std::vector<double> offsets;  ///< T0..T3, m; empty: 1, 2, 3 and 6 voxels
  double frameRate = 30.0;
  int stepsPerFrame = 0;
  double maxAddedMass = 0.02;
  int bendEvery = 0;  ///< --bend-every, or 0: chosen by makeScene from the garment
  int collisionEvery = 1;  ///< --collision-every
  SceneIntegrator integrator;  ///< --integrator, --implicit-tolerance
  double bindThreshold_m = 0.04;
  double selfCollision_m = 0.0;  ///< --self-collision: the ClothSet's selfCollision (0: none)
  double stitchGaps_m = 0.0;  ///< --stitch-gaps: sew boundary vertices facing each other within this, m (0: none)
  StitchPairs stitches;        ///< found from stitchGaps_m
  cloth::Material material = knit();

  /// The walking skirt's knit (examples/walking_skirt) with a tenth of its damping.
  static cloth::Material knit() {
    cloth::Material m;
    m.density_kg_m3 = 300.0;
    m.thickness_m = 0.0005;
    m.youngsModulus_Pa = 5.0e4;
    m.poissonRatio = 0.3;
    m.damping_s = 0.0002;  // stiffness-proportional damping shortens the explicit step
    m.staticFriction = 0.5;
    m.dynamicFriction = 0.3;
    m.compressionScale = 0.2;
    return m;
  }
};

/// Segments with at least one garment vertex within `reach` of their box at rest (world).
std::vector<std::string> segmentsNear(const scene::Avatar& avatar, const mesh::TriMesh& garment, double reach) {
  std::vector<std::string> near;
  for (const scene::Segment& seg : avatar.segments) {
    const RigidTransform rest = avatar.joints[static_cast<std::size_t>(seg.joint)].restWorld();
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (const Vec3& p : seg.mesh.positions) {
      const Vec3 w = rest.apply(p);
      lo = lo.cwiseMin(w);
      hi = hi.cwiseMax(w);
    }
    lo -= Vec3::Constant(reach);
    hi += Vec3::Constant(reach);
    const bool touches = std::any_of(garment.positions.begin(), garment.positions.end(), [&](const Vec3& p) {
      return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all();
    });
    if (touches) near.push_back(seg.name);
  }
  return near;
}

/// The mask moved with the garment's fit: each mask vertex is matched to the garment vertex
/// it sits on as modelled (within 1 mm) and takes that vertex's fitted position.
mesh::TriMesh fitMask(const mesh::TriMesh& mask, const scene::MakeHumanGarment& g, const std::string& maskPath) {
  constexpr double kTolerance_m = 1e-3;
  mesh::TriMesh fitted = mask;
  std::size_t unmatched = 0;
  for (std::size_t i = 0; i < mask.positions.size(); ++i) {
    std::size_t best = 0;
    double bestDistance = std::numeric_limits<double>::infinity();
    for (std::size_t v = 0; v < g.modelled.positions.size(); ++v) {
      const double d = (g.modelled.positions[v] - mask.positions[i]).norm();
      if (d < bestDistance) {
        bestDistance = d;
        best = v;
      }
    }
    if (bestDistance > kTolerance_m) ++unmatched;
    fitted.positions[i] = g.fitted.positions[best];
  }
  if (unmatched > 0)
    throw Error(fmt::format("{}: {} of {} mask vertices are more than 1 mm from every vertex of the garment as "
                            "modelled; is --units right?",
                            maskPath, unmatched, mask.positions.size()));
  return fitted;
}

/// The garment's ClothSet, without its material and avatar.
ClothSetText clothSetOf(const MakeSceneOptions& o, const mesh::TriMesh& garment, const mesh::TriMesh& mask) {
  ClothSetText c;
  c.name = o.name;
  if (!o.add.colour.empty()) c.colour = Vec3(o.add.colour[0], o.add.colour[1], o.add.colour[2]);
  c.cloth = &garment;
  c.mask = &mask;
  c.collidesWith = o.collidesWith;
  c.faceSamplesWith = o.faceSamplesWith;
  c.stitches = o.stitches;
  c.selfCollision_m = o.selfCollision_m;
  c.bindThreshold_m = o.bindThreshold_m;
  return c;
}

void writeScene(const std::string& path, const MakeSceneOptions& o, const mesh::TriMesh& garment,
                const mesh::TriMesh& mask) {
  std::ofstream os(path);
  const double v = o.voxel_m;
  const std::vector<double> t = o.offsets.empty() ? std::vector<double>{v, 2 * v, 3 * v, 6 * v} : o.offsets;
  fmt::print(os, "#VRML V2.0 utf8\n");
  fmt::print(os,
             "# {}: {} ({} triangles) on {}, bound by a constraint mask of {} vertices. Made by\n"
             "# `drape make-scene`; run it with\n#   drape run {} --motion WALK.bvh --out out/{}\n"
             "# Units: metres, kilograms, seconds; y is up.\n\n",
             o.title, o.name, garment.triangleCount(), std::filesystem::path(o.avatar).filename().string(),
             mask.vertexCount(), path, o.name);
  fmt::print(os, "WorldInfo {{ title \"drape: {}\" }}\n\n", o.title);
  fmt::print(os,
             "DEF Simulation Simulation {{\n  gravity 0 -9.81 0\n  frameRate {:g}\n  stepsPerFrame {}\n"
             "  maxAddedMass {:g}\n  airViscosity 0.5\n  offsets [ {:g} {:g} {:g} {:g} ]\n  voxelSize {:g}\n"
             "{}  collisionEvery {}\n  bendEvery {}\n{}}}\n\n",
             o.frameRate, o.stepsPerFrame, o.maxAddedMass, t[0], t[1], t[2], t[3], v, o.integrator.fields(),
             o.collisionEvery, o.bendEvery,
             o.keepApart.empty() ? "" : fmt::format("  keepApart [ \"{}\" ]\n", fmt::join(o.keepApart, "\", \"")));
  writeMaterial(os, o.material);
  fmt::print(os, "DEF Body Avatar {{\n  url \"{}\"\n{}{}{}{}}}\n\n", o.avatarUrl,
             o.avatarRotation.empty() ? "" : fmt::format("  rotation {}\n", o.avatarRotation),
             stringsField("meshes", o.avatarMeshes), stringsField("drawnMeshes", o.drawnMeshes),
             stringsField("cutAtJoints", o.cutAtJoints));
  ClothSetText c = clothSetOf(o, garment, mask);
  c.def = "Garment";
  c.colour = o.add.colour.empty() ? Vec3(0.15, 0.25, 0.55) : c.colour;
  writeClothSet(os, c);
  if (!os) throw Error(fmt::format("{}: cannot be written", path));
}

/// A garment or mask file in metres: an OBJ in --units, the other formats in their own (a
/// mask with its loose points). Says what was read from a file of several meshes, or welded.
mesh::TriMesh readMeshOf(const MakeSceneOptions& o, const std::string& path, const std::vector<std::string>& parts,
                         bool isMask) {
  formats::MeshFileOptions read;
  read.looseVertices = isMask;
  read.metresPerUnit = formats::metresPerUnit(o.units, "--units");
  read.parts = parts;
  formats::MeshFile file = formats::readMeshFile(path, read);
  if (const std::string what = formats::describeRead(file); !what.empty()) fmt::print("{}: {}\n", path, what);
  return std::move(file.mesh);
}

/// The garment and its mask as modelled on the avatar file `avatarFile` at rest, in metres:
/// a MakeHuman .mhclo refitted to the MakeHuman body that file builds.
std::pair<mesh::TriMesh, mesh::TriMesh> readGarment(const MakeSceneOptions& o, const std::string& avatarFile) {
  mesh::TriMesh mask = readMeshOf(o, o.mask, {}, true);
  if (std::filesystem::path(o.garment).extension() != ".mhclo") return {readMeshOf(o, o.garment, o.garmentParts, false), mask};
  // A MakeHuman garment: refitted to the body this avatar is built from.
  if (!o.garmentParts.empty()) throw Error(fmt::format("--garment-parts: {} is one mesh, not a file of parts", o.garment));
  if (std::filesystem::path(avatarFile).extension() != ".mhskel")
    throw Error(fmt::format("{}: a MakeHuman garment (.mhclo) fits the MakeHuman body; give a .mhskel avatar, not {}",
                            o.garment, avatarFile.empty() ? "an H-Anim Humanoid" : avatarFile));
  const scene::MakeHumanGarment fit = scene::fitMakeHumanGarment(o.garment, avatarFile);
  return {fit.fitted, fitMask(mask, fit, o.mask)};
}

/// The collidable segments (the ones near the garment unless given) and those with face
/// samples, checked against the avatar's; `whose` names the avatar in messages.
void chooseCollidables(MakeSceneOptions& o, const scene::Avatar& avatar, const mesh::TriMesh& garment,
                       const std::string& whose) {
  if (o.collidesWith.empty()) o.collidesWith = segmentsNear(avatar, garment, o.reach_m);
  for (const std::string& s : o.collidesWith)
    if (avatar.findSegment(s) < 0) throw Error(fmt::format("--collides-with: {} has no segment '{}'", whose, s));
  if (o.collidesWith.empty())
    throw Error(fmt::format("{}: the garment is not within {} m of any segment of {}; is --units right?", o.garment,
                            o.reach_m, whose));
  for (const std::string& s : o.faceSamplesWith)
    if (std::find(o.collidesWith.begin(), o.collidesWith.end(), s) == o.collidesWith.end())
      throw Error(fmt::format("--face-samples-with: '{}' is not one of the collidable segments ({})", s,
                              fmt::join(o.collidesWith, ", ")));
}

int makeScene(MakeSceneOptions& o) {
  scene::Avatar avatar = scene::loadAvatarFile(o.avatar, o.avatarMeshes, o.drawnMeshes);
  sayWhichMeshesMakeTheBody(avatar, o.avatar);
  // A body standing along +z stood up, and the garment modelled on it with it.
  const std::optional<scene::Upright> upright = standUp(avatar, o.avatar);
  if (upright) o.avatarRotation = upright->rotationText();
  // The parts as the scene will cut them: which are within reach of the garment may change.
  if (!o.cutAtJoints.empty()) scene::segmentSkinnedAvatar(avatar, o.cutAtJoints);
  auto [garment, mask] = readGarment(o, o.avatar);
  if (upright) {
    garment.transform(RigidTransform{upright->turn, Vec3::Zero()});
    mask.transform(RigidTransform{upright->turn, Vec3::Zero()});
  }
  if (o.name.empty()) o.name = std::filesystem::path(o.garment).stem().string();
  if (o.title.empty()) o.title = o.name;
  if (!o.voxelGiven) {
    const SceneScale scale = sceneScaleOf(avatar);
    o.voxel_m = scale.voxel_m;
    sayWhereTheVoxelIsScaled(scale, o.avatar);
  }
  chooseCollidables(o, avatar, garment, o.avatar);
  for (const std::string& s : o.keepApart)
    if (avatar.findSegment(s) < 0) throw Error(fmt::format("--keep-apart: {} has no segment '{}'", o.avatar, s));
  // The fewest substeps per frame, at least the paper's 33, that mass scaling keeps stable
  // within the allowance; or the count asked for, and what it needs.
  const mesh::Topology topology = mesh::Topology::build(garment);
  const bool implicit = o.integrator.implicit();
  const cloth::SubstepChoice choice = cloth::fewestStableSubsteps(
      garment, topology, o.material, o.frameRate, o.maxAddedMass, std::max(33, implicit ? 0 : o.stepsPerFrame));
  std::string substeps;  // what the choice was, for the summary
  if (implicit) {
    // Stable at any substep, with no mass added and bending in every solve: an eighth of the
    // explicit steps' count unless asked.
    if (o.bendEvery > 1)
      throw Error(fmt::format("--bend-every {}: backward Euler takes bending into its solve every substep; leave "
                              "--bend-every out with --integrator backward-euler",
                              o.bendEvery));
    o.bendEvery = 1;
    o.maxAddedMass = 0.0;
    if (o.stepsPerFrame == 0) o.stepsPerFrame = cloth::implicitSubstepsFor(choice.substepsPerFrame);
    substeps = fmt::format("{} substeps per frame at {:g} frames/s, each a backward-Euler solve (the explicit steps "
                           "would take {} with {:.2f} % of the mass added)",
                           o.stepsPerFrame, o.frameRate, choice.substepsPerFrame, 100.0 * choice.addedMassFraction);
  } else {
    // Unscaled masses: scaling only adds mass, which slows bending, so this is the cautious
    // rhythm; a rhythm asked for is held to the bending forces' stable step, as drape run
    // holds it.
    const auto unscaled = cloth::ClothModel::build(garment, topology, o.material);
    // Runge-Kutta: its own bound, and mass scaling for it, from any count up (none where the
    // unscaled membrane keeps the bound, and then the scene allows none).
    const bool rungeKutta = o.integrator.kind == cloth::IntegratorKind::RungeKutta4;
    const cloth::IntegratorKind bound = rungeKutta ? o.integrator.kind : cloth::IntegratorKind::SymplecticEuler;
    const cloth::SubstepChoice own =
        rungeKutta ? cloth::fewestStableSubsteps(garment, topology, o.material, o.frameRate, o.maxAddedMass,
                                                 std::max(1, o.stepsPerFrame), bound)
                   : choice;
    if (o.stepsPerFrame == 0) o.stepsPerFrame = own.substepsPerFrame;
    const double added = o.stepsPerFrame == own.substepsPerFrame
                             ? own.addedMassFraction
                             : cloth::addedMassFractionAt(garment, topology, o.material, o.frameRate,
                                                          o.stepsPerFrame, bound);
    const bool unscaledRungeKutta = rungeKutta && added == 0.0;
    if (unscaledRungeKutta) o.maxAddedMass = 0.0;
    if (added > o.maxAddedMass)
      throw Error(fmt::format("--substeps {}: mass scaling would add {:.2f} % of the garment's mass, more than "
                              "--max-added-mass {:g}; {} substeps per frame need no more than that",
                              o.stepsPerFrame, 100.0 * added, o.maxAddedMass, own.substepsPerFrame));
    if (!cloth::StepSettings::oneStageExplicit(o.integrator.kind)) {
      if (o.bendEvery > 1)
        throw Error(fmt::format("--bend-every {}: the {} step takes bending into each of its stages; leave "
                                "--bend-every out with it",
                                o.bendEvery, cloth::integratorName(o.integrator.kind)));
      o.bendEvery = 1;
    } else if (o.bendEvery == 0) {
      o.bendEvery = cloth::suggestedBendEvery(*unscaled, 1.0 / (o.frameRate * o.stepsPerFrame));
    } else {
      cloth::StepSettings rhythm;
      rhythm.frameRate_hz = o.frameRate;
      rhythm.substepsPerFrame = o.stepsPerFrame;
      rhythm.bendEvery = o.bendEvery;
      cloth::checkBendingStep(*unscaled, rhythm);
    }
    const std::string symplectic = fmt::format("symplectic Euler would take {} with {:.2f} % of the mass added",
                                               choice.substepsPerFrame, 100.0 * choice.addedMassFraction);
    substeps =
        unscaledRungeKutta
            ? fmt::format("{} substeps per frame at {:g} frames/s, each a fourth-order Runge-Kutta step, no mass added "
                          "({})",
                          o.stepsPerFrame, o.frameRate, symplectic)
        : rungeKutta ? fmt::format("{} substeps per frame at {:g} frames/s, each a fourth-order Runge-Kutta step "
                                   "(mass scaling adds {:.2f} % of the mass; {})",
                                   o.stepsPerFrame, o.frameRate, 100.0 * added, symplectic)
                     : fmt::format("{} substeps per frame at {:g} frames/s (mass scaling adds {:.2f} % of the mass)",
                                   o.stepsPerFrame, o.frameRate, 100.0 * added);
  }

  if (o.stitchGaps_m > 0.0) o.stitches = openingsToSew(garment, topology, o.name, o.stitchGaps_m);

  o.avatarUrl = prepareSceneDir(o.out, o.avatar, o.avatarUrl);
  const std::filesystem::path dir(o.out);
  writeScene((dir / "scene.wrl").string(), o, garment, mask);
  formats::writeObj((dir / (o.name + ".obj")).string(), garment.positions, garment.triangles,
                    "drape make-scene: " + o.name + " on the avatar at rest (m)");
  formats::writeObj((dir / (o.name + "_mask.obj")).string(), mask.positions, mask.triangles,
                    "drape make-scene: constraint mask of " + o.name + " (m)");
  fmt::print("{}: {} vertices, {} triangles; mask {} vertices\n", o.name, garment.vertexCount(),
             garment.triangleCount(), mask.vertexCount());
  fmt::print("collides with {}\n", fmt::join(o.collidesWith, ", "));
  fmt::print("{}\n", substeps);
  if (!o.stitches.empty())
    fmt::print("{} stitches across gaps of up to {:.1f} mm\n", o.stitches.size(), 1e3 * widestStitch_m(garment, o.stitches));
  fmt::print("wrote {}/scene.wrl, {}.obj, {}_mask.obj\n", o.out, o.name, o.name);
  printHowToRun((dir / "scene.wrl").string(), avatar);
  return 0;
}

/// --add-to: the garment put on the scene's character where the scene places it, and appended.
int addGarment(MakeSceneOptions& o) {
  const SceneToDress dress = openSceneToDress(o.add.scene, o.add.character);
  const scene::Avatar& avatar = *dress.character.avatar;
  auto [garment, mask] = readGarment(o, dress.avatarFile);
  // Modelled on the avatar file at rest; the scene places that file's frame.
  for (mesh::TriMesh* m : {&garment, &mask})
    for (Vec3& p : m->positions) p = dress.placement.apply(dress.scale * p);
  if (o.name.empty()) o.name = std::filesystem::path(o.garment).stem().string();
  checkNewGarment(dress, o.name, o.add.over);
  const SceneScale scale = sceneScaleOf(avatar);
  const std::string scaled = fitToASmallCharacter(o.add, dress, scale);
  chooseCollidables(o, avatar, garment, fmt::format("{} ('{}')", o.add.scene, dress.character.name));
  const double added = checkSceneSteps(dress, garment, o.material, o.name);
  if (o.stitchGaps_m > 0.0) o.stitches = openingsToSew(garment, mesh::Topology::build(garment), o.name, o.stitchGaps_m);

  const mesh::TriMesh cloth = inFileUnits(dress, garment), clothMask = inFileUnits(dress, mask);
  ClothSetText c = clothSetOf(o, cloth, clothMask);
  if (!o.offsets.empty()) c.offsets = std::array<double, 4>{o.offsets[0], o.offsets[1], o.offsets[2], o.offsets[3]};
  dressFor(c, dress, o.add, materialNode(o.material, "  ", o.name + " knit"));
  std::ostringstream text;
  text << addedComment("make-scene", o.name, dress, o.add);
  writeClothSet(text, c);
  appendToScene(dress, text.str());

  const std::filesystem::path dir = std::filesystem::path(o.add.scene).parent_path();
  formats::writeObj((dir / (o.name + ".obj")).string(), garment.positions, garment.triangles,
                    "drape make-scene: " + o.name + " (m, world)");
  formats::writeObj((dir / (o.name + "_mask.obj")).string(), mask.positions, mask.triangles,
                    "drape make-scene: constraint mask of " + o.name + " (m, world)");
  fmt::print("{}: {} vertices, {} triangles; mask {} vertices; {}\n", o.name, garment.vertexCount(),
             garment.triangleCount(), mask.vertexCount(), wornText(dress, o.add));
  if (!scaled.empty()) fmt::print("{} is {:.2f} m tall: {}\n", dress.character.name, scale.height_m, scaled);
  fmt::print("collides with {}\n", fmt::join(o.collidesWith, ", "));
  printSceneSteps(dress, added);
  if (!o.stitches.empty())
    fmt::print("{} stitches across gaps of up to {:.1f} mm\n", o.stitches.size(), 1e3 * widestStitch_m(garment, o.stitches));
  fmt::print("added it to {}; wrote {}.obj, {}_mask.obj beside it\n", o.add.scene, o.name, o.name);
  printHowToRun(o.add.scene, avatar, dress.character.motion);
  return 0;
}

RunFunction setupMakeScene(CLI::App& app) {
  static MakeSceneOptions o;
  app.add_option("avatar", o.avatar,
                 "Avatar file the garment was modelled on (.glb, .gltf, .vrm, .dae, .fbx, MakeHuman .mhskel, or a VRML97 "
                 "H-Anim humanoid .wrl; one standing along +z is stood up with the garment); not with --add-to");
  app.add_option("--garment", o.garment,
                 "Garment in the avatar's rest pose: OBJ, glTF (.glb, .gltf, .vrm), Collada (.dae) or FBX (.fbx), its "
                 "vertices welded where those files split them; or a MakeHuman .mhclo (refitted to the MakeHuman body)")
      ->required();
  app.add_option("--garment-parts", o.garmentParts,
                 "The meshes of the garment file that are the garment, by node or mesh name or shell pattern (OBJ: g/o "
                 "groups); default: all")
      ->delimiter(',');
  app.add_option("--mask", o.mask,
                 "Constraint mask (OBJ, glTF, Collada or FBX): the garment vertices bound to the body (for a .mhclo: "
                 "on its OBJ as modelled)")
      ->required();
  app.add_option("--out", o.out, "Directory for scene.wrl (required without --add-to)");
  addAddToOptions(app, o.add,
                  "Add the garment to this scene instead, on its character (a jacket over the shirt it wears): "
                  "modelled on the file its Avatar node loads, placed as the node places it, and appended to the "
                  "scene as a ClothSet once the scene with it loads; NAME.obj and NAME_mask.obj are written beside "
                  "it. --offsets become the garment's own",
                  "blue");
  app.add_option("--units", o.units,
                 "Length unit of the garment and mask where they are OBJ files: m, dm, cm, mm, in (glTF, Collada and "
                 "FBX state their own)")
      ->capture_default_str();
  app.add_option("--name", o.name, "Garment name (default: the garment file's name)");
  app.add_option("--title", o.title, "Scene title (default: the garment name)");
  app.add_option("--avatar-url", o.avatarUrl, "The Avatar url written into scene.wrl (default: the avatar's path relative to --out)");
  app.add_option("--collides-with", o.collidesWith,
                 "Collidable segments (default: every segment the garment comes within --reach of at rest)")
      ->delimiter(',');
  app.add_option("--face-samples-with", o.faceSamplesWith,
                 "Of the collidable segments, those the garment's triangle centroids collide with too, not only "
                 "its vertices (where its triangles are large against the segment's curvature)")
      ->delimiter(',');
  app.add_option("--self-collision", o.selfCollision_m,
                 "Keep the garment's own layers this many m apart, written as its selfCollision (default 0: they "
                 "pass through one another)")
      ->type_name("M")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--keep-apart", o.keepApart,
                 "Body parts whose motion is corrected to keep them out of the collidable parts they go into, "
                 "written as the scene's keepApart (e.g. LeftForeArm,RightForeArm,LeftArm,RightArm)")
      ->delimiter(',');
  app.add_option("--avatar-meshes", o.avatarMeshes,
                 "The avatar file's skinned meshes that make the body, by node or mesh name or shell pattern (a "
                 "character file that holds its clothes or hair too: e.g. Body,Shoes), written as the Avatar node's meshes; default: "
                 "every mesh of its skin (drape inspect FILE lists them)")
      ->delimiter(',');
  app.add_option("--avatar-drawn-meshes", o.drawnMeshes,
                 "Of the avatar file's skinned meshes, those drawn with the body but not collided with (hair, eyes, "
                 "accessories), by node or mesh name or shell pattern (*: every mesh the body leaves out), written as "
                 "the Avatar node's drawnMeshes; default: none")
      ->delimiter(',');
  app.add_option("--cut-at-joints", o.cutAtJoints,
                 "Joints whose rigid parts are cut across the joint, what lies behind it going to the parent's part, "
                 "written as the Avatar node's cutAtJoints (e.g. LeftArm,RightArm; see drape run --help)")
      ->delimiter(',');
  app.add_option("--reach", o.reach_m, "Distance from a segment's box that makes it collidable, m")->capture_default_str();
  app.add_option("--voxel", o.voxel_m,
                 "Distance-field voxel, m; without --offsets, T0..T3 are 1, 2, 3 and 6 voxels (default: 0.005, less for "
                 "an avatar under 1 m tall, by its height against a person's 1.7 m)");
  app.add_option("--offsets", o.offsets, "The offset surfaces T0,T1,T2,T3 in m (a garment modelled tight on the body "
                 "needs T2 below its clearance)")
      ->delimiter(',')
      ->expected(4);
  app.add_option("--damping", o.material.damping_s, "The knit's stiffness-proportional damping time, s")
      ->capture_default_str();
  app.add_option("--frame-rate", o.frameRate, "Frames per second")->capture_default_str();
  app.add_option("--substeps", o.stepsPerFrame,
                 "Substeps per frame (default: the fewest that are stable, with mass scaling within --max-added-mass)");
  app.add_option("--bend-every", o.bendEvery,
                 "Bending forces every K substeps, written as the scene's bendEvery (default: a rhythm well inside "
                 "the bending forces' stable step; a K beyond that step is refused)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--collision-every", o.collisionEvery,
                 "Collision tests every K substeps, written as the scene's collisionEvery")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  app.add_option("--max-added-mass", o.maxAddedMass, "Mass scaling allowed, a fraction of the garment's mass")
      ->capture_default_str();
  o.integrator.addOptions(app, "and by default an eighth of the explicit steps' substeps");
  app.add_option("--youngs-modulus", o.material.youngsModulus_Pa, "The knit's Young's modulus, Pa")->capture_default_str();
  app.add_option("--bind-threshold", o.bindThreshold_m, "Written into the ClothSet, m")->capture_default_str();
  app.add_option("--stitch-gaps", o.stitchGaps_m,
                 "Sew the garment's openings shut: boundary vertices that face each other across a gap of at most "
                 "this many m (a jacket's fronts) become the ClothSet's stitches, drawn together in the simulation "
                 "(0: none)")
      ->capture_default_str();
  return [&app] {
    o.material.validate("--");
    if (!(o.voxel_m > 0.0)) throw Error(fmt::format("--voxel must be > 0 m, got {}", o.voxel_m));
    o.voxelGiven = app.count("--voxel") > 0;
    o.integrator.check(app);
    o.add.overGapGiven = app.count("--over-gap") > 0;
    if (!(o.frameRate > 0.0)) throw Error(fmt::format("--frame-rate must be > 0, got {}", o.frameRate));
    if (o.stepsPerFrame < 0) throw Error(fmt::format("--substeps must be >= 1, got {}", o.stepsPerFrame));
    if (!(o.stitchGaps_m >= 0.0)) throw Error(fmt::format("--stitch-gaps must be >= 0 m, got {}", o.stitchGaps_m));
    const auto isObj = [](const std::string& path) { return lowerExtension(path) == ".obj"; };
    if (app.count("--units") > 0 && !isObj(o.garment) && !isObj(o.mask))
      throw Error(fmt::format("--units {}: applies to OBJ files; {} and {} state their own unit", o.units, o.garment, o.mask));
    if (!addingToScene(app, o.add, "make-scene", o.avatar, o.out,
                       {"--out", "--avatar-url", "--title", "--voxel", "--frame-rate", "--substeps", "--bend-every",
                        "--collision-every", "--max-added-mass", "--integrator", "--implicit-tolerance",
                        "--keep-apart", "--cut-at-joints", "--avatar-meshes", "--avatar-drawn-meshes"}))
      return makeScene(o);
    return addGarment(o);
  };
}

const bool registered_cmd_make_scene = registerCommand(
    {"make-scene", "Dress an avatar in a garment modelled for it and write a ready-to-run scene", "", 61, &setupMakeScene});

}  // namespace
}  // namespace drape::cli
