#include "run_setup.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/cloth/forces.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/solver.hpp"
#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/core/progress.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::cli {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

/// Triangles smaller than this (m^2) are degenerate for the membrane model.
constexpr double kMinTriangleArea_m2 = 1e-12;

/// One garment being simulated: its model, solver and output streams.
struct GarmentRun {
  std::string fileStem;  ///< "garment" alone, "garment-<name>" when there are several
  std::shared_ptr<const cloth::ClothModel> model;
  std::unique_ptr<cloth::ClothSolver> solver;
  std::unique_ptr<formats::Pc2Writer> cache;
};

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void createOutDir(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(fs::path(dir) / "frames", ec);
  if (ec) throw Error(fmt::format("--out {}: cannot create the directory ({})", dir, ec.message()));
}

std::vector<cloth::PinGroup> pinsOf(const GarmentSetup& g, const cloth::ClothModel& model) {
  if (g.pinned.empty()) return {};
  return {cloth::PinGroup::atRest(g.pinned, model.restX(), model.restY(), model.restZ())};
}

}  // namespace

void validateRunSetup(const RunSetup& setup) {
  if (setup.garments.empty()) throw Error("drape run: no garment to simulate");
  setup.settings.validate("--");
  if (setup.frames < 1) throw Error(fmt::format("--frames must be >= 1, got {}", setup.frames));
  if (setup.objEvery < 1) throw Error(fmt::format("--every must be >= 1, got {}", setup.objEvery));
  for (const SphereSetup& s : setup.spheres)
    if (!(s.radius_m > 0.0) || !s.centre_m.allFinite())
      throw Error(fmt::format("--sphere needs a finite centre and a radius > 0, got radius {}", s.radius_m));
  for (const GarmentSetup& g : setup.garments) {
    g.material.validate("--");
    for (std::uint32_t v : g.pinned)
      if (v >= g.mesh.vertexCount())
        throw Error(fmt::format("--pin-vertices: vertex {} is out of range ({} has {} vertices, 0..{})", v, g.name,
                                g.mesh.vertexCount(), g.mesh.vertexCount() - 1));
  }
}

int stableSubsteps(const RunSetup& setup) {
  long n = 1;
  for (const GarmentSetup& g : setup.garments) {
    const auto model = cloth::ClothModel::build(g.mesh, mesh::Topology::build(g.mesh, kMinTriangleArea_m2), g.material);
    n = std::max(n, static_cast<long>(std::ceil(1.0 / (setup.settings.frameRate_hz * model->estimatedStableStep_s()))));
  }
  return static_cast<int>(std::min(n, 100000L));
}

