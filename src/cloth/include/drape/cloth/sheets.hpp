#pragma once
// Rectangular sheets for tests, benchmarks and examples (STYLE habit 12: one scene builder
// shared by all of them). The sheet spans origin + s * sizeU * axisU + t * sizeV * axisV for
// s, t in [0, 1]; vertex (i, j) of the grid has index j * (nu + 1) + i.

#include <cstdint>
#include <string>

#include "drape/mesh/trimesh.hpp"

namespace drape::cloth {

struct SheetSpec {
  double sizeU_m = 1.0, sizeV_m = 1.0;
  int cellsU = 10, cellsV = 10;
  Vec3 origin = Vec3::Zero();
  Vec3 axisU = Vec3::UnitX();
  Vec3 axisV = Vec3::UnitY();
  std::string name = "sheet";
};

/// A regular grid, neighbouring cells split along alternating diagonals (so the mesh has
/// no preferred diagonal direction).
[[nodiscard]] mesh::TriMesh gridSheet(const SheetSpec& spec);

/// An irregular triangulation of the same rectangle: interior vertices jittered by up to
/// `jitter` of a cell and each cell split along a random diagonal (seeded, deterministic).
[[nodiscard]] mesh::TriMesh irregularSheet(const SheetSpec& spec, double jitter = 0.3, std::uint32_t seed = 1);

/// Vertex index of grid point (i, j) of a sheet made by the functions above.
[[nodiscard]] inline std::uint32_t sheetVertex(const SheetSpec& spec, int i, int j) {
  return static_cast<std::uint32_t>(j * (spec.cellsU + 1) + i);
}

}  // namespace drape::cloth
