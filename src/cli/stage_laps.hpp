#pragma once
// The milliseconds each simulation stage took for one frame, from the solvers' running
// totals: stats.json's `frame_ms_per_stage` (drape run) and the live player's overlay
// (drape play SCENE) show a frame's own times, where a frame computed again costs more.
// And the garments' totals added up, with the step time the collision share divides by.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "drape/cloth/solver.hpp"
#include "drape/render/frame.hpp"

namespace drape::cli {

/// The stages stats.json names (`ms_per_stage`, `frame_ms_per_stage`), in that order.
inline constexpr std::array<const char*, 5> kStageNames{"forces", "integrate", "collide", "fixtures", "strain_limit"};

using StageMs = std::array<double, kStageNames.size()>;

/// A solver's running totals in milliseconds per stage; the stability check counts with the
/// fixtures, as stats.json has always reported it.
[[nodiscard]] inline StageMs stageTotalsMs(const cloth::StageTimes& t) {
  return {1e3 * t.forces_s, 1e3 * t.integrate_s, 1e3 * t.collide_s, 1e3 * (t.fixtures_s + t.stability_s),
          1e3 * t.strainLimit_s};
}

/// The garments' stage times added up, stage by stage.
inline cloth::StageTimes& operator+=(cloth::StageTimes& a, const cloth::StageTimes& b) {
  a.forces_s += b.forces_s;
  a.integrate_s += b.integrate_s;
  a.collide_s += b.collide_s;
  a.fixtures_s += b.fixtures_s;
  a.fixturePoses_s += b.fixturePoses_s;
  a.strainLimit_s += b.strainLimit_s;
  a.stability_s += b.stability_s;
  return a;
}

/// The step's work as the collision share counts it (`drape bench paper` and stats.json's
/// `collision_time_share`, after the paper's Table 3): forces, integration, collision,
/// fixtures and the stability check; strain limiting, which only a rescue turns on, aside.
[[nodiscard]] inline double stepSeconds(const cloth::StageTimes& t) {
  return t.forces_s + t.integrate_s + t.collide_s + t.fixtures_s + t.stability_s;
}

inline StageMs& operator+=(StageMs& a, const StageMs& b) {
  for (std::size_t i = 0; i < a.size(); ++i) a[i] += b[i];
  return a;
}

/// The totals' growth from one call to the next: a frame's own time per stage.
class StageLaps {
 public:
  /// Milliseconds per stage since the last call (the first: since the totals started).
  [[nodiscard]] StageMs lap(const StageMs& totals) {
    StageMs since{};
    for (std::size_t i = 0; i < since.size(); ++i) since[i] = totals[i] - last_[i];
    last_ = totals;
    return since;
  }

 private:
  StageMs last_{};
};

/// For the overlay: the stages that took any time, by name.
[[nodiscard]] inline std::vector<render::StageTime> stagesTaken(const StageMs& ms) {
  std::vector<render::StageTime> stages;
  for (std::size_t i = 0; i < ms.size(); ++i)
    if (ms[i] > 0.0) stages.push_back({kStageNames[i], ms[i]});
  return stages;
}

}  // namespace drape::cli
