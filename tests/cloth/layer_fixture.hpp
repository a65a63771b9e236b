#pragma once
// Shared by the layer collision tests: every pair a LayerCollider tests, checked one by one.

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "drape/cloth/layer_collider.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::cloth::testing {

/// (vertex, triangle, side, crossed) of each contact.
using ContactSet = std::set<std::tuple<std::uint32_t, std::uint32_t, double, bool>>;

/// The contacts brute force finds between `s0` and `s1` of mesh `m` (the collider's
/// numbering: a garment's own points and triangles, then those below it): every pair the
/// collider tests, at the thickness it keeps it at.
inline ContactSet everyPair(const LayerCollider& collider, const mesh::TriMesh& m, const ClothState& s0,
                            const ClothState& s1) {
  ContactSet out;
  for (std::uint32_t v = 0; v < m.positions.size(); ++v)
    for (std::uint32_t t = 0; t < m.triangles.size(); ++t) {
      const double thickness = collider.pairThickness(v, t);
      if (thickness == 0) continue;
      const mesh::Triangle& tri = m.triangles[t];
      const std::array<Vec3, 3> t0{s0.position(tri[0]), s0.position(tri[1]), s0.position(tri[2])};
      const std::array<Vec3, 3> t1{s1.position(tri[0]), s1.position(tri[1]), s1.position(tri[2])};
      if (auto c = layerContact(s0.position(v), s1.position(v), t0, t1, thickness))
        out.insert({v, t, c->side, c->crossed});
    }
  return out;
}

/// The contacts a collider's test found, as everyPair gives them; a pair found twice (which
/// the test would resolve twice) is a failure.
inline ContactSet contactSet(const std::vector<LayerContact>& contacts) {
  ContactSet out;
  for (const LayerContact& c : contacts)
    if (!out.insert({c.vertex, c.triangle, c.side, c.crossed}).second)
      ADD_FAILURE() << "vertex " << c.vertex << " and triangle " << c.triangle << " found twice";
  return out;
}

/// Test `test` of a run of layers along y whose points are carried along together (a walk's
/// common motion, which keeps a candidate list) while each wanders a little and two of them,
/// at random, jump, one 5 `scale` up or down through the layer beside it, the other 3 along its
/// layer (which mends the list: their pairs, and those of the triangles around them, change);
/// with `scatter`, every tenth test they all wander 1.5 `scale` instead (which makes the list
/// again).
inline void carryAndWander(ClothState& points, int test, double scale, std::mt19937& random, bool scatter) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Vec3 carried(0.02 * unit(random), 0.01 * unit(random), -0.015 * unit(random));
  scatter = scatter && test % 10 == 9;
  const double wander = (scatter ? 1.5 : 0.12) * scale;
  for (std::size_t v = 0; v < points.size(); ++v)
    points.setPosition(
        v, points.position(v) + carried + wander * Vec3(unit(random) - 0.5, unit(random) - 0.5, unit(random) - 0.5));
  if (scatter) return;
  std::uniform_int_distribution<std::size_t> anyPoint(0, points.size() - 1);
  for (int jumper = 0; jumper < 2; ++jumper) {
    const std::size_t v = anyPoint(random);
    const double sign = unit(random) < 0.5 ? -1.0 : 1.0;
    const double angle = 6.283185307179586 * unit(random);
    const Vec3 jump = jumper == 0 ? Vec3(0.3 * (unit(random) - 0.5), sign, 0.3 * (unit(random) - 0.5))
                                  : Vec3(std::cos(angle), 0.1 * sign, std::sin(angle));
    points.setPosition(v, points.position(v) + (jumper == 0 ? 5.0 : 3.0) * scale * jump.normalized());
  }
}

}  // namespace drape::cloth::testing
