#pragma once
// ClothSolver: one garment instance stepping through time. The frame step is a visible loop
// of substeps, each a short list of named phases (STYLE habit 2):
//
//   accumulate forces -> integrate -> collide -> apply fixtures -> [limit strain] -> check stability
//
// with wall-clock time per phase (strain limiting only once on: StepSettings::strainLimit,
// or the rescue of a frame no refinement keeps stable). Nothing allocates inside the loop,
// and the same input gives bit-identical results. Instability (a NaN or a vertex faster
// than the bound) stops the step and comes back as a report, never as an exception from
// inside the loop.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "drape/cloth/collider.hpp"
#include "drape/cloth/fixture.hpp"
#include "drape/cloth/forces.hpp"
#include "drape/cloth/integrator.hpp"
#include "drape/cloth/material.hpp"
#include "drape/cloth/model.hpp"
#include "drape/cloth/state.hpp"
#include "drape/cloth/strain_limit.hpp"
#include "drape/core/stage_clock.hpp"

namespace drape::cloth {

/// Stage clock ticks per phase, accumulated over the substeps run so far (StageTimes in seconds).
struct StageTicks {
  StageClock::Ticks forces = 0, integrate = 0, collide = 0, fixtures = 0, fixturePoses = 0, strainLimit = 0,
                    stability = 0;
};

/// Seconds spent per phase, accumulated over the substeps run so far.
struct StageTimes {
  double forces_s = 0.0;
  double integrate_s = 0.0;     ///< with the Runge-Kutta step's three later stages' forces
  double collide_s = 0.0;
  double fixtures_s = 0.0;      ///< the fixtures, and the stitches held after them (ClothSolver::setStitches)
  double fixturePoses_s = 0.0;  ///< the part of fixtures_s spent asking for the fixtures' poses
  double strainLimit_s = 0.0;   ///< strain limiting, once on (StepSettings::strainLimit, rescueStrainLimit)
  double stability_s = 0.0;
};

/// Why a step stopped: the first vertex found with a non-finite value or excessive speed.
struct Instability {
  bool detected = false;
  bool nan = false;           ///< a NaN or infinity (else: the speed bound)
  std::uint32_t vertex = 0;
  double speed_m_s = 0.0;
  long frame = 0;             ///< the frame being computed
  int substep = 0;
  int substepsPerFrame = 0;   ///< of the attempt that went unstable
  /// How many times the settings' substeps that attempt took (StepSettings::maxRefinement):
  /// 1 unless the frame had gone unstable with fewer.
  int refinement = 1;
  /// The strain limit on in that attempt (0: none), and whether the run's rescue turned it on.
  double strainLimit = 0.0;
  bool rescued = false;
  /// "garment 'dress': vertex 12 reached 73.2 m/s (bound 50 m/s) in frame 4, substep 17".
  [[nodiscard]] std::string describe(const std::string& garment, double bound_m_s) const;
};

/// Throws drape::Error, naming the garment and the largest bendEvery that is stable, when
/// settings.bendEvery substeps exceed the model's bending forces' stable step (the solver
/// checks it; a caller may check it before costlier set-up).
void checkBendingStep(const ClothModel& model, const StepSettings& settings);

/// Throws drape::Error, naming the garment, the most damping the substep allows and the
/// substeps per frame the damping needs, when the material's internal damping makes the
/// symplectic Euler substep unstable (dampedStableStep_s with `omega_rad_s`, the membrane's
/// highest frequency, ClothModel::membraneFrequency_rad_s; forward Euler has
/// checkForwardEulerStep). A substep too long even without damping is left to the
/// wave-speed estimate's warning. The solver checks it.
void checkDampedStep(const ClothModel& model, const StepSettings& settings, double omega_rad_s);

/// Throws drape::Error, naming the garment and the damping window that would work (or the
/// substeps per frame that open one), when forward Euler cannot keep the membrane stable:
/// internal damping outside forwardEulerDampingWindow(omega_rad_s, dt), undamped included.
/// The solver checks it for forward Euler, with omega_rad_s measured with the pins held.
void checkForwardEulerStep(const ClothModel& model, const StepSettings& settings, double omega_rad_s);

/// Throws drape::Error, naming the garment, the longest stable substep and the substeps per
/// frame it needs, when the classical Runge-Kutta step cannot keep the membrane's stiffest
/// mode (`omega_rad_s`, measured with the pins held) stable at the settings' substep with the
/// material's damping (rungeKuttaStableStep_s). The solver checks it for that integrator.
void checkRungeKuttaStep(const ClothModel& model, const StepSettings& settings, double omega_rad_s);

class ClothSolver {
 public:
  ClothSolver(std::shared_ptr<const ClothModel> model, const StepSettings& settings, std::vector<PinGroup> pins = {});

