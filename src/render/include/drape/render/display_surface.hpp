#pragma once
// The garments as pictures show them: Loop subdivision surfaces (OpenSubdiv) of the
// simulated meshes. The simulation's mesh is as coarse as its speed needs (the walking
// skirt's 480 triangles); drawn as it is, its hem is a polygon and its folds are facets.
// Drawn as the limit surface of a few uniform refinements it is smooth; moved out first by
// what the limit takes off at each simulated vertex, it passes near the simulated points,
// which are what the collisions keep out of the body (docs/PLAYER.md). Only the pictures
// change: every file a run writes keeps the simulated mesh.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/render/frame.hpp"

namespace drape::render {

/// How many refinements pictures use unless told otherwise: 16 triangles for each simulated one.
inline constexpr int kDefaultSubdivisionLevels = 2;

/// One mesh's Loop subdivision surface: its topology refined `levels` times, once; then,
/// per frame, the refined positions on the limit surface and the refined vertex states.
class LoopSurface {
 public:
  /// Throws drape::Error when OpenSubdiv does not accept the topology (a triangle that
  /// repeats a vertex, an index out of range) or `levels` is outside 1..8.
  LoopSurface(std::size_t vertexCount, std::span<const mesh::Triangle> triangles, int levels);
  ~LoopSurface();
  LoopSurface(LoopSurface&&) noexcept;
  LoopSurface& operator=(LoopSurface&&) noexcept;

  [[nodiscard]] std::size_t vertexCount() const;
  [[nodiscard]] const std::vector<mesh::Triangle>& triangles() const;
  /// The refined positions, on the limit surface (out is resized to vertexCount()).
  void positions(std::span<const Vec3> coarse, std::vector<Vec3>& out);
  /// The refined vertex states (frame.hpp, vertex_state): a vertex that a simulated vertex
  /// becomes keeps its state; the others take the collision state of the simulated vertex
  /// they are nearest to in the mesh (the heaviest in their subdivision rule) and no pin or
  /// bound flag, so that markers stay on the simulated vertices.
  void states(std::span<const std::uint8_t> coarse, std::vector<std::uint8_t>& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A FrameSource whose garments are drawn as LoopSurfaces of `levels` refinements (0: as
/// simulated); the other meshes (the body) pass through as they are. A garment whose
/// topology OpenSubdiv refuses is drawn as simulated, with a warning.
class SubdividedSource final : public FrameSource {
 public:
  SubdividedSource(FrameSource& inner, int levels);
  ~SubdividedSource() override;
  [[nodiscard]] const std::vector<MeshInfo>& meshes() const override { return meshes_; }
  [[nodiscard]] double frameRate() const override { return inner_.frameRate(); }
  [[nodiscard]] std::optional<std::int64_t> frameCount() const override { return inner_.frameCount(); }
  bool read(std::int64_t index, Frame& out) override;
  [[nodiscard]] bool ready(std::int64_t index) override { return inner_.ready(index); }

 private:
  FrameSource& inner_;
  std::vector<MeshInfo> meshes_;
  std::vector<std::optional<LoopSurface>> surfaces_;  ///< per mesh: its surface, or none (drawn as it is)
  Frame coarse_;
};

}  // namespace drape::render
