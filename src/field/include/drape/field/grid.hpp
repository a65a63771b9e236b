#pragma once
// Voxel grid vocabulary shared by voxelization, propagation and the distance field.
// Voxel (x, y, z) has the linear index x + nx * (y + ny * z): x varies fastest.

#include <cstddef>
#include <cstdint>

namespace drape::field {

/// Grid dimensions in voxels.
struct GridDims {
  int nx = 0;
  int ny = 0;
  int nz = 0;

  [[nodiscard]] std::size_t count() const {
    return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz);
  }
  [[nodiscard]] std::uint32_t index(int x, int y, int z) const {
    return static_cast<std::uint32_t>(x + nx * (y + ny * z));
  }
  [[nodiscard]] int xOf(std::uint32_t i) const { return static_cast<int>(i % static_cast<std::uint32_t>(nx)); }
  [[nodiscard]] int yOf(std::uint32_t i) const {
    return static_cast<int>((i / static_cast<std::uint32_t>(nx)) % static_cast<std::uint32_t>(ny));
  }
  [[nodiscard]] int zOf(std::uint32_t i) const {
    return static_cast<int>(i / (static_cast<std::uint32_t>(nx) * static_cast<std::uint32_t>(ny)));
  }
  [[nodiscard]] bool contains(int x, int y, int z) const {
    return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz;
  }
  /// Squared distance in voxel units between the centres of voxels a and b.
  [[nodiscard]] std::int32_t distance2(std::uint32_t a, std::uint32_t b) const {
    const int dx = xOf(a) - xOf(b), dy = yOf(a) - yOf(b), dz = zOf(a) - zOf(b);
    return dx * dx + dy * dy + dz * dz;
  }
};

/// Largest grid side drape builds (coordinates are packed in 10 bits during propagation).
inline constexpr int kMaxGridSide = 1000;
/// Largest grid drape builds (about 1.3 GB while building, 0.5-1 GB once built).
inline constexpr std::size_t kMaxVoxels = 100'000'000;

}  // namespace drape::field
