#include "drape/mesh/surface_distance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/mesh/edge_key.hpp"
#include "drape/mesh/closest_point.hpp"

namespace drape::mesh {
namespace {

constexpr int kMaxCellsPerAxis = 256;

double cornerAngle(const Vec3& at, const Vec3& b, const Vec3& c) {
  const Vec3 u = b - at, v = c - at;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

/// A cell as wide as the mean edge at least, and about two triangles per cell of the
/// bounding box, within kMaxCellsPerAxis along each axis.
double cellSize(std::span<const Vec3> x, std::span<const Triangle> triangles, const Vec3& extent) {
  double edges = 0;
  for (const Triangle& t : triangles) edges += (x[t[1]] - x[t[0]]).norm();
  const double meanEdge = edges / static_cast<double>(triangles.size());
  const Vec3 padded = extent.cwiseMax(Vec3::Constant(std::max(meanEdge, 1e-9)));
  const double perTwoTriangles = std::cbrt(padded.prod() / (0.5 * static_cast<double>(triangles.size())));
  return std::max({meanEdge, perTwoTriangles, padded.maxCoeff() / kMaxCellsPerAxis, 1e-9});
}

}  // namespace

SurfaceDistance::SurfaceDistance(std::span<const Vec3> positions, std::span<const Triangle> triangles)
    : x_(positions), triangles_(triangles) {
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const std::uint32_t v : triangles[t])
      if (v >= positions.size())
        throw Error(fmt::format("triangle {} uses vertex {}, but there are {} vertices", t, v, positions.size()));
  if (triangles.empty()) return;

  faceNormals_.resize(triangles.size());
  cornerNormals_.assign(positions.size(), Vec3::Zero());
  std::unordered_map<std::uint64_t, Vec3> edgeSums;
  edgeSums.reserve(triangles.size() * 2);
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const Triangle& tri = triangles[t];
    const Vec3 n = (x_[tri[1]] - x_[tri[0]]).cross(x_[tri[2]] - x_[tri[0]]);
    faceNormals_[t] = n.norm() > 0 ? Vec3(n.normalized()) : Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = tri[i], b = tri[(i + 1) % 3], c = tri[(i + 2) % 3];
      cornerNormals_[a] += cornerAngle(x_[a], x_[b], x_[c]) * faceNormals_[t];
      auto [it, added] = edgeSums.try_emplace(edgeKey(a, b), Vec3::Zero());
      it->second += faceNormals_[t];
    }
  }
  edgeNormals_.resize(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (int i = 0; i < 3; ++i) edgeNormals_[3 * t + i] = edgeSums.at(edgeKey(triangles[t][i], triangles[t][(i + 1) % 3]));

  Aabb box;
  for (const Triangle& t : triangles)
    for (const std::uint32_t v : t) box.extend(x_[v]);
  origin_ = box.min;
  cell_m_ = cellSize(x_, triangles, box.size());
  for (int a = 0; a < 3; ++a) dims_[a] = std::clamp(static_cast<int>(std::ceil(box.size()[a] / cell_m_)), 1, kMaxCellsPerAxis);
  const auto cellOf = [&](const Vec3& p, int a) {
    return std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / cell_m_)), 0, dims_[a] - 1);
  };
  // Each triangle goes into every cell its bounding box touches (counted, then filled).
  const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  cellStart_.assign(cells + 1, 0);
  const auto forCells = [&](const Triangle& t, auto&& visit) {
    Aabb tb;
    for (const std::uint32_t v : t) tb.extend(x_[v]);
    for (int k = cellOf(tb.min, 2); k <= cellOf(tb.max, 2); ++k)
      for (int j = cellOf(tb.min, 1); j <= cellOf(tb.max, 1); ++j)
        for (int i = cellOf(tb.min, 0); i <= cellOf(tb.max, 0); ++i)
          visit((static_cast<std::size_t>(k) * dims_[1] + j) * dims_[0] + i);
  };
  for (const Triangle& t : triangles) forCells(t, [&](std::size_t c) { ++cellStart_[c + 1]; });
  for (std::size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
  cellTriangles_.resize(cellStart_.back());
  std::vector<std::uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    forCells(triangles[t], [&](std::size_t c) { cellTriangles_[fill[c]++] = static_cast<std::uint32_t>(t); });
}

