// `drape run`: simulate garments and write frames, PC2 caches, result.wrl, result.glb,
// stats.json and manifest.json into the output directory. The garments come from a VRML97
// scene (with its avatar, materials and settings) or from --garment; a character moves with
// --motion (BVH, ASF/AMC) and its body parts collide through distance fields.

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <functional>
#include <cmath>
#include <filesystem>
#include <optional>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/log.hpp"

#include "command.hpp"
#include "drape/cloth/field_collider.hpp"
#include "drape/core/error.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/formats/units.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/avatar_segment.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/scene_setup.hpp"
#include "drape/studio/takes.hpp"
#include "live_capture.hpp"
#include "live_run.hpp"
#include "run_setup.hpp"
#include "stop_signal.hpp"
#include "stitch_gaps.hpp"

namespace drape::cli {
namespace {

struct RunOptions {
  std::string scene, avatar, jointMap, animation, fieldMethod = "dvdp";
  std::vector<std::string> motions;  ///< --motion FILE, or NAME=FILE per character
  double motionScale = 0.0, voxel_m = 0.0, leadIn_s = 1.0, settle_s = 1.0;
  bool preview = false, countEverySubstep = false, exactSliding = false, freePinches = false, noStitches = false;
  double stitchGaps_m = 0.0;  ///< --stitch-gaps
  double selfCollision_m = 0.0;  ///< --self-collision
  std::vector<std::string> faceSamplesWith, keepApart, cutAtJoints;
  std::vector<std::string> avatarMeshes;  ///< --avatar-meshes: the meshes of --avatar FILE that make the body
  std::vector<std::string> drawnMeshes;   ///< --avatar-drawn-meshes: those drawn with it, not collided with
  std::string events;                       ///< --events: an EGML event graph instead of --motion
  std::vector<std::string> lives;           ///< --live SOURCE, or NAME=SOURCE per character: captures as they come
  std::string liveHeader;                   ///< --live-header FILE.bvh: the sources' skeleton
  double giveUp_s = 0.0;                    ///< --give-up: a live source silent this long ends the run
  std::string timecode;                     ///< --timecode: motion frame 0's time code, HH:MM:SS:FF or now
  std::vector<std::string> sets, sends;     ///< --set NAME=VALUE, --send EVENT@SECONDS
  std::string garment, units = "m", pinVertices, pinMask, out, substeps = "33", integrator = "symplectic-euler";
  std::string strainLimit = "auto";
  std::string wind, gravity;
  std::vector<std::string> spheres;
  double pinTolerance_m = 1e-4;
  long frames = 0, every = 1;
  int collisionEvery = 1;
  std::vector<double> offsets;  ///< T0..T3, m; empty: the scene's, or from the voxel size
  cloth::Material material;
  cloth::StepSettings settings;
};

/// "x,y,z" -> Vec3; throws naming `option`.
Vec3 parseVec3(const std::string& text, const std::string& option) {
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw Error(fmt::format("{}: '{}' is not a number", option, item));
    }
  }
  if (v.size() != 3) throw Error(fmt::format("{}: expected three numbers x,y,z, got '{}'", option, text));
  return {v[0], v[1], v[2]};
}

/// "0,5,17" -> sorted unique indices; throws naming --pin-vertices.
std::vector<std::uint32_t> parseIndexList(const std::string& text) {
  std::vector<std::uint32_t> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const std::optional<long long> value = wholeNumber(item, 0, 0xfffffffell);
    if (!value) throw Error(fmt::format("--pin-vertices: '{}' is not a vertex index (0-based, comma-separated)", item));
    out.push_back(static_cast<std::uint32_t>(*value));
  }
  if (out.empty()) throw Error("--pin-vertices: the list is empty");
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Garment vertices within `tolerance` of a vertex of the mask mesh (paper 4.1: a constraint
/// mask is a subset of the garment, matched within a tolerance). Brute force: masks and
/// garments are small and this runs once.
std::vector<std::uint32_t> matchMask(const mesh::TriMesh& garment, const mesh::TriMesh& mask, double tolerance) {
  std::vector<std::uint32_t> out;
  const double t2 = tolerance * tolerance;
  for (std::size_t i = 0; i < garment.vertexCount(); ++i)
    for (const Vec3& p : mask.positions)
      if ((garment.positions[i] - p).squaredNorm() <= t2) {
        out.push_back(static_cast<std::uint32_t>(i));
        break;
      }
  if (out.empty())
    throw Error(fmt::format("{}: no vertex of the mask lies within {} m of a garment vertex (--pin-tolerance)",
                            mask.name, tolerance));
  return out;
}

int substepsFrom(const std::string& text) {
  if (text == "auto") return 0;
  const std::optional<long long> value = wholeNumber(text, 1, 100000);
  if (!value) throw Error(fmt::format("--substeps must be a whole number in [1, 100000] or 'auto', got '{}'", text));
  return static_cast<int>(*value);
}

/// --strain-limit: 'auto' (strain limiting only from a frame no substeps keep stable on),
/// 'none' (never: the run stops on such a frame) or a stretch (from the first frame).
void applyStrainLimit(const std::string& text, cloth::StepSettings& s) {
  if (text == "auto") {
    s.strainLimit = 0.0;
    s.rescueStrainLimit = cloth::StepSettings{}.rescueStrainLimit;
    return;
  }
  if (text == "none") {
    s.strainLimit = 0.0;
    s.rescueStrainLimit = 0.0;
    return;
  }
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc{} || end != text.data() + text.size() || !(value > 0.0 && value <= 10.0))
    throw Error(fmt::format("--strain-limit must be 'auto', 'none' or a stretch beyond the rest length in (0, 10] "
                            "(0.5: edges at most 1.5 times as long), got '{}'",
                            text));
  s.strainLimit = value;
  s.rescueStrainLimit = 0.0;
}

