#include "drape/cloth/solver.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "drape/cloth/forces.hpp"
#include "drape/cloth/strain_limit.hpp"
#include "drape/core/error.hpp"
#include "drape/core/threads.hpp"

namespace drape::cloth {

std::string Instability::describe(const std::string& garment, double bound) const {
  const std::string what =
      nan ? fmt::format("garment '{}': vertex {} became NaN or infinite in frame {}, substep {}", garment, vertex,
                        frame, substep)
          : fmt::format("garment '{}': vertex {} reached {:.4g} m/s (bound {:.4g} m/s) in frame {}, substep {}",
                        garment, vertex, speed_m_s, bound, frame, substep);
  const std::string limited =
      strainLimit > 0.0 ? fmt::format("edges held to {:.3g} times their rest length{}", 1.0 + strainLimit,
                                      rescued ? " since the frame went unstable without" : "")
                        : "";
  if (refinement <= 1) return limited.empty() ? what : fmt::format("{} (with {})", what, limited);
  return fmt::format("{} of {} (the frame computed again with {} times the substeps{}, after it went unstable with "
                     "fewer)",
                     what, substepsPerFrame, refinement, limited.empty() ? "" : " and " + limited);
}

ClothSolver::ClothSolver(std::shared_ptr<const ClothModel> model, const StepSettings& settings,
                         std::vector<PinGroup> pins)
    : model_(std::move(model)),
      settings_(settings),
      pins_(std::move(pins)),
      integrator_(makeIntegrator(settings.integrator)),
      state_(ClothState::atRest(*model_)),
      dt_(settings_.substep_s()),
      substepsPerFrame_(settings_.substepsPerFrame) {
  settings_.validate("--");
  parallelForces_ = threadsAllowed() > 1;
  checkBendingStep(*model_, settings_);
  checkPinGroups();
  strainLimit_ = settings_.strainLimit;
  strainWeight_ = model_->inverseMass();
  for (const PinGroup& g : pins_)
    for (const std::uint32_t v : g.vertices) strainWeight_[v] = 0.0;  // placed by their fixtures
  std::vector<std::uint8_t> fixed(model_->vertexCount(), 0);
  for (const PinGroup& g : pins_)
    for (const std::uint32_t v : g.vertices) fixed[v] = 1;
  integrator_->prepare(*model_, settings_, fixed);
  // The explicit steps' stability with damping; the implicit one is stable at any step.
  // Runge-Kutta's, damped or not: the wave-speed estimate is symplectic Euler's, and its
  // bound moves with the damping the other way.
  const bool forwardEuler = settings_.integrator == IntegratorKind::ForwardEuler;
  const bool implicit = settings_.integrator == IntegratorKind::BackwardEuler;
  const bool rungeKutta = settings_.integrator == IntegratorKind::RungeKutta4;
  if ((model_->material().damping_s > 0.0 && !implicit) || forwardEuler || rungeKutta) {
    dampedOmega_ = model_->membraneFrequency_rad_s(fixed);
    if (forwardEuler) checkForwardEulerStep(*model_, settings_, dampedOmega_);
    else if (rungeKutta) checkRungeKuttaStep(*model_, settings_, dampedOmega_);
    else checkDampedStep(*model_, settings_, dampedOmega_);
  }
}

void ClothSolver::checkPinGroups() {
  // Each blended vertex's weights sum to 1, unless a group without weights places it (which
  // wins: those groups are applied last).
  const std::size_t n = model_->vertexCount();
  std::vector<std::uint8_t> alone(n, 0);
  std::vector<double> weightSum(n, 0.0);
  for (const PinGroup& g : pins_) {
    if (!g.weight.empty() && g.weight.size() != g.vertices.size())
      throw Error(fmt::format("a fixture group has {} weights for {} vertices", g.weight.size(), g.vertices.size()),
                  ExitCode::Internal);
    for (std::size_t k = 0; k < g.vertices.size(); ++k) {
      const std::uint32_t v = g.vertices[k];
      if (v >= n) throw Error(fmt::format("fixture vertex {} is out of range ({} vertices)", v, n), ExitCode::Internal);
      if (g.weight.empty()) alone[v] = 1;
      else weightSum[v] += g.weight[k];
    }
  }
  for (std::size_t v = 0; v < n; ++v) {
    if (weightSum[v] == 0.0) continue;
    if (!alone[v] && std::abs(weightSum[v] - 1.0) > 1e-9)
      throw Error(fmt::format("fixture vertex {} has weights summing to {}, not 1", v, weightSum[v]),
                  ExitCode::Internal);
    blended_.push_back(static_cast<std::uint32_t>(v));
  }
}

void checkForwardEulerStep(const ClothModel& model, const StepSettings& settings, double omega) {
  const double beta = model.material().damping_s;
  const double dt = settings.substep_s();
  const ForwardEulerDampingWindow window = forwardEulerDampingWindow(omega, dt);
  if (window.holds(beta)) return;
  const std::string head =
      fmt::format("garment '{}': forward Euler is unstable at a substep of {:.3g} ms with internal damping of {:.3g} ms",
                  model.name(), 1e3 * dt, 1e3 * beta);
  if (!window.empty())
    throw Error(fmt::format("{}: its modes grow unless the damping is above the substep and, for the membrane's "
                            "stiffest mode ({:.4g} rad/s), at most {:.3g} ms; set damping above {:.3g} ms and at most "
                            "{:.3g} ms, or use --integrator symplectic-euler",
                            head, omega, 1e3 * window.most_s, 1e3 * window.least_s, 1e3 * window.most_s));
  // The window opens once the step is below 2 kDampedStepMargin / omega.
  const long substeps = static_cast<long>(std::floor(omega / (2.0 * kDampedStepMargin * settings.frameRate_hz)));
  throw Error(fmt::format("{}: no damping keeps the membrane's stiffest mode ({:.4g} rad/s) stable at this substep; "
                          "use more than {} substeps per frame (then damping above the substep), or --integrator "
                          "symplectic-euler",
                          head, omega, substeps));
}

void checkRungeKuttaStep(const ClothModel& model, const StepSettings& settings, double omega) {
  const double beta = model.material().damping_s;
  const double dt = settings.substep_s();
  const double most = rungeKuttaStableStep_s(omega, beta);
  if (dt <= most) return;
  const long substeps = static_cast<long>(std::ceil(1.0 / (settings.frameRate_hz * most)));
  throw Error(fmt::format("garment '{}': the runge-kutta-4 step is unstable at a substep of {:.3g} ms (the membrane's "
                          "stiffest mode, {:.4g} rad/s, with internal damping of {:.3g} ms allows at most {:.3g} ms); "
                          "use {} substeps per frame or more",
                          model.name(), 1e3 * dt, omega, 1e3 * beta, 1e3 * most, substeps));
}

void checkBendingStep(const ClothModel& model, const StepSettings& settings) {
  const double span = settings.bendEvery * settings.substep_s();
  const double stable = model.bendingStableStep_s();
  if (settings.bendEvery == 1 || span <= stable) return;  // every substep: the stability guard watches
  const int most = std::max(1, static_cast<int>(stable / settings.substep_s()));
  throw Error(fmt::format("garment '{}': bending every {} substeps spans {:.3g} ms, above the bending forces' "
                          "stable step of {:.3g} ms; set bendEvery (--bend-every) to {} or less",
                          model.name(), settings.bendEvery, 1e3 * span, 1e3 * stable, most));
}

void checkDampedStep(const ClothModel& model, const StepSettings& settings, double omega) {
  const double beta = model.material().damping_s;
  if (!(beta > 0.0) || settings.integrator != IntegratorKind::SymplecticEuler) return;
  const double dt = settings.substep_s();
  // A substep too long even undamped is the wave-speed estimate's to warn about (it diverges
  // either way); this check is for the damping.
  if (dt <= dampedStableStep_s(omega, beta) || dt > dampedStableStep_s(omega, 0.0)) return;
  const double most = largestStableDamping_s(omega, dt);
  const long substeps = static_cast<long>(std::ceil(1.0 / (settings.frameRate_hz * dampedStableStep_s(omega, beta))));
  const std::string lessDamping = fmt::format("set damping to {:.3g} s or less, or ", most);
  // More substeps need less mass scaling, which raises the frequency again: the count is a
  // floor there, and the ladder of fewestStableSubsteps (--substeps auto) finds the count.
  const std::string count = settings.maxAddedMass > 0.0
                                ? fmt::format("at least {} substeps per frame (--substeps auto finds how many)", substeps)
                                : fmt::format("{} substeps per frame or more", substeps);
  throw Error(fmt::format("garment '{}': internal damping of {:.3g} s makes the substep of {:.3g} ms unstable (the "
                          "membrane's stiffest mode, {:.4g} rad/s, allows at most {:.3g} ms at this damping); {}use {}",
                          model.name(), beta, 1e3 * dt, omega, 1e3 * dampedStableStep_s(omega, beta), lessDamping,
                          count));
}

bool ClothSolver::stepFrame(long frame) {
  // A frame that goes unstable is computed again from its start with twice the substeps
  // (an explicit step's stability limit scales with the substep): a garment crushed where
  // the body's parts overlap, or moved by a collision in one substep by more than its
  // smallest triangles' size, stiffens locally beyond the substep the rest shape allows.
  // The copy is of positions and velocities, 48 bytes a vertex (the skirt 13 KB, the dress
  // 106 KB) per frame, with no allocation after the first; the benchmark's figures did not
  // move with it.
  const bool rescuable = strainLimit_ == 0.0 && settings_.rescueStrainLimit > 0.0;
  if (settings_.maxRefinement > 1 || rescuable) {
    const std::array<const std::vector<double>*, 6> motion{&state_.x,  &state_.y,  &state_.z,
                                                           &state_.vx, &state_.vy, &state_.vz};
    for (std::size_t k = 0; k < motion.size(); ++k) frameStart_[k] = *motion[k];
    frameStartSubsteps_ = substepCount_;
    for (Collider* c : colliders_) c->beginFrame();
  }
  if (climbRefinements(frame)) return true;
  if (!rescuable) return false;
  // Cloth that no substep keeps stable is cloth stretched far beyond its rest length (its
  // stiffness grows with the stretch squared): the frame once more, with the stretch held
  // to a limit from now on (strain_limit.hpp).
  strainLimitedBecause_ = instability_;
  strainLimit_ = settings_.rescueStrainLimit;
  strainLimitedFrom_ = frame;
  restartFrame(frame);
  return climbRefinements(frame);
}

bool ClothSolver::climbRefinements(long frame) {
  lastRefinement_ = 1;
  for (int refinement = 1;; refinement *= 2) {
    if (runFrame(frame, refinement)) {
      if (refinement > 1) ++refinedFrames_;
      lastRefinement_ = refinement;
      return true;
    }
    if (refinement * 2 > settings_.maxRefinement) return false;
    if (refinement == 1) refinedBecause_ = instability_;
    restartFrame(frame);
  }
}

void ClothSolver::restartFrame(long frame) {
  const std::array<std::vector<double>*, 6> motion{&state_.x, &state_.y, &state_.z, &state_.vx, &state_.vy, &state_.vz};
  for (std::size_t k = 0; k < motion.size(); ++k) *motion[k] = frameStart_[k];
  substepCount_ = frameStartSubsteps_;
  // The frame's start as its first unrefined substep has it (runFrame).
  const double t0 = static_cast<double>((frame - 1) * settings_.substepsPerFrame) * settings_.substep_s();
  for (Collider* c : colliders_) c->restartFrame(state_, t0);
}

void ClothSolver::setWind(const Vec3& wind_m_s) {
  if (!wind_m_s.allFinite()) throw Error("the wind must be finite", ExitCode::Internal);
  settings_.wind_m_s = wind_m_s;
}

bool ClothSolver::runFrame(long frame, int refinement) {
  const int n = settings_.substepsPerFrame * refinement;
  // The same expression as StepSettings::substep_s: unrefined frames keep their bits.
  const double dt = 1.0 / (settings_.frameRate_hz * n);
  dt_ = dt;
  substepsPerFrame_ = n;
  refinement_ = refinement;
  bool stable = true;
  for (int s = 0; s < n && stable; ++s) {
    // Times from a substep counter, not an accumulated sum, so no drift over long takes;
    // both ends from the counter, so this substep's t1 is the next one's t0 exactly (the
    // poses of the body parts are cached by time).
    const double t0 = static_cast<double>((frame - 1) * n + s) * dt;
    const double t1 = static_cast<double>((frame - 1) * n + s + 1) * dt;
    stable = substep(t0, t1, frame, s);
  }
  dt_ = settings_.substep_s();
  substepsPerFrame_ = settings_.substepsPerFrame;
  refinement_ = 1;
  return stable;
}

bool ClothSolver::substep(double t0, long frame, int substepIndex) {
  return substep(t0, t0 + settings_.substep_s(), frame, substepIndex);
}

bool ClothSolver::substep(double t0, double t1, long frame, int substepIndex) {
  const double dt = dt_;
  // One clock reading per stage boundary (StageClock).
  StageClock::Ticks t = StageClock::now();
  accumulateForces();  // membrane, bending, drag into state_.f*
  t = StageClock::lap(ticks_.forces, t);
  integrate(dt);  // new velocities and positions
  t = StageClock::lap(ticks_.integrate, t);
  collide(t0, t1);  // colliders correct the end-of-substep state
  t = StageClock::lap(ticks_.collide, t);
  applyFixtures(t0, t1, dt);  // pinned vertices follow their transforms
  if (!stitches_.empty())  // after the fixtures, whose vertices it leaves where they are
    stitchCorrections_ += holdStitches(stitches_, strainWeight_, kStrainLimitSweeps, state_);
  t = StageClock::lap(ticks_.fixtures, t);
  if (strainLimit_ > 0.0) {
    limitStrain();  // no edge beyond the limit (after the fixtures, whose vertices it leaves where they are)
    t = StageClock::lap(ticks_.strainLimit, t);
  }
  const bool stable = checkStability(frame, substepIndex);  // NaN or speed bound
  StageClock::lap(ticks_.stability, t);
  return stable;
}

namespace {

/// Every force the step applies, into io.f*: membrane, bending (when `bendScale` > 0, times
/// it) and drag. The substep's own forces and the Runge-Kutta step's stages alike.
void accumulateStepForces(const ClothModel& model, const StepSettings& settings, double bendScale,
                          ForceLoops* loops, ClothState& io) {
  clearForces(io);
  accumulateMembraneForces(model, io, loops);
  if (bendScale > 0.0) accumulateBendingForces(model, io, bendScale, loops);
  accumulateDragForces(model, settings, io);
}

/// The Runge-Kutta step's later stages: bending in every stage, unscaled, on the solver's
/// threads as its own forces are.
class SolverStageForces final : public StageForces {
 public:
  SolverStageForces(const ClothModel& model, const StepSettings& settings, ForceLoops* loops)
      : model_(model), settings_(settings), loops_(loops) {}
  void accumulate(ClothState& io) override { accumulateStepForces(model_, settings_, 1.0, loops_, io); }

