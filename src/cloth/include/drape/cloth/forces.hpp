#pragma once
// Force kernels (STYLE habit 6): one function per force type over the model's element
// arrays, adding into the state's force accumulators. Each states its formula; the
// derivations are in docs/PHYSICS.md. Energies are computed by matching functions so tests
// can check force = -gradient(energy) and energy conservation.

#include "drape/cloth/material.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/state.hpp"
#include "drape/core/threads.hpp"

namespace drape::cloth {

/// Models with at least this many triangles (hinges) compute their membrane (bending)
/// forces in pieces on TBB's threads when given ForceLoops. Each element's forces and each
/// vertex's sums are computed as with one thread, in the same order: the same forces to the
/// bit.
inline constexpr std::size_t kParallelFrom_elements = 2048;

/// The force kernels' loops over threads, one set per garment, kept from call to call
/// (PieceLoop: each piece stays on its thread).
struct ForceLoops {
  PieceLoop membraneRuns, membraneElements, membraneBlocks, membraneVertices;
  PieceLoop hingeRuns, hinges, hingeVertices;
};

/// Sets every force accumulator to zero.
void clearForces(ClothState& io);

/// CST St Venant-Kirchhoff membrane in plane stress, per triangle of rest area A:
///   E = (F^T F - I) / 2,  S = lambda_t tr(E) I + 2 mu_t E (+ damping_s * same of dE/dt),
///   f_i = -A F S grad(N_i).
/// Compressive principal stresses are scaled by material.compressionScale.
/// With `loops`, a model of kParallelFrom_elements triangles or more runs on TBB's threads.
void accumulateMembraneForces(const ClothModel& model, ClothState& io, ForceLoops* loops = nullptr);

/// Dihedral hinges: W = k / 2 (psi - psi0)^2 with psi = 2 sin(theta / 2), f = -dW/dx,
/// times `scale` (the multiple-time-stepping impulse: bendEvery substeps' worth at once).
/// With `loops`, a model of kParallelFrom_elements hinges or more runs on TBB's threads.
void accumulateBendingForces(const ClothModel& model, ClothState& io, double scale = 1.0,
                             ForceLoops* loops = nullptr);

/// Viscous air drag relative to the wind, per vertex: f = -c A_v (v - wind).
void accumulateDragForces(const ClothModel& model, const StepSettings& settings, ClothState& io);

/// Elastic energies, J.
[[nodiscard]] double membraneEnergy(const ClothModel& model, const ClothState& state);
[[nodiscard]] double bendingEnergy(const ClothModel& model, const ClothState& state);
/// Kinetic energy, J.
[[nodiscard]] double kineticEnergy(const ClothModel& model, const ClothState& state);
/// Gravitational potential -sum m g . x, J (zero at the origin).
[[nodiscard]] double gravityEnergy(const ClothModel& model, const ClothState& state, const Vec3& gravity_m_s2);

/// The model's edges' extremes against their rest lengths l0: the longest stretch
/// max (l - l0) / l0 and the deepest compression max (l0 - l) / l0, each 0 when no edge is
/// so. A NaN position makes both NaN.
struct EdgeStrain {
  double stretch = 0.0;
  double compression = 0.0;
  /// Largest |l - l0| / l0: the larger of the two.
  [[nodiscard]] double largest() const { return stretch >= compression ? stretch : compression; }
};
[[nodiscard]] EdgeStrain edgeStrain(const ClothModel& model, const ClothState& state);

/// Largest |l - l0| / l0 over the model's edges.
[[nodiscard]] inline double maxEdgeStrain(const ClothModel& model, const ClothState& state) {
  return edgeStrain(model, state).largest();
}

}  // namespace drape::cloth
