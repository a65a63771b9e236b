#pragma once
// Indexed triangle meshes: garments, body segments, constraint masks. Positions in metres
// once loaded (formats/ scales file units on load).

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "drape/core/math.hpp"

namespace drape::mesh {

using Triangle = std::array<std::uint32_t, 3>;
inline constexpr std::uint32_t kNoVertex = 0xffffffffu;

struct TriMesh {
  std::string name;               ///< for messages: a file name, a DEF name, a segment name
  std::vector<Vec3> positions;    ///< m
  std::vector<Triangle> triangles;  ///< counter-clockwise seen from outside (outward normal)

  [[nodiscard]] std::size_t vertexCount() const { return positions.size(); }
  [[nodiscard]] std::size_t triangleCount() const { return triangles.size(); }
  [[nodiscard]] Aabb bounds() const;
  /// Unnormalised normal of triangle t: (b - a) x (c - a), twice the area.
  [[nodiscard]] Vec3 triangleNormalArea(std::size_t t) const;
  [[nodiscard]] double triangleArea(std::size_t t) const { return 0.5 * triangleNormalArea(t).norm(); }
  [[nodiscard]] double totalArea() const;
  /// Area-weighted vertex normals (unit length; zero for isolated vertices).
  [[nodiscard]] std::vector<Vec3> vertexNormals() const;
  /// Applies x -> scale * x (unit conversion).
  void scale(double factor);
  void transform(const RigidTransform& t);
};

/// Area-weighted unit vertex normals of `triangles` over `positions`, into `out` (resized;
/// zero for vertices no triangle uses). For meshes that move: no TriMesh to build per frame.
void vertexNormals(std::span<const Vec3> positions, std::span<const Triangle> triangles, std::vector<Vec3>& out);

/// Splits a polygon (vertex indices, in order) into a fan of triangles appended to `out`.
void triangulatePolygon(const std::vector<std::uint32_t>& polygon, std::vector<Triangle>& out);

}  // namespace drape::mesh
