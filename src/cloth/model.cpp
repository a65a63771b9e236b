#include "drape/cloth/model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <numeric>
#include <optional>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

/// psi = 2 sin(theta / 2) of the hinge (see BendElement), with theta the signed dihedral
/// angle, zero when flat; the same formula the bending kernel evaluates.
double hingePsi(const Vec3& e0, const Vec3& e1, const Vec3& a, const Vec3& b) {
  const Vec3 edge = e1 - e0;
  const Vec3 n1 = (a - e0).cross(a - e1);
  const Vec3 n2 = (b - e1).cross(b - e0);
  const double denom = std::sqrt(n1.squaredNorm() * n2.squaredNorm());
  if (denom <= 0.0) return 0.0;
  const double c = std::clamp(n1.dot(n2) / denom, -1.0, 1.0);
  const double s = n1.cross(n2).dot(edge);
  const double psi = std::sqrt(2.0 * (1.0 - c));
  return s < 0.0 ? -psi : psi;
}

/// The kernel order of a list of elements given their corner indices (N per element): runs
/// (at least kKernelRun elements whose every corner goes up by one from each to the next)
/// first, then the other elements by their lowest corner. Returns the list's indices in kernel
/// order; fills `blocks` (the first element of each block of kKernelRun the kernels take)
/// and `runEnd` (the elements in runs). With `overlap` a run's last block ends where the
/// run does and may overlap the one before; without, what a run leaves over after its whole
/// blocks goes with the other elements.
template <std::size_t N>
std::vector<std::uint32_t> kernelOrder(const std::vector<std::array<std::uint32_t, N>>& corners, bool overlap,
                                       std::vector<std::int32_t>& blocks, std::int32_t& runEnd) {
  // Sorted by the corners' offsets from the first corner, then by the first corner, the
  // elements of a run are neighbours.
  const auto key = [&](std::uint32_t e) {
    std::array<std::int64_t, N> k{};
    for (std::size_t c = 1; c < N; ++c) k[c - 1] = std::int64_t{corners[e][c]} - corners[e][0];
    k[N - 1] = corners[e][0];
    return k;
  };
  std::vector<std::uint32_t> sorted(corners.size());
  std::iota(sorted.begin(), sorted.end(), 0U);
  std::sort(sorted.begin(), sorted.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  const auto continues = [&](std::uint32_t previous, std::uint32_t next) {
    const auto p = key(previous), q = key(next);
    return std::equal(p.begin(), p.end() - 1, q.begin()) && q[N - 1] == p[N - 1] + 1;
  };

  std::vector<std::uint32_t> order;
  std::vector<char> inRun(corners.size(), 0);
  blocks.clear();
  for (std::size_t i = 0; i < sorted.size();) {
    std::size_t j = i + 1;
    while (j < sorted.size() && continues(sorted[j - 1], sorted[j])) ++j;
    const auto length = static_cast<std::int32_t>(j - i);
    if (length >= kKernelRun) {
      const auto first = static_cast<std::int32_t>(order.size());
      const std::int32_t taken = overlap ? length : length / kKernelRun * kKernelRun;
      for (std::int32_t b = 0; b < taken; b += kKernelRun) blocks.push_back(first + std::min(b, taken - kKernelRun));
      for (std::size_t r = i; r < i + static_cast<std::size_t>(taken); ++r) {
        order.push_back(sorted[r]);
        inRun[sorted[r]] = 1;
      }
    }
    i = j;
  }
  runEnd = static_cast<std::int32_t>(order.size());
  const std::size_t rest = order.size();
  for (std::uint32_t e = 0; e < corners.size(); ++e)
    if (!inRun[e]) order.push_back(e);
  // By their lowest corner, so that the pieces the threads take (element ranges) read about
  // the vertices the same threads sum (vertex ranges) where the vertex order keeps neighbours
  // together. The sums do not change: each vertex adds its corners in the list's order.
  const auto lowest = [&](std::uint32_t e) { return *std::min_element(corners[e].begin(), corners[e].end()); };
  std::stable_sort(order.begin() + static_cast<std::ptrdiff_t>(rest), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return lowest(a) < lowest(b); });
  return order;
}

/// Per vertex (CSR: start[v] .. start[v + 1]) the workspace offsets of the elements' corner
/// forces, listed in the elements' order: column c of the element at kernel position p is
/// at 3 c n + p (x; y and z n and 2 n further). columns[j][c] is the vertex of column c of
/// element j; position[j] its kernel position.
template <std::size_t N>
void buildCornerLists(const std::vector<std::array<std::uint32_t, N>>& columns,
                      const std::vector<std::int32_t>& position, std::size_t vertices, std::vector<std::int32_t>& start,
                      std::vector<std::int32_t>& offset) {
  const std::size_t n = columns.size();
  start.assign(vertices + 1, 0);
  for (const std::array<std::uint32_t, N>& element : columns)
    for (const std::uint32_t v : element) ++start[v + 1];
  for (std::size_t v = 0; v < vertices; ++v) start[v + 1] += start[v];
  offset.assign(N * n, 0);
  std::vector<std::int32_t> next(start.begin(), start.end() - 1);
  for (std::size_t j = 0; j < n; ++j)
    for (std::size_t c = 0; c < N; ++c)
      offset[next[columns[j][c]]++] = static_cast<std::int32_t>(3 * c * n) + position[j];
}

