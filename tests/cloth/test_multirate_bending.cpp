// Multiple time stepping of the bending forces (StepSettings::bendEvery): the slow force as
// one impulse every k substeps must give the same statics as every substep, stay
// energy-bounded, and be refused beyond the bending forces' stable step.
#include <gtest/gtest.h>

#include <cmath>

#include <fmt/format.h>

#include "cloth_fixture.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

using testing::column;
using testing::makeModel;
using testing::pinAt;
using testing::run;
using testing::settingsWithStep;

/// The largest k whose k substeps stay within the bending forces' stable step.
int largestBendEvery(const ClothModel& model, const StepSettings& s) {
  return static_cast<int>(std::min<double>(s.substepsPerFrame, model.bendingStableStep_s() / s.substep_s()));
}

// A thin, stiff cantilever (t / h = 0.05: the membrane limits the step, bending is slow)
// clamped along one edge sags to the Euler-Bernoulli tip deflection rho t g L^4 / (8 D).
// Bending as an impulse every k substeps must reach the same rest shape as every substep:
// were the impulse not k substeps' worth, the tip would sag k times as far.
struct Cantilever {
  double L = 0.2, W = 0.2, h = 0.02, E = 1.3e9, t = 1e-3, rho = 1.0 / 1e-3;
  SheetSpec spec{L + h, W, static_cast<int>(std::lround(L / h)) + 1, static_cast<int>(std::lround(W / h)),
                 Vec3(-h, 0, 0), Vec3::UnitX(), Vec3::UnitZ(), "cantilever"};

  [[nodiscard]] double expectedTip() const {
    const double D = testing::fabric(E, t, rho).bendingModulus();
    return rho * t * 9.81 * std::pow(L + 0.5 * h, 4) / (8 * D);
  }
  /// Tip deflection after `seconds` with bending every `every` substeps (0: the largest
  /// stable k, returned in *used).
  double tip(int every, double seconds, int* used = nullptr) const {
    auto model = makeModel(gridSheet(spec), testing::fabric(E, t, rho));
    StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 60.0);
    settings.bendEvery = every > 0 ? every : std::min(8, largestBendEvery(*model, settings));
    if (used != nullptr) *used = settings.bendEvery;
    std::vector<std::uint32_t> clamp = column(spec, 0);
    for (std::uint32_t v : column(spec, 1)) clamp.push_back(v);
    ClothSolver solver(model, settings, {pinAt(*model, clamp)});
    EXPECT_TRUE(run(solver, static_cast<long>(seconds / settings.substep_s())));
    double sum = 0.0;  // mean over the free edge
    for (std::uint32_t v : column(spec, spec.cellsU)) sum -= solver.state().y[v];
    return sum / (spec.cellsV + 1);
  }
};

TEST(MultirateBending, CantileverSagsAsWhenBendingEverySubstep) {
  const Cantilever c;
  int k = 0;
  const double multirate = c.tip(0, 0.5, &k);
  ASSERT_GE(k, 4) << "the test needs a plate whose bending is much slower than its membrane";
  const double everySubstep = c.tip(1, 0.5);
  const double expected = c.expectedTip();
  EXPECT_NEAR(everySubstep, expected, 0.2 * expected);
  EXPECT_NEAR(multirate, everySubstep, 0.01 * everySubstep) << "bending every " << k << " substeps";
}

// Without damping or drag a swinging sheet keeps its total energy within a small band over
// 10,000 substeps when its bending comes as an impulse every k substeps (the impulse
// method is symplectic, like the symplectic Euler step inside it).
TEST(MultirateBending, EnergyStaysBounded) {
  SheetSpec spec{0.3, 0.3, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "sheet"};
  Material m = testing::fabric(2e4, 1e-3, 300);
  m.bendingStiffness_Nm = 2e-5;  // a fold that swings: bending matters to the motion
  auto model = makeModel(gridSheet(spec), m);
  StepSettings settings = settingsWithStep(0.3 * model->estimatedStableStep_s(), 0.0);
  settings.bendEvery = std::min(6, largestBendEvery(*model, settings));
  ASSERT_GE(settings.bendEvery, 3);
  ClothSolver solver(model, settings, {pinAt(*model, {sheetVertex(spec, 0, 0), sheetVertex(spec, 6, 0)})});
  const double e0 = solver.totalEnergy();
  double drift = 0.0, maxKinetic = 0.0, maxBending = 0.0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_TRUE(run(solver, 102));  // a multiple of bendEvery for 3 and 6
    drift = std::max(drift, std::abs(solver.totalEnergy() - e0));
    maxKinetic = std::max(maxKinetic, kineticEnergy(*model, solver.state()));
    maxBending = std::max(maxBending, bendingEnergy(*model, solver.state()));
  }
  ASSERT_GT(maxKinetic, 1e-3);
  ASSERT_GT(maxBending, 1e-3 * maxKinetic);
  EXPECT_LT(drift, 0.02 * maxKinetic);
}

TEST(MultirateBending, ASpanBeyondTheStableStepIsRefusedNamingTheLargest) {
  SheetSpec spec{0.3, 0.3, 6, 6, Vec3::Zero(), Vec3::UnitX(), Vec3::UnitZ(), "stiff"};
  Material m = testing::fabric(2e4, 1e-3, 300);
  m.bendingStiffness_Nm = 1e-2;  // bending-limited: the largest stable k is small
  auto model = makeModel(gridSheet(spec), m);
  StepSettings settings = settingsWithStep(0.5 * model->estimatedStableStep_s(), 0.0);
  const int largest = largestBendEvery(*model, settings);
  ASSERT_LT(largest, settings.substepsPerFrame);
  settings.bendEvery = largest + 1;
  try {
    ClothSolver solver(model, settings);
    FAIL() << "bendEvery " << settings.bendEvery << " was accepted";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("garment 'stiff'"), std::string::npos) << what;
    EXPECT_NE(what.find(fmt::format("set bendEvery (--bend-every) to {} or less", std::max(1, largest))), std::string::npos) << what;
  }
  settings.bendEvery = std::max(1, largest);
  EXPECT_NO_THROW(ClothSolver(model, settings));
}

}  // namespace
}  // namespace drape::cloth
