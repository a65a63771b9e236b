#pragma once
// The distance field of one body part (paper section 4.3.2): built once, in the part's
// local unit-scale frame, then only read by the collision code (section 4.3.3).
//
// Layout: a grid of dims() voxels of voxelSize() metres; voxel (x, y, z) covers
// origin() + voxelSize() * [x, x+1) x [y, y+1) x [z, z+1) and has linear index
// x + nx * (y + ny * z). Continuous voxel coordinates put voxel centres at integers:
// c = (p - origin) / voxelSize - 0.5. The outermost layer is tagged border (a trace that
// reaches it has left the volume); the border is wide enough that the shell (T3) around
// the body never reaches it.
//
// Storage per voxel (structure of arrays): signed distance as int16 in 1/64 voxel (2 bytes),
// flags (1 byte), Voronoi normal octahedron-encoded in 2 x int8 (2 bytes); references to
// the surface voxels of each Voronoi cell only for voxels within the shell.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/field/grid.hpp"
#include "drape/field/propagation.hpp"
#include "drape/field/voxelize.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::field {

struct FieldSettings {
  double voxelSize_m = 0.01;  ///< m, edge of a cubic voxel (ignored when dims is set)
  double shell_m = 0.06;      ///< m, the outer offset surface T3: Voronoi references are kept within it
  double shellVoxels = 0;     ///< if positive: the shell in voxels, overriding shell_m (the paper's T3 = 6)
  /// Voxels of border around the part's bounding box, the tagged outermost layer included;
  /// must hold the shell plus that layer. 0: automatic, ceil(shell / voxel) + 2 (8 with dims).
  int borderVoxels = 0;
  /// If all three are positive: the grid has exactly these dimensions (border included) and
  /// the voxel size follows from the part's bounding box (its largest extent per voxel).
  std::array<int, 3> dims{0, 0, 0};
  FieldMethod method = FieldMethod::Dvdp;
};

/// How the build went: counts, times (ms, wall clock, one thread) and memory.
struct FieldStats {
  std::size_t voxels = 0;
  std::size_t surfaceVoxels = 0;
  std::size_t insideVoxels = 0;  ///< voxels whose centre is inside the body (surface voxels included)
  std::size_t shellVoxels = 0;   ///< voxels with Voronoi references
  std::size_t references = 0;    ///< total references in the shell
  double voxelizeMs = 0;
  double propagateMs = 0;  ///< DVDP or the exact transform
  double finishMs = 0;     ///< normals and compact storage
  std::size_t bytes = 0;   ///< memory of the built field
};

/// Distance and offset-surface normal at one point, from one trilinear gather.
struct FieldSample {
  double distance_m = 0;   ///< signed, trilinear; negative inside the body
  Vec3 normal = Vec3::UnitZ();  ///< unit, pointing away from the body (local frame)
};

/// A sample and the gradient of the trilinear distance at the same point, from one gather:
/// enough to continue the distance to first order (a tangent plane).
struct FieldJet {
  FieldSample sample;
  Vec3 gradient = Vec3::Zero();  ///< m of distance per voxel of motion, the grid's axes
};

/// The result of DistanceField::locate for a local point.
struct PointLocation {
  bool inVolume = false;      ///< inside the grid and not in the border layer
  std::uint32_t voxel = 0;    ///< voxel containing the point (clamped to the grid)
  double distance_m = 0;      ///< signed, trilinear; negative inside the body
};

class DistanceField {
 public:
  /// Builds the field of one body part. `part` is in the part's local frame, metres, closed,
  /// triangles wound counter-clockwise seen from outside. Throws drape::Error on bad
  /// settings (naming the setting) or an empty mesh.
  [[nodiscard]] static DistanceField build(const mesh::TriMesh& part, const FieldSettings& settings);