 private:
  const ClothModel& model_;
  const StepSettings& settings_;
  ForceLoops* loops_;
};

}  // namespace

void ClothSolver::accumulateForces() {
  // The impulse method (Verlet-I / r-RESPA) for the slow force: one kick of bendEvery
  // substeps' worth at the first of every bendEvery substeps. Symplectic with the
  // symplectic inner step; counted over the whole take so that the rhythm runs on across
  // frame boundaries.
  const int every = settings_.bendEvery;
  const double bendScale = substepCount_++ % every == 0 ? static_cast<double>(every) : 0.0;
  accumulateStepForces(*model_, settings_, bendScale, parallelForces_ ? &forceLoops_ : nullptr, state_);
}

void ClothSolver::setStitches(std::vector<Stitch> stitches, const std::string& garment) {
  const std::size_t n = model_->vertexCount();
  for (const Stitch& st : stitches) {
    if (st.a >= n || st.b >= n)
      throw Error(fmt::format("garment '{}': a stitch joins vertex {} and {}, but it has {} vertices", garment, st.a,
                              st.b, n));
    if (st.a == st.b) throw Error(fmt::format("garment '{}': a stitch joins vertex {} to itself", garment, st.a));
    if (!(st.length_m >= 0.0) || !std::isfinite(st.length_m))
      throw Error(fmt::format("garment '{}': the stitch of vertices {} and {} is {:g} m long", garment, st.a, st.b,
                              st.length_m));
  }
  stitches_ = std::move(stitches);
}

void ClothSolver::limitStrain() {
  strainLimitCorrections_ += cloth::limitStrain(*model_, strainWeight_, strainLimit_, kStrainLimitSweeps, state_);
}

void ClothSolver::integrate(double dt) {
  for (const Collider* c : colliders_) integrator_->holdPinched(c->pinched());
  // Given every substep, so a moved solver gives its own (the integrator keeps no solver).
  SolverStageForces stageForces(*model_, settings_, parallelForces_ ? &forceLoops_ : nullptr);
  integrator_->useStageForces(&stageForces);
  integrator_->advance(*model_, settings_.gravity_m_s2, dt, state_);
}

void ClothSolver::collide(double t0, double t1) {
  for (Collider* c : colliders_) c->collide(*model_, t0, t1, state_);
}

void ClothSolver::applyFixtures(double t0, double t1, double dt) {
  // A blended vertex is the sum of its groups' weighted placements: cleared first.
  for (const std::uint32_t v : blended_) {
    state_.setPosition(v, Vec3::Zero());
    state_.setVelocity(v, Vec3::Zero());
  }
  for (const bool weighted : {true, false})
    for (const PinGroup& g : pins_)
      if (g.weight.empty() != weighted) applyFixture(g, t0, t1, dt);
}

void ClothSolver::applyFixture(const PinGroup& g, double t0, double t1, double dt) {
  // Timed apart: on a moving body this is animation (the skeleton's evaluation and
  // interpolation, whoever asks first in a substep), which the collision share leaves out.
  const StageClock::Ticks poseStart = StageClock::now();
  const RigidTransform now = g.motion ? g.motion->poseAt(t1) : RigidTransform::identity();
  const RigidTransform before = g.motion ? g.motion->poseAt(t0) : RigidTransform::identity();
  StageClock::lap(ticks_.fixturePoses, poseStart);
  const Mat3 r1 = now.rotation.toRotationMatrix(), r0 = before.rotation.toRotationMatrix();
  const Vec3 p1 = now.translation, p0 = before.translation;
  const double invDt = 1.0 / dt;
  for (std::size_t k = 0; k < g.vertices.size(); ++k) {
    const Vec3 local(g.localX[k], g.localY[k], g.localZ[k]);
    const Vec3 at = r1 * local + p1;
    const Vec3 was = r0 * local + p0;
    const std::uint32_t v = g.vertices[k];
    if (g.weight.empty()) {
      state_.setPosition(v, at);
      state_.setVelocity(v, (at - was) * invDt);
    } else {
      const double w = g.weight[k];
      state_.setPosition(v, state_.position(v) + w * at);
      state_.setVelocity(v, state_.velocity(v) + (w * invDt) * (at - was));
    }
  }
}

bool ClothSolver::checkStability(long frame, int substepIndex) {
  const double bound2 = settings_.maxSpeed_m_s * settings_.maxSpeed_m_s;
  const std::size_t n = state_.size();
  const double *x = state_.x.data(), *y = state_.y.data(), *z = state_.z.data();
  const double *vx = state_.vx.data(), *vy = state_.vy.data(), *vz = state_.vz.data();
  // Branch-free pass (vectorises); the slow search runs only when something is wrong.
  int bad = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double s2 = vx[i] * vx[i] + vy[i] * vy[i] + vz[i] * vz[i];
    const double p = x[i] + y[i] + z[i];
    bad |= static_cast<int>(!(s2 <= bound2)) | static_cast<int>(!(p - p == 0.0));
  }
  if (!bad) return true;
  for (std::size_t i = 0; i < n; ++i) {
    const double s2 = vx[i] * vx[i] + vy[i] * vy[i] + vz[i] * vz[i];
    const double p = x[i] + y[i] + z[i];
    const bool nan = !std::isfinite(s2) || !std::isfinite(p);
    if (nan || s2 > bound2) {
      instability_ = {true,         nan,          static_cast<std::uint32_t>(i), nan ? 0.0 : std::sqrt(s2),
                      frame,        substepIndex, substepsPerFrame_,             refinement_,
                      strainLimit_, strainLimitedFrom_ > 0};
      return false;
    }
  }
  return true;
}