int simulateRun(const RunSetup& setup) {
  validateRunSetup(setup);
  createOutDir(setup.outDir);
  const fs::path out(setup.outDir);
  const cloth::StepSettings& settings = setup.settings;

  // Build every garment (topology checks happen here: non-manifold, degenerate).
  std::vector<cloth::SphereCollider> spheres;
  for (const SphereSetup& s : setup.spheres) spheres.emplace_back(s.centre_m, s.radius_m);
  std::vector<GarmentRun> runs;
  formats::RunManifest manifest;
  manifest.frameRate = settings.frameRate_hz;
  for (const GarmentSetup& g : setup.garments) {
    GarmentRun r;
    r.fileStem = setup.garments.size() == 1 ? "garment" : "garment-" + g.name;
    const mesh::Topology topology = mesh::Topology::build(g.mesh, kMinTriangleArea_m2);
    r.model = cloth::ClothModel::build(g.mesh, topology, g.material);
    r.solver = std::make_unique<cloth::ClothSolver>(r.model, settings, pinsOf(g, *r.model));
    for (cloth::SphereCollider& s : spheres) r.solver->addCollider(s);
    const double stable = r.model->estimatedStableStep_s();
    if (settings.substep_s() > stable)
      spdlog::warn("{}: the substep {:.3g} s is longer than the estimated stable step {:.3g} s; "
                   "the run may diverge (try --substeps {} or more)",
                   g.name, settings.substep_s(), stable,
                   static_cast<long>(std::ceil(1.0 / (settings.frameRate_hz * stable))));
    formats::writeObj((out / (r.fileStem + ".obj")).string(), g.mesh.positions, g.mesh.triangles,
                      "drape run: rest topology of " + g.name + " (m)");
    r.cache = std::make_unique<formats::Pc2Writer>((out / (r.fileStem + ".pc2")).string(), g.mesh.vertexCount(), 0.0,
                                                   1.0);
    manifest.meshes.push_back({g.name, "garment", r.fileStem + ".obj", r.fileStem + ".pc2"});
    runs.push_back(std::move(r));
  }

  // Per-frame records for stats.json.
  std::vector<double> frameMs, energy;
  double maxStrain = 0.0, outputSeconds = 0.0;
  std::vector<Vec3> positions;
  std::string unstable;
  bool unstableNan = false;

  auto writeFrame = [&](long frame) {
    const Clock::time_point start = Clock::now();
    double e = 0.0;
    for (GarmentRun& r : runs) {
      const cloth::ClothState& s = r.solver->state();
      s.copyPositions(positions);
      r.cache->writeFrame(positions);
      if (frame % setup.objEvery == 0 || frame == setup.frames) {
        const std::string name =
            runs.size() == 1 ? fmt::format("frame_{:05d}.obj", frame) : fmt::format("{}_{:05d}.obj", r.fileStem, frame);
        formats::writeObj((out / "frames" / name).string(), positions, r.model->triangles(),
                          fmt::format("drape run: frame {} of {} (m)", frame, r.model->name()));
      }
      e += r.solver->totalEnergy();
      maxStrain = std::max(maxStrain, cloth::maxEdgeStrain(*r.model, s));
    }
    energy.push_back(e);
    outputSeconds += std::chrono::duration<double>(Clock::now() - start).count();
  };

  // The frame loop: every garment steps one frame, then the frame is written.
  writeFrame(0);
  Progress progress("drape run", setup.frames);
  long done = 0;
  for (long frame = 1; frame <= setup.frames && unstable.empty(); ++frame) {
    const Clock::time_point start = Clock::now();
    for (std::size_t g = 0; g < runs.size() && unstable.empty(); ++g)
      if (!runs[g].solver->stepFrame(frame)) {
        unstable = runs[g].solver->instability().describe(setup.garments[g].name, settings.maxSpeed_m_s);
        unstableNan = runs[g].solver->instability().nan;
      }
    frameMs.push_back(1e3 * std::chrono::duration<double>(Clock::now() - start).count());
    if (!unstable.empty()) break;
    writeFrame(frame);
    done = frame;
    progress.update(frame);
  }
  progress.finish();

  // Close the caches and write stats and manifest (also after an instability).
  for (GarmentRun& r : runs) r.cache->close();
  manifest.frames = done + 1;
  formats::writeRunManifest(setup.outDir, manifest);

  cloth::StageTimes total;
  for (const GarmentRun& r : runs) {
    const cloth::StageTimes& t = r.solver->stageTimes();
    total.forces_s += t.forces_s;
    total.integrate_s += t.integrate_s;
    total.collide_s += t.collide_s;
    total.fixtures_s += t.fixtures_s + t.stability_s;
  }
  const double perFrame = 1e3 / static_cast<double>(std::max<long>(1, static_cast<long>(frameMs.size())));
  nlohmann::json stats;
  stats["frames"] = done;
  stats["frames_requested"] = setup.frames;
  stats["frame_rate"] = settings.frameRate_hz;
  stats["substeps_per_frame"] = settings.substepsPerFrame;
  stats["integrator"] = cloth::integratorName(settings.integrator);
  stats["ms_per_frame"] = medianOf(frameMs);
  stats["ms_per_stage"] = {{"forces", total.forces_s * perFrame},
                           {"integrate", total.integrate_s * perFrame},
                           {"collide", total.collide_s * perFrame},
                           {"fixtures", total.fixtures_s * perFrame},
                           {"output", outputSeconds * 1e3 / static_cast<double>(energy.size())}};
  stats["energy"] = energy;
  stats["max_strain"] = maxStrain;
  stats["nan_detected"] = unstableNan;
  stats["unstable"] = !unstable.empty();
  stats["instability"] = unstable.empty() ? nlohmann::json(nullptr) : nlohmann::json(unstable);
  nlohmann::json garments = nlohmann::json::array();
  for (std::size_t g = 0; g < runs.size(); ++g) {
    const cloth::ClothModel& m = *runs[g].model;
    garments.push_back({{"name", setup.garments[g].name},
                        {"vertices", m.vertexCount()},
                        {"triangles", m.triangleCount()},
                        {"pinned", setup.garments[g].pinned.size()},
                        {"mass_kg", m.totalMass_kg()},
                        {"estimated_stable_substep_s", m.estimatedStableStep_s()}});
  }
  stats["garments"] = garments;
  const std::string statsPath = (out / "stats.json").string();
  std::ofstream statsFile(statsPath);
  statsFile << stats.dump(2) << "\n";
  if (!statsFile) throw Error(fmt::format("{}: write failed", statsPath));

  if (!unstable.empty())
    throw Error(fmt::format("{} (results up to frame {} kept in {})", unstable, done, setup.outDir),
                ExitCode::Unstable);
  return 0;
}

}  // namespace drape::cli
