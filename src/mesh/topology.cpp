#include "drape/mesh/topology.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <unordered_map>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/mesh/edge_key.hpp"

namespace drape::mesh {
namespace {

struct HalfEdge {
  std::uint64_t key;       // (min vertex << 32) | max vertex
  std::uint32_t face;
  std::uint32_t corner;    // edge joins corner and corner+1 of the face
};

void checkTriangles(const TriMesh& mesh, double minArea) {
  const std::size_t n = mesh.positions.size();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (std::uint32_t v : tri) {
      if (v >= n) {
        throw Error(fmt::format("{}: triangle {} uses vertex {} but the mesh has {} vertices",
                                mesh.name, t, v, n));
      }
    }
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
      throw Error(fmt::format("{}: triangle {} is degenerate (vertices {}, {}, {} repeat)", mesh.name,
                              t, tri[0], tri[1], tri[2]));
    }
    const double area = mesh.triangleArea(t);
    if (!(area > minArea)) {
      throw Error(fmt::format("{}: triangle {} is degenerate (area {:.3g} m^2 at vertices {}, {}, {})",
                              mesh.name, t, area, tri[0], tri[1], tri[2]));
    }
  }
}

std::vector<HalfEdge> sortedHalfEdges(const TriMesh& mesh) {
  std::vector<HalfEdge> half;
  half.reserve(mesh.triangles.size() * 3);
  for (std::uint32_t t = 0; t < mesh.triangles.size(); ++t) {
    const Triangle& tri = mesh.triangles[t];
    for (std::uint32_t c = 0; c < 3; ++c) half.push_back({edgeKey(tri[c], tri[(c + 1) % 3]), t, c});
  }
  std::sort(half.begin(), half.end(), [](const HalfEdge& a, const HalfEdge& b) {
    return a.key != b.key ? a.key < b.key : a.face < b.face;
  });
  return half;
}