/// Blocks of kKernelRun consecutive vertices whose corner lists (CSR `start`, `offset`) run
/// in parallel: as long, each offset one more than the previous vertex's. Along a row of a
/// structured mesh the vertices take their corners from the same runs. Every other vertex
/// with corners goes to `singles`.
void findVertexBlocks(const std::vector<std::int32_t>& start, const std::vector<std::int32_t>& offset,
                      std::vector<std::int32_t>& blocks, std::vector<std::int32_t>& singles) {
  const std::size_t vertices = start.size() - 1;
  const auto parallel = [&](std::size_t v) {
    const std::int32_t count = start[v + 1] - start[v];
    if (count == 0) return false;
    for (std::size_t l = 1; l < kKernelRun; ++l) {
      if (start[v + l + 1] - start[v + l] != count) return false;
      for (std::int32_t k = 0; k < count; ++k)
        if (offset[start[v + l] + k] != offset[start[v] + k] + static_cast<std::int32_t>(l)) return false;
    }
    return true;
  };
  blocks.clear();
  singles.clear();
  for (std::size_t v = 0; v < vertices;) {
    if (v + kKernelRun <= vertices && parallel(v)) {
      blocks.push_back(static_cast<std::int32_t>(v));
      v += kKernelRun;
    } else {
      if (start[v + 1] > start[v]) singles.push_back(static_cast<std::int32_t>(v));
      ++v;
    }
  }
}

}  // namespace

std::shared_ptr<const ClothModel> ClothModel::build(const mesh::TriMesh& mesh, const mesh::Topology& topology,
                                                    const Material& material, const MassScaling& scaling) {
  material.validate("--");
  if (mesh.triangles.empty()) throw Error(fmt::format("{}: the garment has no triangles", mesh.name));
  if (mesh.vertexCount() >= (std::size_t{1} << 31))
    throw Error(fmt::format("{}: more than 2^31 vertices", mesh.name));
  auto model = std::make_shared<ClothModel>(ClothModel());
  model->name_ = mesh.name;
  model->material_ = material;
  model->triangles_ = mesh.triangles;
  model->buildMasses(mesh);
  model->buildMembrane(mesh);
  model->buildBending(mesh, topology);
  model->applyMassScaling(mesh, scaling);
  model->buildEdges(topology);
  model->buildKernelData();
  return model;
}

// Masses: each triangle's rho t A shared equally by its three corners (paper 4.1).
void ClothModel::buildMasses(const mesh::TriMesh& mesh) {
  const std::size_t n = mesh.vertexCount();
  restX_.resize(n);
  restY_.resize(n);
  restZ_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    restX_[i] = mesh.positions[i].x();
    restY_[i] = mesh.positions[i].y();
    restZ_[i] = mesh.positions[i].z();
  }
  mass_.assign(n, 0.0);
  vertexArea_.assign(n, 0.0);
  const double areal = material_.arealDensity();
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const double third = mesh.triangleArea(t) / 3.0;
    for (std::uint32_t v : mesh.triangles[t]) {
      vertexArea_[v] += third;
      mass_[v] += areal * third;
    }
  }
  updateInverseMasses();
}

void ClothModel::updateInverseMasses() {
  inverseMass_.resize(mass_.size());
  totalMass_ = 0.0;
  for (std::size_t i = 0; i < mass_.size(); ++i) {
    inverseMass_[i] = mass_[i] > 0.0 ? 1.0 / mass_[i] : 0.0;
    totalMass_ += mass_[i];
  }
}

