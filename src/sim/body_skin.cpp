#include "drape/sim/body_skin.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "drape/core/error.hpp"
#include "drape/mesh/closest_point.hpp"
#include "drape/motion/skinning.hpp"

namespace drape::sim {
namespace {

/// Influences lighter than this do not decide whether a vertex is fitted: skinning tools
/// leave small weights on joints far along the chain.
constexpr float kLeastWeight = 0.05f;
/// Steps of the fit per vertex (BodySkin::pose).
constexpr int kSteps = 8;
/// Passes of the tuck: a pushed triangle's neighbours may then be nearest to the cloth.
constexpr int kTuckPasses = 4;
/// Vertices or cloth points per parallel task: a few microseconds of work each.
constexpr std::size_t kGrain = 256;
/// The tuck's grid cell: two cells around a point reach as deep as the tuck goes.
constexpr double kCell_m = 0.5 * BodySkin::kTuckMost_m;

}  // namespace

BodySkin::BodySkin(const scene::Avatar& avatar, const std::vector<PartField>& fields, double allowance_m)
    : avatar_(avatar), fields_(fields), allowance_m_(allowance_m) {
  if (!avatar.skin) throw Error(fmt::format("{}: the avatar has no skinned mesh to draw", avatar.source));
  std::vector<int> fieldOfJoint(avatar.joints.size(), -1);
  for (std::size_t f = 0; f < fields.size(); ++f)
    if (fields[f].joint >= 0) fieldOfJoint[static_cast<std::size_t>(fields[f].joint)] = static_cast<int>(f);
  const scene::SkinnedMesh& skin = *avatar.skin;
  first_.reserve(skin.mesh.positions.size() + 1);
  first_.push_back(0);
  for (std::size_t v = 0; v < skin.mesh.positions.size(); ++v) {
    std::vector<std::uint32_t> parts;
    bool allCollidable = true;
    for (std::size_t k = 0; k < 4; ++k) {
      if (skin.weights[v][k] < kLeastWeight) continue;
      const int f = fieldOfJoint[skin.joints[v][k]];
      if (f < 0) allCollidable = false;
      else parts.push_back(static_cast<std::uint32_t>(f));
    }
    if (allCollidable) fieldOf_.insert(fieldOf_.end(), parts.begin(), parts.end());
    first_.push_back(static_cast<std::uint32_t>(fieldOf_.size()));
    float collidable = 0.0f;
    for (std::size_t k = 0; k < 4; ++k)
      if (fieldOfJoint[skin.joints[v][k]] >= 0) collidable += skin.weights[v][k];
    tuckable_.push_back(collidable >= 0.5f);
  }
  buildRings();
}

void BodySkin::buildRings() {
  const std::vector<mesh::Triangle>& triangles = avatar_.skin->mesh.triangles;
  ringFirst_.assign(first_.size(), 0);
  for (const mesh::Triangle& t : triangles)
    for (const std::uint32_t v : t) ++ringFirst_[v + 1];
  for (std::size_t v = 1; v < ringFirst_.size(); ++v) ringFirst_[v] += ringFirst_[v - 1];
  ring_.resize(ringFirst_.back());
  std::vector<std::uint32_t> next(ringFirst_.begin(), ringFirst_.end() - 1);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const std::uint32_t v : triangles[t]) ring_[next[v]++] = static_cast<std::uint32_t>(t);
}

void BodySkin::pose(std::span<const RigidTransform> jointWorld, std::span<const GarmentSurface> garments,
                    std::vector<Vec3>& out) {
  motion::poseSkin(avatar_, jointWorld, out);
  toLocal_.resize(fields_.size());
  for (std::size_t f = 0; f < fields_.size(); ++f)
    toLocal_[f] = jointWorld[static_cast<std::size_t>(fields_[f].joint)].inverse();
  fit(out, jointWorld);
  if (garments.empty()) return;
  sampleGarments(garments);
  // The fitted skin's normals for every pass: a vertex moves along its own normal only,
  // however its neighbours moved before it.
  mesh::vertexNormals(out, avatar_.skin->mesh.triangles, normals_);
  pushed_.assign(out.size(), 0.0);
  for (int pass = 0; pass < kTuckPasses; ++pass)
    if (!tuck(out)) break;
}