std::vector<std::vector<std::uint32_t>> traceBoundaryLoops(const Topology& topo) {
  // Boundary edges as undirected (vertex, edge) incidences sorted by vertex. Walking edges,
  // not vertices, keeps a loop whole through a pinch vertex that two boundary runs touch,
  // and ignoring winding keeps it whole across faces of inconsistent orientation.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> incident;  // (vertex, edge)
  for (std::uint32_t e = 0; e < topo.edges.size(); ++e) {
    if (!topo.edges[e].boundary()) continue;
    incident.emplace_back(topo.edges[e].v0, e);
    incident.emplace_back(topo.edges[e].v1, e);
  }
  std::sort(incident.begin(), incident.end());
  std::vector<bool> used(topo.edges.size(), false);
  auto unusedEdgeAt = [&](std::uint32_t v) -> std::uint32_t {
    auto it = std::lower_bound(incident.begin(), incident.end(), std::make_pair(v, std::uint32_t{0}));
    for (; it != incident.end() && it->first == v; ++it)
      if (!used[it->second]) return it->second;
    return kNone;
  };
  std::vector<std::vector<std::uint32_t>> loops;
  for (std::uint32_t first = 0; first < topo.edges.size(); ++first) {
    if (!topo.edges[first].boundary() || used[first]) continue;
    std::vector<std::uint32_t> loop;
    const std::uint32_t start = topo.edges[first].v0;
    std::uint32_t v = start;
    for (std::uint32_t e = first; e != kNone;) {
      used[e] = true;
      loop.push_back(v);
      v = topo.edges[e].v0 == v ? topo.edges[e].v1 : topo.edges[e].v0;
      if (v == start) break;
      e = unusedEdgeAt(v);
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

}  // namespace

std::size_t Topology::interiorEdgeCount() const {
  return static_cast<std::size_t>(std::count_if(edges.begin(), edges.end(), [](const Edge& e) { return !e.boundary(); }));
}

Topology Topology::build(const TriMesh& mesh, double minArea) {
  checkTriangles(mesh, minArea);
  const std::vector<HalfEdge> half = sortedHalfEdges(mesh);

  Topology topo;
  topo.triangleEdges.assign(mesh.triangles.size(), {kNone, kNone, kNone});
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i + 1;
    while (j < half.size() && half[j].key == half[i].key) ++j;
    const auto v0 = static_cast<std::uint32_t>(half[i].key >> 32);
    const auto v1 = static_cast<std::uint32_t>(half[i].key & 0xffffffffu);
    if (j - i > 2) {
      const Vec3& p = mesh.positions[v0];
      throw Error(fmt::format("{}: non-manifold edge between vertices {} and {} (shared by {} triangles, "
                              "near {:.4f} {:.4f} {:.4f} m)",
                              mesh.name, v0, v1, j - i, p.x(), p.y(), p.z()));
    }
    Edge e{v0, v1, half[i].face, kNone, kNone, kNone};
    auto opposite = [&](const HalfEdge& h) { return mesh.triangles[h.face][(h.corner + 2) % 3]; };
    e.opposite0 = opposite(half[i]);
    if (j - i == 2) {
      e.face1 = half[i + 1].face;
      e.opposite1 = opposite(half[i + 1]);
    }
    const auto index = static_cast<std::uint32_t>(topo.edges.size());
    for (std::size_t k = i; k < j; ++k) topo.triangleEdges[half[k].face][half[k].corner] = index;
    topo.edges.push_back(e);
    i = j;
  }
  topo.boundaryLoops = traceBoundaryLoops(topo);
  return topo;
}

std::size_t countNonManifoldEdges(const TriMesh& mesh) {
  const std::vector<HalfEdge> half = sortedHalfEdges(mesh);
  std::size_t count = 0;
  for (std::size_t i = 0; i < half.size();) {
    std::size_t j = i + 1;
    while (j < half.size() && half[j].key == half[i].key) ++j;
    if (j - i > 2) ++count;
    i = j;
  }
  return count;
}

std::vector<std::array<std::uint32_t, 2>> facingBoundaryPairs(const TriMesh& mesh, const Topology& topology,
                                                              double maxGap_m, int minSeparation) {
  // The grid's cells are the gap wide: a gap that is not a positive number has no cells.
  if (!(maxGap_m > 0.0)) throw Error(fmt::format("facing boundary pairs: the gap must be > 0 m, got {}", maxGap_m));
  struct Place {
    std::uint32_t vertex, loop, index;  ///< the vertex, its loop and where along it
  };
  std::vector<Place> boundary;
  for (std::size_t l = 0; l < topology.boundaryLoops.size(); ++l)
    for (std::size_t i = 0; i < topology.boundaryLoops[l].size(); ++i)
      boundary.push_back({topology.boundaryLoops[l][i], static_cast<std::uint32_t>(l), static_cast<std::uint32_t>(i)});
  const auto apartAlongBoundary = [&](const Place& p, const Place& q) {
    if (p.loop != q.loop) return true;
    const auto length = static_cast<std::uint32_t>(topology.boundaryLoops[p.loop].size());
    const std::uint32_t d = p.index > q.index ? p.index - q.index : q.index - p.index;
    return static_cast<int>(std::min(d, length - d)) >= minSeparation;
  };
  // A uniform grid of cells at least maxGap wide: a vertex's candidates are in the 27 cells
  // around its own. Cells are at most a million to a side (keys fit 21 bits an axis).
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::max());
  Vec3 hi = -lo;
  for (const Place& p : boundary) {
    lo = lo.cwiseMin(mesh.positions[p.vertex]);
    hi = hi.cwiseMax(mesh.positions[p.vertex]);
  }
  const double cell = boundary.empty() ? 1.0 : std::max(maxGap_m, 1e-6 * (hi - lo).maxCoeff());
  const auto cellOf = [&](const Vec3& x) {
    std::array<std::int64_t, 3> c{};
    for (int k = 0; k < 3; ++k) c[static_cast<std::size_t>(k)] = static_cast<std::int64_t>((x[k] - lo[k]) / cell);
    return c;
  };
  const auto key = [](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (static_cast<std::uint64_t>(x) << 42) | (static_cast<std::uint64_t>(y) << 21) | static_cast<std::uint64_t>(z);
  };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells;
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const auto c = cellOf(mesh.positions[boundary[i].vertex]);
    cells[key(c[0], c[1], c[2])].push_back(i);
  }
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> nearest(boundary.size(), kNone);
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const Vec3& x = mesh.positions[boundary[i].vertex];
    const auto c = cellOf(x);
    double best = maxGap_m;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dz = -1; dz <= 1; ++dz) {
          if (c[0] + dx < 0 || c[1] + dy < 0 || c[2] + dz < 0) continue;
          const auto found = cells.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (found == cells.end()) continue;
          for (const std::size_t j : found->second) {
            if (j == i || !apartAlongBoundary(boundary[i], boundary[j])) continue;
            const double d = (mesh.positions[boundary[j].vertex] - x).norm();
            // Of equally near ones, the last along the boundary: the choice does not hang on
            // the order the cells are visited in.
            if (d < best || (d == best && (nearest[i] == kNone || j > nearest[i]))) {
              best = d;
              nearest[i] = j;
            }
          }
        }
  }
  std::vector<std::array<std::uint32_t, 2>> pairs;
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const std::size_t j = nearest[i];
    if (j == kNone || j < i || nearest[j] != i) continue;  // each mutual pair once
    const std::uint32_t a = boundary[i].vertex, b = boundary[j].vertex;
    pairs.push_back({std::min(a, b), std::max(a, b)});
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace drape::mesh