  /// Adds a collider (not owned; it must outlive the solver's steps).
  void addCollider(Collider& collider) { colliders_.push_back(&collider); }
  /// The garment's stitches (holdStitches), held after the fixtures on every substep.
  /// Throws drape::Error, naming the garment (StepSettings has no name: `garment`), on a
  /// vertex out of range, a stitch from a vertex to itself or a length that is negative or
  /// not finite.
  void setStitches(std::vector<Stitch> stitches, const std::string& garment);
  [[nodiscard]] const std::vector<Stitch>& stitches() const { return stitches_; }
  /// Stitch corrections made so far (holdStitches's count).
  [[nodiscard]] std::size_t stitchCorrections() const { return stitchCorrections_; }

  /// Computes frame `frame` (1-based: frame 0 is the initial state; frames up to 0 settle
  /// a garment before it, CharacterWorld::settle) from the current state:
  /// settings.substepsPerFrame substeps covering [(frame - 1) / fps, frame / fps]. When the
  /// guard trips, the frame is computed again from its start with twice the substeps, and
  /// again, up to settings.maxRefinement times as many (the colliders start the frame over,
  /// Collider::restartFrame); the next frame goes back to the settings' substeps. When that
  /// fails too and strain limiting is off, the frame is computed again with strain limiting
  /// at settings.rescueStrainLimit, which then stays on (strainLimitedFrom()). Returns false
  /// and fills instability() when the guard trips on the last attempt (the state is left as
  /// it was at that substep).
  bool stepFrame(long frame);
  /// How many times the settings' substeps the last frame took (1: it was stable with them).
  [[nodiscard]] int lastRefinement() const { return lastRefinement_; }
  /// Frames computed again with more substeps, so far.
  [[nodiscard]] long refinedFrames() const { return refinedFrames_; }
  /// Why the last refined frame was computed again: the first attempt's instability.
  [[nodiscard]] const Instability& refinedBecause() const { return refinedBecause_; }
  /// The strain limit on now (StepSettings::strainLimit, or the rescue's once it came; 0: none).
  [[nodiscard]] double strainLimit() const { return strainLimit_; }
  /// The frame the rescue turned strain limiting on in (0: it has not), and why: the
  /// instability of that frame's last attempt without it.
  [[nodiscard]] long strainLimitedFrom() const { return strainLimitedFrom_; }
  [[nodiscard]] const Instability& strainLimitedBecause() const { return strainLimitedBecause_; }
  /// Edge corrections strain limiting made so far (limitStrain's count).
  [[nodiscard]] std::size_t strainLimitCorrections() const { return strainLimitCorrections_; }

  /// One substep over [t0, t0 + dt] (exposed for tests); returns false on instability.
  bool substep(double t0_s, long frame, int substepIndex);
  /// The same over [t0, t1] with t1 given (t1 - t0 is the substep up to rounding), so that
  /// consecutive substeps share their boundary times bit for bit and every pose is
  /// evaluated once per time.
  bool substep(double t0_s, double t1_s, long frame, int substepIndex);