void BodySkin::fit(std::vector<Vec3>& out, std::span<const RigidTransform> jointWorld) {
  // Each vertex moves by its own reads alone: in parallel, the same result on any number
  // of threads.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, first_.size() - 1, kGrain), [&](const auto& range) {
    for (std::size_t v = range.begin(); v != range.end(); ++v) {
      if (first_[v] == first_[v + 1]) continue;
      // Steps towards the nearest part by the excess; where the field bends (a crease
      // between two parts, the nearest part changing) one step falls short, so repeat.
      for (int step = 0; step < kSteps; ++step) {
        const Nearest n = nearestPart(v, out[v], jointWorld);
        if (!(n.distance_m > allowance_m_) || !std::isfinite(n.distance_m)) break;
        out[v] -= (n.distance_m - allowance_m_) * n.away;
      }
    }
  });
}

void BodySkin::sampleGarments(std::span<const GarmentSurface> garments) {
  samples_.clear();
  for (const GarmentSurface& g : garments) {
    // Its vertices (of its triangles: a stray vertex is not cloth).
    used_.assign(g.positions.size(), 0);
    for (const mesh::Triangle& t : g.triangles)
      for (const std::uint32_t v : t) used_[v] = 1;
    for (std::size_t v = 0; v < used_.size(); ++v)
      if (used_[v]) samples_.push_back(g.positions[v]);
    for (const mesh::Triangle& t : g.triangles) {
      const Vec3& a = g.positions[t[0]];
      const Vec3 ab = g.positions[t[1]] - a, ac = g.positions[t[2]] - a;
      // The centroids of an n x n split of the triangle, n from its longest edge.
      const double longest = std::sqrt(std::max({ab.squaredNorm(), ac.squaredNorm(), (ac - ab).squaredNorm()}));
      const int n = std::clamp(static_cast<int>(std::ceil(longest / kTuckSpacing_m)), 1, 8);
      const Vec3 du = ab / n, dv = ac / n;
      for (int i = 0; i < n; ++i)
        for (int j = 0; i + j < n; ++j) {
          samples_.push_back(a + (i + 1.0 / 3.0) * du + (j + 1.0 / 3.0) * dv);
          if (i + j + 1 < n) samples_.push_back(a + (i + 2.0 / 3.0) * du + (j + 2.0 / 3.0) * dv);
        }
    }
  }
  active_.resize(samples_.size());
  for (std::size_t i = 0; i < active_.size(); ++i) active_[i] = static_cast<std::uint32_t>(i);
}

bool BodySkin::tuck(std::vector<Vec3>& out) {
  buildGrid(out);
  push_.assign(out.size(), 0.0);
  // The skin only moves in, away from the cloth: the next pass looks again only where this
  // one pushed (a pushed triangle's neighbour may be the nearest now, or the push fell short
  // where the cloth's points pushed a triangle from its corners' sides).
  // Where each point wants the skin, in parallel (reads only); then the pushes, in the
  // points' order (a maximum per vertex: the same on any number of threads).
  asks_.resize(active_.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, active_.size(), kGrain), [&](const auto& range) {
    for (std::size_t j = range.begin(); j != range.end(); ++j) asks_[j] = tuckUnder(samples_[active_[j]], out);
  });
  const std::vector<mesh::Triangle>& triangles = avatar_.skin->mesh.triangles;
  std::size_t kept = 0;
  for (std::size_t j = 0; j < active_.size(); ++j) {
    const Ask& ask = asks_[j];
    if (!(ask.depth > 0)) continue;
    active_[kept++] = active_[j];
    if (!ask.push) continue;
    // The whole triangle in by the depth: the skin's triangles are about as large as the
    // spacing of the cloth's points, so one point may be all that reaches a triangle.
    for (const std::uint32_t corner : triangles[ask.face])
      if (tuckable_[corner]) push_[corner] = std::max(push_[corner], ask.depth);
  }
  active_.resize(kept);
  bool moved = false;
  for (std::size_t v = 0; v < out.size(); ++v) {
    const double push = std::min(push_[v], kTuckMost_m - pushed_[v]);
    if (!(push > 0)) continue;
    out[v] -= push * normals_[v];
    pushed_[v] += push;
    moved = true;
  }
  return moved;
}