/// --offsets for every garment, checked.
void applyOffsets(const RunOptions& o, RunSetup& setup) {
  if (o.offsets.empty()) return;
  const cloth::OffsetSurfaces offsets{o.offsets[0], o.offsets[1], o.offsets[2], o.offsets[3]};
  offsets.validate("--");
  for (GarmentSetup& g : setup.garments) {
    g.offsets = offsets;
    g.offsetsGiven = true;
  }
}

/// --stitch-gaps: the garment's openings sewn shut, as drape make-scene finds them.
std::vector<cloth::Stitch> stitchesAcrossGaps(const GarmentSetup& g, double gap_m) {
  if (!(gap_m > 0.0)) throw Error(fmt::format("--stitch-gaps must be > 0 m, got {}", gap_m));
  const StitchPairs pairs = openingsToSew(g.mesh, mesh::Topology::build(g.mesh), g.name, gap_m);
  std::vector<cloth::Stitch> stitches = cloth::stitchesDrawnTogether(pairs);
  spdlog::info("{}: {} stitches across gaps of up to {:.1f} mm (--stitch-gaps {:g})", g.name, stitches.size(),
               1e3 * widestStitch_m(g.mesh, pairs), gap_m);
  return stitches;
}

/// --collision-every, --face-samples-with, --self-collision, --no-stitches and --stitch-gaps for every garment (a
/// scene's or --garment's).
void applyCollisionOptions(const CLI::App& app, const RunOptions& o, RunSetup& setup) {
  const bool faces = app.count("--face-samples-with") > 0;
  const std::vector<std::string> faceParts = facePartsOption(o.faceSamplesWith);
  if (faces && setup.characters.empty() && !faceParts.empty())
    throw Error("--face-samples-with: there is no avatar to collide with (the scene has none; without a scene, give "
                "--avatar FILE)");
  for (GarmentSetup& g : setup.garments) {
    if (app.count("--collision-every")) g.collisionEvery = o.collisionEvery;
    if (faces) g.faceSamplesWith = faceParts;
    if (app.count("--self-collision")) g.selfCollision_m = o.selfCollision_m;
    if (o.noStitches) g.stitches.clear();
    if (app.count("--stitch-gaps")) g.stitches = stitchesAcrossGaps(g, o.stitchGaps_m);
  }
}

