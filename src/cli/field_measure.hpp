#pragma once
// Side-by-side measurement of DVDP and the exact feature transform on one voxelized mesh:
// used by `drape field --dims ... --json` and `drape bench field`.

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include "drape/field/distance_field.hpp"
#include "drape/field/propagation.hpp"
#include "drape/field/voxelize.hpp"
#include "measure.hpp"

namespace drape::cli {

struct FieldMeasurement {
  field::GridDims dims;
  std::size_t surfaceVoxels = 0;
  double voxelizeMs = 0;
  double dvdpMs = 0;              ///< DVDP, references within the shell, distances everywhere
  double dvdpDistanceOnlyMs = 0;  ///< DVDP without references (the paper's "(0)")
  double dvdpPaperMs = 0;         ///< DVDP with the paper's unchecked references in the shell
  double exactMs = 0;             ///< exact feature transform with shell references
  double exactDistanceOnlyMs = 0; ///< exact squared distances only
  std::size_t shellVoxels = 0;
  std::size_t shellMismatches = 0;       ///< shell voxels where DVDP's distance or a reference is not exact
  std::size_t paperShellMismatches = 0;  ///< the same for the paper variant
  double maxErrorVoxels = 0;             ///< max |DVDP - exact| distance anywhere (voxels)
  double maxErrorDistanceOnlyVoxels = 0; ///< the same for DVDP (0)
  std::size_t voxelsWithError = 0;       ///< voxels where DVDP's distance differs from exact
  double meanRelativeErrorBeyondShell = 0;
  double maxRelativeErrorBeyondShell = 0;  ///< max |DVDP - exact| / exact beyond the shell
  double maxOverestimateVoxels = 0;        ///< max DVDP - exact (positive: DVDP too far)
  double maxUnderestimateVoxels = 0;       ///< max exact - DVDP
  double bytesPerVoxel = 0;
  double dvdpWallMs = 0, dvdpDistanceOnlyWallMs = 0, exactWallMs = 0, exactDistanceOnlyWallMs = 0;
};

inline double threadCpuMs() { return 1e3 * threadCpuSeconds(); }

/// Median over `runs` of the work's time (ms): this thread's CPU time, which a machine shared
/// with other jobs inflates less than the wall clock; the median wall time goes to *wallMs.
inline double medianMs(int runs, const std::function<void()>& work, double* wallMs = nullptr) {
  std::vector<double> cpu, wall;
  for (int r = 0; r < runs; ++r) {
    const auto start = std::chrono::steady_clock::now();
    const double startCpu = threadCpuMs();
    work();
    cpu.push_back(threadCpuMs() - startCpu);
    wall.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  if (wallMs) *wallMs = median(wall);
  return median(cpu);
}

inline std::size_t countShellMismatches(const field::Propagation& p, const std::vector<std::int32_t>& exact,
                                        int shell2) {
  std::size_t bad = 0, expected = 0;
  for (std::int32_t d : exact) expected += d <= shell2;
  for (std::size_t k = 0; k < p.shellVoxels.size(); ++k) {
    const std::uint32_t v = p.shellVoxels[k];
    bool ok = p.distance2[v] == exact[v];
    for (std::uint32_t r : p.refsOf(k)) ok = ok && p.dims.distance2(v, r) == exact[v];
    bad += !ok;
  }
  // Voxels of the exact shell that the propagation left out of its shell.
  std::size_t inBoth = 0;
  for (std::uint32_t v : p.shellVoxels) inBoth += exact[v] <= shell2;
  return bad + (expected - inBoth);
}

/// Builds the grid for `mesh` with exactly `dims` (border included) and measures.
inline FieldMeasurement measureField(const mesh::TriMesh& mesh, const std::array<int, 3>& dims, int border,
                                     int shellVoxels, int runs) {
  field::FieldSettings settings;
  settings.dims = dims;
  settings.borderVoxels = border;
  settings.shellVoxels = shellVoxels;
  const field::GridPlacement grid = field::placeGrid(mesh.bounds(), settings, border);
  FieldMeasurement m;
  m.dims = grid.dims;
  field::Voxelization vox;
  m.voxelizeMs = medianMs(1, [&] { vox = field::voxelize(mesh, grid); });
  std::vector<std::uint8_t> surface(vox.flags.size());
  for (std::size_t i = 0; i < surface.size(); ++i) surface[i] = vox.flags[i] & field::kVoxelSurface;
  m.surfaceVoxels = vox.surfaceVoxels.size();
  const int shell2 = shellVoxels * shellVoxels;

  field::Propagation dvdp, dvdp0, paper, exact;
  std::vector<std::int32_t> exact0;
  m.dvdpMs = medianMs(runs, [&] { dvdp = field::propagateDvdp(grid.dims, surface, {shell2}); }, &m.dvdpWallMs);
  m.dvdpDistanceOnlyMs =
      medianMs(runs, [&] { dvdp0 = field::propagateDvdp(grid.dims, surface, {-1}); }, &m.dvdpDistanceOnlyWallMs);
  m.dvdpPaperMs = medianMs(runs, [&] {
    paper = field::propagateDvdp(grid.dims, surface, {shell2, field::DvdpVariant::Paper});
  });
  m.exactMs =
      medianMs(runs, [&] { exact = field::exactFeatureTransform(grid.dims, surface, {shell2}); }, &m.exactWallMs);
  m.exactDistanceOnlyMs =
      medianMs(runs, [&] { exact0 = field::exactDistance2(grid.dims, surface); }, &m.exactDistanceOnlyWallMs);

  m.shellVoxels = exact.shellVoxels.size();
  m.shellMismatches = countShellMismatches(dvdp, exact0, shell2);
  m.paperShellMismatches = countShellMismatches(paper, exact0, shell2);
  double relSum = 0;
  std::size_t beyond = 0;
  for (std::size_t v = 0; v < exact0.size(); ++v) {
    const double e = std::sqrt(static_cast<double>(exact0[v]));
    const double err = std::abs(std::sqrt(static_cast<double>(dvdp.distance2[v])) - e);
    m.maxErrorVoxels = std::max(m.maxErrorVoxels, err);
    m.maxErrorDistanceOnlyVoxels =
        std::max(m.maxErrorDistanceOnlyVoxels, std::abs(std::sqrt(static_cast<double>(dvdp0.distance2[v])) - e));
    m.voxelsWithError += dvdp.distance2[v] != exact0[v];
    const double signedErr = std::sqrt(static_cast<double>(dvdp.distance2[v])) - e;
    m.maxOverestimateVoxels = std::max(m.maxOverestimateVoxels, signedErr);
    m.maxUnderestimateVoxels = std::max(m.maxUnderestimateVoxels, -signedErr);
    if (exact0[v] > shell2) {
      m.maxRelativeErrorBeyondShell = std::max(m.maxRelativeErrorBeyondShell, err / e);
      relSum += err / e;
      ++beyond;
    }
  }
  m.meanRelativeErrorBeyondShell = beyond ? relSum / beyond : 0;
  const field::DistanceField f = field::DistanceField::build(mesh, settings);
  m.bytesPerVoxel = static_cast<double>(f.memoryBytes()) / static_cast<double>(f.voxelCount());
  return m;
}

inline nlohmann::json toJson(const FieldMeasurement& m) {
  return {{"dims", {m.dims.nx, m.dims.ny, m.dims.nz}},
          {"voxels", m.dims.count()},
          {"surface_voxels", m.surfaceVoxels},
          {"voxelize_ms", m.voxelizeMs},
          {"dvdp_ms", m.dvdpMs},
          {"dvdp_distance_only_ms", m.dvdpDistanceOnlyMs},
          {"dvdp_paper_refs_ms", m.dvdpPaperMs},
          {"exact_ms", m.exactMs},
          {"exact_distance_only_ms", m.exactDistanceOnlyMs},
          {"shell_voxels", m.shellVoxels},
          {"shell_mismatches", m.shellMismatches},
          {"paper_shell_mismatches", m.paperShellMismatches},
          {"max_error_voxels", m.maxErrorVoxels},
          {"max_error_distance_only_voxels", m.maxErrorDistanceOnlyVoxels},
          {"voxels_with_error", m.voxelsWithError},
          {"mean_relative_error_beyond_shell", m.meanRelativeErrorBeyondShell},
          {"max_relative_error_beyond_shell", m.maxRelativeErrorBeyondShell},
          {"max_overestimate_voxels", m.maxOverestimateVoxels},
          {"max_underestimate_voxels", m.maxUnderestimateVoxels},
          {"bytes_per_voxel", m.bytesPerVoxel},
          {"timing", "median thread CPU time (ms); *_wall_ms: median wall clock"},
          {"dvdp_wall_ms", m.dvdpWallMs},
          {"dvdp_distance_only_wall_ms", m.dvdpDistanceOnlyWallMs},
          {"exact_wall_ms", m.exactWallMs},
          {"exact_distance_only_wall_ms", m.exactDistanceOnlyWallMs}};
}

}  // namespace drape::cli
