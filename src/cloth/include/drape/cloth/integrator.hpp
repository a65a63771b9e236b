#pragma once
// Time integrators behind one interface. The explicit one-stage integrators take the forces
// the step accumulated for this substep; gravity enters as a body acceleration (so a vertex
// of zero mass still falls). The classical Runge-Kutta step (the paper's future work) takes
// them as its first stage and asks StageForces for three more. The implicit one (backward
// Euler, the paper's other future work) linearises the forces at the substep's start as well
// (backward_euler.hpp).

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "drape/cloth/collider.hpp"
#include "drape/cloth/material.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/state.hpp"

namespace drape::cloth {

/// What an implicit integrator's linear solves took, summed over the substeps so far.
struct SolveStats {
  long solves = 0;       ///< substeps solved
  long iterations = 0;   ///< conjugate-gradient iterations (one product with the system each)
  long unconverged = 0;  ///< solves that reached the iteration cap above the tolerance
  /// Solves stopped where the system was not positive definite (the cloth compressed or
  /// folded past what the linearisation holds): the step so far was taken.
  long indefinite = 0;
  SolveStats& operator+=(const SolveStats& o) {
    solves += o.solves;
    iterations += o.iterations;
    unconverged += o.unconverged;
    indefinite += o.indefinite;
    return *this;
  }
  [[nodiscard]] double meanIterations() const {
    return solves > 0 ? static_cast<double>(iterations) / static_cast<double>(solves) : 0.0;
  }
};

/// A vertex held for one step along one or two orthonormal directions: a point the colliders
/// found pinched between parts, along their normals there (PinchedPoint). Its velocity
/// along them stays what the colliders gave it, their parts' mean.
struct HeldPoint {
  std::uint32_t vertex = 0;
  int directions = 0;
  Vec3 e[2] = {Vec3::Zero(), Vec3::Zero()};
  /// `a` without its components along the held directions.
  [[nodiscard]] Vec3 filtered(Vec3 a) const {
    for (int k = 0; k < directions; ++k) a -= a.dot(e[k]) * e[k];
    return a;
  }
};

/// Adds to `holds` each of `points` whose vertex `skip` does not name (one flag per vertex:
/// placed by a fixture, or massless) and `held` does not have yet (one flag per vertex, set
/// for each one added): its directions made orthonormal, a direction within 1e-3 of the
/// ones before it left out, and a point left with none not held.
void addHolds(std::span<const PinchedPoint> points, std::span<const std::uint8_t> skip, std::vector<std::uint8_t>& held,
              std::vector<HeldPoint>& holds);

/// Ends the holds of one step: `held`'s flags cleared and `holds` emptied.
void clearHolds(std::vector<std::uint8_t>& held, std::vector<HeldPoint>& holds);

/// The forces at a stage of a multi-stage step: every force the step applies (membrane,
/// bending, drag), for the positions and velocities in `io`, into io.f* (cleared first).
class StageForces {
 public:
  virtual ~StageForces() = default;
  virtual void accumulate(ClothState& io) = 0;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  [[nodiscard]] virtual IntegratorKind kind() const = 0;
  /// Sizes the workspace for `model` (no allocation afterwards), takes the drag of
  /// `settings`, and names the vertices the fixtures place (one flag per vertex, or none),
  /// which an implicit solve holds.
  virtual void prepare(const ClothModel& /*model*/, const StepSettings& /*settings*/,
                       std::span<const std::uint8_t> /*fixed*/) {}
  /// Advances positions and velocities by dt_s from the forces in io.f* (those of io's
  /// state: every force the step applies).
  virtual void advance(const ClothModel& model, const Vec3& gravity_m_s2, double dt_s, ClothState& io) = 0;
  /// The points the colliders found pinched between parts at their last test, for the next
  /// advance alone. The implicit solve and the Runge-Kutta step keep their velocity along
  /// the parts' normals (the velocity the colliders gave them, their parts' mean; HeldPoint);
  /// the one-stage explicit steps ignore them, their substeps being short.
  virtual void holdPinched(std::span<const PinchedPoint> /*points*/) {}
  /// Where the next advance evaluates its further stages' forces (the multi-stage steps
  /// alone; the others ignore it). Given before each advance: the caller owns it.
  virtual void useStageForces(StageForces* /*forces*/) {}
  [[nodiscard]] virtual SolveStats solveStats() const { return {}; }
};

[[nodiscard]] std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind);

}  // namespace drape::cloth
