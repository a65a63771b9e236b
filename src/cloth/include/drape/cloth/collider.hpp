#pragma once
// The collider hook. A collider sees the state once per substep, after integration, with
// positions and velocities at the end of the substep and the interval [t0, t1]; it may
// correct both (project points out, remove inward velocity, apply friction). One virtual
// call per collider per substep, never per vertex. The analytic sphere below serves the
// benchmark and tests; the distance-field collision of the paper (section 4.3.3) implements
// the same interface.

#include <cstdint>
#include <span>
#include <string>

#include "drape/cloth/model.hpp"
#include "drape/cloth/state.hpp"
#include "drape/core/math.hpp"

namespace drape::cloth {

/// What a collider did so far (accumulated over calls).
struct ColliderCounters {
  std::uint64_t calls = 0;           ///< substeps handled
  std::uint64_t pointsTested = 0;    ///< vertex tests
  std::uint64_t contacts = 0;        ///< vertex corrections
  double maxPenetration_m = 0.0;     ///< deepest correction, m
};

/// A point two or more parts moved at a collider's test (pinched between them), and the
/// directions (unit, world) in which the first two of them moved it: their surfaces'
/// normals there, to first order. A zero direction is none.
struct PinchedPoint {
  std::uint32_t vertex = 0;
  Vec3 along[2] = {Vec3::Zero(), Vec3::Zero()};
};

class Collider {
 public:
  virtual ~Collider() = default;
  [[nodiscard]] virtual std::string name() const = 0;
  /// Corrects io's positions and velocities at the end of the substep [t0_s, t1_s].
  virtual void collide(const ClothModel& model, double t0_s, double t1_s, ClothState& io) = 0;
  [[nodiscard]] virtual ColliderCounters counters() const = 0;
  /// The points pinched at the collider's last test, each once; an implicit step keeps them
  /// from moving along those directions in its next solve (BackwardEuler).
  [[nodiscard]] virtual std::span<const PinchedPoint> pinched() const { return {}; }
  /// The solver is about to compute a frame it may compute again (StepSettings::
  /// maxRefinement): keep what restartFrame needs.
  virtual void beginFrame() = 0;
  /// The frame went unstable and is computed again, with more substeps, from `state`, where
  /// the frame started at t_s: forget what the attempt did (its counts included).
  virtual void restartFrame(const ClothState& state, double t_s) = 0;
};

/// A static analytic sphere. A point that ends a substep inside radius + margin is put
/// back on that surface, loses its inward normal velocity and has its tangential velocity
/// reduced by Coulomb friction (the material's dynamic friction times the removed normal
/// speed; at rest below the static coefficient it sticks).
class SphereCollider final : public Collider {
 public:
  SphereCollider(const Vec3& centre_m, double radius_m, double margin_m = 0.0);
  [[nodiscard]] std::string name() const override { return "sphere"; }
  void collide(const ClothModel& model, double t0_s, double t1_s, ClothState& io) override;
  [[nodiscard]] ColliderCounters counters() const override { return counters_; }
  void beginFrame() override { frameStart_ = counters_; }
  void restartFrame(const ClothState&, double) override { counters_ = frameStart_; }

 private:
  Vec3 centre_;
  double radius_;
  ColliderCounters counters_;
  ColliderCounters frameStart_;  ///< the counters when the frame began
};

}  // namespace drape::cloth