BodySkin::Ask BodySkin::tuckUnder(const Vec3& p, const std::vector<Vec3>& out) const {
  constexpr double kFar = -std::numeric_limits<double>::infinity();
  const std::int64_t nearest = nearestTuckable(p);
  if (nearest < 0) return {kFar, 0, false};
  // The nearest skin triangle around the nearest tuckable vertex.
  const std::vector<mesh::Triangle>& triangles = avatar_.skin->mesh.triangles;
  const auto v = static_cast<std::size_t>(nearest);
  double best = std::numeric_limits<double>::infinity();
  std::uint32_t face = 0;
  Vec3 closest = Vec3::Zero();
  for (std::uint32_t i = ringFirst_[v]; i < ringFirst_[v + 1]; ++i) {
    const mesh::Triangle& t = triangles[ring_[i]];
    const Vec3 q = mesh::closestOnTriangle(p, out[t[0]], out[t[1]], out[t[2]]);
    if (const double d2 = (q - p).squaredNorm(); d2 < best) {
      best = d2;
      face = ring_[i];
      closest = q;
    }
  }
  // Which side of the skin p is on: by the vertex normals blended at the closest point, not
  // the triangle's own normal, which points anywhere where the closest point is a corner
  // (the crotch's, under a skirt).
  const mesh::Triangle& t = triangles[face];
  const Vec3 w = mesh::barycentric(closest, out[t[0]], out[t[1]], out[t[2]]);
  const Vec3 n = w.x() * normals_[t[0]] + w.y() * normals_[t[1]] + w.z() * normals_[t[2]];
  const double distance = std::sqrt(best);
  const double depth = kTuckMargin_m - ((p - closest).dot(n) < 0 ? -distance : distance);  // how far to push in
  return {depth, face, depth > 0 && depth <= kTuckMost_m && outsideTheParts(p)};
}

void BodySkin::buildGrid(const std::vector<Vec3>& out) {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t v = 0; v < out.size(); ++v) {
    if (!tuckable_[v]) continue;
    lo = lo.cwiseMin(out[v]);
    hi = hi.cwiseMax(out[v]);
  }
  cellFirst_.clear();
  cellVertices_.clear();
  if (!(lo.x() <= hi.x())) {  // nothing to tuck
    gridDims_ = {0, 0, 0};
    return;
  }
  gridOrigin_ = lo;
  for (int a = 0; a < 3; ++a) gridDims_[a] = static_cast<std::int64_t>((hi[a] - lo[a]) / kCell_m) + 1;
  const auto cellOf = [&](const Vec3& p) {
    const Vec3 c = (p - gridOrigin_) / kCell_m;
    return (static_cast<std::int64_t>(c.z()) * gridDims_[1] + static_cast<std::int64_t>(c.y())) * gridDims_[0] +
           static_cast<std::int64_t>(c.x());
  };
  cellFirst_.assign(static_cast<std::size_t>(gridDims_[0] * gridDims_[1] * gridDims_[2] + 1), 0);
  for (std::size_t v = 0; v < out.size(); ++v)
    if (tuckable_[v]) ++cellFirst_[static_cast<std::size_t>(cellOf(out[v])) + 1];
  for (std::size_t c = 1; c < cellFirst_.size(); ++c) cellFirst_[c] += cellFirst_[c - 1];
  cellVertices_.resize(cellFirst_.back());
  for (std::vector<double>* c : {&cellX_, &cellY_, &cellZ_}) c->resize(cellFirst_.back());
  std::vector<std::uint32_t>& next = cellNext_;
  next.assign(cellFirst_.begin(), cellFirst_.end() - 1);
  for (std::size_t v = 0; v < out.size(); ++v) {
    if (!tuckable_[v]) continue;
    const std::uint32_t i = next[static_cast<std::size_t>(cellOf(out[v]))]++;
    cellVertices_[i] = static_cast<std::uint32_t>(v);
    cellX_[i] = out[v].x();
    cellY_[i] = out[v].y();
    cellZ_[i] = out[v].z();
  }
}

