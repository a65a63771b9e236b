#pragma once
// Backward Euler for the cloth, the implicit step the paper leaves to future work (its
// section 6: "compatibility with lower frequency solvers, such as Runge Kutta and Implicit
// methods"), as Baraff and Witkin (1998) take it: one Newton step of
//
//   v1 = v0 + h M^-1 f(x0 + h v1, v1) + h g,   x1 = x0 + h v1,
//
// linearised at (x0, v0), with K = df/dx and D = df/dv:
//
//   (M - h D - h^2 K) dv = h (f0 + M g) + h^2 K v0,   v1 = v0 + dv.
//
// The forces f0 are the explicit step's own (every kernel, to the bit). The matrices are
// the positive semi-definite parts of the true ones, so that the system is positive
// definite and conjugate gradients solve it (a projected Newton step):
// - membrane: the material stiffness A (dE/dx)^T C (dE/dx) in full, and the geometric
//   stiffness (grad N_i . S grad N_j) I with the stress S's compressive principal part
//   dropped (under compression the exact stiffness is negative out of the sheet's plane: a
//   step that followed it would push a buckle further), and the internal damping as beta
//   times the material stiffness;
// - bending: the Gauss-Newton term k grad psi grad psi^T (the term in (psi - psi0) dropped);
// - drag: c A_v on the diagonal.
// Each substep assembles the system as 3x3 blocks over the vertices that share a triangle
// or a hinge (the pattern built once), from the deformation gradients, clamped stresses and
// hinge gradients at the substep's start; each conjugate-gradient iteration is one product
// with it, warm-started from the last substep's dv. The vertices the fixtures place are
// held (their dv is 0 in the solve, Baraff and Witkin's constraint filter), and the
// fixtures then place them. The points the colliders found pinched between two parts at
// their last test are held along those parts' normals for one solve (the same filter with
// one or two directions, free along the crease): they keep the velocity the collider gave
// them there (their parts' mean) instead of being pulled deeper between the parts by the
// cloth around them over a substep eight times the explicit one's. The preconditioner is
// block Jacobi: the inverse of each vertex's 3x3 block of the system.
// docs/PHYSICS.md.

#include <vector>

#include "drape/cloth/integrator.hpp"

namespace drape::cloth {

class BackwardEuler final : public Integrator {
 public:
  /// Conjugate-gradient iterations at most per substep.
  static constexpr int kMaxIterations = 200;

  [[nodiscard]] IntegratorKind kind() const override { return IntegratorKind::BackwardEuler; }
  void prepare(const ClothModel& model, const StepSettings& settings, std::span<const std::uint8_t> fixed) override;
  void advance(const ClothModel& model, const Vec3& gravity_m_s2, double dt_s, ClothState& io) override;
  [[nodiscard]] SolveStats solveStats() const override { return stats_; }
  void holdPinched(std::span<const PinchedPoint> points) override;

  /// The forces' linearisation at `s`'s positions (deformation gradients, clamped
  /// stresses, hinge gradients), which stiffnessTimes then applies. Exposed for tests.
  void linearise(const ClothModel& model, const ClothState& s);
  /// out = (material (K_membrane,material) + geometric (K_membrane,geometric + K_bending)) p
  /// at the last linearisation, with K the stiffness -df/dx as described above; p and out
  /// hold 3 n values, the x block, then y, then z.
  void stiffnessTimes(const ClothModel& model, std::span<const double> p, double material, double geometric,
                      std::span<double> out) const;

 private:
  /// The block CSR pattern of the system (prepare): rows per vertex, 3x3 blocks.
  void buildPattern(const ClothModel& model);
  /// The system's blocks at the last linearisation, A = M + (h^2 + h beta) K_m + h^2 (K_g +
  /// K_b) + h c A_v (the operator stiffnessTimes applies, with the mass and drag), and the
  /// inverses of its diagonal blocks for the preconditioner.
  void assemble(const ClothModel& model, double h);
  void invertDiagonalBlocks();
  /// out = A p for the free vertices, 0 for the held ones (p's held entries must be 0).
  void applySystem(std::span<const double> p, std::span<double> out) const;
  /// Zeroes v's entries of the held vertices and the pinched ones' components along their
  /// constrained directions (Baraff and Witkin's filter S).
  void filter(std::span<double> v) const;
  /// The pinched vertices' part of filter alone: applySystem and the preconditioner leave
  /// the held ones at zero already.
  void filterPinched(std::span<double> v) const;

  std::vector<std::uint8_t> held_;  ///< per vertex: placed by a fixture, or massless
  /// For this solve alone: the vertices pinched between parts at the last collision test,
  /// each with an orthonormal basis of the directions it may not move along (one or two).
  std::vector<HeldPoint> pinched_;
  std::vector<std::uint8_t> isPinched_;  ///< per vertex: in pinched_
  /// Per membrane element, at the last linearisation: the deformation gradient's columns
  /// (Fu, Fv: 6 values) and the stress with its compressive part dropped (S11, S22, S12).
  std::vector<double> gradient_, stress_;
  /// Per hinge: sqrt(k) grad psi for its corners a, b, e0, e1 (12 values).
  std::vector<double> hinge_;
  /// The system as block CSR: row v's blocks rowStart_[v] .. rowStart_[v + 1] in column
  /// order, 9 values each (row-major) in matrix_; the diagonal block's index per vertex; each
  /// membrane element's 9 and each hinge's 16 block indices (corner r, corner c).
  std::vector<std::uint32_t> rowStart_, column_, diagonal_, membraneBlock_, hingeBlock_;
  std::vector<double> matrix_;
  double dragPerArea_ = 0.0;  ///< the settings' air viscosity c, N s/m^3
  double tolerance_ = 1e-3;   ///< the settings' implicitTolerance
  std::vector<double> rhs_, dv_, r_, z_, d_, q_, precond_;
  SolveStats stats_;
};

}  // namespace drape::cloth