void SurfaceDistance::visitCell(std::size_t cell, const Vec3& p, double& best2, SurfacePoint& found,
                                TriangleFeature& feature) const {
  for (std::uint32_t i = cellStart_[cell]; i < cellStart_[cell + 1]; ++i) {
    const std::uint32_t t = cellTriangles_[i];
    const Triangle& tri = triangles_[t];
    const TrianglePoint q = closestOnTriangleFeature(p, x_[tri[0]], x_[tri[1]], x_[tri[2]]);
    if (const double d2 = (p - q.point).squaredNorm(); d2 < best2) {
      best2 = d2;
      found.point = q.point;
      found.triangle = t;
      feature = q.feature;
    }
  }
}

Vec3 SurfaceDistance::pseudoNormal(std::uint32_t t, TriangleFeature feature) const {
  // Told by the region the closest point was found in, not by its barycentric weights: on a
  // sliver those are too ill-conditioned to say which corner or edge the point is.
  switch (feature) {
    case TriangleFeature::CornerA: return cornerNormals_[triangles_[t][0]];
    case TriangleFeature::CornerB: return cornerNormals_[triangles_[t][1]];
    case TriangleFeature::CornerC: return cornerNormals_[triangles_[t][2]];
    case TriangleFeature::EdgeAB: return edgeNormals_[3 * t];  // edge i joins corners i and i + 1
    case TriangleFeature::EdgeBC: return edgeNormals_[3 * t + 1];
    case TriangleFeature::EdgeCA: return edgeNormals_[3 * t + 2];
    case TriangleFeature::Face: break;
  }
  return faceNormals_[t];
}

SurfacePoint SurfaceDistance::at(const Vec3& p) const {
  SurfacePoint found;
  found.distance_m = std::numeric_limits<double>::infinity();
  if (triangles_.empty()) return found;
  std::array<int, 3> c{};
  for (int a = 0; a < 3; ++a)
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / cell_m_)), 0, dims_[a] - 1);
  double best2 = std::numeric_limits<double>::infinity();
  TriangleFeature feature = TriangleFeature::Face;
  for (int r = 0;; ++r) {
    // The cells at Chebyshev distance r from c (within the grid).
    const int i0 = std::max(c[0] - r, 0), i1 = std::min(c[0] + r, dims_[0] - 1);
    const int j0 = std::max(c[1] - r, 0), j1 = std::min(c[1] + r, dims_[1] - 1);
    const int k0 = std::max(c[2] - r, 0), k1 = std::min(c[2] + r, dims_[2] - 1);
    for (int k = k0; k <= k1; ++k)
      for (int j = j0; j <= j1; ++j) {
        const bool shellRow = std::abs(k - c[2]) == r || std::abs(j - c[1]) == r;
        const int step = shellRow ? 1 : 2 * r;
        for (int i = c[0] - r; i <= c[0] + r; i += std::max(step, 1)) {
          if (i < i0 || i > i1) continue;
          visitCell((static_cast<std::size_t>(k) * dims_[1] + j) * dims_[0] + i, p, best2, found, feature);
        }
      }
    // Every cell not yet visited lies beyond a face of the visited block that is not on the
    // grid's border, so at least that face's distance from p away.
    double beyond = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (c[a] + r < dims_[a] - 1) beyond = std::min(beyond, origin_[a] + (c[a] + r + 1) * cell_m_ - p[a]);
      if (c[a] - r > 0) beyond = std::min(beyond, p[a] - (origin_[a] + (c[a] - r) * cell_m_));
    }
    if (std::isinf(beyond) || best2 <= beyond * beyond) break;
  }
  const double distance = std::sqrt(best2);
  // The pseudo-normal is right only where the mesh does not pass through itself, which a
  // skinned body does (thighs, armpits) and a segment cut from it may (a folded sliver at
  // the shoulder): an inside it finds is confirmed by the winding number, which is robust
  // and slow, and paid for only by points that seem inside.
  const bool inside = pseudoNormal(found.triangle, feature).dot(p - found.point) < 0 &&
                      windingNumber(x_, triangles_, p) > 0.5;
  found.distance_m = inside ? -distance : distance;
  return found;
}

double windingNumber(std::span<const Vec3> positions, std::span<const Triangle> triangles, const Vec3& p) {
  // Van Oosterom and Strackee's solid angle of each triangle seen from the point.
  double total = 0;
  for (const Triangle& tri : triangles) {
    const Vec3 a = positions[tri[0]] - p;
    const Vec3 b = positions[tri[1]] - p;
    const Vec3 c = positions[tri[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double det = a.dot(b.cross(c));
    const double div = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    total += 2 * std::atan2(det, div);
  }
  return total / (4 * std::numbers::pi);
}

}  // namespace drape::mesh