/// Command-line values that override the scene's (only those the user gave).
void applyOverrides(const CLI::App& app, const RunOptions& o, RunSetup& setup) {
  cloth::StepSettings& s = setup.settings;
  if (app.count("--frame-rate")) s.frameRate_hz = o.settings.frameRate_hz;
  if (app.count("--air-viscosity")) s.airViscosity_Ns_m3 = o.settings.airViscosity_Ns_m3;
  if (app.count("--max-speed")) s.maxSpeed_m_s = o.settings.maxSpeed_m_s;
  if (app.count("--max-added-mass")) s.maxAddedMass = o.settings.maxAddedMass;
  // The integrator before the rhythm: switching to backward Euler or Runge-Kutta resets it (useIntegrator), and
  // a --bend-every given with it is then refused by validate(), naming why.
  if (app.count("--integrator")) s.useIntegrator(cloth::parseIntegrator(o.integrator, "--integrator"));
  if (app.count("--bend-every")) s.bendEvery = o.settings.bendEvery;
  if (app.count("--implicit-tolerance")) s.implicitTolerance = o.settings.implicitTolerance;
  if (app.count("--max-refinement")) s.maxRefinement = o.settings.maxRefinement;
  if (app.count("--strain-limit")) applyStrainLimit(o.strainLimit, s);
  if (app.count("--wind")) s.wind_m_s = parseVec3(o.wind, "--wind");
  if (app.count("--gravity")) s.gravity_m_s2 = parseVec3(o.gravity, "--gravity");
  for (GarmentSetup& g : setup.garments) {
    cloth::Material& m = g.material;
    if (app.count("--density")) m.density_kg_m3 = o.material.density_kg_m3;
    if (app.count("--thickness")) m.thickness_m = o.material.thickness_m;
    if (app.count("--youngs-modulus")) m.youngsModulus_Pa = o.material.youngsModulus_Pa;
    if (app.count("--poisson-ratio")) m.poissonRatio = o.material.poissonRatio;
    if (app.count("--bending-stiffness")) m.bendingStiffness_Nm = o.material.bendingStiffness_Nm;
    if (app.count("--damping")) m.damping_s = o.material.damping_s;
    if (app.count("--static-friction")) m.staticFriction = o.material.staticFriction;
    if (app.count("--dynamic-friction")) m.dynamicFriction = o.material.dynamicFriction;
    if (app.count("--compression-scale")) m.compressionScale = o.material.compressionScale;
  }
}

/// A garment from --garment (OBJ, glTF, Collada or FBX) with its pins or mask.
void setupFromGarment(const RunOptions& o, RunSetup& setup, bool onAvatar) {
  formats::MeshFileOptions read;
  read.metresPerUnit = formats::metresPerUnit(o.units, "--units");
  GarmentSetup garment;
  formats::MeshFile file = formats::readMeshFile(o.garment, read);
  if (const std::string what = formats::describeRead(file); !what.empty()) spdlog::info("{}: {}", o.garment, what);
  garment.mesh = std::move(file.mesh);
  garment.name = std::filesystem::path(o.garment).stem().string();
  garment.material = o.material;
  if (!o.pinVertices.empty()) garment.pinned = parseIndexList(o.pinVertices);
  if (!o.pinMask.empty()) {
    if (!(o.pinTolerance_m > 0.0)) throw Error(fmt::format("--pin-tolerance must be > 0 m, got {}", o.pinTolerance_m));
    read.looseVertices = true;  // a mask's points count, whatever uses them
    garment.pinned = matchMask(garment.mesh, formats::readMeshFile(o.pinMask, read).mesh, o.pinTolerance_m);
  }
  if (onAvatar) std::swap(garment.bound, garment.pinned);  // a mask on a body binds to it
  setup.settings = o.settings;
  setup.settings.integrator = cloth::parseIntegrator(o.integrator, "--integrator");
  if (!o.wind.empty()) setup.settings.wind_m_s = parseVec3(o.wind, "--wind");
  if (!o.gravity.empty()) setup.settings.gravity_m_s2 = parseVec3(o.gravity, "--gravity");
  applyStrainLimit(o.strainLimit, setup.settings);
  setup.garments.push_back(std::move(garment));
}

/// The avatar file's, its parts cut across the joints named (none: as segmented on load).
std::shared_ptr<const scene::Avatar> loadAvatarCut(const std::string& path, const std::vector<std::string>& meshes,
                                                   const std::vector<std::string>& drawnMeshes,
                                                   const std::vector<std::string>& cutAtJoints) {
  scene::Avatar avatar = scene::loadAvatarFile(path, meshes, drawnMeshes);
  if (!cutAtJoints.empty()) {
    std::size_t moved = 0;
    scene::segmentSkinnedAvatar(avatar, cutAtJoints, &moved);
    spdlog::info("{}: the parts of {} cut across their joints, {} triangles behind them given to their parents", path,
                 fmt::join(cutAtJoints, ", "), moved);
  }
  return std::make_shared<const scene::Avatar>(std::move(avatar));
}

/// --timecode: the run's frames numbered from motion frame 0 at that time code (now: the
/// time of day, `earlier_s` before now), the lead-in's before it, as the studio numbers a take's.
void stampTimeCode(const RunOptions& o, RunSetup& setup, double earlier_s = 0.0) {
  if (o.timecode.empty()) return;
  TimeCode motionStart = TimeCode::parseOption(o.timecode, setup.settings.frameRate_hz);
  if (o.timecode == "now") motionStart.frame -= std::llround(earlier_s * motionStart.rate);
  setup.timeCodeOfFrame0 = setup.characters.empty()
                               ? motionStart.frame
                               : studio::clothTimeCode(0, motionStart, setup.characters.front().leadIn_s).frame;
}

