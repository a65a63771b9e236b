#pragma once
// Bullet's soft bodies on `drape bench cloth`'s scenario: a 1 m square sheet of 1 kg, pinned
// at the two corners of one edge, falling onto a sphere. `drape bench cloth` runs it as the
// peer of drape's own sheet; `drape bench paper` times its smallest case in the same run as
// a fixed reference workload, so that the scenario's speed can be read against what the
// machine gives at that moment (a shared host's speed moves by a third from day to day).

#include <memory>
#include <string>

#include "drape/core/math.hpp"

namespace drape::cli {

/// The scenario, fixed before any measurement.
struct SheetScenario {
  static constexpr double kFrameRate = 30.0;
  static constexpr int kSubsteps = 33;
  static constexpr double kSpeedBound_m_s = 50.0;  ///< faster than this: diverged
  static constexpr double kSphereRadius = 0.25;
  /// The sheet spans x, z in [0, 1] at y = 0; the sphere is 0.4 m below, a little off centre.
  static Vec3 sphereCentre() { return {0.55, -0.4, 0.55}; }
};

/// One run of Bullet's sheet.
struct BulletSheetRun {
  double msPerFrame = 0.0;  ///< this thread's CPU time per frame
  bool diverged = false;    ///< NaN, or a node faster than the speed bound
  std::string why;          ///< the first node and frame that diverged
  double maxStrain = 0.0;   ///< the largest link strain at the end
};

/// The sheet of cellsU x cellsV cells (with diagonals) in Bullet's btSoftRigidDynamicsWorld
/// at 33 substeps per frame, stepped a few frames at a time: `drape bench paper` interleaves
/// it with the scenario's frames, so that the two are timed on the host in the same state.
class BulletSheet {
 public:
  BulletSheet(int cellsU, int cellsV);
  ~BulletSheet();
  BulletSheet(const BulletSheet&) = delete;
  BulletSheet& operator=(const BulletSheet&) = delete;

  /// Steps until `frames` frames in all have been stepped, or the sheet has gone NaN.
  void stepTo(long frames);
  [[nodiscard]] long frames() const { return frames_; }
  /// The run so far (its CPU time in stepTo, the divergence checks included, per frame),
  /// with the links' largest strain now.
  [[nodiscard]] BulletSheetRun result() const;

 private:
  struct World;
  std::unique_ptr<World> world_;
  long frames_ = 0;
  double cpuSeconds_ = 0.0;
  bool nan_ = false;
  BulletSheetRun run_;
};

/// Runs the sheet for `frames` frames in one go.
[[nodiscard]] BulletSheetRun runBulletSheet(int cellsU, int cellsV, long frames);

/// Bullet's version and the soft body's settings, for the benchmarks' JSON.
[[nodiscard]] std::string bulletVersion();
inline constexpr const char* kBulletSheetSettings =
    "btSoftRigidDynamicsWorld, CreatePatch with diagonals, kLST 1, 2 position iterations, 33 substeps, total mass "
    "1 kg, float";

}  // namespace drape::cli
