#include "drape/mesh/weld.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <unordered_set>

namespace drape::mesh {

std::vector<std::uint32_t> weldByPosition(const TriMesh& mesh, double tolerance) {
  const std::size_t n = mesh.positions.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  auto cell = [&](std::uint32_t v) {
    const Vec3& p = mesh.positions[v];
    return std::array<long long, 3>{std::llround(p.x() / tolerance), std::llround(p.y() / tolerance),
                                    std::llround(p.z() / tolerance)};
  };
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const auto ca = cell(a), cb = cell(b);
    return ca != cb ? ca < cb : a < b;
  });
  std::vector<std::uint32_t> map(n);
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    const auto c = cell(order[i]);
    while (j < n && cell(order[j]) == c) map[order[j++]] = order[i];
    i = j;
  }
  return map;
}

namespace {

// The triangle's vertices rotated so the lowest comes first: the same triangle, whichever
// corner a file starts it at. Two windings of one triangle stay two keys (a two-sided copy
// is the reverse winding: that counts as a duplicate too, below).
std::array<std::uint32_t, 3> canonical(const Triangle& t) {
  const std::size_t first = static_cast<std::size_t>(std::min_element(t.begin(), t.end()) - t.begin());
  return {t[first], t[(first + 1) % 3], t[(first + 2) % 3]};
}

struct TriangleHash {
  std::size_t operator()(const std::array<std::uint32_t, 3>& t) const {
    return std::hash<std::uint64_t>{}((std::uint64_t{t[0]} << 42) ^ (std::uint64_t{t[1]} << 21) ^ t[2]);
  }
};

}  // namespace

Welded weld(const TriMesh& mesh, double tolerance, bool keepLoose) {
  const std::vector<std::uint32_t> map = weldByPosition(mesh, tolerance);
  Welded out;
  out.mesh.name = mesh.name;
  for (std::size_t v = 0; v < map.size(); ++v)
    if (map[v] != v) ++out.merged;
  std::vector<std::uint32_t> renumbered(mesh.positions.size(), kNoVertex);
  std::unordered_set<std::array<std::uint32_t, 3>, TriangleHash> seen;
  seen.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    const Triangle w{map[t[0]], map[t[1]], map[t[2]]};
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) {
      ++out.collapsed;
      continue;
    }
    const auto key = canonical(w);
    const auto reversed = canonical(Triangle{w[0], w[2], w[1]});
    if (seen.count(key) != 0 || seen.count(reversed) != 0) {
      ++out.duplicates;
      continue;
    }
    seen.insert(key);
    Triangle tri;
    for (int c = 0; c < 3; ++c) {
      std::uint32_t& r = renumbered[w[static_cast<std::size_t>(c)]];
      if (r == kNoVertex) {
        r = static_cast<std::uint32_t>(out.mesh.positions.size());
        out.mesh.positions.push_back(mesh.positions[w[static_cast<std::size_t>(c)]]);
      }
      tri[static_cast<std::size_t>(c)] = r;
    }
    out.mesh.triangles.push_back(tri);
  }
  std::size_t used = 0;
  for (std::size_t v = 0; v < map.size(); ++v) {
    if (map[v] != v) continue;
    ++used;
    if (keepLoose && renumbered[v] == kNoVertex) {
      renumbered[v] = static_cast<std::uint32_t>(out.mesh.positions.size());
      out.mesh.positions.push_back(mesh.positions[v]);
    }
  }
  out.unused = used - out.mesh.positions.size();
  return out;
}

}  // namespace drape::mesh
