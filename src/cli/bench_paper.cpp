// `drape bench paper --json`: the paper's walking-skirt scenario (section 5, Table 3)
// without rendering or output, single thread: a skirt of about 480 triangles bound at the
// waist of a walking avatar whose hips, thighs and shins collide, 33 substeps per frame.
// Prints our figures beside the paper's Table 3 (2.8 GHz Pentium 4, 2003) and beside a fixed
// reference workload timed in the same run, interleaved with the scenario's frames (Bullet's
// soft-body sheet of `drape bench cloth`): a shared host's speed moves by a third from day to
// day and within minutes, and the ratio of the two is what a speed target can be held to.

#include <algorithm>
#include <chrono>
#include <iostream>
#include <optional>

#include <tbb/global_control.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "bench_machine.hpp"
#include "bullet_sheet.hpp"
#include "command.hpp"
#include "measure.hpp"
#include "stage_laps.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/character_world.hpp"
#include "drape/sim/scene_setup.hpp"
#include "run_setup.hpp"

namespace drape::cli {
namespace {

/// The threads the benchmark runs on: one, as the paper's figures, unless --threads says otherwise.
int benchThreads() { return globalOptions().threads > 0 ? globalOptions().threads : 1; }

/// CPU time, s: the calling thread's with one thread (other processes inflate it less), all
/// threads' with --threads above one.
double cpuSeconds() { return benchThreads() > 1 ? processCpuSeconds() : threadCpuSeconds(); }

const std::string kBundledScene = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/scene.wrl";
const std::string kBundledMotion = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh";

struct PaperBenchOptions {
  std::string scene = kBundledScene;
  std::string motion = kBundledMotion;
  long frames = 0;  // 0: the whole clip
  int runs = 3;
  int collisionEvery = 0;  // 0: as the scene says
  int bendEvery = 0;       // 0: as the scene says
  int substeps = 0;        // 0: as the scene says
  std::string integrator;  // empty: as the scene says
  bool exactSliding = false;  // sliding pairs read the field on every test (no contact planes)
  bool freePinches = false;   // pinched points move freely between reduced-frequency tests
  std::optional<std::vector<std::string>> keepApart;  // parts kept out of the others, instead of the scene's
  bool noRestingBalls = false;  // every pair inside a part's volume goes through the per-pair test
  std::optional<std::vector<std::string>> faceSamplesWith;  // set: overrides the scene's
  std::optional<double> selfCollision_m;                    // set: overrides the scene's
  bool json = false;
};

struct PaperRun {
  long frames = 0;
  long framesRefined = 0;  ///< frames computed again with more substeps (StepSettings::maxRefinement)
  double simSeconds = 0, simCpuSeconds = 0, collideSeconds = 0, forcesSeconds = 0, integrateSeconds = 0;
  double stepSeconds = 0;
  double poseSeconds = 0;  ///< pose fetches (animation, interpolation) by the collider and the fixtures
  double colliderPoseSeconds = 0;  ///< the collider's, inside the collide stage
  int collisionEvery = 1;
  int bendEvery = 1;
  cloth::IntegratorKind integrator = cloth::IntegratorKind::SymplecticEuler;
  cloth::SolveStats solves;  ///< the implicit integrator's, summed over the garments
  cloth::FieldCollisionCounters counters;
  cloth::LayerCounters self;  ///< the garments' layer collision (their own, those below), summed
  double selfThickness_m = 0;  ///< the largest
  std::size_t triangles = 0;
  int substeps = 0;
  double fieldBuildSeconds = 0;
  double referenceMsPerFrame = 0;  ///< the reference's CPU time per frame, stepped between this run's frames
  long referenceFrames = 0;        ///< the reference's frames stepped in this run
};

// The reference workload: Bullet's sheet-480 of `drape bench cloth` (16 x 15 cells, 272
// nodes), 300 frames per run of the scenario. It is stepped in slices between blocks of the
// scenario's frames, so that both are timed on the host in the same state: five slices of
// about 0.1 s on the bundled scenario. Each slice leaves the scenario's caches cold: blocks
// of 10 frames cost it about 10 % more CPU time per frame, blocks of 34 too little to see
// beside the host's noise, with half the spread of the ratio that runs one after the other
// gave (docs/PERFORMANCE.md).
constexpr int kReferenceCellsU = 16, kReferenceCellsV = 15;
constexpr long kReferenceFrames = 300;
constexpr long kFramesPerSlice = 34;  ///< the scenario's frames between two slices of the reference

/// One run of the scenario. `measure`: keep the penetration figures, on every substep
/// (reads only: the motion is the same, but the timing is not the benchmark's), and no
/// reference; otherwise the collider keeps none, the collision time is the collision work
/// alone, and the reference is stepped between blocks of frames.
PaperRun runOnce(const PaperBenchOptions& o, bool measure) {
  RunSetup setup = runSetupFromScene(o.scene);
  CharacterSetup* character = oneCharacter(setup, "drape bench paper");
  if (!character) throw Error(fmt::format("{}: the scene has no avatar", o.scene));
  if (o.collisionEvery > 0)
    for (GarmentSetup& g : setup.garments) g.collisionEvery = o.collisionEvery;
  if (!o.integrator.empty()) setup.settings.useIntegrator(cloth::parseIntegrator(o.integrator, "--integrator"));
  if (o.bendEvery > 0) setup.settings.bendEvery = o.bendEvery;
  if (o.substeps > 0) setup.settings.substepsPerFrame = o.substeps;
  setup.settings.validate("--");
  if (o.faceSamplesWith)
    for (GarmentSetup& g : setup.garments) g.faceSamplesWith = *o.faceSamplesWith;
  if (o.selfCollision_m)
    for (GarmentSetup& g : setup.garments) g.selfCollision_m = *o.selfCollision_m;
  if (o.keepApart) setKeepApart(*character, *o.keepApart);
  addMotion(setup, *character, o.motion);
  const std::unique_ptr<sim::CharacterWorld> worldPtr = buildWorld(setup, *character);
  sim::CharacterWorld& world = *worldPtr;
  for (std::size_t g = 0; g < world.garmentCount(); ++g) {
    world.collider(g)->setMeasurePenetration(measure);
    world.collider(g)->setContactPlanes(!o.exactSliding);
    world.collider(g)->setPinchHold(!o.freePinches);
    world.collider(g)->setRestingBalls(!o.noRestingBalls);
    world.collider(g)->setCountEverySubstep(measure);
  }
  (void)settleWorld(*character, world);  // before the frames timed: the solvers' clocks start after it

  PaperRun r;
  r.substeps = setup.settings.substepsPerFrame;
  r.collisionEvery = setup.garments.empty() ? 1 : setup.garments.front().collisionEvery;
  r.bendEvery = setup.settings.bendEvery;
  r.integrator = setup.settings.integrator;
  r.fieldBuildSeconds = world.fieldBuild_s();
  for (std::size_t g = 0; g < world.garmentCount(); ++g) r.triangles += world.garment(g).mesh.triangleCount();
  r.frames = o.frames > 0 ? o.frames : defaultFrames(setup);
  // Animation and interpolation are inside the step: every part's pose is evaluated per
  // substep by the fixtures and colliders that ask for it. Timed per block of frames, so
  // that the reference's slices between blocks stay out of the scenario's time.
  std::optional<BulletSheet> reference;
  if (!measure) reference.emplace(kReferenceCellsU, kReferenceCellsV);
  for (long first = 1; first <= r.frames; first += kFramesPerSlice) {
    const long last = std::min(r.frames, first + kFramesPerSlice - 1);
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = cpuSeconds();
    for (long f = first; f <= last; ++f)
      if (!world.stepFrame(f)) throw Error(world.instability(), ExitCode::Unstable);
    r.simCpuSeconds += cpuSeconds() - cpuStart;
    r.simSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (reference) reference->stepTo(kReferenceFrames * last / r.frames);
  }
  if (reference) {
    r.referenceMsPerFrame = reference->result().msPerFrame;
    r.referenceFrames = reference->frames();
  }
  for (std::size_t g = 0; g < world.garmentCount(); ++g) {
    const cloth::StageTimes& t = world.solver(g).stageTimes();
    r.collideSeconds += t.collide_s;
    r.forcesSeconds += t.forces_s;
    r.integrateSeconds += t.integrate_s;
    r.stepSeconds += stepSeconds(t);
    r.colliderPoseSeconds += world.collider(g)->poseSeconds();
    r.poseSeconds += world.collider(g)->poseSeconds() + t.fixturePoses_s;
    r.counters += world.collider(g)->fieldCounters();
    if (const cloth::LayerCollider* self = world.layerCollider(g)) {
      r.self += self->layerCounters();
      r.selfThickness_m = std::max(r.selfThickness_m, self->thickness_m());
    }
    r.framesRefined += world.solver(g).refinedFrames();
    r.solves += world.solver(g).solveStats();
  }
  return r;
}

RunFunction setupPaperBench(CLI::App& app) {
  static PaperBenchOptions o;
  // The defaults live in the source tree; the help names them relative to it, not by the
  // absolute path they had where drape was built.
  app.add_option("--scene", o.scene, "The scenario's scene (default: the bundled examples/walking_skirt/scene.wrl)");
  app.add_option("--motion", o.motion, "The scenario's motion (default: the bundled examples/walking_skirt/walk.bvh)");
  app.add_option("--frames", o.frames, "Frames per run (default: the lead-in and the whole clip)");
  app.add_option("--runs", o.runs, "Runs; the median is reported")->capture_default_str()->check(CLI::Range(1, 100));
  app.add_option("--collision-every", o.collisionEvery,
                 "Collision tests every K substeps, overriding the scene (the paper's reduced-frequency tests)")
      ->check(CLI::Range(1, 1000));
  app.add_option("--bend-every", o.bendEvery,
                 "Bending forces every K substeps as an impulse (multiple time stepping), overriding the scene")
      ->check(CLI::Range(1, 1000));
  app.add_option("--substeps", o.substeps, "Substeps per frame, overriding the scene")->check(CLI::Range(1, 100000));
  app.add_option("--integrator", o.integrator,
                 "symplectic-euler, forward-euler, backward-euler or runge-kutta-4, overriding the scene "
                 "(backward-euler and runge-kutta-4 bend every substep)");
  app.add_flag("--exact-sliding", o.exactSliding,
               "Sliding points read the distance field on every test instead of their contact planes "
               "(the reference the planes are measured against)");
  app.add_flag("--free-pinches", o.freePinches,
               "Points pinched between two or more parts keep their own velocity at a test and, with "
               "--collision-every K > 1, move freely until the next, instead of taking their parts' mean "
               "velocity and being held by them (the paper's collision response as it is)");
  app.add_option_function<std::vector<std::string>>(
         "--keep-apart", [](const std::vector<std::string>& parts) { o.keepApart = parts; },
         "Body parts whose motion is corrected to keep them out of the collidable parts, instead of the scene's "
         "keepApart ('none' for none), as in drape run")
      ->delimiter(',');
  app.add_flag("--no-resting-balls", o.noRestingBalls,
               "Every pair whose point is inside a part's volume goes through the per-pair test, instead "
               "of being left out while the point stays in a ball found clear of T2 (the reference the "
               "balls are measured against)");
  app.add_option_function<std::vector<std::string>>(
         "--face-samples-with",
         [](const std::vector<std::string>& parts) { o.faceSamplesWith = facePartsOption(parts); },
         "Body parts against which the triangles' centroids collide too, overriding the scene's "
         "faceSamplesWith; 'none' for none")
      ->delimiter(',');
  app.add_option_function<double>(
         "--self-collision", [](double m) { o.selfCollision_m = m; },
         "Keep each garment's own layers this many m apart, overriding the scene's selfCollision (0: none); its "
         "time counts in the collision's")
      ->type_name("M")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--json", o.json, "Print JSON (the only format)");
  return [] {
    const int threads = benchThreads();
    const tbb::global_control threadLimit(tbb::global_control::max_allowed_parallelism,
                                          static_cast<std::size_t>(threads));
    std::vector<PaperRun> runs;
    std::vector<double> referenceMs, speedVsReference;
    for (int i = 0; i < o.runs; ++i) {
      runs.push_back(runOnce(o, false));
      const PaperRun& run = runs.back();
      referenceMs.push_back(run.referenceMsPerFrame);
      speedVsReference.push_back(run.simCpuSeconds > 0 ? run.referenceMsPerFrame * 1e-3 * run.frames / run.simCpuSeconds
                                                       : 0.0);
      spdlog::info("run {}: {} frames in {:.3f} s; the reference {:.3f} ms per frame: {:.3f} of the scenario's "
                   "frames per reference frame",
                   i + 1, run.frames, run.simSeconds, run.referenceMsPerFrame, speedVsReference.back());
    }
    std::sort(runs.begin(), runs.end(), [](const PaperRun& a, const PaperRun& b) { return a.simSeconds < b.simSeconds; });
    const PaperRun& r = runs[runs.size() / 2];
    // The penetration figures over every substep, from one more run of the same motion that
    // measures them (the timed runs keep none: measuring is not the collision's work).
    const cloth::FieldCollisionCounters penetration = runOnce(o, true).counters;
    nlohmann::json j;
    // Named as the paper's only when it is the bundled one (its Table 3 below compares with it).
    const bool bundled = o.scene == kBundledScene && o.motion == kBundledMotion;
    j["scenario"] = bundled ? "walking skirt: MakeHuman body, CMU walk, hips/thighs/shins collidable"
                            : fmt::format("{} with {}", o.scene, o.motion);
    j["frames"] = r.frames;
    j["frames_refined"] = r.framesRefined;
    j["triangles"] = r.triangles;
    j["substeps_per_frame"] = r.substeps;
    j["collision_every"] = r.collisionEvery;
    j["bend_every"] = r.bendEvery;
    j["integrator"] = cloth::integratorName(r.integrator);
    if (r.integrator == cloth::IntegratorKind::BackwardEuler)
      j["implicit_mean_iterations"] = r.solves.meanIterations();
    j["sim_fps"] = r.frames / r.simSeconds;
    j["ms_per_frame"] = 1e3 * r.simSeconds / r.frames;
    j["cpu_ms_per_frame"] = 1e3 * r.simCpuSeconds / r.frames;
    j["collide_ms_per_frame"] = 1e3 * (r.collideSeconds - r.colliderPoseSeconds) / r.frames;
    j["animation_ms_per_frame"] = 1e3 * r.poseSeconds / r.frames;
    j["forces_ms_per_frame"] = 1e3 * r.forcesSeconds / r.frames;
    // The step's update, with backward Euler's solve and the Runge-Kutta step's later stages.
    j["integrate_ms_per_frame"] = 1e3 * r.integrateSeconds / r.frames;
    // The paper's definition: collision tests over the simulation time, both without the
    // animation and its interpolation (here the pose fetches of the collider and the fixtures).
    const double simulated = r.stepSeconds - r.poseSeconds;
    j["collision_time_share"] = simulated > 0 ? (r.collideSeconds - r.colliderPoseSeconds) / simulated : 0.0;
    j["mean_collision_path_voxels"] = r.counters.meanPathVoxels();
    j["contact_planes"] = !o.exactSliding;
    j["sliding_reads_from_contact_planes"] = r.counters.slidingReadsFromPlanes();
    // Of the (vertex, part) pairs tested: those the cull left out as resting in their balls,
    // and those whose motion the per-pair test walked (or settled in their voxel).
    const auto ofTests = [&](std::uint64_t n) { return r.counters.tests ? double(n) / double(r.counters.tests) : 0.0; };
    j["pairs_resting_fraction"] = ofTests(r.counters.restingSkips);
    j["pairs_walked_fraction"] = ofTests(r.counters.traces - r.counters.restingSkips);
    j["resting_balls"] = !o.noRestingBalls;
    j["pinch_hold"] = !o.freePinches;
    j["vertex_substeps_held_in_pinches"] = r.counters.heldVertexSubsteps;
    j["vertex_tests_pinched"] = r.counters.pinchedVertexTests;
    j["crease_moves"] = r.counters.creaseMoves;
    j["crease_moves_refused"] = r.counters.creaseMovesRefused;
    j["face_tests"] = r.counters.faceTests;
    j["face_contacts"] = r.counters.faceContacts;
    j["self_collision_m"] = r.selfThickness_m;  // 0: none (its time is in the collision's)
    j["self_collision_contacts"] = r.self.contacts;
    j["self_collision_crossings"] = r.self.crossings;
    j["worn_over_contacts"] = r.self.contactsBelow;  // with the garments worn under (the scene's over)
    j["worn_over_crossings"] = r.self.crossingsBelow;
    j["vertex_substeps"] = penetration.vertexSubsteps;  // free vertices x substeps: all of them
    j["vertex_substeps_inside_body"] = penetration.vertexSubstepsInsideBody;
    j["vertex_substeps_below_T1_fraction"] =
        penetration.vertexSubsteps ? double(penetration.vertexSubstepsBelowT1) / double(penetration.vertexSubsteps)
                                   : 0.0;
    j["max_penetration_m"] = penetration.maxPenetration_m;
    j["distance_field_build_s"] = r.fieldBuildSeconds;
    j["runs"] = o.runs;
    j["threads"] = threads;
    j["machine"] = benchMachine();
    const double reference = median(referenceMs);
    const std::string workload = fmt::format(
        "Bullet's soft-body sheet of drape bench cloth (sheet-480: {} x {} cells, {} nodes), {} frames at {} "
        "substeps per run, stepped in slices after every {} of the scenario's frames, this thread's CPU time",
        kReferenceCellsU, kReferenceCellsV, (kReferenceCellsU + 1) * (kReferenceCellsV + 1), kReferenceFrames,
        SheetScenario::kSubsteps, kFramesPerSlice);
    j["reference"] = {{"workload", workload},
                      {"bullet_version", bulletVersion()},
                      {"settings", kBulletSheetSettings},
                      {"ms_per_frame", reference},
                      {"frames_per_run", r.referenceFrames},
                      {"runs", referenceMs.size()}};
    // How many of the scenario's frames the machine computes in the time it computes one
    // frame of the reference, both in CPU time, per run (the two interleaved), median over
    // the runs: a figure meant to move with our code more than with the host's speed
    // (docs/PERFORMANCE.md measures how far it does).
    j["speed_vs_reference"] = median(speedVsReference);
    j["paper_table3"] = {{"hardware", "Intel Pentium 4 2.8 GHz (2003)"},
                         {"frames", 203},
                         {"sim_fps", 30.2},
                         {"rendered_fps", 26.62},
                         {"collision_time_share", 0.171},
                         {"mean_collision_path_voxels", 0.166036}};
    std::cout << j.dump(2) << std::endl;
    return 0;
  };
}

const bool registered_bench_paper = registerCommand(
    {"paper", "The paper's walking-skirt scenario (Table 3) without rendering", "bench", 30, &setupPaperBench});

}  // namespace
}  // namespace drape::cli
