#pragma once
// Voxelization of a closed triangle mesh into a binary voxel space (paper section 4.3.2):
// surface voxels (every voxel a triangle overlaps, with the normals of all the triangles
// touching it) and the inside fill.

#include <cstdint>
#include <span>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/field/grid.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::field {

/// Placement of a voxel grid in the mesh's frame: voxel (x, y, z) covers
/// origin + voxelSize * [x, x+1) x [y, y+1) x [z, z+1).
struct GridPlacement {
  GridDims dims;
  Vec3 origin = Vec3::Zero();  ///< m: the corner of voxel (0, 0, 0)
  double voxelSize = 0;        ///< m: edge of a (cubic) voxel
};

/// Voxel bit flags, one byte per voxel.
enum VoxelFlag : std::uint8_t {
  kVoxelBorder = 1,   ///< outermost layer of the grid: a trace stepping here has left the volume
  kVoxelInside = 2,   ///< the voxel centre is inside the body (majority of three axis parity tests)
  kVoxelSurface = 4,  ///< a triangle overlaps the voxel (the set S0 of DVDP)
  kVoxelShell = 8,    ///< Voronoi references are kept for this voxel (|distance| <= shell)
};

struct Voxelization {
  GridPlacement grid;
  std::vector<std::uint8_t> flags;  ///< per voxel, VoxelFlag bits (border, inside, surface)
  /// Surface voxels in increasing index order, and for each the unit outward normals of the
  /// triangles that overlap it: normals[normalStart[k] .. normalStart[k+1]) belong to surfaceVoxels[k].
  std::vector<std::uint32_t> surfaceVoxels;
  std::vector<std::uint32_t> normalStart;
  std::vector<Vec3f> normals;
  std::vector<std::uint32_t> normalTriangle;  ///< triangle index of each entry of `normals`

  [[nodiscard]] std::span<const Vec3f> normalsOf(std::size_t surfaceSlot) const {
    return {normals.data() + normalStart[surfaceSlot], normalStart[surfaceSlot + 1] - normalStart[surfaceSlot]};
  }
};

/// Exact triangle / axis-aligned box overlap (separating axis test of Akenine-Moller).
/// Touching counts as overlap.
[[nodiscard]] bool triangleOverlapsBox(const Vec3& boxCentre, const Vec3& boxHalfSize, const Vec3& a, const Vec3& b,
                                       const Vec3& c);

/// Voxelizes `mesh` (positions in the same frame and units as `grid`). Triangles must lie
/// inside the grid without touching its outermost (border) layer; degenerate triangles are
/// skipped. The inside fill casts one ray per voxel row along each axis and counts
/// crossings; a voxel is inside when at least two of the three axes say so, which closes
/// small holes (a gap in a cap flips rays along one axis only).
[[nodiscard]] Voxelization voxelize(const mesh::TriMesh& mesh, const GridPlacement& grid);

}  // namespace drape::field
