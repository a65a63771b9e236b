#include "drape/field/voxelize.hpp"

#include <algorithm>
#include <cmath>

#include "drape/core/error.hpp"

namespace drape::field {
namespace {

// Separating axis test of a triangle (already translated to the box centre) against the
// 9 cross products of the box axes and the triangle edges.
bool separatedOnEdgeAxes(const Vec3 v[3], const Vec3& half) {
  for (int e = 0; e < 3; ++e) {
    const Vec3 edge = v[(e + 1) % 3] - v[e];
    for (int axis = 0; axis < 3; ++axis) {
      // axis_unit x edge
      Vec3 a = Vec3::Zero();
      a[(axis + 1) % 3] = -edge[(axis + 2) % 3];
      a[(axis + 2) % 3] = edge[(axis + 1) % 3];
      const double p0 = a.dot(v[0]), p1 = a.dot(v[1]), p2 = a.dot(v[2]);
      const double lo = std::min({p0, p1, p2}), hi = std::max({p0, p1, p2});
      const double r = half.x() * std::abs(a.x()) + half.y() * std::abs(a.y()) + half.z() * std::abs(a.z());
      if (lo > r || hi < -r) return true;
    }
  }
  return false;
}

// Where voxel rows cross the surface: one entry per (ray, crossing coordinate).
struct Crossing {
  std::uint32_t ray;
  float t;  // voxel units along the ray's axis
};

// Casts rays along `axis` through every voxel row (centres of the two other coordinates,
// nudged by a tiny irrational offset so a ray never runs exactly through an edge or a
// vertex of a mesh with round coordinates) and adds one vote to each voxel whose centre
// has an odd number of crossings before it.
void voteAlongAxis(const std::vector<Vec3>& voxelPositions, const mesh::TriMesh& mesh, const GridDims& dims, int axis,
                   std::vector<std::uint8_t>& votes) {
  const int b = (axis + 1) % 3, c = (axis + 2) % 3;
  const int n[3] = {dims.nx, dims.ny, dims.nz};
  const double nudgeB = 1.2345678e-4, nudgeC = 3.1415927e-4;
  std::vector<Crossing> crossings;
  for (const mesh::Triangle& tri : mesh.triangles) {
    const Vec3& p0 = voxelPositions[tri[0]];
    const Vec3& p1 = voxelPositions[tri[1]];
    const Vec3& p2 = voxelPositions[tri[2]];
    const double area = (p1[b] - p0[b]) * (p2[c] - p0[c]) - (p1[c] - p0[c]) * (p2[b] - p0[b]);
    if (area == 0) continue;
    const int j0 = std::max(0, static_cast<int>(std::floor(std::min({p0[b], p1[b], p2[b]}) - 0.5)));
    const int j1 = std::min(n[b] - 1, static_cast<int>(std::ceil(std::max({p0[b], p1[b], p2[b]}) - 0.5)));
    const int k0 = std::max(0, static_cast<int>(std::floor(std::min({p0[c], p1[c], p2[c]}) - 0.5)));
    const int k1 = std::min(n[c] - 1, static_cast<int>(std::ceil(std::max({p0[c], p1[c], p2[c]}) - 0.5)));
    for (int k = k0; k <= k1; ++k) {
      const double pc = k + 0.5 + nudgeC;
      for (int j = j0; j <= j1; ++j) {
        const double pb = j + 0.5 + nudgeB;
        // Barycentric weights of the ray in the projected triangle.
        const double w0 = (p1[b] - pb) * (p2[c] - pc) - (p1[c] - pc) * (p2[b] - pb);
        const double w1 = (p2[b] - pb) * (p0[c] - pc) - (p2[c] - pc) * (p0[b] - pb);
        const double w2 = (p0[b] - pb) * (p1[c] - pc) - (p0[c] - pc) * (p1[b] - pb);
        const bool in = (w0 > 0 && w1 > 0 && w2 > 0) || (w0 < 0 && w1 < 0 && w2 < 0);
        if (!in) continue;
        const double t = (w0 * p0[axis] + w1 * p1[axis] + w2 * p2[axis]) / (w0 + w1 + w2);
        crossings.push_back({static_cast<std::uint32_t>(j + n[b] * k), static_cast<float>(t)});
      }
    }
  }
  std::sort(crossings.begin(), crossings.end(),
            [](const Crossing& l, const Crossing& r) { return l.ray != r.ray ? l.ray < r.ray : l.t < r.t; });
  const int stride[3] = {1, dims.nx, dims.nx * dims.ny};
  for (std::size_t first = 0; first < crossings.size();) {
    std::size_t last = first;
    while (last < crossings.size() && crossings[last].ray == crossings[first].ray) ++last;
    const int j = static_cast<int>(crossings[first].ray) % n[b];
    const int k = static_cast<int>(crossings[first].ray) / n[b];
    const std::size_t base = static_cast<std::size_t>(j) * stride[b] + static_cast<std::size_t>(k) * stride[c];
    std::size_t next = first;
    bool inside = false;
    for (int i = 0; i < n[axis]; ++i) {
      const double centre = i + 0.5;
      while (next < last && crossings[next].t < centre) {
        inside = !inside;
        ++next;
      }
      if (inside) ++votes[base + static_cast<std::size_t>(i) * stride[axis]];
    }
    first = last;
  }
}

}  // namespace

bool triangleOverlapsBox(const Vec3& boxCentre, const Vec3& half, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 v[3] = {a - boxCentre, b - boxCentre, c - boxCentre};
  // The box's own axes: the triangle's bounding box against the box.
  for (int axis = 0; axis < 3; ++axis) {
    const double lo = std::min({v[0][axis], v[1][axis], v[2][axis]});
    const double hi = std::max({v[0][axis], v[1][axis], v[2][axis]});
    if (lo > half[axis] || hi < -half[axis]) return false;
  }
  // The triangle's plane.
  const Vec3 normal = (v[1] - v[0]).cross(v[2] - v[0]);
  const double r = half.x() * std::abs(normal.x()) + half.y() * std::abs(normal.y()) + half.z() * std::abs(normal.z());
  if (std::abs(normal.dot(v[0])) > r) return false;
  return !separatedOnEdgeAxes(v, half);
}

Voxelization voxelize(const mesh::TriMesh& mesh, const GridPlacement& grid) {
  const GridDims& dims = grid.dims;
  Voxelization out;
  out.grid = grid;
  out.flags.assign(dims.count(), 0);

  // Border layer.
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x)
        if (x == 0 || y == 0 || z == 0 || x == dims.nx - 1 || y == dims.ny - 1 || z == dims.nz - 1)
          out.flags[dims.index(x, y, z)] |= kVoxelBorder;

