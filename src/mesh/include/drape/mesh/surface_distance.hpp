#pragma once
// Exact signed distance from points to a closed triangle mesh in one pose: a body part or
// the skinned body as a run recorded them. The nearest point comes from a uniform grid of
// the triangles searched ring by ring until no unvisited cell can hold a nearer one; the
// side from the angle-weighted pseudo-normal of the feature (face, edge or corner) the
// nearest point lies on (Baerentzen and Aanaes, 2005), which is right for any closed,
// manifold mesh that does not pass through itself, and, where it says inside, from the
// winding number as well (inside where both say so), since skinned bodies and the parts cut
// from them do pass through themselves in places. Built once per pose, for diagnostics
// (`drape inspect RUN`) and tests; the simulation reads distance fields instead.

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/closest_point.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::mesh {

struct SurfacePoint {
  double distance_m = 0;       ///< signed: negative inside (winding number above 1/2 too); +infinity: no triangles
  Vec3 point = Vec3::Zero();   ///< the nearest point of the surface
  std::uint32_t triangle = 0;  ///< the triangle it lies on
};

class SurfaceDistance {
 public:
  /// Throws drape::Error on a triangle index out of range of `positions`.
  SurfaceDistance(std::span<const Vec3> positions, std::span<const Triangle> triangles);

  [[nodiscard]] SurfacePoint at(const Vec3& p) const;

 private:
  [[nodiscard]] Vec3 pseudoNormal(std::uint32_t t, TriangleFeature feature) const;
  void visitCell(std::size_t cell, const Vec3& p, double& best2, SurfacePoint& found, TriangleFeature& feature) const;

  std::span<const Vec3> x_;
  std::span<const Triangle> triangles_;
  std::vector<Vec3> faceNormals_;    ///< unit, or zero for a degenerate triangle
  std::vector<Vec3> edgeNormals_;    ///< per triangle and edge (corners i, i + 1): the sum of its faces' normals
  std::vector<Vec3> cornerNormals_;  ///< per vertex: its faces' normals weighted by their angles there
  Vec3 origin_ = Vec3::Zero();
  double cell_m_ = 1.0;
  std::array<int, 3> dims_{0, 0, 0};
  std::vector<std::uint32_t> cellStart_;  ///< per cell, into cellTriangles_ (cells + 1 entries)
  std::vector<std::uint32_t> cellTriangles_;
};

/// Generalised winding number of the triangles around p (the sum of their solid angles seen
/// from p over 4 pi): about 1 inside a closed mesh, 0 outside, robust to small holes and
/// slow (every triangle): the reference of tests.
[[nodiscard]] double windingNumber(std::span<const Vec3> positions, std::span<const Triangle> triangles,
                                   const Vec3& p);

}  // namespace drape::mesh
