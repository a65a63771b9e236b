#include "drape/cloth/sheets.hpp"

#include <random>

namespace drape::cloth {
namespace {

mesh::TriMesh sheet(const SheetSpec& spec, double jitter, std::uint32_t seed, bool randomDiagonals) {
  mesh::TriMesh m;
  m.name = spec.name;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double du = spec.sizeU_m / spec.cellsU, dv = spec.sizeV_m / spec.cellsV;
  for (int j = 0; j <= spec.cellsV; ++j) {
    for (int i = 0; i <= spec.cellsU; ++i) {
      double s = i * du, t = j * dv;
      const bool interior = i > 0 && i < spec.cellsU && j > 0 && j < spec.cellsV;
      if (interior && jitter > 0.0) {
        s += jitter * du * unit(rng);
        t += jitter * dv * unit(rng);
      }
      m.positions.push_back(spec.origin + s * spec.axisU + t * spec.axisV);
    }
  }
  std::bernoulli_distribution coin(0.5);
  for (int j = 0; j < spec.cellsV; ++j) {
    for (int i = 0; i < spec.cellsU; ++i) {
      const std::uint32_t a = sheetVertex(spec, i, j), b = sheetVertex(spec, i + 1, j);
      const std::uint32_t c = sheetVertex(spec, i + 1, j + 1), d = sheetVertex(spec, i, j + 1);
      const bool flip = randomDiagonals ? coin(rng) : ((i + j) % 2 == 1);
      if (!flip) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      } else {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, c, d});
      }
    }
  }
  return m;
}

}  // namespace

mesh::TriMesh gridSheet(const SheetSpec& spec) { return sheet(spec, 0.0, 0, false); }

mesh::TriMesh irregularSheet(const SheetSpec& spec, double jitter, std::uint32_t seed) {
  return sheet(spec, jitter, seed, true);
}

}  // namespace drape::cloth
