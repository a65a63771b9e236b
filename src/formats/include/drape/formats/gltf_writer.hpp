#pragma once
// Animated glTF 2.0 binary (.glb) output through tinygltf, for any DCC tool or web viewer.
//
// Deforming meshes (garments, or body parts known only by their world positions) become
// one mesh each with a morph target per frame and a weights animation that switches from
// target to target (LINEAR, so viewers interpolate positions between frames). Rigid parts
// given as a rest mesh in their own frame plus a rigid transform per frame become nodes
// with translation/rotation (TRS) animation.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats {

/// A mesh whose vertices move freely: one morph target per frame.
struct GltfDeformingMesh {
  std::string name;
  std::vector<mesh::Triangle> triangles;
  std::vector<std::vector<Vec3>> frames;                   ///< world positions (m, Y up), per frame, all the same size
  std::array<float, 4> colour = {0.8f, 0.8f, 0.8f, 1.0f};  ///< linear RGBA base colour
  bool doubleSided = true;                                 ///< cloth: both sides visible
};

/// A rigid part: its mesh in its own frame, moved by one rigid transform per frame.
struct GltfRigidMesh {
  std::string name;
  mesh::TriMesh mesh;                  ///< m, in the part's (joint's) frame
  std::vector<RigidTransform> frames;  ///< part frame -> world, per frame
  std::array<float, 4> colour = {0.8f, 0.8f, 0.8f, 1.0f};
  bool doubleSided = false;
};

struct GltfAnimation {
  double frameRate = 30.0;  ///< frames per second of every `frames` list
  std::vector<GltfDeformingMesh> deforming;
  std::vector<GltfRigidMesh> rigid;
};

/// Writes `animation` as a binary glTF file. Every mesh must have the same number of
/// frames (at least one). Throws drape::Error naming the path or the mesh otherwise, or
/// when the file cannot be written.
void writeGlb(const std::string& path, const GltfAnimation& animation);

/// Fits the rigid motion taking `from` to `to` (least squares, Kabsch) and returns it with
/// the largest distance (m) between a moved `from` point and its `to` point.
struct RigidFit {
  RigidTransform transform;
  double maxError_m = 0.0;
};
[[nodiscard]] RigidFit fitRigid(const std::vector<Vec3>& from, const std::vector<Vec3>& to);

/// Which of a run's bodies an export carries.
enum class ExportedBody : std::uint8_t {
  /// The rigid parts the cloth collides with: a TRS-animated node each, kilobytes a part.
  Segments,
  /// The skinned body and its drawn meshes, as the players draw them (fitted and tucked under
  /// the cloth): a morph target per frame, tens of kilobytes a frame. A character without a
  /// skinned body keeps its segments.
  Skin,
};

/// Exports a run directory (manifest.json with OBJ + PC2 per mesh) to `glbPath`: garments
/// as morph-target meshes; segments as TRS-animated nodes when their caches move rigidly
/// (within `rigidTolerance_m`), else as morph-target meshes too; or, with `body` Skin, each
/// character's skinned body and drawn meshes instead of its segments.
struct RunExportSummary {
  std::size_t deforming = 0;
  std::size_t rigid = 0;
  std::size_t skins = 0;  ///< skinned bodies and drawn meshes written (ExportedBody::Skin)
  long frames = 0;
};
RunExportSummary exportRunToGlb(const std::string& runDirectory, const std::string& glbPath,
                                ExportedBody body = ExportedBody::Segments, double rigidTolerance_m = 1e-4);

}  // namespace drape::formats
