#pragma once
// Replays a finished run directory (DIR/manifest.json, its OBJ topologies and PC2 caches,
// the garments' state caches and DIR/stats.json's stage times when present) as a
// FrameSource.

#include <span>
#include <string>

#include "drape/render/frame.hpp"

namespace drape::render {

class RunReplay final : public FrameSource {
 public:
  /// Reads the whole run; throws drape::Error naming the file on a missing or bad file,
  /// or on a cache whose point count or frame count disagrees with its topology or manifest.
  explicit RunReplay(const std::string& directory);

  [[nodiscard]] const std::vector<MeshInfo>& meshes() const override { return meshes_; }
  [[nodiscard]] double frameRate() const override { return frameRate_; }
  [[nodiscard]] std::optional<std::int64_t> frameCount() const override { return frames_; }
  bool read(std::int64_t index, Frame& out) override;

  [[nodiscard]] std::int64_t startFrame() const { return startFrame_; }
  [[nodiscard]] const std::string& directory() const { return directory_; }
  /// Bounds over every frame of every mesh (m): what the camera frames.
  [[nodiscard]] Aabb bounds() const { return bounds_; }
  /// Bounds of every mesh at frame `f` alone (m): what a camera that follows frames.
  [[nodiscard]] Aabb frameBounds(std::int64_t f) const;
  /// Whether some mesh has per-vertex states (a state cache; runs made before drape wrote
  /// them have none, and their overlays that need states show nothing).
  [[nodiscard]] bool hasStates() const {
    for (const auto& s : states_)
      if (!s.empty()) return true;
    return false;
  }
  /// World positions of mesh `m` at frame `f` (m).
  [[nodiscard]] const std::vector<Vec3>& positions(std::size_t m, std::int64_t f) const {
    return caches_[m][static_cast<std::size_t>(f)];
  }
  /// The vertex_state bytes of mesh `m` at frame `f`; empty for a mesh without a state cache.
  [[nodiscard]] std::span<const std::uint8_t> states(std::size_t m, std::int64_t f) const {
    if (states_[m].empty()) return {};
    return states_[m][static_cast<std::size_t>(f)];
  }

 private:
  std::string directory_;
  std::vector<MeshInfo> meshes_;
  std::vector<std::vector<std::vector<Vec3>>> caches_;  ///< [mesh][frame][vertex], m
  std::vector<std::vector<std::vector<std::uint8_t>>> states_;  ///< [mesh][frame][vertex], or [mesh] empty
  /// From stats.json: [frame][stage], or one list of the run's means, or none.
  std::vector<std::vector<StageTime>> stages_;
  double frameRate_ = 30.0;
  std::int64_t frames_ = 0;
  std::int64_t startFrame_ = 0;
  Aabb bounds_;
};

}  // namespace drape::render