// Membrane: rest shape of each triangle in its own plane (u along the first edge), and the
// plane-stress Lame constants times thickness.
void ClothModel::buildMembrane(const mesh::TriMesh& mesh) {
  const double E = material_.youngsModulus_Pa, nu = material_.poissonRatio, t = material_.thickness_m;
  lambdaT_ = E * nu / (1.0 - nu * nu) * t;
  muT_ = E / (2.0 * (1.0 + nu)) * t;
  membrane_.clear();
  membrane_.reserve(mesh.triangleCount());
  minAltitude_ = std::numeric_limits<double>::infinity();
  for (std::size_t tri = 0; tri < mesh.triangleCount(); ++tri) {
    const auto& [i0, i1, i2] = mesh.triangles[tri];
    const Vec3 e1 = mesh.positions[i1] - mesh.positions[i0];
    const Vec3 e2 = mesh.positions[i2] - mesh.positions[i0];
    const Vec3 normal = e1.cross(e2);
    const double twiceArea = normal.norm();
    const double len1 = e1.norm();
    if (!(twiceArea > 0.0) || !(len1 > 0.0))
      throw Error(fmt::format("{}: triangle {} is degenerate (zero area)", mesh.name, tri + 1));
    const Vec3 u = e1 / len1;
    const Vec3 v = (normal / twiceArea).cross(u);
    // Dm = [[a, b], [0, d]] with columns e1, e2 in (u, v) coordinates; g rows of Dm^-1.
    const double a = len1, b = e2.dot(u), d = e2.dot(v);
    // Dm^-1 = [[1/a, -b/(a d)], [0, 1/d]].
    membrane_.push_back({i0, i1, i2, 0, 1.0 / a, -b / (a * d), 0.0, 1.0 / d, 0.5 * twiceArea});
    const double longest = std::max({len1, e2.norm(), (e2 - e1).norm()});
    minAltitude_ = std::min(minAltitude_, twiceArea / longest);
  }
  membraneStep_ = 0.5 * minAltitude_ / membraneWaveSpeed_m_s();
}

// Membrane: explicit CFL bound for one linear triangle (a wave may not cross its smallest
// altitude in one step; the factor 0.5 covers lumped-mass spectra of irregular meshes).
double ClothModel::membraneStableStep(const mesh::TriMesh& mesh, std::size_t tri) const {
  const auto& [i0, i1, i2] = mesh.triangles[tri];
  const Vec3 e1 = mesh.positions[i1] - mesh.positions[i0];
  const Vec3 e2 = mesh.positions[i2] - mesh.positions[i0];
  const double longest = std::max({e1.norm(), e2.norm(), (e2 - e1).norm()});
  return 0.5 * (e1.cross(e2).norm() / longest) / membraneWaveSpeed_m_s();
}

// Mass scaling, element by element as explicit finite-element codes do it: a triangle whose
// own stable step dt is below the target gets its density scaled by (target / dt)^2, which
// slows its membrane wave by target / dt; a vertex whose bending frequency bound is still too
// high for the target then gets the mass that brings it down. Garments modelled for drawing
// have a few sliver triangles (seams, darts) that would otherwise set the step of the whole
// garment; scaling them adds little mass where it changes nothing visible.
void ClothModel::applyMassScaling(const mesh::TriMesh& mesh, const MassScaling& scaling) {
  if (!(scaling.targetStep_s > 0.0)) return;
  const double step = scaling.targetStep_s;
  const double beta = material_.damping_s;
  const bool rungeKutta = scaling.integrator == IntegratorKind::RungeKutta4;
  const double unscaledStep = estimatedStableStep_s();  // for the error message
  const double baseMass = totalMass_;
  const std::vector<double> base = mass_;
  if (rungeKutta) {
    scaleForRungeKutta(mesh, base, step);
  } else {
    scaleMassesFor(mesh, base, step, step);
    // With damping, the measured stiffest mode is what the solver holds the step to.
    if (beta > 0.0) holdMeasuredStep(mesh, base, step, step, stableOmega(scaling.integrator, step, beta));
  }
  addedMass_ = totalMass_ - baseMass;
  massScaledVertices_ = 0;
  for (std::size_t i = 0; i < mass_.size(); ++i) massScaledVertices_ += mass_[i] > base[i] ? 1 : 0;
  if (addedMass_ > scaling.maxAddedFraction * baseMass) {
    double stableStep = unscaledStep;
    if (beta > 0.0 || rungeKutta) {  // the unscaled masses back, for the bound the message names
      freeMembraneOmega_ = 0.0;
      mass_ = base;
      updateInverseMasses();
      const double omega = membraneFrequency_rad_s();
      stableStep = rungeKutta ? rungeKuttaStableStep_s(omega, beta)
                              : std::min(stableStep, dampedStableStep_s(omega, beta));
    }
    const std::string stableAt =
        scaling.frameRate_hz > 0.0
            ? fmt::format("{} substeps per frame",
                          static_cast<long>(std::ceil(1.0 / (scaling.frameRate_hz * stableStep))))
            : fmt::format("a substep of {:.3g} ms", 1e3 * stableStep);
    const std::string damped = beta > 0.0 ? fmt::format(" with internal damping of {:.3g} s", beta) : "";
    const std::string by = rungeKutta ? fmt::format(" for the {} step", integratorName(scaling.integrator)) : "";
    throw Error(fmt::format("{}: keeping the substep of {:.3g} ms stable{}{} needs {:.1f} % more mass on {} of {} "
                            "vertices, more than maxAddedMass {:g} allows; use more substeps per frame (the "
                            "garment is stable without mass scaling at {}) or allow more added mass",
                            name_, 1e3 * step, by, damped, 100.0 * addedMass_ / baseMass, massScaledVertices_,
                            mass_.size(), scaling.maxAddedFraction, stableAt));
  }
}