  [[nodiscard]] const ClothModel& model() const { return *model_; }
  [[nodiscard]] const StepSettings& settings() const { return settings_; }
  /// The wind from the next substep on (a scripted event graph changes it from frame to
  /// frame, docs/EVENTS.md); throws drape::Error when it is not finite.
  void setWind(const Vec3& wind_m_s);
  [[nodiscard]] const ClothState& state() const { return state_; }
  /// Mutable state for set-up (initial velocities, tests). Not during a step.
  [[nodiscard]] ClothState& mutableState() { return state_; }
  [[nodiscard]] StageTimes stageTimes() const;
  /// Starts stageTimes again from zero (work before the frames timed, such as settling).
  void resetStageTimes() { ticks_ = {}; }
  [[nodiscard]] const Instability& instability() const { return instability_; }
  [[nodiscard]] const std::vector<Collider*>& colliders() const { return colliders_; }
  /// The pinned vertices (no motion) and the bound ones (following a body part).
  [[nodiscard]] const std::vector<PinGroup>& pins() const { return pins_; }
  /// With internal damping and symplectic Euler, with forward Euler, or with Runge-Kutta: the
  /// membrane's highest frequency with the pinned and bound vertices held, which
  /// checkDampedStep, checkForwardEulerStep or checkRungeKuttaStep judged the substep by;
  /// else 0.
  [[nodiscard]] double dampedMembraneFrequency_rad_s() const { return dampedOmega_; }
  /// Total energy (kinetic + gravitational + membrane + bending), J.
  [[nodiscard]] double totalEnergy() const;
  /// The implicit integrator's linear solves so far (zeros for the explicit ones).
  [[nodiscard]] SolveStats solveStats() const { return integrator_->solveStats(); }

 private:
  /// The frame at 1, 2, 4, ... times the settings' substeps up to maxRefinement, each attempt
  /// from the frame's start; false when the last attempt trips the guard.
  bool climbRefinements(long frame);
  /// Puts back the state and the colliders as they were at the frame's start.
  void restartFrame(long frame);
  /// The frame's substeps at `refinement` times the settings' count; false when the guard trips.
  bool runFrame(long frame, int refinement);
  void limitStrain();
  void accumulateForces();
  void integrate(double dt_s);
  void collide(double t0_s, double t1_s);
  void applyFixtures(double t0_s, double t1_s, double dt_s);
  void applyFixture(const PinGroup& g, double t0_s, double t1_s, double dt_s);
  void checkPinGroups();
  bool checkStability(long frame, int substepIndex);

  std::shared_ptr<const ClothModel> model_;
  StepSettings settings_;
  std::vector<PinGroup> pins_;
  std::vector<std::uint32_t> blended_;  ///< vertices placed by weighted groups
  std::unique_ptr<Integrator> integrator_;
  std::vector<Collider*> colliders_;
  ClothState state_;
  StageTicks ticks_;
  Instability instability_;
  long substepCount_ = 0;  ///< substeps taken, for the bending rhythm
  /// Whether more than one thread was allowed when the solver was made (threadsAllowed):
  /// the force kernels of a large model then run on TBB's threads, in forceLoops_.
  bool parallelForces_ = false;
  ForceLoops forceLoops_;
  double dt_ = 0.0;        ///< the substep being taken, s (shorter in a refined frame)
  int substepsPerFrame_ = 0;  ///< of the frame being computed
  int refinement_ = 1;        ///< of the frame being computed
  /// Where the frame being computed started, to compute it again (stepFrame): positions
  /// and velocities (the forces and the kernels' workspace are rebuilt every substep).
  std::array<std::vector<double>, 6> frameStart_;
  long frameStartSubsteps_ = 0;
  int lastRefinement_ = 1;
  long refinedFrames_ = 0;
  Instability refinedBecause_;
  /// Strain limiting: the limit on (0: none), the weights it and the stitches move vertices
  /// by (inverse masses, 0 for the pinned and bound ones), since which frame the rescue has
  /// had it on.
  double strainLimit_ = 0.0;
  std::vector<double> strainWeight_;
  long strainLimitedFrom_ = 0;
  Instability strainLimitedBecause_;
  std::size_t strainLimitCorrections_ = 0;
  std::vector<Stitch> stitches_;
  std::size_t stitchCorrections_ = 0;
  double dampedOmega_ = 0.0;  ///< dampedMembraneFrequency_rad_s
};

/// What the last frame's refinement was, for a log line: "garment 'dress': vertex 1046
/// reached 74.08 m/s (bound 50 m/s) in frame 26, substep 115; computed again with 2 times
/// the substeps (310 per frame)". Empty when the frame was stable at once.
[[nodiscard]] std::string describeRefinedFrame(const ClothSolver& solver, const std::string& garment);

/// When strain limiting came on in `frame` (StepSettings::rescueStrainLimit), for a log
/// line: why, and what it does from then on. Empty otherwise.
[[nodiscard]] std::string describeStrainLimitRescue(const ClothSolver& solver, const std::string& garment,
                                                    long frame);

}  // namespace drape::cloth
