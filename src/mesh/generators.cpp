#include "drape/mesh/generators.hpp"

#include <cmath>
#include <numbers>

namespace drape::mesh {

TriMesh makeSheet(const Vec3& origin, const Vec3& uAxis, const Vec3& vAxis, int nu, int nv) {
  TriMesh m;
  m.name = "sheet";
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) m.positions.push_back(origin + uAxis * (double(i) / nu) + vAxis * (double(j) / nv));
  auto id = [nu](int i, int j) { return static_cast<std::uint32_t>(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      if ((i + j) % 2 == 0) {
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({a, c, d});
      } else {
        m.triangles.push_back({a, b, d});
        m.triangles.push_back({b, c, d});
      }
    }
  return m;
}

Skirt makeSkirt(const SkirtShape& s) {
  Skirt out;
  out.mesh.name = "skirt";
  for (int r = 0; r <= s.rings; ++r) {
    const double f = double(r) / s.rings;
    const double flare = 1.0 + (s.hemFlare - 1.0) * f;
    const bool profiled = s.ringRadiusX.size() == std::size_t(s.rings + 1) && s.ringRadiusZ.size() == std::size_t(s.rings + 1);
    const double rx = profiled ? s.ringRadiusX[r] : s.waistRadiusX * flare;
    const double rz = profiled ? s.ringRadiusZ[r] : s.waistRadiusZ * flare;
    // Stagger alternate rings by half a segment: near-equilateral triangles.
    const double phase = (r % 2) * 0.5;
    for (int k = 0; k < s.segments; ++k) {
      const double a = 2.0 * std::numbers::pi * (k + phase) / s.segments;
      out.mesh.positions.push_back(s.waistCentre + Vec3(rx * std::sin(a), -s.length * f, rz * std::cos(a)));
    }
  }
  auto id = [&](int r, int k) { return static_cast<std::uint32_t>(r * s.segments + (k % s.segments)); };
  for (int r = 0; r < s.rings; ++r) {
    for (int k = 0; k < s.segments; ++k) {
      // Winding chosen so the normal (b - a) x (c - a) points away from the axis.
      if (r % 2 == 0) {
        out.mesh.triangles.push_back({id(r, k), id(r + 1, k), id(r, k + 1)});
        out.mesh.triangles.push_back({id(r, k + 1), id(r + 1, k), id(r + 1, k + 1)});
      } else {
        out.mesh.triangles.push_back({id(r, k), id(r + 1, k), id(r + 1, k + 1)});
        out.mesh.triangles.push_back({id(r, k), id(r + 1, k + 1), id(r, k + 1)});
      }
    }
  }
  // The mask is the waist ring itself, as a polygon over the opening (a mask only has to
  // carry the vertices it marks).
  out.waistband.name = "waistband";
  out.waistband.positions.assign(out.mesh.positions.begin(), out.mesh.positions.begin() + s.segments);
  std::vector<std::uint32_t> ring(static_cast<std::size_t>(s.segments));
  for (int k = 0; k < s.segments; ++k) ring[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(k);
  triangulatePolygon(ring, out.waistband.triangles);
  return out;
}

}  // namespace drape::mesh
