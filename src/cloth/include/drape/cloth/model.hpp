#pragma once
// ClothModel: what a garment is (STYLE habit 1). Built once from a mesh, its topology and a
// Material by explicit Build passes (habit 4); immutable afterwards and shared by every
// instance of the garment (several characters wearing the same dress share one model).
//
// Membrane: one constant-strain triangle (CST) per face, St Venant-Kirchhoff in plane
// stress, so stiffness follows from E, nu, t and each triangle's own rest shape (no per-edge
// spring constants). Bending: one hinge per interior edge, a dihedral-angle energy whose
// stiffness follows from the bending modulus D and the rest geometry of the hinge. See
// docs/PHYSICS.md for the derivations.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "drape/cloth/material.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::cloth {

/// One membrane triangle (56 bytes). Filled by buildMembrane.
///   F = (x1 - x0) (x) g1 + (x2 - x0) (x) g2   (3x2 deformation gradient)
/// where g1, g2 are the rows of the inverse rest shape matrix in the triangle's rest plane.
struct MembraneElement {
  std::uint32_t v0, v1, v2;  ///< vertex indices
  std::uint32_t pad = 0;
  double g1u, g1v;           ///< gradient of the barycentric weight of v1 in rest-plane coords, 1/m
  double g2u, g2v;           ///< gradient of the barycentric weight of v2, 1/m
  double restArea_m2;        ///< rest area, m^2
};

/// One bending hinge (48 bytes). Filled by buildBending. The orientation is edge-local:
///
///          a                 N1 = (a - e0) x (a - e1)
///         / \                N2 = (b - e1) x (b - e0)
///       e0---e1              so the hinge is consistent however the two faces are wound.
///         \ /
///          b
struct BendElement {
  std::uint32_t e0, e1;  ///< the shared edge
  std::uint32_t a, b;    ///< the vertices opposite it
  double restPsi;        ///< rest value of psi = 2 sin(theta / 2) (theta: signed dihedral angle)
  double stiffness_Nm;   ///< k in W = k / 2 (psi - restPsi)^2, N m
};

/// The kernel lists begin with runs: at least kKernelRun elements whose every corner index
/// goes up by one from one element to the next (rows of a structured mesh: a generated
/// skirt, a grid). The kernels load their vertices as vectors instead of gathering them one
/// coordinate at a time, in blocks of kKernelRun elements (a vector of doubles on AVX-512).
/// The membrane's last block of a run ends where the run does and may overlap the one
/// before (computing some elements twice, to the same values), so that a row's triangles
/// lie together and its vertices' sums can go as vectors too; the hinges take whole blocks
/// only, and what a run leaves over goes with the other hinges.
inline constexpr std::int32_t kKernelRun = 8;

/// The membrane elements again as structure of arrays, what the vectorised kernel reads
/// (filled by buildKernelData from the MembraneElement list). The runs come first
/// (elements [0, runEnd), taken in the blocks that start at `runBlocks`); the other
/// elements follow by their lowest corner (the threads' pieces, docs/PERFORMANCE.md). Indices are signed 32-bit because that is what
/// vector gather instructions take.
struct MembraneArrays {
  std::vector<std::int32_t> v0, v1, v2;
  std::vector<double> g1u, g1v, g2u, g2v, area;
  std::vector<std::int32_t> runBlocks;
  std::int32_t runEnd = 0;
  /// Per vertex (CSR: cornerStart[v] .. cornerStart[v + 1]) the offsets of its corner
  /// forces in the kernel workspace (corner c of kernel element t at 3 c n + t, x; y and z
  /// n and 2 n further): the forces are summed per vertex, loads only, instead of
  /// scattered, in the order of membrane(), so that the sums do not depend on the runs.
  std::vector<std::int32_t> cornerStart, cornerOffset;
  /// The first vertices of blocks of kKernelRun consecutive vertices whose corner lists run
  /// in parallel (as long, each offset one more than the previous vertex's): summed as
  /// vectors. The other vertices with corners are `singleVertices`.
  std::vector<std::int32_t> vertexBlocks, singleVertices;
};

/// The bending hinges as structure of arrays (buildKernelData), runs first as in
/// MembraneArrays.
struct BendArrays {
  std::vector<std::int32_t> e0, e1, a, b;
  std::vector<double> restPsi, stiffness;
  std::vector<std::int32_t> runBlocks;
  std::int32_t runEnd = 0;
  /// Per vertex (CSR) the offsets of its hinge forces in the kernel workspace (corner c =
  /// a, b, e0, e1 of kernel hinge i at 3 c n + i, x; y and z n and 2 n further), in the
  /// order of bending(): summed per vertex, loads only.
  std::vector<std::int32_t> cornerStart, cornerOffset;
};