void ClothModel::scaleMassesFor(const mesh::TriMesh& mesh, const std::vector<double>& base, double membraneTarget_s,
                                double bendingTarget_s) {
  freeMembraneOmega_ = 0.0;
  mass_ = base;
  const double areal = material_.arealDensity();
  membraneStep_ = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const double dt = membraneStableStep(mesh, t);
    if (dt < membraneTarget_s) {
      const double ratio = membraneTarget_s / dt;
      const double added = areal * mesh.triangleArea(t) / 3.0 * (ratio * ratio - 1.0);
      for (std::uint32_t v : mesh.triangles[t]) mass_[v] += added;
    }
    membraneStep_ = std::min(membraneStep_, std::max(dt, membraneTarget_s));
  }
  const double omegaMax = 1.8 / bendingTarget_s;  // bending: symplectic Euler's 2 / omega, with 0.9 of it
  const std::vector<double> rowSum = bendingRowSums(mesh);
  for (std::size_t i = 0; i < mass_.size(); ++i) mass_[i] = std::max(mass_[i], rowSum[i] / (omegaMax * omegaMax));
  updateInverseMasses();
  bendingOmega_ = estimateBendingOmega(mesh);
}

// Internal damping beta shortens symplectic Euler's stable step: a mode of frequency omega
// needs omega^2 dt (dt + 2 beta) < 4, so masses scaled for dt alone can leave the stiffest
// mode too fast; and the Runge-Kutta step's bound is on that mode, which the element
// estimates do not bound. The slivers are then scaled for a longer step, in proportion to how
// much too fast the mode is (a scaled triangle's frequency goes as one over its target),
// measured again, and so on for a few rounds; bending is not damped and keeps its target. A
// mode still too fast after the last round is the solver's to refuse (checkDampedStep,
// checkRungeKuttaStep), with the way out in its message.
void ClothModel::holdMeasuredStep(const mesh::TriMesh& mesh, const std::vector<double>& base, double membraneTarget_s,
                                  double bendingTarget_s, double allowedOmega) {
  constexpr int kRounds = 4;
  constexpr double kOvershoot = 1.02;  // the next round aims a little past the bound
  double membraneTarget = membraneTarget_s;
  for (int round = 0; round < kRounds; ++round) {
    const double omega = membraneFrequency_rad_s();
    if (omega <= allowedOmega) {
      freeMembraneOmega_ = omega;  // the masses are final: the substep search asks again
      return;
    }
    membraneTarget *= kOvershoot * omega / allowedOmega;
    scaleMassesFor(mesh, base, membraneTarget, bendingTarget_s);
  }
}

// Where the unscaled membrane's measured stiffest mode keeps the Runge-Kutta step's bound,
// nothing is added: the element estimates would add mass to slivers that do not need it.
// Otherwise the element estimates are symplectic Euler's; undamped, the Runge-Kutta step
// reaches sqrt(2) times as far on every mode, so the triangles and hinges are scaled for that
// shorter step, and then, as for the damped symplectic step, the measured stiffest mode is
// held to the step's own bound (the element estimates do not bound it, and damping moves the
// bound). The estimates are cautious on slivers, and that caution is kept on purpose: scaling
// only until the mode measured at rest keeps the bound left the walking dress's slivers light
// enough to diverge where the walk stretches them (frames computed again at every count from
// 66 to 108; docs/PERFORMANCE.md, "Mass scaling for the Runge-Kutta step").
void ClothModel::scaleForRungeKutta(const mesh::TriMesh& mesh, const std::vector<double>& base, double step_s) {
  const double allowed = stableOmega(IntegratorKind::RungeKutta4, step_s, material_.damping_s);
  if (const double unscaled = membraneFrequency_rad_s(); unscaled <= allowed) {
    freeMembraneOmega_ = unscaled;  // the masses are final
    return;
  }
  const double elementStep = step_s / std::sqrt(2.0);
  scaleMassesFor(mesh, base, elementStep, elementStep);
  holdMeasuredStep(mesh, base, elementStep, elementStep, allowed);
}

double undampedEquivalentStep_s(double step_s, double damping_s) {
  return std::sqrt(step_s * (step_s + 2.0 * std::max(damping_s, 0.0)));
}

// Bending: one hinge per interior edge; k = 2 C D |e|^2 / (A1 + A2) from the rest geometry.
void ClothModel::buildBending(const mesh::TriMesh& mesh, const mesh::Topology& topology) {
  const double D = material_.bendingModulus();
  bending_.clear();
  bending_.reserve(topology.interiorEdgeCount());
  for (const mesh::Edge& e : topology.edges) {
    if (e.boundary()) continue;
    const Vec3& x0 = mesh.positions[e.v0];
    const Vec3& x1 = mesh.positions[e.v1];
    const Vec3& xa = mesh.positions[e.opposite0];
    const Vec3& xb = mesh.positions[e.opposite1];
    const double areas = mesh.triangleArea(e.face0) + mesh.triangleArea(e.face1);
    if (!(areas > 0.0)) continue;
    const double k = 2.0 * kBendCoefficient * D * (x1 - x0).squaredNorm() / areas;
    bending_.push_back({e.v0, e.v1, e.opposite0, e.opposite1, hingePsi(x0, x1, xa, xb), k});
  }
  bendingOmega_ = estimateBendingOmega(mesh);
}

