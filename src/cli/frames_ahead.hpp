#pragma once
// Simulating ahead of the outputs: `drape run` writes frame N (caches, OBJ frames, the
// skinned body fitted and tucked under the cloth) and `drape play SCENE` draws it while the
// next frames are simulated on a thread of their own (RunAhead).

#include <cstdint>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/core/run_ahead.hpp"
#include "stage_laps.hpp"

namespace drape::cli {

/// What the outputs need of one frame, taken from the solvers and the avatar's poses by the
/// simulating thread (the only one that touches them: the pose cache is not thread-safe).
struct FrameTaken {
  long frame = 0;
  std::vector<std::vector<Vec3>> positions;       ///< per garment
  std::vector<std::vector<std::uint8_t>> states;  ///< per garment, as the state caches store them
  std::vector<std::vector<RigidTransform>> joints;  ///< per character: its avatar's joints in the world
  StageMs stageMs{};                              ///< what each stage took for this frame
};

using FramesAhead = RunAhead<FrameTaken>;

/// How far the simulation may run ahead of the outputs: enough to even out frames that cost
/// more (a frame computed again, an OBJ frame written), few enough to hold little memory.
constexpr std::size_t kFramesAhead = 3;

}  // namespace drape::cli