class ClothModel {
 public:
  /// Builds the model. Throws drape::Error naming mesh.name on an invalid material or a
  /// mesh with no triangles. `topology` must be mesh::Topology::build(mesh).
  [[nodiscard]] static std::shared_ptr<const ClothModel> build(const mesh::TriMesh& mesh,
                                                               const mesh::Topology& topology,
                                                               const Material& material,
                                                               const MassScaling& scaling = {});

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] const Material& material() const { return material_; }
  [[nodiscard]] std::size_t vertexCount() const { return restX_.size(); }
  [[nodiscard]] std::size_t triangleCount() const { return triangles_.size(); }

  // Rest positions (SoA), m.
  [[nodiscard]] const std::vector<double>& restX() const { return restX_; }
  [[nodiscard]] const std::vector<double>& restY() const { return restY_; }
  [[nodiscard]] const std::vector<double>& restZ() const { return restZ_; }
  /// Lumped vertex masses, kg (a third of each adjacent triangle's rho t A).
  [[nodiscard]] const std::vector<double>& mass() const { return mass_; }
  /// 1 / mass, 1/kg; 0 for vertices no triangle uses (they only feel gravity).
  [[nodiscard]] const std::vector<double>& inverseMass() const { return inverseMass_; }
  /// Vertex areas (a third of each adjacent triangle's area), m^2: the drag area.
  [[nodiscard]] const std::vector<double>& vertexArea() const { return vertexArea_; }
  [[nodiscard]] double totalMass_kg() const { return totalMass_; }

  [[nodiscard]] const std::vector<MembraneElement>& membrane() const { return membrane_; }
  [[nodiscard]] const std::vector<BendElement>& bending() const { return bending_; }
  [[nodiscard]] const MembraneArrays& membraneArrays() const { return membraneArrays_; }
  [[nodiscard]] const BendArrays& bendArrays() const { return bendArrays_; }
  /// Plane-stress Lame constants times thickness (membrane stiffnesses), N/m.
  [[nodiscard]] double lambdaT() const { return lambdaT_; }
  [[nodiscard]] double muT() const { return muT_; }

  /// Edges (for strain statistics): endpoints and rest lengths, m.
  [[nodiscard]] const std::vector<std::uint32_t>& edgeV0() const { return edgeV0_; }
  [[nodiscard]] const std::vector<std::uint32_t>& edgeV1() const { return edgeV1_; }
  [[nodiscard]] const std::vector<double>& edgeRestLength() const { return edgeRest_; }
  /// Triangles as loaded (for writing frames).
  [[nodiscard]] const std::vector<mesh::Triangle>& triangles() const { return triangles_; }

  /// Smallest altitude over all triangles, m: the length that limits the explicit step.
  [[nodiscard]] double minAltitude_m() const { return minAltitude_; }
  /// Membrane wave speed sqrt(E / (rho (1 - nu^2))), m/s.
  [[nodiscard]] double membraneWaveSpeed_m_s() const;
  /// A conservative estimate of the largest stable substep of the explicit integrators, s
  /// (with the masses as scaled).
  [[nodiscard]] double estimatedStableStep_s() const;
  /// The same for the bending forces alone (infinite without hinges), s: the longest step
  /// the multiple-time-stepping bending impulse (StepSettings::bendEvery) may span.
  [[nodiscard]] double bendingStableStep_s() const;
  /// The membrane's highest angular frequency, rad/s: the square root of the largest
  /// eigenvalue of M^-1 K, with K the membrane's stiffness linearised at rest (compression
  /// unsoftened) and the masses as scaled; vertices flagged in `fixed` (one flag per vertex,
  /// or empty) held still. By power iteration: about 20 ms for 4,000 triangles. With
  /// internal damping this frequency, not the wave speed, bounds the explicit step
  /// (dampedStableStep_s). With every vertex free, the value mass scaling measured on the
  /// final masses (with damping) is returned without iterating again.
  [[nodiscard]] double membraneFrequency_rad_s(std::span<const std::uint8_t> fixed = {}) const;
  /// K u for the membrane linearised at rest; u and out hold x, y, z per vertex (3 n values).
  void membraneStiffnessTimes(std::span<const double> u, std::span<double> out) const;
  /// Mass added by mass scaling, kg, and the number of vertices that received some.
  [[nodiscard]] double addedMass_kg() const { return addedMass_; }
  /// The added mass as a fraction of the garment's own (unscaled) mass.
  [[nodiscard]] double addedMassFraction() const { return addedMass_ / (totalMass_ - addedMass_); }
  [[nodiscard]] std::size_t massScaledVertexCount() const { return massScaledVertices_; }

 private:
  void buildMasses(const mesh::TriMesh& mesh);
  void buildMembrane(const mesh::TriMesh& mesh);
  void buildBending(const mesh::TriMesh& mesh, const mesh::Topology& topology);
  void buildEdges(const mesh::Topology& topology);
  void buildKernelData();
  void applyMassScaling(const mesh::TriMesh& mesh, const MassScaling& scaling);
  /// Masses from `base`: triangles scaled for a membrane step of membraneTarget_s, vertices
  /// topped up for a bending step of bendingTarget_s.
  void scaleMassesFor(const mesh::TriMesh& mesh, const std::vector<double>& base, double membraneTarget_s,
                      double bendingTarget_s);
  /// Scales the slivers further, from masses scaled for membraneTarget_s, until the
  /// membrane's measured stiffest mode (every vertex free) is at most allowedOmega.
  void holdMeasuredStep(const mesh::TriMesh& mesh, const std::vector<double>& base, double membraneTarget_s,
                        double bendingTarget_s, double allowedOmega);
  /// Masses for the Runge-Kutta step at step_s: its bound on the measured stiffest mode (none
  /// added where the unscaled mode keeps it).
  void scaleForRungeKutta(const mesh::TriMesh& mesh, const std::vector<double>& base, double step_s);
  void updateInverseMasses();
  [[nodiscard]] std::vector<double> bendingRowSums(const mesh::TriMesh& mesh) const;
  [[nodiscard]] double estimateBendingOmega(const mesh::TriMesh& mesh) const;
  [[nodiscard]] double membraneStableStep(const mesh::TriMesh& mesh, std::size_t tri) const;

  static constexpr int kMaxPowerIterations = 5000;

  std::string name_;
  Material material_;
  std::vector<double> restX_, restY_, restZ_;
  std::vector<double> mass_, inverseMass_, vertexArea_;
  double totalMass_ = 0.0;
  std::vector<MembraneElement> membrane_;
  std::vector<BendElement> bending_;
  MembraneArrays membraneArrays_;
  BendArrays bendArrays_;
  double lambdaT_ = 0.0, muT_ = 0.0;
  std::vector<std::uint32_t> edgeV0_, edgeV1_;
  std::vector<double> edgeRest_;
  std::vector<mesh::Triangle> triangles_;
  double minAltitude_ = 0.0;
  double bendingOmega_ = 0.0;  ///< highest bending frequency bound, rad/s (buildBending)
  /// membraneFrequency_rad_s() with every vertex free, when mass scaling measured it on the
  /// final masses (0: not measured).
  double freeMembraneOmega_ = 0.0;
  double membraneStep_ = 0.0;  ///< stable step of the stiffest triangle after mass scaling, s
  double addedMass_ = 0.0;
  std::size_t massScaledVertices_ = 0;
};

