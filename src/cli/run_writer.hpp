#pragma once
// A run directory, frame by frame: what `drape run --out DIR` writes, and what `drape player
// --record DIR` writes from a studio's streams, with the same code so that the two are the
// same to the byte. docs/ARCHITECTURE.md lists the files.
//
//   DIR/garment[-NAME].obj, .pc2, .states   rest topology, positions and vertex states per frame
//   DIR/frames/*.obj                        every objEvery-th frame of each garment
//   DIR/segments/*.obj, *.pc2               the avatar's body parts, moving
//   DIR/body.obj, body.pc2                  the skinned body, fitted and tucked under the cloth
//   (with several characters, DIR/segments/CHARACTER/*.obj, *.pc2 and DIR/body-CHARACTER.obj, .pc2)
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

/// What the writer needs of a character before frame 0.
struct CharacterAtStart {
  /// The part fields its skinned body is fitted to (its world's); null: no skinned body.
  const std::vector<sim::PartField>* fields = nullptr;
  double skinAllowance_m = 0.0;        ///< how far out of them the skin may stand (leastT0)
  std::vector<RigidTransform> joints;  ///< its joints at frame 0
};

class RunWriter {
 public:
  /// Creates setup.outDir and writes the rest meshes: the garments, and per character of the
  /// setup (`characters`, in its order) its parts and skinned body.
  RunWriter(const RunSetup& setup, const std::vector<CharacterAtStart>& characters);
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