// Highest bending frequency, from a Gershgorin bound on M^-1 K at rest: each hinge adds
// k |g_i| |g_j| to row i (g = dtheta/dx at rest, the Bridson vectors).
double ClothModel::estimateBendingOmega(const mesh::TriMesh& mesh) const {
  const std::vector<double> rowSum = bendingRowSums(mesh);
  double omega2 = 0.0;
  for (std::size_t i = 0; i < rowSum.size(); ++i) omega2 = std::max(omega2, rowSum[i] * inverseMass_[i]);
  return std::sqrt(omega2);
}

std::vector<double> ClothModel::bendingRowSums(const mesh::TriMesh& mesh) const {
  std::vector<double> rowSum(vertexCount(), 0.0);
  for (const BendElement& h : bending_) {
    const Vec3 &x3 = mesh.positions[h.e0], &x4 = mesh.positions[h.e1];
    const Vec3 &x1 = mesh.positions[h.a], &x2 = mesh.positions[h.b];
    const Vec3 e = x4 - x3;
    const Vec3 n1 = (x1 - x3).cross(x1 - x4), n2 = (x2 - x4).cross(x2 - x3);
    const double el = e.norm();
    if (!(n1.squaredNorm() > 0.0) || !(n2.squaredNorm() > 0.0) || !(el > 0.0)) continue;
    const Vec3 a1 = n1 / n1.squaredNorm(), a2 = n2 / n2.squaredNorm();
    const std::array<double, 4> g = {(a1 * el).norm(), (a2 * el).norm(),
                                     (a1 * (x1 - x4).dot(e) / el + a2 * (x2 - x4).dot(e) / el).norm(),
                                     (a1 * (x1 - x3).dot(e) / el + a2 * (x2 - x3).dot(e) / el).norm()};
    const double total = g[0] + g[1] + g[2] + g[3];
    const std::array<std::uint32_t, 4> v = {h.a, h.b, h.e0, h.e1};
    for (int i = 0; i < 4; ++i) rowSum[v[i]] += h.stiffness_Nm * g[i] * total;
  }
  return rowSum;
}

void ClothModel::buildEdges(const mesh::Topology& topology) {
  edgeV0_.clear();
  edgeV1_.clear();
  edgeRest_.clear();
  for (const mesh::Edge& e : topology.edges) {
    const Vec3 d(restX_[e.v1] - restX_[e.v0], restY_[e.v1] - restY_[e.v0], restZ_[e.v1] - restZ_[e.v0]);
    edgeV0_.push_back(e.v0);
    edgeV1_.push_back(e.v1);
    edgeRest_.push_back(d.norm());
  }
}

// The element lists as structure of arrays for the kernels (gathers vectorise; AoS would
// not), runs first.
void ClothModel::buildKernelData() {
  MembraneArrays& m = membraneArrays_;
  std::vector<std::array<std::uint32_t, 3>> triangleCorners;
  for (const MembraneElement& el : membrane_) triangleCorners.push_back({el.v0, el.v1, el.v2});
  const std::vector<std::uint32_t> triangleOrder = kernelOrder(triangleCorners, true, m.runBlocks, m.runEnd);
  const std::size_t n = membrane_.size();
  std::vector<std::int32_t> position(n);
  for (std::size_t t = 0; t < n; ++t) {
    const MembraneElement& el = membrane_[triangleOrder[t]];
    position[triangleOrder[t]] = static_cast<std::int32_t>(t);
    m.v0.push_back(static_cast<std::int32_t>(el.v0));
    m.v1.push_back(static_cast<std::int32_t>(el.v1));
    m.v2.push_back(static_cast<std::int32_t>(el.v2));
    m.g1u.push_back(el.g1u);
    m.g1v.push_back(el.g1v);
    m.g2u.push_back(el.g2u);
    m.g2v.push_back(el.g2v);
    m.area.push_back(el.restArea_m2);
  }
  // Corner incidences per vertex, in the order of membrane_ (a fixed summation order).
  buildCornerLists(triangleCorners, position, vertexCount(), m.cornerStart, m.cornerOffset);
  findVertexBlocks(m.cornerStart, m.cornerOffset, m.vertexBlocks, m.singleVertices);

  BendArrays& b = bendArrays_;
  // In the order of the workspace columns fa, fb, fe0, fe1 (forces.cpp).
  std::vector<std::array<std::uint32_t, 4>> hingeCorners;
  for (const BendElement& h : bending_) hingeCorners.push_back({h.a, h.b, h.e0, h.e1});
  const std::vector<std::uint32_t> hingeOrder = kernelOrder(hingeCorners, false, b.runBlocks, b.runEnd);
  const std::size_t hinges = bending_.size();
  std::vector<std::int32_t> hingePosition(hinges);
  for (std::size_t i = 0; i < hinges; ++i) {
    const BendElement& h = bending_[hingeOrder[i]];
    hingePosition[hingeOrder[i]] = static_cast<std::int32_t>(i);
    b.e0.push_back(static_cast<std::int32_t>(h.e0));
    b.e1.push_back(static_cast<std::int32_t>(h.e1));
    b.a.push_back(static_cast<std::int32_t>(h.a));
    b.b.push_back(static_cast<std::int32_t>(h.b));
    b.restPsi.push_back(h.restPsi);
    b.stiffness.push_back(h.stiffness_Nm);
  }
  buildCornerLists(hingeCorners, hingePosition, vertexCount(), b.cornerStart, b.cornerOffset);
}