/// Symplectic Euler on a mode of angular frequency omega with stiffness-proportional damping
/// (the membrane's: c = damping_s omega^2) is stable while omega^2 dt (dt + 2 damping_s) < 4;
/// without damping that is the familiar dt < 2 / omega, and damping shortens it. These use
/// omega / kDampedStepMargin, the margin the bending step keeps too: measured on the bundled
/// garments, the runs diverge within 10 % of the bound at rest (the cloth stiffens as it
/// stretches; docs/PHYSICS.md).
inline constexpr double kDampedStepMargin = 0.9;
/// The longest stable step with damping `damping_s` (infinite for omega = 0).
[[nodiscard]] double dampedStableStep_s(double omega_rad_s, double damping_s);
/// The undamped step with the bound of `step_s` at damping `damping_s`: sqrt(dt (dt + 2 beta)).
[[nodiscard]] double undampedEquivalentStep_s(double step_s, double damping_s);
/// The most damping stable at `step_s` (negative when the step is too long even undamped).
[[nodiscard]] double largestStableDamping_s(double omega_rad_s, double step_s);

/// Forward Euler (x += dt v, v += dt a) on the same mode is the map with trace 2 - b and
/// determinant 1 - b + a (a = omega^2 dt^2, b = damping_s omega^2 dt): stable while
/// dt < damping_s (every mode, however slow, gains energy otherwise, undamped at any step)
/// and omega^2 dt (2 damping_s - dt) < 4. So only damping within a window works:
/// (dt, dt / 2 + 2 / (omega^2 dt)), with omega / kDampedStepMargin; empty once dt reaches
/// 2 kDampedStepMargin / omega.
struct ForwardEulerDampingWindow {
  double least_s = 0.0;  ///< damping must exceed this (the step)
  double most_s = 0.0;   ///< and stay at or below this (below least_s: no damping works)
  [[nodiscard]] bool holds(double damping_s) const { return damping_s > least_s && damping_s <= most_s; }
  [[nodiscard]] bool empty() const { return most_s <= least_s; }
};
[[nodiscard]] ForwardEulerDampingWindow forwardEulerDampingWindow(double omega_rad_s, double step_s);

