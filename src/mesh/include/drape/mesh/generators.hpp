#pragma once
// Procedural garments and test meshes, shared by tests, examples and benchmarks.

#include <vector>

#include "drape/mesh/trimesh.hpp"

namespace drape::mesh {

/// A rectangular sheet in the plane spanned by `uAxis` and `vAxis` from `origin`, with
/// `nu` x `nv` quads split into triangles along alternating diagonals (so that it has no
/// preferred shear direction). Vertex (i, j) has index j * (nu + 1) + i.
[[nodiscard]] TriMesh makeSheet(const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis, int nu, int nv);

/// A skirt: a tube from an elliptical waist down to a wider elliptical hem, Y up.
struct SkirtShape {
  Vec3 waistCentre = Vec3::Zero();  ///< m, centre of the waist ellipse
  double waistRadiusX = 0.16;       ///< m, half-width of the waist (left-right)
  double waistRadiusZ = 0.12;       ///< m, half-depth of the waist (front-back)
  double hemFlare = 1.6;            ///< hem radii = waist radii * flare
  double length = 0.55;             ///< m, waist to hem
  int segments = 24;                ///< vertices around
  int rings = 10;                   ///< bands of quads from waist to hem
  /// Optional profile: if both have rings + 1 entries, ring r has these radii (m) instead
  /// of the linear flare.
  std::vector<double> ringRadiusX, ringRadiusZ;
};

struct Skirt {
  TriMesh mesh;   ///< (segments x rings x 2) triangles, normals outward
  TriMesh waistband;  ///< the constraint mask: the waist ring (the mesh's first `segments` vertices)
};

[[nodiscard]] Skirt makeSkirt(const SkirtShape& shape);

}  // namespace drape::mesh