double ClothModel::membraneWaveSpeed_m_s() const {
  const double nu = material_.poissonRatio;
  return std::sqrt(material_.youngsModulus_Pa / (material_.density_kg_m3 * (1.0 - nu * nu)));
}

double ClothModel::estimatedStableStep_s() const {
  // Membrane: see membraneStableStep. Bending: symplectic Euler needs dt < 2 / omega_max;
  // 0.9 of that.
  const double membrane = membraneStep_;
  const double bending = bendingOmega_ > 0.0 ? 1.8 / bendingOmega_ : membrane;
  return std::min(membrane, bending);
}

void ClothModel::membraneStiffnessTimes(std::span<const double> u, std::span<double> out) const {
  std::fill(out.begin(), out.end(), 0.0);
  const auto at = [&](std::uint32_t i) { return Vec3(u[3 * i], u[3 * i + 1], u[3 * i + 2]); };
  const auto rest = [&](std::uint32_t i) { return Vec3(restX_[i], restY_[i], restZ_[i]); };
  for (const MembraneElement& el : membrane_) {
    // At rest F maps the rest plane onto the triangle's tangents (fu, fv) and S = 0, so a
    // displacement's force is that of its stress alone: dE = sym(F^T dF), dS = lambda_t
    // tr(dE) I + 2 mu_t dE, df_i = -A F dS grad(N_i) (the kernel's formula with S -> dS).
    const Vec3 d1 = rest(el.v1) - rest(el.v0), d2 = rest(el.v2) - rest(el.v0);
    const Vec3 fu = d1 * el.g1u + d2 * el.g2u, fv = d1 * el.g1v + d2 * el.g2v;
    const Vec3 w1 = at(el.v1) - at(el.v0), w2 = at(el.v2) - at(el.v0);
    const Vec3 du = w1 * el.g1u + w2 * el.g2u, dv = w1 * el.g1v + w2 * el.g2v;
    const double e11 = fu.dot(du), e22 = fv.dot(dv), e12 = 0.5 * (fu.dot(dv) + fv.dot(du));
    const double tr = lambdaT_ * (e11 + e22);
    const double sa = tr + 2.0 * muT_ * e11, sb = tr + 2.0 * muT_ * e22, sc = 2.0 * muT_ * e12;
    const double A = el.restArea_m2;
    const Vec3 f1 = -A * ((sa * el.g1u + sc * el.g1v) * fu + (sc * el.g1u + sb * el.g1v) * fv);
    const Vec3 f2 = -A * ((sa * el.g2u + sc * el.g2v) * fu + (sc * el.g2u + sb * el.g2v) * fv);
    const std::array<std::pair<std::uint32_t, Vec3>, 3> corners = {{{el.v0, -(f1 + f2)}, {el.v1, f1}, {el.v2, f2}}};
    for (const auto& [v, f] : corners)
      for (int a = 0; a < 3; ++a) out[3 * v + static_cast<std::size_t>(a)] -= f[a];  // K u = -df
  }
}

// Power iteration on M^-1/2 K M^-1/2 (symmetric, so the Rayleigh quotient converges fast and
// from below) from a fixed pseudo-random start, until the quotient moves less than 1e-6
// (relative) over 20 iterations. Fixed vertices are left out: their rows and columns are
// zero, as if their mass were infinite.
double ClothModel::membraneFrequency_rad_s(std::span<const std::uint8_t> fixed) const {
  if (fixed.empty() && freeMembraneOmega_ > 0.0) return freeMembraneOmega_;
  const std::size_t n = 3 * vertexCount();
  std::vector<double> weight(n), q(n), kq(n), scaled(n);
  for (std::size_t i = 0; i < n; ++i) {
    const bool held = !fixed.empty() && fixed[i / 3];
    weight[i] = held ? 0.0 : std::sqrt(inverseMass_[i / 3]);
  }
  std::uint64_t seed = 0x9E3779B97F4A7C15ULL;
  for (std::size_t i = 0; i < n; ++i) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    q[i] = weight[i] * (static_cast<double>(seed >> 11) / static_cast<double>(1ULL << 53) - 0.5);
  }
  const auto normalise = [](std::vector<double>& x) {
    double s = 0.0;
    for (const double e : x) s += e * e;
    const double inv = s > 0.0 ? 1.0 / std::sqrt(s) : 0.0;
    for (double& e : x) e *= inv;
  };
  normalise(q);
  double lambda = 0.0, checkpoint = 0.0;
  for (int it = 1; it <= kMaxPowerIterations; ++it) {
    for (std::size_t i = 0; i < n; ++i) scaled[i] = q[i] * weight[i];
    membraneStiffnessTimes(scaled, kq);
    lambda = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      kq[i] *= weight[i];
      lambda += q[i] * kq[i];
    }
    q.swap(kq);
    normalise(q);
    if (it % 20 == 0) {
      if (std::abs(lambda - checkpoint) <= 1e-6 * lambda) break;
      checkpoint = lambda;
    }
  }
  return std::sqrt(std::max(lambda, 0.0));
}

