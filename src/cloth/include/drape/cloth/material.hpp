#pragma once
// What a garment is made of (Material) and how it is stepped (StepSettings). Both are plain
// creation structs with defaults; validate() checks them where they enter the system (the
// CLI, a scene loader) and throws drape::Error with one line: `prefix` + the field's name as
// the CLI spells it + what is wrong. The CLI passes "--" ("--density must be > 0 kg/m^3, got
// -1"); a scene loader passes e.g. "scene.wrl:12: ClothMaterial ".

#include <string>

#include "drape/core/math.hpp"

namespace drape::cloth {

/// A cloth material (paper section 4.1: density, thickness, Young's modulus, Poisson
/// coefficient). Defaults: a soft knit, about 0.2 kg/m^2 and a membrane stiffness E t of
/// 100 N/m, soft enough to stay stable with a few hundred substeps on garment meshes.
struct Material {
  double density_kg_m3 = 400.0;           ///< bulk density of the fabric, kg/m^3
  double thickness_m = 0.5e-3;            ///< m
  double youngsModulus_Pa = 2.0e5;        ///< in-plane Young's modulus E, Pa
  double poissonRatio = 0.3;              ///< nu, in [0, 0.5)
  double bendingStiffness_Nm = -1.0;      ///< D in N m; < 0: derived as E t^3 / (12 (1 - nu^2))
  double damping_s = 0.0;                 ///< stiffness-proportional (Rayleigh) damping time, s
  double staticFriction = 0.5;            ///< Coulomb coefficient against bodies (static)
  double dynamicFriction = 0.3;           ///< Coulomb coefficient against bodies (sliding)
  double compressionScale = 1.0;          ///< factor on compressive principal stresses, (0, 1]