std::int64_t BodySkin::nearestTuckable(const Vec3& p) const {
  if (gridDims_[0] == 0) return -1;
  const Vec3 c = (p - gridOrigin_) / kCell_m;
  std::array<std::int64_t, 3> at{};
  for (int a = 0; a < 3; ++a) {
    if (!(c[a] > -2.0 && c[a] < static_cast<double>(gridDims_[a]) + 2.0)) return -1;  // beyond reach
    at[a] = static_cast<std::int64_t>(std::floor(c[a]));
  }
  // The cells around p's first; a vertex found within a cell of p is the nearest (any
  // other is a cell away at least). Else the next ring of cells, as far as the tuck reaches.
  double best = std::numeric_limits<double>::infinity();
  std::int64_t nearest = -1;
  for (std::int64_t reach = 1; reach <= 2; ++reach) {
    for (std::int64_t z = std::max<std::int64_t>(at[2] - reach, 0); z <= std::min(at[2] + reach, gridDims_[2] - 1); ++z)
      for (std::int64_t y = std::max<std::int64_t>(at[1] - reach, 0); y <= std::min(at[1] + reach, gridDims_[1] - 1);
           ++y)
        for (std::int64_t x = std::max<std::int64_t>(at[0] - reach, 0); x <= std::min(at[0] + reach, gridDims_[0] - 1);
             ++x) {
          const bool inner = std::abs(x - at[0]) < reach && std::abs(y - at[1]) < reach && std::abs(z - at[2]) < reach;
          if (inner) continue;  // searched at the smaller reach
          const auto cell = static_cast<std::size_t>((z * gridDims_[1] + y) * gridDims_[0] + x);
          for (std::uint32_t i = cellFirst_[cell]; i < cellFirst_[cell + 1]; ++i) {
            const double dx = cellX_[i] - p.x(), dy = cellY_[i] - p.y(), dz = cellZ_[i] - p.z();
            if (const double d2 = dx * dx + dy * dy + dz * dz; d2 < best) {
              best = d2;
              nearest = cellVertices_[i];
            }
          }
        }
    if (best <= kCell_m * kCell_m * static_cast<double>(reach * reach)) break;
  }
  return nearest;
}

bool BodySkin::outsideTheParts(const Vec3& p) const {
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    const field::PointLocation at = fields_[f].field.locate(toLocal_[f].apply(p));
    if (at.inVolume && at.distance_m < 0) return false;
  }
  return true;
}

BodySkin::Nearest BodySkin::nearestPart(std::size_t v, const Vec3& p, std::span<const RigidTransform> jointWorld) const {
  Nearest n;
  for (std::uint32_t i = first_[v]; i < first_[v + 1]; ++i) {
    const PartField& part = fields_[fieldOf_[i]];
    const Vec3 local = toLocal_[fieldOf_[i]].apply(p);
    const field::PointLocation at = part.field.locate(local);
    // Beyond the grid the distance is clamped, not measured: a vertex that far from a part
    // it is skinned to is left where skinning put it.
    if (!at.inVolume || at.distance_m >= n.distance_m) continue;
    // A Newton step on the trilinear distance: one step meets the allowance where the
    // field is linear.
    n.distance_m = at.distance_m;
    n.away = jointWorld[static_cast<std::size_t>(part.joint)].rotation * part.field.newtonDirection(local);
  }
  return n;
}

}  // namespace drape::sim
