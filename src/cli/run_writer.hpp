#pragma once
// A run directory, frame by frame: what `drape run --out DIR` writes, and what `drape player
// --record DIR` writes from a studio's streams, with the same code so that the two are the
// same to the byte. docs/ARCHITECTURE.md lists the files.
//
//   DIR/garment[-NAME].obj, .pc2, .states   rest topology, positions and vertex states per frame
//   DIR/frames/*.obj                        every objEvery-th frame of each garment
//   DIR/segments/*.obj, *.pc2               the avatar's body parts, moving
//   DIR/body.obj, body.pc2                  the skinned body, fitted and tucked under the cloth
//   DIR/manifest.json, result.wrl, result.glb, stats.json, and with preview the contact sheet

#include <memory>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "drape/core/math.hpp"
#include "drape/sim/character_world.hpp"
#include "frames_ahead.hpp"
#include "run_setup.hpp"

namespace drape::cli {

class RunWriter {
 public:
  /// Creates setup.outDir and writes the rest meshes. With a character, `fields` are the
  /// part fields the skinned body is fitted to (the world's), `skinAllowance_m` how far out
  /// of them it may stand (leastT0), `jointsAtStart` the joints at frame 0.
  RunWriter(const RunSetup& setup, const std::vector<sim::PartField>* fields, double skinAllowance_m,
            std::span<const RigidTransform> jointsAtStart);
  ~RunWriter();
  RunWriter(const RunWriter&) = delete;
  RunWriter& operator=(const RunWriter&) = delete;

  /// One frame, in order from 0.
  void write(const FrameTaken& frame);
  /// Closes the caches and writes manifest.json, result.wrl, result.glb and, when the setup
  /// asks, the preview: `frames` frames after frame 0 were written.
  void close(long frames);
  /// DIR/stats.json.
  void writeStats(const nlohmann::json& stats) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Creates DIR and DIR/frames; throws drape::Error naming --out when it cannot.
void createOutDir(const std::string& dir);

}  // namespace drape::cli