  // Positions in voxel units (voxel (x, y, z) is the box [x, x+1) x ...).
  std::vector<Vec3> vp(mesh.positions.size());
  for (std::size_t i = 0; i < vp.size(); ++i) vp[i] = (mesh.positions[i] - grid.origin) / grid.voxelSize;

  // Surface voxels: every voxel each triangle overlaps, as (voxel, triangle) pairs.
  struct Hit {
    std::uint32_t voxel;
    std::uint32_t triangle;
  };
  std::vector<Hit> hits;
  const Vec3 half = Vec3::Constant(0.5);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Vec3& a = vp[mesh.triangles[t][0]];
    const Vec3& b = vp[mesh.triangles[t][1]];
    const Vec3& c = vp[mesh.triangles[t][2]];
    if ((b - a).cross(c - a).squaredNorm() == 0) continue;
    const Vec3 lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
    const int x0 = static_cast<int>(std::floor(lo.x())), x1 = static_cast<int>(std::floor(hi.x()));
    const int y0 = static_cast<int>(std::floor(lo.y())), y1 = static_cast<int>(std::floor(hi.y()));
    const int z0 = static_cast<int>(std::floor(lo.z())), z1 = static_cast<int>(std::floor(hi.z()));
    if (x0 < 1 || y0 < 1 || z0 < 1 || x1 > dims.nx - 2 || y1 > dims.ny - 2 || z1 > dims.nz - 2)
      throw Error(mesh.name + ": triangle " + std::to_string(t) + " lies outside the voxel grid or on its border",
                  ExitCode::Internal);
    for (int z = z0; z <= z1; ++z)
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
          if (triangleOverlapsBox(Vec3(x + 0.5, y + 0.5, z + 0.5), half, a, b, c))
            hits.push_back({dims.index(x, y, z), static_cast<std::uint32_t>(t)});
  }
  std::sort(hits.begin(), hits.end(),
            [](const Hit& l, const Hit& r) { return l.voxel != r.voxel ? l.voxel < r.voxel : l.triangle < r.triangle; });

  // Normal lists per surface voxel (compressed rows).
  out.normals.reserve(hits.size());
  out.normalTriangle.reserve(hits.size());
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (i == 0 || hits[i].voxel != hits[i - 1].voxel) {
      out.surfaceVoxels.push_back(hits[i].voxel);
      out.normalStart.push_back(static_cast<std::uint32_t>(out.normals.size()));
      out.flags[hits[i].voxel] |= kVoxelSurface;
    }
    const Vec3 n = mesh.triangleNormalArea(hits[i].triangle).normalized();
    out.normals.push_back(n.cast<float>());
    out.normalTriangle.push_back(hits[i].triangle);
  }
  out.normalStart.push_back(static_cast<std::uint32_t>(out.normals.size()));

  // Inside fill: three axis parity votes, majority wins.
  std::vector<std::uint8_t> votes(dims.count(), 0);
  for (int axis = 0; axis < 3; ++axis) voteAlongAxis(vp, mesh, dims, axis, votes);
  for (std::size_t i = 0; i < votes.size(); ++i)
    if (votes[i] >= 2 && !(out.flags[i] & kVoxelBorder)) out.flags[i] |= kVoxelInside;
  return out;
}

}  // namespace drape::field