  /// Membrane bending modulus actually used, N m.
  [[nodiscard]] double bendingModulus() const;
  /// Mass per area, kg/m^2.
  [[nodiscard]] double arealDensity() const { return density_kg_m3 * thickness_m; }
  /// Throws drape::Error(BadInput) on the first bad value (see the file comment).
  void validate(const std::string& prefix = "--") const;
};

enum class IntegratorKind {
  SymplecticEuler,  ///< v += a dt; x += v dt (default: stable for oscillators, energy bounded)
  ForwardEuler,     ///< x += v dt; v += a dt (the paper's solver)
  /// v += dt a(x + dt v_new, v_new), linearised once per substep and solved by conjugate
  /// gradients (Baraff and Witkin 1998; the paper's future work): stable at any substep.
  BackwardEuler,
  /// The classical fourth-order Runge-Kutta step (the paper's other future work): four
  /// force evaluations per substep, stable to a substep sqrt(2) times symplectic Euler's on
  /// an undamped oscillator; bending in every stage.
  RungeKutta4,
};

/// "symplectic-euler" / "forward-euler" / "backward-euler" / "runge-kutta-4".
[[nodiscard]] std::string integratorName(IntegratorKind kind);
/// Parses the names above; throws drape::Error naming `option` otherwise.
[[nodiscard]] IntegratorKind parseIntegrator(const std::string& text, const std::string& option = "--integrator");
/// Substeps per frame to give backward Euler where the explicit steps need
/// `explicitSubsteps`: an eighth, at least 2. Measured on the bundled garments
/// (docs/PERFORMANCE.md, "Backward Euler"): the skirt at an eighth of its 33 stays out of
/// the body; the dress at an eighth of its 155 stays out of it too, with about 1.3 times the
/// explicit step's share of vertex-substeps below T1 (its pinched points held in the solve,
/// crease moves checked: "Long projections read again, crease moves checked"), at 1.1 to 1.5
/// times its speed; fewer
/// substeps lengthen the collision response's stride further.
[[nodiscard]] int implicitSubstepsFor(int explicitSubsteps);

/// Mass scaling (explicit finite elements' standard remedy for a few tiny elements): mass is
/// added to the triangles and hinges whose own stable step is shorter than targetStep_s,
/// until it is not; the rest of the garment is untouched. Off when targetStep_s is 0.
struct MassScaling {
  double targetStep_s = 0.0;      ///< the substep the model must stay stable at, s
  double maxAddedFraction = 0.0;  ///< largest added mass, as a fraction of the garment's mass
  double frameRate_hz = 0.0;      ///< for messages: substeps per frame instead of seconds
  /// Whose stability bound the masses are scaled for: symplectic Euler's (also taken for
  /// forward Euler, whose damping window the solver checks), or the Runge-Kutta step's,
  /// which is the longer on every mode and so needs less mass at the same substep.
  IntegratorKind integrator = IntegratorKind::SymplecticEuler;
};

/// Environment and time stepping (the paper's Simulation node).
struct StepSettings {
  Vec3 gravity_m_s2 = Vec3(0.0, -9.81, 0.0);  ///< Y up, as the run manifest says
  double frameRate_hz = 30.0;                 ///< output frames per second
  int substepsPerFrame = 33;                  ///< explicit steps per frame (the paper: ~30)
  double airViscosity_Ns_m3 = 0.5;            ///< linear drag per area: f = -c A (v - wind), N s/m^3
  Vec3 wind_m_s = Vec3::Zero();               ///< constant wind velocity, m/s
  IntegratorKind integrator = IntegratorKind::SymplecticEuler;
  double maxSpeed_m_s = 50.0;                 ///< stability guard: faster vertices mean divergence
  /// Mass scaling allowed to keep substep_s() stable, as a fraction of each garment's mass;
  /// 0: none (a substep above the stable step is only warned about).
  double maxAddedMass = 0.0;
  /// Multiple time stepping: bending, the slow force, is evaluated every bendEvery-th substep
  /// and applied there as an impulse over the bendEvery substeps (r-RESPA); 1: every substep.
  int bendEvery = 1;
  /// A frame that goes unstable (a NaN, a vertex beyond maxSpeed) is computed again from its
  /// start with 2, 4, ... times the substeps, up to this factor, before the instability is
  /// reported (ClothSolver::stepFrame); 1: reported at once, the fixed step as it is.
  int maxRefinement = 8;
  /// Strain limiting (strain_limit.hpp) from the first frame: after each substep's
  /// collisions and fixtures, edges longer than (1 + strainLimit) times their rest length
  /// are pulled back to it (two sweeps, so a little may be left to the next substep where
  /// edges share a vertex); 0: none.
  double strainLimit = 0.0;
  /// A frame that goes unstable even with maxRefinement times the substeps is computed once
  /// more from its start with strain limiting at this limit, which then stays on for the rest
  /// of the run (ClothSolver::stepFrame); 0: the instability is reported instead. Without
  /// effect when strainLimit is already on.
  double rescueStrainLimit = 0.5;
  /// Backward Euler: a substep's linear solve stops when its residual, in the
  /// preconditioner's norm, is this fraction of the right-hand side's.
  double implicitTolerance = 1e-3;

  [[nodiscard]] double substep_s() const { return 1.0 / (frameRate_hz * substepsPerFrame); }
  /// Switches to `kind`. Backward Euler takes bending into its solve every substep, and the
  /// Runge-Kutta step into every stage, so a rhythm set for symplectic Euler (bendEvery)
  /// gives way to 1.
  void useIntegrator(IntegratorKind kind) {
    integrator = kind;
    if (!oneStageExplicit(kind)) bendEvery = 1;
  }
  /// Whether `kind` is a one-stage explicit step (symplectic or forward Euler): those alone
  /// take bending as an impulse every bendEvery substeps.
  [[nodiscard]] static bool oneStageExplicit(IntegratorKind kind) {
    return kind == IntegratorKind::SymplecticEuler || kind == IntegratorKind::ForwardEuler;
  }
  /// What ClothModel::build needs to honour maxAddedMass: none for the implicit step, which
  /// needs no mass added to be stable; for the Runge-Kutta step, the mass its own bound asks.
  [[nodiscard]] MassScaling massScaling() const {
    if (!(maxAddedMass > 0.0) || integrator == IntegratorKind::BackwardEuler) return {};
    return {substep_s(), maxAddedMass, frameRate_hz, massScalingBound()};
  }
  /// Whose stability bound mass scaling aims at for this integrator (MassScaling::integrator).
  [[nodiscard]] IntegratorKind massScalingBound() const {
    return integrator == IntegratorKind::RungeKutta4 ? integrator : IntegratorKind::SymplecticEuler;
  }
  void validate(const std::string& prefix = "--") const;
};

}  // namespace drape::cloth
