// `drape run` end to end on the bundled example, every bad input it must refuse, and an
// unstable run.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/testing/assimp_export.hpp"
#include "drape/testing/long_scenario.hpp"

namespace drape {
namespace {

using testing::CliResult;
using testing::lineCount;
using testing::runDrape;
using testing::ScratchDir;
using testing::slurp;
using testing::statsOf;

const std::string kDress = std::string(DRAPE_SOURCE_DIR) + "/examples/hanging_dress/dress.obj";
const std::string kMask = std::string(DRAPE_SOURCE_DIR) + "/examples/hanging_dress/shoulders_mask.obj";

TEST(Run, AutoSubstepsTakeTheMassScalingAllowance) {
  // --substeps auto with --max-added-mass: the fewest substeps mass scaling keeps stable
  // within the allowance, far fewer than without it, and the run reports the mass it added.
  ScratchDir dir("run-auto-scaled");
  const auto runAuto = [&](const std::string& extra, const std::string& name) {
    const std::string out = testing::runInto(
        dir, name, "--garment '" + kDress + "' --units dm --pin-mask '" + kMask + "' --substeps auto --frames 1 " + extra);
    return statsOf(out);
  };
  const nlohmann::json plain = runAuto("", "plain");
  const nlohmann::json scaled = runAuto("--max-added-mass 0.02", "scaled");
  const int unscaled = plain["substeps_per_frame"].get<int>();
  const int fewer = scaled["substeps_per_frame"].get<int>();
  EXPECT_LT(fewer, unscaled / 2) << "the dress's slivers dominate its stable step";
  const nlohmann::json& g = scaled["garments"][0];
  EXPECT_GT(g["added_mass_kg"].get<double>(), 0.0);
  EXPECT_LE(g["added_mass_kg"].get<double>(), 0.02 * (g["mass_kg"].get<double>() - g["added_mass_kg"].get<double>()));
  EXPECT_EQ(plain["garments"][0]["added_mass_kg"].get<double>(), 0.0);
  EXPECT_FALSE(scaled["unstable"].get<bool>());
}

TEST(Run, AGarmentFromAGlbHangsAsItsObjDoes) {
  // The hanging dress as Assimp's glTF exporter writes it (in metres, not indexed: a vertex
  // per triangle corner) is welded back into the dress, and hangs from the same pinned
  // vertices to the same shape as its OBJ, vertex for vertex.
  ScratchDir dir("run-glb");
  (void)testing::exportThroughAssimp(kDress, 0.1, "glb2", dir / "dress.glb");
  const std::string common = " --units dm --pin-mask '" + kMask + "' --substeps auto --frames 3";
  const std::string fromObj = testing::runInto(dir, "obj", "--garment '" + kDress + "'" + common);
  const CliResult r = runDrape("run --garment '" + dir / "dress.glb" + "'" + common + " --out '" + dir / "glb" + "'", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("dress.glb: mesh defaultobject (2205 vertices, 4192 triangles; 10371 split vertices welded)"),
            std::string::npos)
      << r.err;
  const mesh::TriMesh objRest = formats::readObj(fromObj + "/garment.obj"), glbRest = formats::readObj(dir / "glb/garment.obj");
  const formats::Pc2Cache objCache = formats::readPc2(fromObj + "/garment.pc2"), glbCache = formats::readPc2(dir / "glb/garment.pc2");
  ASSERT_EQ(glbCache.pointCount, objCache.pointCount);
  ASSERT_EQ(glbCache.frames.size(), 4u);
  double farthest = 0.0, fallen = 0.0;
  for (std::size_t v = 0; v < glbRest.vertexCount(); ++v) {
    std::size_t same = 0;
    for (std::size_t w = 1; w < objRest.vertexCount(); ++w)
      if ((objRest.positions[w] - glbRest.positions[v]).squaredNorm() < (objRest.positions[same] - glbRest.positions[v]).squaredNorm())
        same = w;
    ASSERT_LT((objRest.positions[same] - glbRest.positions[v]).norm(), 1e-6) << "vertex " << v;
    farthest = std::max(farthest, (glbCache.frames.back()[v] - objCache.frames.back()[same]).norm());
    fallen = std::max(fallen, objCache.frames.front()[same].y() - objCache.frames.back()[same].y());
  }
  EXPECT_GT(fallen, 0.01) << "the free hem falls";
  EXPECT_LT(farthest, 1e-5) << "the same dress, summed in another vertex order";
}

TEST(Run, BundledExampleWritesEverything) {
  ScratchDir dir("run-example");
  const std::string out = dir / "out";
  const CliResult r = runDrape("run --garment '" + kDress + "' --units dm --pin-mask '" + kMask +
                                   "' --substeps auto --frames 3 --every 2 --out '" + out + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;

  // Frames 0, 2 and the last one as OBJ; every frame in the cache.
  for (const char* f : {"frame_00000.obj", "frame_00002.obj", "frame_00003.obj"})
    EXPECT_TRUE(std::filesystem::exists(out + "/frames/" + f)) << f;
  EXPECT_FALSE(std::filesystem::exists(out + "/frames/frame_00001.obj"));
  const mesh::TriMesh rest = formats::readObj(out + "/garment.obj");
  EXPECT_EQ(rest.vertexCount(), 2205u);
  EXPECT_EQ(rest.triangleCount(), 4192u);
  const formats::Pc2Cache cache = formats::readPc2(out + "/garment.pc2");
  ASSERT_EQ(cache.frames.size(), 4u);
  ASSERT_EQ(cache.pointCount, 2205u);
  // The rest topology is in metres (the file is in decimetres: 5.62 dm at the top).
  EXPECT_NEAR(rest.bounds().max.y(), 0.56211, 1e-4);
  // Pinned (top) vertices stay; the free ones fall.
  double moved = 0.0;
  for (std::size_t i = 0; i < cache.pointCount; ++i) {
    const double dy = cache.frames.back()[i].y() - cache.frames.front()[i].y();
    if (rest.positions[i].y() > 0.53) {
      EXPECT_NEAR(dy, 0.0, 1e-6) << i;
    }
    moved = std::min(moved, dy);
  }
  EXPECT_LT(moved, -1e-4);

  const nlohmann::json stats = statsOf(out);
  for (const char* key : {"frames", "substeps_per_frame", "ms_per_frame", "loop_wall_ms_per_frame", "ms_per_stage",
                          "energy", "max_strain", "max_stretch", "max_compression", "nan_detected"})
    EXPECT_TRUE(stats.contains(key)) << key;
  for (const char* stage : {"forces", "integrate", "collide", "fixtures", "output"})
    EXPECT_TRUE(stats["ms_per_stage"].contains(stage)) << stage;
  EXPECT_EQ(stats["frames"], 3);
  EXPECT_GT(stats["substeps_per_frame"].get<int>(), 33);  // auto: the stable count for this mesh
  EXPECT_GT(stats["ms_per_frame"].get<double>(), 0.0);
  EXPECT_EQ(stats["energy"].size(), 4u);
  // Each frame's own stage times add up to the run's means: frame 0, the initial state,
  // simulated nothing but was written. (To 1e-4: the stage clock's counter rate is measured
  // from the program's start to each reading, so an early frame's ticks become seconds at a
  // slightly different rate than the run's total's.)
  for (const char* stage : {"forces", "integrate", "collide", "fixtures", "strain_limit", "output"}) {
    const nlohmann::json& column = stats["frame_ms_per_stage"][stage];
    ASSERT_EQ(column.size(), 4u) << stage;
    double sum = 0.0;
    for (const nlohmann::json& ms : column) {
      EXPECT_GE(ms.get<double>(), 0.0) << stage;
      sum += ms.get<double>();
    }
    const double mean = stats["ms_per_stage"][stage].get<double>();
    if (std::string(stage) == "output") {
      EXPECT_GT(column[0].get<double>(), 0.0);
      EXPECT_NEAR(sum / 4.0, mean, 1e-4 * mean) << stage;  // the output's mean counts every frame written
    } else {
      EXPECT_EQ(column[0].get<double>(), 0.0) << stage;
      EXPECT_NEAR(sum / 3.0, mean, 1e-4 * mean) << stage;
    }
  }
  EXPECT_GT(stats["frame_ms_per_stage"]["forces"][1].get<double>(), 0.0);
  EXPECT_LT(stats["energy"].back().get<double>(), stats["energy"].front().get<double>());  // falling, drag
  EXPECT_GE(stats["max_strain"].get<double>(), 0.0);
  EXPECT_LT(stats["max_strain"].get<double>(), 0.5);
  EXPECT_FALSE(stats["nan_detected"].get<bool>());

  const formats::RunManifest manifest = formats::readRunManifest(out);
  EXPECT_EQ(manifest.frames, 4);
  ASSERT_EQ(manifest.meshes.size(), 1u);
  EXPECT_EQ(manifest.meshes[0].cache, "garment.pc2");
  EXPECT_EQ(manifest.meshes[0].topology, "garment.obj");
}

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

struct BadCase {
  const char* name;
  std::string args;      // after "run"
  const char* expected;  // part of the one-line message
};

TEST(Run, BadInputsGiveOneLineAndExitCode2) {
  ScratchDir dir("run-bad");
  const std::string nonManifold = dir / "nonmanifold.obj", degenerate = dir / "degenerate.obj";
  writeText(nonManifold, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\nf 1 2 5\n");
  writeText(degenerate, "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  const std::string dress = "--garment '" + kDress + "' --units dm --frames 1 --out '" + (dir / "o") + "'";
  const std::string source = DRAPE_SOURCE_DIR;
  const std::string skirt = "'" + source + "/examples/walking_skirt/scene.wrl' --motion '" + source +
                            "/examples/walking_skirt/walk.bvh' --frames 1 --out '" + (dir / "o") + "'";
  const std::vector<BadCase> cases = {
      {"missing file", "--garment /no/such/garment.obj --frames 1 --out '" + (dir / "o") + "'", "no such file"},
      {"non-manifold", "--garment '" + nonManifold + "' --frames 1 --out '" + (dir / "o") + "'", "non-manifold edge"},
      {"degenerate", "--garment '" + degenerate + "' --frames 1 --out '" + (dir / "o") + "'", "degenerate"},
      {"negative thickness", dress + " --thickness -0.001", "--thickness must be > 0 m"},
      {"negative density", dress + " --density -5", "--density must be > 0 kg/m^3"},
      {"poisson 0.5", dress + " --poisson-ratio 0.5", "--poisson-ratio must be in [0, 0.5)"},
      {"poisson negative", dress + " --poisson-ratio -0.1", "--poisson-ratio must be in [0, 0.5)"},
      {"pin out of range", dress + " --pin-vertices 0,5000", "--pin-vertices: vertex 5000 is out of range"},
      {"pin not a number", dress + " --pin-vertices 0,x", "--pin-vertices: 'x' is not a vertex index"},
      {"pin not whole", dress + " --pin-vertices 0,1.5", "--pin-vertices: '1.5' is not a vertex index"},
      {"pin negative", dress + " --pin-vertices -3", "--pin-vertices: '-3' is not a vertex index"},
      {"pin list empty item", dress + " --pin-vertices 0,,2", "--pin-vertices: '' is not a vertex index"},
      {"unknown unit", "--garment '" + kDress + "' --units furlong --frames 1 --out '" + (dir / "o") + "'",
       "--units"},
      {"mask matches nothing", dress + " --pin-mask '" + nonManifold + "'", "no vertex of the mask"},
      {"zero frames", "--garment '" + kDress + "' --units dm --frames 0 --out '" + (dir / "o") + "'",
       "--frames must be >= 1"},
      {"bad substeps", dress + " --substeps fast", "--substeps must be"},
      {"substeps with a unit", dress + " --substeps 12x",
       "--substeps must be a whole number in [1, 100000] or 'auto', got '12x'"},
      {"bad integrator", dress + " --integrator rk4", "--integrator must be"},
      {"no refinement", dress + " --max-refinement 0", "--max-refinement must be in [1, 64], got 0"},
      {"strain limit a word", dress + " --strain-limit some", "--strain-limit must be 'auto', 'none' or a stretch"},
      {"strain limit zero", dress + " --strain-limit 0", "in (0, 10] (0.5: edges at most 1.5 times as long), got '0'"},
      {"keep apart without motion", dress + " --keep-apart LeftForeArm", "--keep-apart corrects a motion: give --motion"},
      {"keep apart unknown part", skirt + " --keep-apart LeftForeArm,Tail", "has no part 'Tail' (it has: Hips, "},
      {"keep apart none in a list", skirt + " --keep-apart none,LeftForeArm", "--keep-apart: 'none' stands alone"},
  };
  for (const BadCase& c : cases) {
    const CliResult r = runDrape("run " + c.args, dir);
    EXPECT_EQ(r.code, 2) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.name << ": " << r.err;
    EXPECT_EQ(lineCount(r.err), 1) << c.name << ": " << r.err;
  }
}

TEST(Run, UnstableRunExits3AndKeepsWhatItWrote) {
  ScratchDir dir("run-unstable");
  const std::string out = dir / "out";
  // The dress at the default 33 substeps is far beyond its stable step; no frame is
  // computed again with more.
  const CliResult r = runDrape("run --garment '" + kDress + "' --units dm --pin-mask '" + kMask +
                                   "' --frames 5 --max-refinement 1 --out '" + out + "'",
                               dir);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("garment 'dress': vertex"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("in frame 1"), std::string::npos) << r.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_TRUE(stats["unstable"].get<bool>());
  EXPECT_EQ(stats["frames"], 0);
  EXPECT_EQ(formats::readPc2(out + "/garment.pc2").frames.size(), 1u);
  EXPECT_EQ(formats::readRunManifest(out).frames, 1);
}

TEST(Run, AWriteThatFailsMidRunStopsItWithTheFileNamed) {
  // Frames are written while the next ones are simulated: a write that fails in frame 2
  // (its OBJ's name taken by a directory) must stop the run with that file named, not
  // hang the simulation waiting for it or lose the message, and keep what was written.
  ScratchDir dir("run-write-fails");
  const std::string out = dir / "out";
  std::filesystem::create_directories(out + "/frames/frame_00002.obj");
  const CliResult r = runDrape("--quiet run --garment '" + kDress + "' --units dm --pin-mask '" + kMask +
                                   "' --substeps auto --frames 6 --every 1 --out '" + out + "'",
                               dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("frame_00002.obj: cannot be written"), std::string::npos) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out + "/frames/frame_00001.obj"));
  EXPECT_FALSE(std::filesystem::exists(out + "/frames/frame_00003.obj"));
  // The cache holds the frames up to the failed one, whose cache frame came first.
  EXPECT_EQ(formats::readPc2(out + "/garment.pc2").frames.size(), 3u);
}

TEST(Run, AnUnstableFrameIsComputedAgainWithMoreSubsteps) {
  ScratchDir dir("run-refined");
  const std::string out = dir / "out";
  // The same dress and substeps: each frame goes unstable, and is computed again with 2, 4
  // or 8 times the substeps (--max-refinement's default), which hold it.
  const CliResult r = runDrape("run --garment '" + kDress + "' --units dm --pin-mask '" + kMask +
                                   "' --frames 3 --out '" + out + "'",
                               dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("garment 'dress': vertex"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("in frame 1, substep"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; computed again with"), std::string::npos) << r.err;
  const nlohmann::json stats = statsOf(out);
  EXPECT_FALSE(stats["unstable"].get<bool>());
  EXPECT_EQ(stats["frames"], 3);
  EXPECT_GE(stats["garments"][0]["frames_refined"].get<int>(), 1);
  EXPECT_LE(stats["garments"][0]["frames_refined"].get<int>(), 3);
}

TEST(Run, FramesWithinTheLeadInAreSaidToEndBeforeTheMotion) {
  // --frames counts from the lead-in's first frame: 0.2 s at 30 Hz is 6 frames blending into
  // the walk, so --frames 3 ends before its first frame, 6 on it, and 7 is past it.
  ScratchDir dir("run-frames-lead-in");
  const std::string example = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/";
  const auto run = [&](long frames) {
    const std::string args = fmt::format("run '{}scene.wrl' --motion '{}walk.bvh' --lead-in 0.2 --frames {} --out '{}'",
                                         example, example, frames, dir / std::to_string(frames));
    const CliResult r = runDrape(args, dir);
    EXPECT_EQ(r.code, 0) << r.err;
    return r.err;
  };
  EXPECT_NE(run(3).find("warning: --frames 3 ends before the motion's first frame: the first 6 frames are the 0.2 s "
                        "lead-in, blending from the rest pose into the motion; --frames 9 simulates 3 frames of the "
                        "motion itself (or give --lead-in 0)"),
            std::string::npos);
  EXPECT_NE(run(6).find("warning: --frames 6 ends at the motion's first frame"), std::string::npos);
  EXPECT_EQ(run(7).find("lead-in, blending"), std::string::npos);
}

TEST(Run, OffsetsASimulationNodeDoesNotWriteFollowTheVoxelSize) {
  // The dressed avatar's Simulation node writes offsets 4, 8, 12 and 16 mm on 10 mm voxels;
  // without them, as without a Simulation node, each garment's are 1, 2, 3 and 6 voxels (the
  // paper's T3 = 6 voxels), and `drape inspect` says so, not the node's unwritten default.
  ScratchDir dir("run-offsets-from-voxels");
  std::string scene = slurp(std::string(DRAPE_SOURCE_DIR) + "/examples/dressed_avatar/scene.wrl");
  const std::string written = "  offsets [ 0.004 0.008 0.012 0.016 ]\n";
  ASSERT_NE(scene.find(written), std::string::npos);
  std::string said;
  const auto offsetsOf = [&](const std::string& name, const std::string& text) {
    const std::string path = dir / (name + ".wrl");
    std::ofstream(path) << text;
    const CliResult r = runDrape(fmt::format("run '{}' --frames 1 --out '{}'", path, dir / name), dir);
    EXPECT_EQ(r.code, 0) << r.err;
    said = r.err;
    return statsOf(dir / name)["garments"][0]["offsets_m"].get<std::vector<double>>();
  };
  const std::vector<double> asWritten = offsetsOf("written", scene);
  EXPECT_EQ(said.find("offset surfaces T0..T3"), std::string::npos) << said;
  std::string unwritten = scene;
  unwritten.erase(unwritten.find(written), written.size());
  const std::vector<double> fromVoxels = offsetsOf("unwritten", unwritten);
  EXPECT_NE(said.find("offset surfaces T0..T3 10, 20, 30 and 60 mm: 1, 2, 3 and 6 voxels, as no offsets are written"),
            std::string::npos)
      << said;
  const std::vector<double> want[2] = {{0.004, 0.008, 0.012, 0.016}, {0.01, 0.02, 0.03, 0.06}};
  ASSERT_EQ(asWritten.size(), 4u);
  ASSERT_EQ(fromVoxels.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(asWritten[i], want[0][i], 1e-7);
    EXPECT_NEAR(fromVoxels[i], want[1][i], 1e-7);
  }
  const CliResult inspected = runDrape(fmt::format("inspect '{}'", dir / "unwritten.wrl"), dir);
  EXPECT_EQ(inspected.code, 0) << inspected.err;
  EXPECT_NE(inspected.out.find("offsets T0..T3 0.01 0.02 0.03 0.06 m (1, 2, 3 and 6 voxels: none written), voxel "
                               "size 0.01 m"),
            std::string::npos)
      << inspected.out;
}

TEST(Run, TheScenesLastResortsReachTheSolverAndTheCommandLineOverridesThem) {
  // A scene's Simulation maxRefinement and strainLimit, as written, and as --max-refinement
  // and --strain-limit replace them.
  ScratchDir dir("run-scene-last-resorts");
  std::string scene = slurp(std::string(DRAPE_SOURCE_DIR) + "/examples/dressed_avatar/scene.wrl");
  const std::string anchor = "integrator \"symplectic-euler\"\n";
  ASSERT_NE(scene.find(anchor), std::string::npos);
  scene.insert(scene.find(anchor) + anchor.size(), "  maxRefinement 2\n  strainLimit 0.3\n");
  const std::string path = dir / "scene.wrl";
  std::ofstream(path) << scene;
  const std::string quoted = fmt::format("'{}' --frames 2", path);
  const nlohmann::json asWritten = statsOf(testing::runInto(dir, "scene", quoted));
  EXPECT_EQ(asWritten["max_refinement"].get<int>(), 2);
  EXPECT_NEAR(asWritten["garments"][0]["strain_limit"].get<double>(), 0.3, 1e-6);
  EXPECT_TRUE(asWritten["garments"][0]["strain_limited_from_frame"].is_null());
  const nlohmann::json overridden =
      statsOf(testing::runInto(dir, "overridden", quoted + " --max-refinement 4 --strain-limit none"));
  EXPECT_EQ(overridden["max_refinement"].get<int>(), 4);
  EXPECT_EQ(overridden["garments"][0]["strain_limit"].get<double>(), 0.0);
}

}  // namespace
}  // namespace drape

namespace drape {
namespace {

// The benchmark's smoke test: `drape bench cloth --quick --no-peers` prints one JSON object
// with the benchmark's keys for the three sheet sizes.
TEST(BenchCloth, QuickPrintsTheCases) {
  testing::ScratchDir dir("bench-cloth");
  const testing::CliResult r = testing::runDrape("bench cloth --quick --no-peers --json", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_GE(j["cases"].size(), 3u);
  for (const auto& c : j["cases"])
    for (const char* key : {"name", "triangles", "vertices", "substeps_per_frame", "ms_per_frame",
                            "vertex_substeps_per_s", "stable", "max_strain"})
      EXPECT_TRUE(c.contains(key)) << key;
  EXPECT_EQ(j["cases"][0]["triangles"], 480);
  EXPECT_EQ(j["cases"][0]["substeps_per_frame"], 33);
  // 20 frames end mid-swing: the quick run judges divergence, not the transient strain.
  EXPECT_EQ(j["cases"][0]["stable"], true) << j["cases"][0].dump();
  EXPECT_TRUE(j.contains("peers"));
}

/// The widest vector instructions this test was compiled for.
std::string buildIsaOfThisTest() {
#if defined(__AVX512F__)
  return "AVX-512";
#elif defined(__AVX2__)
  return "AVX2";
#elif defined(__AVX__)
  return "AVX";
#elif defined(__SSE2__)
  return "SSE2";
#else
  return "none";
#endif
}

/// The value of the first /proc/cpuinfo line whose key is `key`, or "".
std::string firstCpuinfoLine(const std::string& key) {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key, 0) == 0 && line.find(':') != std::string::npos) {
      const std::string value = line.substr(line.find(':') + 1);
      return value.empty() ? value : value.substr(1);
    }
  return "";
}

/// The widest of AVX-512, AVX2, AVX and SSE2 among a processor's flags ("fpu vme ... avx2 ...").
std::string widestIsaIn(const std::string& flags) {
  const std::string padded = " " + flags + " ";
  for (const auto& [flag, isa] : {std::pair{"avx512f", "AVX-512"}, {"avx2", "AVX2"}, {"avx", "AVX"}, {"sse2", "SSE2"}})
    if (padded.find(std::string(" ") + flag + " ") != std::string::npos) return isa;
  return "none";
}

// `drape bench paper` on the first frames of the walking skirt, with the collision tests
// every substep and every third (and bending every fourth): the benchmark's keys, the paper's
// Table 3 and the reference workload beside them, the reduced frequency seen in the counters,
// and the penetration figures still over every substep.
TEST(BenchPaper, PrintsTableThreeFiguresAndTakesTheCollisionFrequency) {
  DRAPE_LONG_SCENARIO();
  testing::ScratchDir dir("bench-paper");
  const auto bench = [&](const std::string& extra) {
    const testing::CliResult r = testing::runDrape("bench paper --json --runs 1 --frames 40 " + extra, dir);
    EXPECT_EQ(r.code, 0) << r.err;
    return nlohmann::json::parse(r.out);
  };
  const nlohmann::json every = bench("");
  const nlohmann::json third = bench("--collision-every 3 --bend-every 4");
  const nlohmann::json exact = bench("--exact-sliding");
  const nlohmann::json free = bench("--collision-every 3 --bend-every 4 --free-pinches");
  for (const char* key : {"frames", "sim_fps", "ms_per_frame", "collision_time_share", "mean_collision_path_voxels",
                          "vertex_substeps_inside_body", "animation_ms_per_frame", "collision_every"})
    EXPECT_TRUE(every.contains(key)) << key;
  EXPECT_EQ(every["frames"], 40);
  EXPECT_EQ(every["paper_table3"]["sim_fps"], 30.2);
  // The paper's scenario is named so only when it is the bundled one.
  EXPECT_EQ(every["scenario"].get<std::string>().rfind("walking skirt: ", 0), 0u) << every["scenario"];
  const std::string otherWalk = std::string(DRAPE_DATA_DIR) + "/mocap/cmu_walk_delfem2.bvh";
  const testing::CliResult otherRun =
      testing::runDrape("bench paper --json --runs 1 --frames 5 --motion '" + otherWalk + "'", dir);
  ASSERT_EQ(otherRun.code, 0) << otherRun.err;
  const nlohmann::json other = nlohmann::json::parse(otherRun.out);
  EXPECT_EQ(other["scenario"].get<std::string>(),
            std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/scene.wrl with " + otherWalk)
      << other["scenario"];
  // The reference workload timed in the same run, and the scenario's speed read against it
  // (CPU time over CPU time).
  const double referenceMs = every["reference"]["ms_per_frame"].get<double>();
  EXPECT_GT(referenceMs, 0.0);
  EXPECT_EQ(every["reference"]["runs"], 1);
  // All of the reference's frames, stepped in slices between blocks of the scenario's 40
  // (34 and 6): the last slice takes it to its end.
  EXPECT_EQ(every["reference"]["frames_per_run"], 300);
  EXPECT_NEAR(every["speed_vs_reference"].get<double>(), referenceMs / every["cpu_ms_per_frame"].get<double>(),
              1e-9 * referenceMs / every["cpu_ms_per_frame"].get<double>());
  // What the figures were measured on: the build's vector instructions (this test is built
  // with the same flags as drape, so its own macros say which), the processor's (from the
  // flags Linux lists for it, where drape asks the processor itself), and its model name.
  ASSERT_TRUE(every.contains("machine"));
  EXPECT_EQ(every["machine"]["build_vector_isa"], buildIsaOfThisTest()) << every["machine"];
  const std::string cpuFlags = firstCpuinfoLine("flags");
  if (!cpuFlags.empty()) {
    EXPECT_EQ(every["machine"]["cpu_vector_isa"], widestIsaIn(cpuFlags)) << every["machine"];
  }
  const std::string model = firstCpuinfoLine("model name");
  EXPECT_EQ(every["machine"]["cpu"], model.empty() ? "unknown" : model);
  EXPECT_EQ(every["collision_every"], 1);
  EXPECT_EQ(third["collision_every"], 3);
  EXPECT_EQ(every["bend_every"], 8);  // the scene's
  EXPECT_EQ(third["bend_every"], 4);
  EXPECT_GT(every["vertex_substeps"].get<long>(), 0);
  EXPECT_EQ(third["vertex_substeps"], every["vertex_substeps"]);
  // Sliding tests answered by contact planes, unless every one reads the field.
  EXPECT_EQ(every["contact_planes"], true);
  EXPECT_GT(every["sliding_reads_from_contact_planes"].get<double>(), 0.5);
  EXPECT_EQ(exact["contact_planes"], false);
  EXPECT_EQ(exact["sliding_reads_from_contact_planes"], 0.0);
  EXPECT_EQ(exact["vertex_substeps"], every["vertex_substeps"]);
  // Pinched points held between reduced-frequency tests, unless they move freely.
  EXPECT_EQ(third["pinch_hold"], true);
  EXPECT_EQ(free["pinch_hold"], false);
  EXPECT_EQ(free["vertex_substeps_held_in_pinches"], 0);
  EXPECT_EQ(every["vertex_substeps_held_in_pinches"], 0);  // tests on every substep: nothing to hold
  for (const nlohmann::json* j : {&every, &third, &exact}) {
    EXPECT_GT((*j)["collision_time_share"].get<double>(), 0.0);
    EXPECT_LT((*j)["collision_time_share"].get<double>(), 1.0);
    EXPECT_GE((*j)["animation_ms_per_frame"].get<double>(), 0.0);
    EXPECT_EQ((*j)["vertex_substeps_inside_body"], 0);
  }
  // A third of the tests, each over three substeps' motion: longer paths per test.
  EXPECT_GT(third["mean_collision_path_voxels"].get<double>(), every["mean_collision_path_voxels"].get<double>());
  for (const char* option : {"--collision-every 0", "--bend-every 0"}) {
    const testing::CliResult bad = testing::runDrape(std::string("bench paper --json ") + option, dir);
    EXPECT_NE(bad.code, 0) << option;
  }
  // The implicit step at 4 substeps a frame: bending every substep, its iterations reported.
  const nlohmann::json implicit = bench("--integrator backward-euler --substeps 4");
  EXPECT_EQ(implicit["integrator"], "backward-euler");
  EXPECT_EQ(every["integrator"], "symplectic-euler");
  EXPECT_FALSE(every.contains("implicit_mean_iterations"));
  EXPECT_EQ(implicit["substeps_per_frame"], 4);
  EXPECT_EQ(implicit["bend_every"], 1);
  EXPECT_GT(implicit["implicit_mean_iterations"].get<double>(), 1.0);
  // The solve is the step's update: it outweighs the forces of the substep's start.
  EXPECT_GT(implicit["integrate_ms_per_frame"].get<double>(), implicit["forces_ms_per_frame"].get<double>());
  EXPECT_EQ(implicit["vertex_substeps_inside_body"], 0);
  EXPECT_EQ(implicit["frames_refined"], 0);
  const testing::CliResult rhythm =
      testing::runDrape("bench paper --json --integrator backward-euler --bend-every 2 --frames 1", dir);
  EXPECT_EQ(rhythm.code, 2) << rhythm.err;
  EXPECT_NE(rhythm.err.find("--bend-every must be 1 with the backward-euler integrator"), std::string::npos)
      << rhythm.err;
  // --keep-apart names parts of the scene's avatar, checked before any field is built.
  const testing::CliResult tail = testing::runDrape("bench paper --json --keep-apart LeftForeArm,Tail", dir);
  EXPECT_EQ(tail.code, 2) << tail.err;
  EXPECT_NE(tail.err.find("--keep-apart: avatar '"), std::string::npos) << tail.err;
  EXPECT_EQ(tail.err.find("distance fields in"), std::string::npos) << tail.err;
}

}  // namespace
}  // namespace drape
