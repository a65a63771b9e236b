#pragma once
// Time integrators behind one interface. The explicit one-stage integrators take the forces
// the step accumulated for this substep; gravity enters as a body acceleration (so a vertex
// of zero mass still falls). Multi-stage ones (Runge-Kutta, the paper's future work) would
// re-evaluate forces through `evaluateForces`.

#include <functional>
#include <memory>

#include "drape/cloth/material.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/state.hpp"

namespace drape::cloth {

class Integrator {
 public:
  virtual ~Integrator() = default;
  [[nodiscard]] virtual IntegratorKind kind() const = 0;
  /// Advances positions and velocities by dt_s from the forces in io.f*.
  virtual void advance(const ClothModel& model, const Vec3& gravity_m_s2, double dt_s, ClothState& io) const = 0;
};

[[nodiscard]] std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind);

}  // namespace drape::cloth