/// `--live SOURCE` (or NAME=SOURCE per character): the run on captures as they come, until a
/// source ends (it closes, Ctrl-C, or silence past --give-up: exit code 4) or --frames; what
/// came is written as any run is. The characters without a source play their Avatar node's
/// motion, or stand.
int runLive(const RunOptions& o, RunSetup& setup, const std::function<void()>& saidResults) {
  const std::atomic<bool>& stop = stopOnSignals();
  const std::chrono::milliseconds giveUp(static_cast<long long>(1000.0 * o.giveUp_s));
  motion::MotionOptions motion = motionOptions(setup);
  if (o.motionScale > 0) motion.clip.metresPerUnit = o.motionScale;
  motion.jointMapPath = o.jointMap;
  const std::vector<std::pair<std::size_t, std::string>> sources = liveSources(setup, o.lives);
  addMotionsOfTheOthers(setup, sources, o.scene, o.motionScale, o.jointMap);
  LiveCast live(setup, sources, {o.liveHeader, giveUp, o.frames}, motion, stop);
  stampTimeCode(o, setup, live.lag_s());  // now: when the first frame came
  const int code = simulateRun(setup, live.gate());
  live.logKeptApart();
  saidResults();
  for (const std::string& line : live.summary()) fmt::print("{}\n", line);
  return live.silent() ? static_cast<int>(ExitCode::Unavailable) : code;
}