double dampedStableStep_s(double omega_rad_s, double damping_s) {
  if (!(omega_rad_s > 0.0)) return std::numeric_limits<double>::infinity();
  const double w = omega_rad_s / kDampedStepMargin;
  return std::sqrt(damping_s * damping_s + 4.0 / (w * w)) - damping_s;
}

namespace {

/// |R(z)| for the classical Runge-Kutta step's stability polynomial.
double rungeKuttaGain(std::complex<double> z) {
  return std::abs(1.0 + z * (1.0 + z * (0.5 + z * (1.0 / 6.0 + z / 24.0))));
}

/// The first s > 0 at which |R(s d)| exceeds 1 along the ray of direction d (|d| = 1, in the
/// left half-plane): scanned in steps of 0.01, then bisected.
double rungeKuttaReach(std::complex<double> d) {
  double inside = 0.0;
  double outside = 0.0;
  for (double s = 0.01; s < 10.0; s += 0.01) {
    if (rungeKuttaGain(s * d) > 1.0) {
      outside = s;
      break;
    }
    inside = s;
  }
  if (outside == 0.0) return 10.0;
  for (int k = 0; k < 50; ++k) {
    const double mid = 0.5 * (inside + outside);
    (rungeKuttaGain(mid * d) > 1.0 ? outside : inside) = mid;
  }
  return inside;
}

}  // namespace

double rungeKuttaStableStep_s(double omega_rad_s, double damping_s) {
  if (!(omega_rad_s > 0.0)) return std::numeric_limits<double>::infinity();
  const double w = omega_rad_s / kDampedStepMargin;
  const double zeta = 0.5 * damping_s * w;
  if (zeta < 1.0)  // a complex pair of magnitude w
    return rungeKuttaReach(std::complex<double>(-zeta, std::sqrt(1.0 - zeta * zeta))) / w;
  // Two real eigenvalues; the larger in magnitude bounds the step.
  const double largest = w * (zeta + std::sqrt(zeta * zeta - 1.0));
  return rungeKuttaReach(std::complex<double>(-1.0, 0.0)) / largest;
}

double stableOmega(IntegratorKind integrator, double step_s, double damping_s) {
  if (integrator != IntegratorKind::RungeKutta4)
    return 2.0 * kDampedStepMargin / undampedEquivalentStep_s(step_s, damping_s);
  // The Runge-Kutta bound falls as the frequency rises (zeta rises with it, and past zeta = 1
  // the larger real eigenvalue grows faster than omega): bisection on omega.
  double below = 0.0;
  double above = 2.0 * std::sqrt(2.0) / step_s;  // the undamped bound, without the margin
  while (rungeKuttaStableStep_s(above, damping_s) >= step_s) above *= 2.0;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (below + above);
    (rungeKuttaStableStep_s(mid, damping_s) >= step_s ? below : above) = mid;
  }
  return below;
}

int rungeKuttaSubsteps(const ClothModel& model, double frameRate_hz) {
  const double most = rungeKuttaStableStep_s(model.membraneFrequency_rad_s(), model.material().damping_s);
  return std::clamp(static_cast<int>(std::ceil(1.0 / (frameRate_hz * most))), 1, 100000);
}

double largestStableDamping_s(double omega_rad_s, double step_s) {
  if (!(omega_rad_s > 0.0)) return std::numeric_limits<double>::infinity();
  const double w = omega_rad_s / kDampedStepMargin;
  return (4.0 / (w * w) - step_s * step_s) / (2.0 * step_s);
}

ForwardEulerDampingWindow forwardEulerDampingWindow(double omega_rad_s, double step_s) {
  if (!(omega_rad_s > 0.0)) return {step_s, std::numeric_limits<double>::infinity()};
  const double w = omega_rad_s / kDampedStepMargin;
  return {step_s, 0.5 * step_s + 2.0 / (w * w * step_s)};
}

double ClothModel::bendingStableStep_s() const {
  return bendingOmega_ > 0.0 ? 1.8 / bendingOmega_ : std::numeric_limits<double>::infinity();
}