  // --- grid geometry -----------------------------------------------------------------
  [[nodiscard]] const GridDims& dims() const { return dims_; }
  [[nodiscard]] double voxelSize() const { return voxelSize_; }  ///< m
  [[nodiscard]] const Vec3& origin() const { return origin_; }    ///< m, corner of voxel (0, 0, 0)
  [[nodiscard]] std::size_t voxelCount() const { return dims_.count(); }
  /// Linear index steps of +1 voxel along x, y, z (for a voxel walk).
  [[nodiscard]] std::array<std::int64_t, 3> strides() const {
    return {1, dims_.nx, static_cast<std::int64_t>(dims_.nx) * dims_.ny};
  }
  [[nodiscard]] std::uint32_t index(int x, int y, int z) const { return dims_.index(x, y, z); }
  [[nodiscard]] Vec3i coordinates(std::uint32_t voxel) const {
    return {dims_.xOf(voxel), dims_.yOf(voxel), dims_.zOf(voxel)};
  }
  /// Local point (m) -> continuous voxel coordinates (voxel centres at integers).
  [[nodiscard]] Vec3 toVoxel(const Vec3& local_m) const { return (local_m - origin_) / voxelSize_ - Vec3::Constant(0.5); }
  /// Continuous voxel coordinates -> local point (m).
  [[nodiscard]] Vec3 toLocal(const Vec3& voxel) const { return origin_ + (voxel + Vec3::Constant(0.5)) * voxelSize_; }
  /// Centre of a voxel in the local frame (m).
  [[nodiscard]] Vec3 centre(std::uint32_t voxel) const { return toLocal(coordinates(voxel).cast<double>()); }
  /// Whether a local point (m) lies in the grid (border layer included).
  [[nodiscard]] bool containsPoint(const Vec3& local_m) const;
  /// The voxel containing a local point (m), clamped to the grid.
  [[nodiscard]] std::uint32_t voxelAt(const Vec3& local_m) const;
  /// The grid's box in the local frame (m): cull with it.
  [[nodiscard]] Aabb bounds() const;
  /// The body part's own bounding box in the local frame (m).
  [[nodiscard]] const Aabb& bodyBounds() const { return bodyBounds_; }

  // --- per voxel -------------------------------------------------------------------------
  /// The one-comparison exit test of a voxel walk: the outermost layer.
  [[nodiscard]] bool isBorder(std::uint32_t voxel) const { return flags_[voxel] & kVoxelBorder; }
  /// The voxel's centre is inside the body.
  [[nodiscard]] bool inside(std::uint32_t voxel) const { return flags_[voxel] & kVoxelInside; }
  [[nodiscard]] bool isSurface(std::uint32_t voxel) const { return flags_[voxel] & kVoxelSurface; }
  /// The voxel is within the shell T3 (has Voronoi references).
  [[nodiscard]] bool inShell(std::uint32_t voxel) const { return flags_[voxel] & kVoxelShell; }
  /// Signed distance (m) from the voxel centre to the nearest surface voxel centre;
  /// negative inside the body, 0 on surface voxels. Resolution 1/64 voxel.
  [[nodiscard]] double distance(std::uint32_t voxel) const { return distance_[voxel] * metresPerUnit_; }
  /// The same in voxel units.
  [[nodiscard]] double distanceVoxels(std::uint32_t voxel) const { return distance_[voxel] * (1.0 / kUnitsPerVoxel); }
  /// Offset-surface normal (unit, pointing away from the body): within the shell, the mean
  /// of the normals of the Voronoi cell's surface voxels; beyond it, the distance gradient.
  [[nodiscard]] Vec3 normal(std::uint32_t voxel) const { return decodeNormal(normal_[voxel]); }

  // --- per local point (no allocation; reads 8 voxels) ---------------------------------------
  /// Signed distance (m) at a local point (m), trilinear between voxel centres; clamped to
  /// the grid for points outside it.
  [[nodiscard]] double distanceAt(const Vec3& local_m) const;
  /// Offset-surface normal at a local point: trilinear blend of the 8 voxel normals, unit.
  [[nodiscard]] Vec3 normalAt(const Vec3& local_m) const;
  /// Both, and whether the point is in the volume, in one call.
  [[nodiscard]] PointLocation locate(const Vec3& local_m) const;

  // --- per point in continuous voxel coordinates (the collision's hot path) ------------------
  // The same trilinear reads as distanceAt and normalAt, without the metre conversion, and
  // both from the one gather of 8 voxels when both are needed.
  [[nodiscard]] double distanceAtVoxel(const Vec3& voxel) const;
  [[nodiscard]] FieldSample sampleAtVoxel(const Vec3& voxel) const;
  /// sampleAtVoxel and the trilinear distance's gradient (zero along an axis where the point
  /// lies beyond the grid, which clamps it there).
  [[nodiscard]] FieldJet jetAtVoxel(const Vec3& voxel) const;
  /// A Newton step's direction at a local point, in local metres of motion per metre of
  /// distance to gain: the trilinear distance's gradient over its squared length, so that
  /// one step meets the level sought where the blend is linear; where the gradient nearly
  /// vanishes (under 1/2 long: a blend's flat middle), the offset-surface normal.
  [[nodiscard]] Vec3 newtonDirection(const Vec3& local_m) const;