int runCommand(const CLI::App& app, RunOptions& o) {
  if (o.scene.empty() == o.garment.empty())
    throw Error("drape run: give either a scene file (drape run SCENE.wrl) or --garment FILE.obj");
  RunSetup setup;
  if (!o.scene.empty()) {
    if (!o.avatarMeshes.empty())
      throw Error("--avatar-meshes chooses the meshes of --avatar FILE; in a scene the Avatar node's meshes field does");
    if (!o.drawnMeshes.empty())
      throw Error("--avatar-drawn-meshes chooses the drawn meshes of --avatar FILE; in a scene the Avatar node's "
                  "drawnMeshes field does");
    setup = runSetupFromScene(o.scene, app.count("--cut-at-joints")
                                           ? std::optional<std::vector<std::string>>(keepApartParts(o.cutAtJoints))
                                           : std::nullopt);
    applyOverrides(app, o, setup);
    applyOffsets(o, setup);
    applyCollisionOptions(app, o, setup);
  } else {
    std::shared_ptr<const scene::Avatar> avatar;
    if (!o.avatar.empty())
      avatar = loadAvatarCut(o.avatar, o.avatarMeshes, o.drawnMeshes, keepApartParts(o.cutAtJoints));
    else if (app.count("--cut-at-joints")) throw Error("--cut-at-joints cuts an avatar's parts: give a scene or --avatar FILE");
    else if (!o.avatarMeshes.empty()) throw Error("--avatar-meshes chooses the meshes of --avatar FILE: give --avatar");
    else if (!o.drawnMeshes.empty())
      throw Error("--avatar-drawn-meshes chooses the drawn meshes of --avatar FILE: give --avatar");
    setupFromGarment(o, setup, avatar != nullptr);
    if (avatar) {
      CharacterSetup& character = setup.characters.emplace_back();
      character.avatar = avatar;
      character.name = avatar->name;
      character.garments = {0};
      for (GarmentSetup& g : setup.garments)
        for (const scene::Segment& seg : avatar->segments) g.collidesWith.push_back(seg.name);
    }
    applyOffsets(o, setup);
    applyCollisionOptions(app, o, setup);
  }
  const bool avatar = !setup.characters.empty();
  if (!o.events.empty() && (!o.motions.empty() || !o.animation.empty()))
    throw Error("--events plays an event graph's motions: give it or --motion, not both");
  if (!o.lives.empty() && (!o.motions.empty() || !o.animation.empty() || !o.events.empty()))
    throw Error(fmt::format("--live plays the motion its source sends: give it or {}, not both",
                            !o.events.empty() ? "--events" : !o.motions.empty() ? "--motion" : "--animation"));
  if (o.lives.empty() && (!o.liveHeader.empty() || o.giveUp_s > 0))
    throw Error(fmt::format("{} is for a live source: give --live SOURCE", o.liveHeader.empty() ? "--give-up" : "--live-header"));
  if (!o.lives.empty() && !avatar) throw Error("--live: there is no avatar for the capture to move");
  if (o.events.empty() && (!o.sets.empty() || !o.sends.empty()))
    throw Error(fmt::format("{}: it is for an event graph: give --events FILE.egml", o.sets.empty() ? "--send" : "--set"));
  const bool motionGiven =
      std::any_of(o.motions.begin(), o.motions.end(), [](const std::string& m) { return m != "none"; });
  if (motionGiven && !avatar)
    throw Error("--motion: there is no avatar to move (the scene has none; without a scene, give --avatar FILE)");
  for (const std::string& sphere : o.spheres) {
    const auto comma = sphere.rfind(',');
    if (comma == std::string::npos) throw Error(fmt::format("--sphere: expected x,y,z,radius (m), got '{}'", sphere));
    const Vec3 c = parseVec3(sphere.substr(0, comma), "--sphere");
    const Vec3 r = parseVec3("0,0," + sphere.substr(comma + 1), "--sphere");
    setup.spheres.push_back({c, r.z()});
  }

  if (!o.events.empty() && !avatar) throw Error("--events: there is no avatar for the event graph to move");
  if (!(o.leadIn_s >= 0)) throw Error(fmt::format("--lead-in must be >= 0 s, got {}", o.leadIn_s));
  if (!(o.settle_s >= 0)) throw Error(fmt::format("--settle must be >= 0 s, got {}", o.settle_s));
  for (CharacterSetup& ch : setup.characters) {
    if (o.voxel_m > 0) ch.voxel_m = o.voxel_m;
    ch.fieldMethod = o.fieldMethod == "exact" ? field::FieldMethod::Exact : field::FieldMethod::Dvdp;
    ch.leadIn_s = o.leadIn_s;
    ch.settle_s = o.settle_s;
    if (app.count("--keep-apart")) setKeepApart(ch, o.keepApart);
  }
  if (o.events.empty() && o.lives.empty())
    addSceneMotions(setup, o.scene, o.motions, o.animation, o.motionScale, o.jointMap);
  const bool moving = std::any_of(setup.characters.begin(), setup.characters.end(),
                                  [](const CharacterSetup& c) { return c.animation != nullptr; });
  if (app.count("--keep-apart") && !keepApartParts(o.keepApart).empty() && !moving && o.events.empty() &&
      o.lives.empty())
    throw Error("--keep-apart corrects a motion: give --motion FILE (or --events FILE, or --live SOURCE) too");
  if (!o.events.empty() && avatar) {
    // With --frames, as many motion frames as those frames read (the lead-in before them).
    const long motionFrames =
        app.count("--frames")
            ? std::max(2L, o.frames - static_cast<long>(std::floor(o.leadIn_s * setup.settings.frameRate_hz)) + 2)
            : 0;
    addEvents(setup, o.events, o.sets, o.sends, motionFrames);
  }

  if (app.count("--substeps") || o.scene.empty()) {
    const int substeps = substepsFrom(o.substeps);
    setup.settings.substepsPerFrame = substeps > 0 ? substeps : 1;
    if (substeps == 0 && setup.settings.integrator == cloth::IntegratorKind::BackwardEuler)
      throw Error("--substeps auto finds the fewest substeps the explicit integrators are stable at; backward-euler "
                  "is stable at any: give a count (--substeps 4 walks the bundled skirt, 20 the bundled dress)");
    if (substeps == 0) {
      setup.settings.substepsPerFrame = stableSubsteps(setup);
      const bool scaled = setup.settings.maxAddedMass > 0.0;
      spdlog::info("--substeps auto: {} substeps per frame ({:.3f} ms){}", setup.settings.substepsPerFrame,
                   1e3 * setup.settings.substep_s(), scaled ? ", with mass scaling within --max-added-mass" : "");
    }
  }
  // Frames: as asked, or the lead-in plus the whole motion (a live one: as long as it comes).
  setup.frames = o.frames;
  if (!app.count("--frames") && o.lives.empty()) setup.frames = defaultFrames(setup);
  if (app.count("--frames") && moving && o.lives.empty())
    warnOfFramesWithinTheLeadIn(setup, {o.frames, o.frames, "simulates", true});
  setup.objEvery = o.every;
  setup.outDir = o.out;
  setup.preview = o.preview;
  setup.countEverySubstep = o.countEverySubstep;
  setup.exactSliding = o.exactSliding;
  setup.freePinches = o.freePinches;
  const bool skin = std::any_of(setup.characters.begin(), setup.characters.end(),
                                [](const CharacterSetup& c) { return c.avatar->skin.has_value(); });
  const bool several = setup.characters.size() > 1;
  const auto saidResults = [&] {
    fmt::print("results in {}/: garment caches (.pc2, .states), {}frames/, result.wrl, result.glb, stats.json{}\n", o.out,
               !skin ? "" : several ? "the skinned bodies (body-CHARACTER.pc2), " : "the skinned body (body.pc2), ",
               o.preview ? ", preview.png" : "");
  };
  if (!o.timecode.empty() && o.timecode != "now") (void)TimeCode::parseSmpte(o.timecode, setup.settings.frameRate_hz);
  if (!o.lives.empty()) return runLive(o, setup, saidResults);
  stampTimeCode(o, setup);
  const int code = simulateRun(setup);
  saidResults();
  return code;
}

