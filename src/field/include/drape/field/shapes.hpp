#pragma once
// Closed synthetic body-part meshes for tests and benchmarks: their insides and normals
// are known exactly.

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::field {

/// A tapered tube along y with rounded ends (a limb): radius `radiusBottom` at the bottom
/// and `radiusTop` at the top (m), total height `height` (m) including the two
/// hemispherical caps; `around` segments round, `along` rings bottom to top. Centred on the origin.
[[nodiscard]] mesh::TriMesh makeRoundedTube(double radiusBottom, double radiusTop, double height, int around = 48,
                                            int along = 40);

/// A UV sphere of radius `radius` (m) at `centre`.
[[nodiscard]] mesh::TriMesh makeSphere(double radius, const Vec3& centre = Vec3::Zero(), int around = 32,
                                       int along = 16);

/// An axis-aligned box between `lo` and `hi` (m), 12 triangles.
[[nodiscard]] mesh::TriMesh makeBox(const Vec3& lo, const Vec3& hi);

/// Scales and moves `m` (non-uniformly) so that its bounding box becomes `box`.
void fitToBox(mesh::TriMesh& m, const Aabb& box);

}  // namespace drape::field