int suggestedBendEvery(const ClothModel& model, double substep_s) {
  const double span = 0.1 * model.bendingStableStep_s() / substep_s;
  return std::clamp(static_cast<int>(std::min(span, 8.0)), 1, 8);
}

double addedMassFractionAt(const mesh::TriMesh& mesh, const mesh::Topology& topology, const Material& material,
                           double frameRate_hz, int substepsPerFrame, IntegratorKind integrator) {
  // An unbounded allowance: the model reports the mass it needs instead of refusing.
  const MassScaling scaling{1.0 / (frameRate_hz * substepsPerFrame), std::numeric_limits<double>::infinity(), 0.0,
                            integrator};
  return ClothModel::build(mesh, topology, material, scaling)->addedMassFraction();
}

SubstepChoice fewestStableSubsteps(const mesh::TriMesh& mesh, const mesh::Topology& topology,
                                   const Material& material, double frameRate_hz, double maxAddedFraction,
                                   int least, IntegratorKind integrator) {
  constexpr int kMost = 100000;
  const double beta = material.damping_s;
  const bool rungeKutta = integrator == IntegratorKind::RungeKutta4;
  const bool measured = beta > 0.0 || rungeKutta;  // the stiffest mode's bound is checked
  // The step a model allows: symplectic Euler's wave-speed estimate, and with internal damping
  // the bound of the membrane's highest frequency; the Runge-Kutta step's bound on that
  // frequency (every vertex free: the garment's pins are not known here).
  const auto allowedStep = [&](const ClothModel& model) {
    if (rungeKutta) return rungeKuttaStableStep_s(model.membraneFrequency_rad_s(), beta);
    const double step = model.estimatedStableStep_s();
    return beta > 0.0 ? std::min(step, dampedStableStep_s(model.membraneFrequency_rad_s(), beta)) : step;
  };
  const double unscaledStep = allowedStep(*ClothModel::build(mesh, topology, material));
  const double unscaled = std::ceil(1.0 / (frameRate_hz * unscaledStep));
  if (!(unscaled <= kMost))
    throw Error(fmt::format("garment '{}': no substep count up to {} is stable at {:g} frames/s", mesh.name, kMost,
                            frameRate_hz));
  const int none = std::max(least, static_cast<int>(unscaled));  // needs no mass scaling
  if (!(maxAddedFraction > 0.0)) return {none, 0.0};
  // The mass a count needs, or nothing when it needs more than allowed or the damping
  // forbids it.
  const auto scaledAt = [&](int n) -> std::optional<double> {
    const double step = 1.0 / (frameRate_hz * n);
    // An unbounded allowance: the model reports the mass it needs instead of refusing.
    const auto model =
        ClothModel::build(mesh, topology, material, {step, std::numeric_limits<double>::infinity(), 0.0, integrator});
    const double added = model->addedMassFraction();
    if (added <= maxAddedFraction && (!measured || step <= allowedStep(*model))) return added;
    return std::nullopt;
  };
  // Between a failing count and a passing one (its mass `added`), the fewest that passes:
  // more substeps never need more mass.
  const auto narrowed = [&](int failing, int passing, double added) -> SubstepChoice {
    while (passing - failing > 1) {
      const int mid = failing + (passing - failing) / 2;
      if (const std::optional<double> a = scaledAt(mid)) {
        passing = mid;
        added = *a;
      } else {
        failing = mid;
      }
    }
    return {passing, added};
  };
  // A ladder of 5 % rungs up to the first count that passes, then bisection between it and
  // the rung below.
  const auto nextRung = [](int n) { return std::max(n + 1, static_cast<int>(std::ceil(n * 1.05))); };
  int failing = std::max(1, least) - 1;
  int n = std::max(1, least);
  // Every Runge-Kutta model measures its stiffest mode (a power iteration), and the counts
  // far below the unscaled one need far more mass than any allowance: bisection from the
  // unscaled count down, about log2 of it models, instead of the ladder.
  if (rungeKutta && n < none) return narrowed(failing, none, 0.0);
  if (beta > 0.0 && !rungeKutta) {
    // Damping only adds mass (ClothModel::holdMeasuredStep, a power iteration per model): the
    // rungs that the undamped masses already put over the allowance are passed over first,
    // on models that need none.
    Material undamped = material;
    undamped.damping_s = 0.0;
    for (; n < none; n = nextRung(n)) {
      const auto model = ClothModel::build(mesh, topology, undamped,
                                           {1.0 / (frameRate_hz * n), std::numeric_limits<double>::infinity()});
      if (model->addedMassFraction() <= maxAddedFraction) break;
      failing = n;
    }
  }
  for (; n < none; n = nextRung(n)) {
    if (const std::optional<double> added = scaledAt(n)) return narrowed(failing, n, *added);
    failing = n;
  }
  return {none, 0.0};
}

}  // namespace drape::cloth