  // --- Voronoi cells (cold: binary search) -----------------------------------------------------
  /// Surface voxels whose Voronoi cell holds this voxel (empty beyond the shell).
  [[nodiscard]] std::span<const std::uint32_t> references(std::uint32_t voxel) const;
  /// Unit normals of the triangles overlapping a surface voxel (empty for other voxels).
  [[nodiscard]] std::span<const Vec3f> surfaceNormals(std::uint32_t voxel) const;

  [[nodiscard]] const FieldStats& stats() const { return stats_; }
  [[nodiscard]] double shell_m() const { return shell_m_; }
  [[nodiscard]] FieldMethod method() const { return method_; }
  /// Memory held by the field (bytes).
  [[nodiscard]] std::size_t memoryBytes() const;

  static constexpr int kUnitsPerVoxel = 64;  ///< fixed-point scale of the stored distances

  [[nodiscard]] static std::uint16_t encodeNormal(const Vec3& unit);
  [[nodiscard]] static Vec3 decodeNormal(std::uint16_t code);
  /// decodeNormal of every code, in float (built on first use, shared, 768 KB): the
  /// collision's normal reads look codes up instead of decoding them.
  [[nodiscard]] static const Vec3f* decodedNormals();

 private:
  /// The 8 voxels around continuous voxel coordinates (clamped to the grid) and their
  /// trilinear weights, in the order x fastest.
  struct Gather {
    std::array<std::size_t, 8> voxel;
    std::array<double, 8> weight;
    double fx, fy, fz;  ///< the point's place in the cell, 0 to 1 per axis
    bool clampedX, clampedY, clampedZ;  ///< beyond the grid's first or last voxel centre
  };
  [[nodiscard]] Gather gatherAt(const Vec3& voxel) const;
  [[nodiscard]] double blendDistance(const Gather& g) const;
  /// Unit blend of the 8 decoded normals; the nearest voxel's normal where they cancel.
  [[nodiscard]] Vec3 blendNormal(const Gather& g, const Vec3& voxel) const;

  GridDims dims_;
  double voxelSize_ = 0;
  double metresPerUnit_ = 0;  // voxelSize_ / kUnitsPerVoxel
  Vec3 origin_ = Vec3::Zero();
  Aabb bodyBounds_;
  double shell_m_ = 0;
  FieldMethod method_ = FieldMethod::Dvdp;
  std::vector<std::int16_t> distance_;   ///< per voxel, 1/64 voxel, signed
  std::vector<std::uint8_t> flags_;      ///< per voxel, VoxelFlag bits
  std::vector<std::uint16_t> normal_;    ///< per voxel, octahedral code
  std::vector<std::uint32_t> shellVoxels_, refStart_, refs_;          ///< shell only
  std::vector<std::uint32_t> surfaceVoxels_, surfaceNormalStart_;    ///< surface voxels, sorted
  std::vector<Vec3f> surfaceNormals_;
  FieldStats stats_;
};

inline DistanceField::Gather DistanceField::gatherAt(const Vec3& c) const {
  const auto axis = [](double v, int n, int& i, bool& clamped) {
    const double inside = std::clamp(v, 0.0, static_cast<double>(n - 1));
    clamped = inside != v;
    i = std::min(static_cast<int>(inside), n - 2);
    return inside - i;
  };
  int x, y, z;
  Gather g;
  const double fx = axis(c.x(), dims_.nx, x, g.clampedX), fy = axis(c.y(), dims_.ny, y, g.clampedY),
               fz = axis(c.z(), dims_.nz, z, g.clampedZ);
  g.fx = fx;
  g.fy = fy;
  g.fz = fz;
  const std::size_t base = dims_.index(x, y, z);
  const std::size_t sy = static_cast<std::size_t>(dims_.nx), sz = sy * static_cast<std::size_t>(dims_.ny);
  for (int k = 0; k < 8; ++k) {
    g.voxel[k] = base + ((k & 1) ? 1 : 0) + ((k & 2) ? sy : 0) + ((k & 4) ? sz : 0);
    g.weight[k] = ((k & 1) ? fx : 1 - fx) * ((k & 2) ? fy : 1 - fy) * ((k & 4) ? fz : 1 - fz);
  }
  return g;
}

