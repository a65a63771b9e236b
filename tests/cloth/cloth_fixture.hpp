#pragma once
// Shared set-up for the cloth tests: a sheet, a model and a solver in a line or two.

#include <concepts>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "drape/cloth/fixture.hpp"
#include "drape/cloth/forces.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/sheets.hpp"
#include "drape/cloth/solver.hpp"
#include "drape/core/error.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::cloth::testing {

inline std::shared_ptr<const ClothModel> makeModel(const mesh::TriMesh& m, const Material& material) {
  return ClothModel::build(m, mesh::Topology::build(m), material);
}

/// A light knit (E = 50 kPa, 0.5 mm, 300 kg/m^3), undamped.
inline Material knit() {
  Material m;
  m.youngsModulus_Pa = 5e4;
  m.thickness_m = 5e-4;
  m.density_kg_m3 = 300;
  return m;
}

/// An isotropic sheet material: Young's modulus E (Pa), thickness t (m), density rho
/// (kg/m^3), Poisson ratio nu; undamped, bending from E t^3 / (12 (1 - nu^2)).
inline Material fabric(double E, double t, double rho, double nu = 0.3) {
  Material m;
  m.youngsModulus_Pa = E;
  m.thickness_m = t;
  m.density_kg_m3 = rho;
  m.poissonRatio = nu;
  return m;
}

/// How far the given vertices hang below their rest places, on average, m.
inline double meanDrop(const ClothModel& model, const ClothState& state, const std::vector<std::uint32_t>& vertices) {
  double drop = 0.0;
  for (const std::uint32_t v : vertices) drop += model.restY()[v] - state.y[v];
  return drop / static_cast<double>(vertices.size());
}

/// The given vertices held where the model's rest shape has them.
inline PinGroup pinAt(const ClothModel& model, std::vector<std::uint32_t> vertices) {
  return PinGroup::atRest(std::move(vertices), model.restX(), model.restY(), model.restZ());
}

/// Vertices of a sheet's grid column i (all j) or row j (all i).
inline std::vector<std::uint32_t> column(const SheetSpec& s, int i) {
  std::vector<std::uint32_t> out;
  for (int j = 0; j <= s.cellsV; ++j) out.push_back(sheetVertex(s, i, j));
  return out;
}
inline std::vector<std::uint32_t> row(const SheetSpec& s, int j) {
  std::vector<std::uint32_t> out;
  for (int i = 0; i <= s.cellsU; ++i) out.push_back(sheetVertex(s, i, j));
  return out;
}

/// `b`'s vertices and triangles appended to `a`'s (two sheets as one mesh, or in the
/// numbering of a layer collider: a garment's own points, then those below it).
inline mesh::TriMesh joinedMeshes(mesh::TriMesh a, const mesh::TriMesh& b) {
  const auto offset = static_cast<std::uint32_t>(a.positions.size());
  a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
  for (mesh::Triangle t : b.triangles) a.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  return a;
}

/// A state with these positions, at rest (no forces or workspace).
inline ClothState stateAt(const std::vector<Vec3>& points) {
  ClothState s;
  for (const Vec3& p : points) {
    s.x.push_back(p.x());
    s.y.push_back(p.y());
    s.z.push_back(p.z());
  }
  s.vx.assign(s.x.size(), 0.0);
  s.vy = s.vz = s.vx;
  return s;
}

/// Runs `steps` substeps; returns false on instability.
inline bool run(ClothSolver& solver, long steps) {
  const double dt = solver.settings().substep_s();
  for (long k = 0; k < steps; ++k)
    if (!solver.substep(static_cast<double>(k) * dt, k / solver.settings().substepsPerFrame + 1,
                        static_cast<int>(k % solver.settings().substepsPerFrame)))
      return false;
  return true;
}

/// Steps frames 1, 2, ... `frames`; the first that goes unstable (1-based), or 0 if none does.
inline long firstUnstableFrame(ClothSolver& solver, long frames) {
  for (long f = 1; f <= frames; ++f)
    if (!solver.stepFrame(f)) return f;
  return 0;
}

/// What settings.validate("--") refuses them with; empty when it accepts them.
inline std::string refusal(const StepSettings& settings) {
  try {
    settings.validate("--");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// What `act` throws drape::Error with; empty when it does not throw.
template <class F>
  requires std::invocable<F>
std::string refusal(F&& act) {
  try {
    std::forward<F>(act)();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// Settings with a given substep (frame rate 30, substeps chosen to give at most dt).
inline StepSettings settingsWithStep(double dt, double air = 0.0, Vec3 gravity = Vec3(0, -9.81, 0)) {
  StepSettings s;
  s.frameRate_hz = 30.0;
  s.substepsPerFrame = static_cast<int>(std::ceil(1.0 / (30.0 * dt)));
  s.airViscosity_Ns_m3 = air;
  s.gravity_m_s2 = gravity;
  return s;
}

}  // namespace drape::cloth::testing