StageTimes ClothSolver::stageTimes() const {
  StageTimes s;
  s.forces_s = StageClock::seconds(ticks_.forces);
  s.integrate_s = StageClock::seconds(ticks_.integrate);
  s.collide_s = StageClock::seconds(ticks_.collide);
  s.fixtures_s = StageClock::seconds(ticks_.fixtures);
  s.fixturePoses_s = StageClock::seconds(ticks_.fixturePoses);
  s.strainLimit_s = StageClock::seconds(ticks_.strainLimit);
  s.stability_s = StageClock::seconds(ticks_.stability);
  return s;
}

std::string describeRefinedFrame(const ClothSolver& solver, const std::string& garment) {
  const int refinement = solver.lastRefinement();
  if (refinement <= 1) return "";
  const StepSettings& s = solver.settings();
  return fmt::format("{}; computed again with {} times the substeps ({} per frame)",
                     solver.refinedBecause().describe(garment, s.maxSpeed_m_s), refinement,
                     refinement * s.substepsPerFrame);
}

std::string describeStrainLimitRescue(const ClothSolver& solver, const std::string& garment, long frame) {
  if (frame == 0 || solver.strainLimitedFrom() != frame) return "";
  return fmt::format("{}; computed again with its edges held to {:.3g} times their rest length (strain limiting), "
                     "which stays on for the rest of the run",
                     solver.strainLimitedBecause().describe(garment, solver.settings().maxSpeed_m_s),
                     1.0 + solver.strainLimit());
}

double ClothSolver::totalEnergy() const {
  return kineticEnergy(*model_, state_) + gravityEnergy(*model_, state_, settings_.gravity_m_s2) +
         membraneEnergy(*model_, state_) + bendingEnergy(*model_, state_);
}

}  // namespace drape::cloth
