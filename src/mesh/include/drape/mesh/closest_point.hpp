#pragma once
// The closest point of a triangle to a point: what brute-force distances to a mesh (the
// player's distance slice, the tests' exact references for the distance fields' uses) are
// made of.

#include <cstdint>

#include "drape/core/math.hpp"

namespace drape::mesh {

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5: the
/// Voronoi regions of the vertices, then the edges, then the face). Degenerate triangles
/// give a point of the triangle, not necessarily the closest.
[[nodiscard]] Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Where on the triangle the closest point lies: what decides which normal tells the side
/// of a closed mesh a point is on (a face's, an edge's or a corner's pseudo-normal).
enum class TriangleFeature : std::uint8_t { CornerA, CornerB, CornerC, EdgeAB, EdgeBC, EdgeCA, Face };
struct TrianglePoint {
  Vec3 point;
  TriangleFeature feature;
};
/// closestOnTriangle, with the Voronoi region it found the point in.
[[nodiscard]] TrianglePoint closestOnTriangleFeature(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

/// Barycentric weights (of a, b, c) of the projection of p onto the plane of triangle abc
/// (Ericson 3.4); a degenerate triangle gives (1, 0, 0).
[[nodiscard]] Vec3 barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace drape::mesh