/// a0 + ... + a7 as a balanced tree: a fixed order, and no serial chain of eight adds.
template <typename T>
inline T sumOfEight(const T (&a)[8]) {
  return ((a[0] + a[1]) + (a[2] + a[3])) + ((a[4] + a[5]) + (a[6] + a[7]));
}

inline double DistanceField::blendDistance(const Gather& g) const {
  double terms[8];
  for (int k = 0; k < 8; ++k) terms[k] = g.weight[k] * distance_[g.voxel[k]];
  return sumOfEight(terms) * metresPerUnit_;
}

inline Vec3 DistanceField::blendNormal(const Gather& g, const Vec3& c) const {
  // Unit normals from the decode table (one load per voxel instead of a square root and a
  // division), blended and normalised in double.
  const Vec3f* table = decodedNormals();
  float tx[8], ty[8], tz[8];
  for (int k = 0; k < 8; ++k) {
    const Vec3f& n = table[normal_[g.voxel[k]]];
    const float w = static_cast<float>(g.weight[k]);
    tx[k] = n.x() * w;
    ty[k] = n.y() * w;
    tz[k] = n.z() * w;
  }
  const double sx = sumOfEight(tx), sy = sumOfEight(ty), sz = sumOfEight(tz);
  const Vec3 sum(sx, sy, sz);
  const double len = sum.norm();
  if (len > 1e-9) return sum / len;
  const int x = std::clamp(static_cast<int>(std::floor(c.x() + 0.5)), 0, dims_.nx - 1);
  const int y = std::clamp(static_cast<int>(std::floor(c.y() + 0.5)), 0, dims_.ny - 1);
  const int z = std::clamp(static_cast<int>(std::floor(c.z() + 0.5)), 0, dims_.nz - 1);
  return normal(dims_.index(x, y, z));
}

inline double DistanceField::distanceAtVoxel(const Vec3& c) const { return blendDistance(gatherAt(c)); }

inline FieldSample DistanceField::sampleAtVoxel(const Vec3& c) const {
  const Gather g = gatherAt(c);
  return {blendDistance(g), blendNormal(g, c)};
}

inline FieldJet DistanceField::jetAtVoxel(const Vec3& c) const {
  const Gather g = gatherAt(c);
  double v[8];
  for (int k = 0; k < 8; ++k) v[k] = distance_[g.voxel[k]];
  // The derivative of the trilinear blend along each axis: the differences across the cell
  // along that axis, blended over the other two (voxel k has x in bit 0, y in bit 1, z in bit 2).
  const double fx = g.fx, fy = g.fy, fz = g.fz;
  const double dx = (1 - fy) * (1 - fz) * (v[1] - v[0]) + fy * (1 - fz) * (v[3] - v[2]) +
                    (1 - fy) * fz * (v[5] - v[4]) + fy * fz * (v[7] - v[6]);
  const double dy = (1 - fx) * (1 - fz) * (v[2] - v[0]) + fx * (1 - fz) * (v[3] - v[1]) +
                    (1 - fx) * fz * (v[6] - v[4]) + fx * fz * (v[7] - v[5]);
  const double dz = (1 - fx) * (1 - fy) * (v[4] - v[0]) + fx * (1 - fy) * (v[5] - v[1]) +
                    (1 - fx) * fy * (v[6] - v[2]) + fx * fy * (v[7] - v[3]);
  const Vec3 gradient(g.clampedX ? 0.0 : dx, g.clampedY ? 0.0 : dy, g.clampedZ ? 0.0 : dz);
  return {{blendDistance(g), blendNormal(g, c)}, gradient * metresPerUnit_};
}

inline Vec3 DistanceField::newtonDirection(const Vec3& local_m) const {
  const FieldJet jet = jetAtVoxel(toVoxel(local_m));
  const Vec3 g = jet.gradient / voxelSize();
  return g.squaredNorm() > 0.25 ? Vec3(g / g.squaredNorm()) : jet.sample.normal;
}

/// Grid placement for a part: its bounding box plus `border` voxels each side (cubic voxels
/// of `voxelSize` m), or exactly `dims` voxels when they are given (voxel size from the box).
[[nodiscard]] GridPlacement placeGrid(const Aabb& box, const FieldSettings& settings, int border);

}  // namespace drape::field