/// The classical Runge-Kutta step on the same mode (eigenvalues lambda = omega (-zeta +-
/// sqrt(zeta^2 - 1)), zeta = damping_s omega / 2) is stable while every |R(lambda dt)| <= 1,
/// R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24: undamped to omega dt = 2 sqrt(2) (symplectic
/// Euler's 2), and damping, which shortens symplectic Euler's step, lengthens or keeps this
/// one up to zeta = 1 (2.63 at the bundled skirt's zeta 0.6). The longest such step, found
/// along the eigenvalues' rays by bisection, with omega / kDampedStepMargin (infinite for
/// omega = 0).
[[nodiscard]] double rungeKuttaStableStep_s(double omega_rad_s, double damping_s);
/// The highest frequency of a membrane mode that `integrator` keeps stable at `step_s` with
/// damping `damping_s`: 2 kDampedStepMargin / undampedEquivalentStep_s for symplectic Euler
/// (and forward Euler, whose window the solver checks), and for the Runge-Kutta step the
/// frequency whose rungeKuttaStableStep_s is `step_s`.
[[nodiscard]] double stableOmega(IntegratorKind integrator, double step_s, double damping_s);
/// The fewest substeps per frame of `frameRate_hz` at which the Runge-Kutta step keeps the
/// model's membrane stable, every vertex free (at least the frequency with pins held).
[[nodiscard]] int rungeKuttaSubsteps(const ClothModel& model, double frameRate_hz);

/// A substep count and the mass scaling it needs.
struct SubstepChoice {
  int substepsPerFrame = 0;
  double addedMassFraction = 0.0;  ///< mass scaling adds this fraction of the garment's mass
};

/// The fraction of the garment's mass that mass scaling adds to keep it stable at
/// `substepsPerFrame` per frame of `frameRate_hz` (builds the model once).
[[nodiscard]] double addedMassFractionAt(const mesh::TriMesh& mesh, const mesh::Topology& topology,
                                         const Material& material, double frameRate_hz, int substepsPerFrame,
                                         IntegratorKind integrator = IntegratorKind::SymplecticEuler);

/// The fewest substeps per frame, from `least` up, at which the garment is stable when mass
/// scaling may add at most `maxAddedFraction` of its mass (0: no scaling: the estimated
/// stable count). Counts below the unscaled stable count are tried on a ladder of 5 % steps
/// (every count up to 20), each by building the model, and the first that passes is narrowed
/// by bisection down to the rung below (more substeps never need more mass); at most 100000.
/// With internal damping
/// a count must also keep dampedStableStep_s of the membrane's highest frequency (every
/// vertex free), which mass scaling lowers. For `integrator` RungeKutta4 the counts, the mass
/// scaling and the bound are that step's: rungeKuttaStableStep_s of the same frequency, with
/// or without damping, and the count is found by bisection from the unscaled count down (every
/// model measures its mode). Throws drape::Error naming the garment when none is stable.
[[nodiscard]] SubstepChoice fewestStableSubsteps(const mesh::TriMesh& mesh, const mesh::Topology& topology,
                                                 const Material& material, double frameRate_hz,
                                                 double maxAddedFraction, int least = 1,
                                                 IntegratorKind integrator = IntegratorKind::SymplecticEuler);

/// The bending rhythm (StepSettings::bendEvery) to write into a scene stepping at
/// `substep_s`: the most substeps, up to 8, that span at most a tenth of the bending forces'
/// stable step, so that the impulse stays accurate, not only stable (omega k dt <= 0.18);
/// 1 when bending is not that slow. Beyond 8 the bending forces cost little already.
[[nodiscard]] int suggestedBendEvery(const ClothModel& model, double substep_s);

/// Bending hinge constant: W_e = kBendCoefficient * D * |e|^2 / (A1 + A2) * (psi - psi0)^2.
/// Chosen (docs/PHYSICS.md) so that a regular grid bent into a cylinder of curvature kappa
/// stores D kappa^2 / 2 per area, as plate theory says; irregular meshes store about 1.5
/// times that (a known limit of hinge energies, measured by the calibration test).
inline constexpr double kBendCoefficient = 0.5;

}  // namespace drape::cloth
