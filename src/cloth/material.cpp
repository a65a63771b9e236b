#include "drape/cloth/material.hpp"

#include <cmath>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

void require(bool ok, const std::string& prefix, const char* field, const std::string& what, double value) {
  if (!ok) throw Error(fmt::format("{}{} must be {}, got {}", prefix, field, what, value));
}

bool finite(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

}  // namespace

double Material::bendingModulus() const {
  if (bendingStiffness_Nm >= 0.0) return bendingStiffness_Nm;
  const double t = thickness_m;
  return youngsModulus_Pa * t * t * t / (12.0 * (1.0 - poissonRatio * poissonRatio));
}

void Material::validate(const std::string& prefix) const {
  // NaN fails every comparison, so each check is written as "ok when".
  require(density_kg_m3 > 0.0 && std::isfinite(density_kg_m3), prefix, "density", "> 0 kg/m^3", density_kg_m3);
  require(thickness_m > 0.0 && std::isfinite(thickness_m), prefix, "thickness", "> 0 m", thickness_m);
  require(youngsModulus_Pa > 0.0 && std::isfinite(youngsModulus_Pa), prefix, "youngs-modulus", "> 0 Pa",
          youngsModulus_Pa);
  require(poissonRatio >= 0.0 && poissonRatio < 0.5, prefix, "poisson-ratio", "in [0, 0.5)", poissonRatio);
  require(std::isfinite(bendingStiffness_Nm), prefix, "bending-stiffness", "finite (N m; negative: derived)",
          bendingStiffness_Nm);
  require(damping_s >= 0.0 && std::isfinite(damping_s), prefix, "damping", ">= 0 s", damping_s);
  require(staticFriction >= 0.0 && std::isfinite(staticFriction), prefix, "static-friction", ">= 0", staticFriction);
  require(dynamicFriction >= 0.0 && std::isfinite(dynamicFriction), prefix, "dynamic-friction", ">= 0",
          dynamicFriction);
  require(compressionScale > 0.0 && compressionScale <= 1.0, prefix, "compression-scale", "in (0, 1]",
          compressionScale);
}

std::string integratorName(IntegratorKind kind) {
  switch (kind) {
    case IntegratorKind::SymplecticEuler: return "symplectic-euler";
    case IntegratorKind::ForwardEuler: return "forward-euler";
    case IntegratorKind::BackwardEuler: return "backward-euler";
    case IntegratorKind::RungeKutta4: return "runge-kutta-4";
  }
  return "unknown";
}

IntegratorKind parseIntegrator(const std::string& text, const std::string& option) {
  if (text == "symplectic-euler") return IntegratorKind::SymplecticEuler;
  if (text == "forward-euler") return IntegratorKind::ForwardEuler;
  if (text == "backward-euler") return IntegratorKind::BackwardEuler;
  if (text == "runge-kutta-4") return IntegratorKind::RungeKutta4;
  throw Error(fmt::format("{} must be symplectic-euler, forward-euler, backward-euler or runge-kutta-4, got '{}'",
                          option, text));
}

int implicitSubstepsFor(int explicitSubsteps) { return std::max(2, (explicitSubsteps + 7) / 8); }

void StepSettings::validate(const std::string& prefix) const {
  require(frameRate_hz > 0.0 && std::isfinite(frameRate_hz), prefix, "frame-rate", "> 0 frames/s", frameRate_hz);
  require(substepsPerFrame >= 1 && substepsPerFrame <= 100000, prefix, "substeps", "in [1, 100000]",
          substepsPerFrame);
  require(airViscosity_Ns_m3 >= 0.0 && std::isfinite(airViscosity_Ns_m3), prefix, "air-viscosity",
          ">= 0 N s/m^3", airViscosity_Ns_m3);
  require(maxSpeed_m_s > 0.0, prefix, "max-speed", "> 0 m/s", maxSpeed_m_s);
  require(maxAddedMass >= 0.0 && maxAddedMass <= 10.0, prefix, "max-added-mass", "in [0, 10] (a fraction)",
          maxAddedMass);
  require(bendEvery >= 1 && bendEvery <= substepsPerFrame, prefix, "bend-every",
          fmt::format("in [1, {}] (the substeps per frame)", substepsPerFrame), bendEvery);
  require(implicitTolerance > 0.0 && implicitTolerance < 1.0, prefix, "implicit-tolerance", "in (0, 1)",
          implicitTolerance);
  require(bendEvery == 1 || integrator != IntegratorKind::BackwardEuler, prefix, "bend-every",
          "1 with the backward-euler integrator (its solve takes the bending forces in every substep)", bendEvery);
  require(bendEvery == 1 || integrator != IntegratorKind::RungeKutta4, prefix, "bend-every",
          "1 with the runge-kutta-4 integrator (each of its stages takes the bending forces)", bendEvery);
  require(maxRefinement >= 1 && maxRefinement <= 64, prefix, "max-refinement", "in [1, 64]", maxRefinement);
  require(strainLimit >= 0.0 && strainLimit <= 10.0, prefix, "strain-limit",
          "in [0, 10] (a stretch beyond the rest length)", strainLimit);
  require(rescueStrainLimit >= 0.0 && rescueStrainLimit <= 10.0, prefix, "strain-limit",
          "in [0, 10] (a stretch beyond the rest length)", rescueStrainLimit);
  if (!finite(gravity_m_s2)) throw Error(fmt::format("{}gravity must be finite", prefix));
  if (!finite(wind_m_s)) throw Error(fmt::format("{}wind must be finite", prefix));
}

}  // namespace drape::cloth
