#pragma once
// What `drape run` simulates, however it was described: garments (meshes in metres,
// materials, pinned vertices), settings, frame count and outputs. Built from command-line
// options today (cmd_run.cpp) and from a VRML97 scene later; both feed simulateRun(), the
// one loop that steps every garment and writes DIR/frames/, DIR/*.pc2, DIR/*.obj,
// DIR/stats.json and DIR/manifest.json.

#include <memory>
#include <string>
#include <vector>

#include "drape/cloth/collider.hpp"
#include "drape/cloth/material.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::cli {

struct GarmentSetup {
  std::string name;                    ///< for messages and file names ("dress")
  mesh::TriMesh mesh;                  ///< rest shape, m
  cloth::Material material;
  std::vector<std::uint32_t> pinned;   ///< vertices pinned in place (sorted, unique)
};

struct SphereSetup {
  Vec3 centre_m = Vec3::Zero();
  double radius_m = 0.0;
};

struct RunSetup {
  std::vector<GarmentSetup> garments;
  cloth::StepSettings settings;
  std::vector<SphereSetup> spheres;    ///< analytic sphere colliders (every garment collides)
  long frames = 0;                     ///< frames to simulate after the initial one
  long objEvery = 1;                   ///< write an OBJ frame every K frames
  std::string outDir;
};

/// Checks the setup (garment topology, materials, settings, pins) and throws drape::Error
/// (BadInput) with one line naming what is wrong.
void validateRunSetup(const RunSetup& setup);

/// The smallest substep count per frame that the explicit integrators are estimated to
/// keep stable for every garment (ClothModel::estimatedStableStep_s), at least 1.
[[nodiscard]] int stableSubsteps(const RunSetup& setup);

/// Simulates and writes every output. Returns 0; on instability it finishes the files
/// written so far (caches, stats with nan_detected, manifest) and throws drape::Error with
/// ExitCode::Unstable naming garment, vertex and frame.
int simulateRun(const RunSetup& setup);

}  // namespace drape::cli