RunFunction setupRun(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  app.footer(
      "Examples:\n"
      "  drape run examples/walking_skirt/scene.wrl --motion examples/walking_skirt/walk.bvh --out out/ws --preview\n"
      "  drape run --garment dress.obj --units dm --pin-mask mask.obj --substeps auto --frames 90 --out out/dress\n"
      "Writes DIR/frames/frame_NNNNN.obj (every --every frames), DIR/garment.pc2 and DIR/garment.obj, the avatar's "
      "parts as DIR/segments/NAME.{obj,pc2}, DIR/result.wrl (VRML97), DIR/result.glb (glTF 2.0), DIR/stats.json and "
      "DIR/manifest.json. Units are SI; Y is up.\n"
      "With a scene, the fabric, step and collision settings are the scene's; an option given here overrides "
      "them for every garment. The defaults shown are those of --garment runs.\n"
      "Exit codes: 0 done, 2 bad input, 3 the simulation became unstable (files so far are kept).");
  app.add_option("scene", o->scene, "VRML97 scene with ClothSet garments (and an avatar)");
  app.add_option("--garment", o->garment,
                 "Garment mesh (OBJ, or glTF, Collada or FBX: every mesh of the file, welded where it splits "
                 "vertices), instead of a scene");
  app.add_option("--avatar", o->avatar, "Avatar to wear --garment (.glb, .gltf, .vrm, .dae, .fbx, MakeHuman .mhskel)");
  app.add_option("--avatar-meshes", o->avatarMeshes,
                 "With --avatar: its file's skinned meshes that make the body, by node or mesh name or shell pattern "
                 "(a character file that holds its clothes or hair too); default: every mesh of its skin")
      ->delimiter(',');
  app.add_option("--avatar-drawn-meshes", o->drawnMeshes,
                 "With --avatar: its file's skinned meshes drawn with the body but not collided with (hair, eyes, "
                 "accessories), by node or mesh name or shell pattern; default: none")
      ->delimiter(',');
  app.add_option("--motion", o->motions, std::string("Motion for the avatar ") + kMotionHelp + kMotionPerCharacterHelp)
      ->type_name("FILE|NAME=FILE");
  app.add_option("--events", o->events,
                 "Instead of --motion: an EGML event graph (.egml) that plays motions on the avatar, in sequence, "
                 "blended, looped, by state, moves it along paths and sets the wind (docs/EVENTS.md)");
  app.add_option("--set", o->sets, "With --events: a parameter of the graph, NAME=VALUE (its Conditions test them); repeatable");
  app.add_option("--send", o->sends,
                 "With --events: an event for the graph's state machines at a time of the script, EVENT@SECONDS; "
                 "repeatable");
  app.add_option("--live", o->lives,
                 std::string("Instead of a motion: ") + kLiveHelp +
                     "; with several characters in the scene, NAME=SOURCE for each that a capture moves (repeatable)")
      ->type_name("SOURCE|NAME=SOURCE");
  app.add_option("--live-header", o->liveHeader, kLiveHeaderHelp)->type_name("FILE.bvh");
  app.add_option("--give-up", o->giveUp_s, "With --live: end the run after S seconds without a line (exit code 4)")
      ->check(CLI::PositiveNumber);
  app.add_option("--timecode", o->timecode,
                 "The time code of the motion's first frame (the lead-in's frames before it): HH:MM:SS:FF, or now "
                 "(this machine's time of day, local; with --live, when the first frame came); default the motion's own")
      ->type_name("TIMECODE|now");
  app.add_option("--joint-map", o->jointMap, "JSON map from the motion's joint names to the avatar's");
  app.add_option("--animation", o->animation, kAnimationHelp);
  app.add_option("--motion-scale", o->motionScale, "Metres per motion-file unit (default: guessed from the skeleton)");
  app.add_option("--voxel", o->voxel_m, "Distance-field voxel size, m (default: the scene's, or 0.005)");
  app.add_option("--field-method", o->fieldMethod, "dvdp (the paper's) or exact")
      ->capture_default_str()
      ->check(CLI::IsMember({"dvdp", "exact"}));
  app.add_option("--cut-at-joints", o->cutAtJoints,
                 "Joints whose rigid body parts are cut across the joint, what lies behind it going to the parent's "
                 "part, so that the part's end does not swing out through its neighbour as the joint turns (an upper "
                 "arm's over the shoulder), e.g. LeftArm,RightArm; needs a skinned avatar; overrides the Avatar node's "
                 "cutAtJoints, 'none' for none")
      ->delimiter(',');
  app.add_option("--keep-apart", o->keepApart,
                 "Body parts whose motion is corrected, before simulating, to keep them out of the collidable parts "
                 "they go into (a forearm swung through the back): each is swung about the joint above it and "
                 "keeps twice the garments' T2 from the other part's surface, e.g. LeftForeArm,RightForeArm (with "
                 "--live, each frame once the 15 after it have come, at 30 Hz); overrides the scene's keepApart, 'none' "
                 "for none")
      ->delimiter(',');
  app.add_option("--lead-in", o->leadIn_s, "Seconds to blend from the rest pose into the motion")->capture_default_str();
  app.add_option("--settle", o->settle_s,
                 "Longest time the garments settle at the rest pose before frame 0, so that cloth modelled "
                 "tighter than the offset surfaces starts the run out of them (only as long as that takes; 0: "
                 "frame 0 is the garment as modelled)")
      ->capture_default_str();
  app.add_flag("--preview", o->preview, "Also render a contact sheet and, with ffmpeg, an MP4 into the output directory");
  app.add_option("--offsets", o->offsets,
                 "The offset surfaces T0,T1,T2,T3 in m, overriding the scene's (default: 1, 2, 3 and 6 voxels); "
                 "collisions register on T2")
      ->delimiter(',')
      ->expected(4);
  app.add_option("--collision-every", o->collisionEvery,
                 "Collision tests every K substeps, overriding the scene's collisionEvery (the paper's "
                 "reduced-frequency tests)")
      ->check(CLI::Range(1, 1000));
  app.add_flag("--count-every-substep", o->countEverySubstep,
               "With collision tests every K > 1 substeps (the scene's collisionEvery), count the penetration "
               "figures in stats.json on every substep, not only the tested ones (slower)");
  app.add_flag("--exact-sliding", o->exactSliding,
               "Sliding points read the distance field on every collision test instead of answering from "
               "their contact planes (slower; the reference the planes are measured against)");
  app.add_flag("--free-pinches", o->freePinches,
               "Points pinched between two or more parts at a collision test keep their own velocity and, "
               "with tests every K > 1 substeps, move freely until the next, instead of taking those parts' "
               "mean velocity and being held by them (the paper's collision response as it is)");
  app.add_option("--face-samples-with", o->faceSamplesWith,
                 "Body parts against which the garments' triangle centroids collide too, not only their "
                 "vertices, overriding the scene's faceSamplesWith (e.g. LeftUpLeg,RightUpLeg): the parts no "
                 "longer bulge through triangles that are large against their curvature; 'none' for none")
      ->delimiter(',');
  app.add_option("--self-collision", o->selfCollision_m,
                 "Keep each garment's own layers this many m apart (a skirt folding between the legs, a jacket's "
                 "hem over its skirt), overriding the scene's selfCollision; 0: they pass through each other")
      ->type_name("M")
      ->check(CLI::NonNegativeNumber);
  auto* unsewn = app.add_flag("--no-stitches", o->noStitches,
                              "Leave the scene's stitches out: the openings they sew shut (a jacket's fronts) hang free");
  app.add_option("--stitch-gaps", o->stitchGaps_m,
                 "Sew the garments' openings shut, instead of the scene's stitches: boundary vertices that face each "
                 "other across a gap of at most this many m (a jacket's fronts) are drawn together (as drape "
                 "make-scene --stitch-gaps finds them)")
      ->excludes(unsewn);
  app.add_option("--units", o->units, "Length unit of the OBJ files: m, dm, cm, mm, in (glTF, Collada and FBX state their own)")
      ->capture_default_str();
  auto* pins = app.add_option("--pin-vertices", o->pinVertices, "Vertices pinned in place, 0-based, e.g. 0,12,40");
  auto* mask = app.add_option("--pin-mask", o->pinMask, "Mesh (OBJ, glTF, Collada or FBX) whose vertices mark the pinned garment vertices");
  pins->excludes(mask);
  mask->excludes(pins);
  app.add_option("--pin-tolerance", o->pinTolerance_m, "Distance within which a mask vertex matches, m")
      ->capture_default_str();
  app.add_option("--frames", o->frames, "Frames to simulate, counted from the lead-in's first (default with --motion: the lead-in and the whole motion)");
  app.add_option("--out", o->out, "Output directory")->required();
  app.add_option("--every", o->every, "Write an OBJ frame every K frames")->capture_default_str();

  cloth::Material& m = o->material;
  app.add_option("--density", m.density_kg_m3, "Fabric density, kg/m^3")->capture_default_str();
  app.add_option("--thickness", m.thickness_m, "Fabric thickness, m")->capture_default_str();
  app.add_option("--youngs-modulus", m.youngsModulus_Pa, "Young's modulus E, Pa")->capture_default_str();
  app.add_option("--poisson-ratio", m.poissonRatio, "Poisson ratio, [0, 0.5)")->capture_default_str();
  app.add_option("--bending-stiffness", m.bendingStiffness_Nm, "Bending modulus D, N m (default E t^3/(12(1-nu^2)))");
  app.add_option("--damping", m.damping_s, "Internal (stiffness-proportional) damping time, s")->capture_default_str();
  app.add_option("--static-friction", m.staticFriction, "Static friction coefficient")->capture_default_str();
  app.add_option("--dynamic-friction", m.dynamicFriction, "Dynamic friction coefficient")->capture_default_str();
  app.add_option("--compression-scale", m.compressionScale, "Factor on compressive stresses, (0, 1]")
      ->capture_default_str();

  cloth::StepSettings& s = o->settings;
  app.add_option("--substeps", o->substeps, "Substeps per frame, or 'auto' (the fewest estimated stable, the damping included, with --max-added-mass of mass scaling)")
      ->capture_default_str();
  app.add_option("--frame-rate", s.frameRate_hz, "Frames per second")->capture_default_str();
  app.add_option("--integrator", o->integrator,
                 "symplectic-euler, forward-euler (the paper's; stable only with --damping inside a window the "
                 "substep sets, which a refusal names), backward-euler (implicit, stable at long substeps, with "
                 "--substeps N: 4 walks the bundled skirt, 20 the dress; each substep solves a linear system, no "
                 "mass is added, and bending runs every substep) or runge-kutta-4 (classical fourth order: four "
                 "force evaluations per substep, bending in each; stable at fewer substeps than symplectic Euler, "
                 "which --substeps auto finds, with mass scaling aimed at its bound: 10 walk the bundled skirt, "
                 "108 the dress)")
      ->capture_default_str();
  app.add_option("--implicit-tolerance", s.implicitTolerance,
                 "backward-euler: each substep's linear solve stops at this residual relative to its right-hand "
                 "side (smaller: more iterations, closer to the exact implicit step; default: the scene's "
                 "implicitTolerance, 0.001)");
  app.add_option("--air-viscosity", s.airViscosity_Ns_m3, "Linear air drag per area, N s/m^3")->capture_default_str();
  app.add_option("--wind", o->wind, "Wind velocity x,y,z, m/s");
  app.add_option("--gravity", o->gravity, "Gravity x,y,z, m/s^2 (default 0,-9.81,0)");
  app.add_option("--max-speed", s.maxSpeed_m_s, "Stability bound on vertex speed, m/s")->capture_default_str();
  app.add_option("--max-added-mass", s.maxAddedMass,
                 "Mass scaling: mass that may be added to sliver triangles so the substep stays stable, as a "
                 "fraction of the garment's mass (0: none)")
      ->capture_default_str();
  app.add_option("--bend-every", s.bendEvery,
                 "Bending forces every K substeps, applied as one impulse (multiple time stepping; must stay "
                 "within the bending forces' stable step)")
      ->capture_default_str();
  app.add_option("--max-refinement", s.maxRefinement,
                 "A frame that goes unstable is computed again with 2, 4, ... up to this many times the substeps "
                 "before strain limiting comes on for it (--strain-limit auto) or the run stops on it (1: at once); "
                 "overrides the scene's maxRefinement")
      ->capture_default_str();
  app.add_option("--strain-limit", o->strainLimit,
                 "Largest stretch of an edge beyond its rest length, held after every substep (0.5: at most 1.5 "
                 "times as long), from the first frame; 'auto': only from a frame that goes unstable even with "
                 "--max-refinement times the substeps (cloth crushed in a pinch), at 0.5, for the rest of the run; "
                 "'none': never, the run stops on such a frame; overrides the scene's strainLimit and "
                 "rescueStrainLimit")
      ->capture_default_str();
  app.add_option("--sphere", o->spheres, "A static sphere collider x,y,z,radius (m); repeatable");
  return [o, &app] { return runCommand(app, *o); };
}

const bool registered_cmd_run =
    registerCommand({"run", "Simulate garments (on a moving avatar) and write frames, caches, VRML97, glTF and stats", "", 10, &setupRun});

}  // namespace
}  // namespace drape::cli
