#include "drape/cloth/self_collider.hpp"

#include <algorithm>
#include <bit>
#include <cmath>

#include <fmt/format.h>

#include "drape/cloth/model.hpp"
#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

/// Jacobi sweeps over the contacts' positions: each moves every pair by the average of its
/// pushes, so that a vertex in several contacts converges instead of overshooting.
constexpr int kPositionSweeps = 3;
/// The candidate pairs hold while no vertex moves more than half this many thicknesses
/// (beyond the garment's common motion) from where they were found.
constexpr double kMarginThicknesses = 2.0;
/// How far outside a triangle (in barycentric weight) a projection may fall and still count:
/// a vertex over the edge between two faces belongs to both.
constexpr double kEdgeTolerance = 1e-9;

Vec3 at(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& z, std::uint32_t i) {
  return {x[i], y[i], z[i]};
}

/// The unit normal of the triangle, or zero when it is degenerate.
Vec3 unitNormal(const std::array<Vec3, 3>& t) {
  const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const double length = n.norm();
  return length > 0 ? Vec3(n / length) : Vec3(Vec3::Zero());
}

/// The barycentric weights of p's projection on the triangle's plane, when it falls inside.
std::optional<std::array<double, 3>> barycentric(const Vec3& p, const std::array<Vec3, 3>& t) {
  const Vec3 r = p - t[0], e1 = t[1] - t[0], e2 = t[2] - t[0];
  const double a = e1.dot(e1), b = e1.dot(e2), c = e2.dot(e2), re1 = r.dot(e1), re2 = r.dot(e2);
  const double det = a * c - b * b;
  if (!(det > 0)) return std::nullopt;
  const double v = (c * re1 - b * re2) / det, w = (a * re2 - b * re1) / det, u = 1.0 - v - w;
  if (u < -kEdgeTolerance || v < -kEdgeTolerance || w < -kEdgeTolerance) return std::nullopt;
  return std::array<double, 3>{u, v, w};
}

}  // namespace

std::optional<SelfContact> selfContact(const Vec3& p0, const Vec3& p1, const std::array<Vec3, 3>& t0,
                                       const std::array<Vec3, 3>& t1, double thickness) {
  // Most pairs a test reads are farther than h on their side: said with the normals as they
  // come (twice the areas), without a square root.
  const Vec3 n1 = (t1[1] - t1[0]).cross(t1[2] - t1[0]);
  const double area2 = n1.squaredNorm();
  if (!(area2 > 0)) return std::nullopt;
  const Vec3 n0 = (t0[1] - t0[0]).cross(t0[2] - t0[0]);
  // The side it keeps to: where it was at the last test (the end's, if the triangle was
  // degenerate then).
  const double d0 = (p0 - t0[0]).dot(n0.squaredNorm() > 0 ? n0 : n1);
  const double side = d0 >= 0 ? 1.0 : -1.0;
  const double d1 = side * (p1 - t1[0]).dot(n1);  // times |n1|
  if (d1 >= 0 && d1 * d1 >= thickness * thickness * area2) return std::nullopt;
  SelfContact contact;
  contact.side = side;
  contact.crossed = d1 < 0;
  std::optional<std::array<double, 3>> weights;
  if (!contact.crossed) {
    weights = barycentric(p1, t1);  // within h over the face
  } else {
    // Through the plane: where its distance, taken as linear over the interval, was zero,
    // the point must lie in the triangle as it was then.
    const double s = side * d0 / std::sqrt(n0.squaredNorm() > 0 ? n0.squaredNorm() : area2);
    const double e = d1 / std::sqrt(area2);
    const double when = s / (s - e);
    const auto mix = [when](const Vec3& a, const Vec3& b) -> Vec3 { return a + when * (b - a); };
    weights = barycentric(mix(p0, p1), {mix(t0[0], t1[0]), mix(t0[1], t1[1]), mix(t0[2], t1[2])});
  }
  if (!weights) return std::nullopt;
  contact.weights = *weights;
  return contact;
}

SelfCollider::SelfCollider(const ClothModel& model, std::string garment, double thickness_m, int every)
    : garment_(std::move(garment)),
      thickness_(thickness_m),
      every_(std::max(1, every)),
      staticFriction_(model.material().staticFriction),
      dynamicFriction_(model.material().dynamicFriction) {
  if (!(thickness_m > 0) || !std::isfinite(thickness_m))
    throw Error(
        fmt::format("garment '{}': self-collision thickness {} m must be a positive length", garment_, thickness_m));
  const std::size_t n = model.vertexCount(), m = model.triangleCount();
  triangles_.assign(model.triangles().begin(), model.triangles().end());
  // Neighbours (CSR) and the mean edge length, from the triangles' edges.
  std::vector<std::vector<std::uint32_t>> around(n);
  double edges = 0;
  for (const auto& t : triangles_)
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = t[e], b = t[(e + 1) % 3];
      around[a].push_back(b);
      around[b].push_back(a);
      edges += (at(model.restX(), model.restY(), model.restZ(), a) - at(model.restX(), model.restY(), model.restZ(), b))
                   .norm();
    }
  setNeighbours(around);
  // Cells as wide as a triangle's box grown by h + m on each side (an edge and a little
  // more): a triangle's box touches at most two along each axis, and a vertex's mostly one.
  const double meanEdge = m > 0 ? edges / (3.0 * static_cast<double>(m)) : thickness_m;
  margin_ = kMarginThicknesses * thickness_m;
  cell_m_ = meanEdge + 2.0 * (thickness_m + margin_);
  inverseMass_ = model.inverseMass();
  lastX_ = model.restX();
  lastY_ = model.restY();
  lastZ_ = model.restZ();
  vertexLo_.resize(3 * n);
  vertexHi_.resize(3 * n);
  const std::size_t buckets = std::bit_ceil(std::max<std::size_t>(64, 2 * n));
  bucketMask_ = static_cast<std::uint32_t>(buckets - 1);
  bucketStart_.resize(buckets + 1);
  bucketFill_.resize(buckets);
  entries_.resize(2 * n);
  seen_.resize(n);
  contacts_.reserve(n);
  pairs_.reserve(4 * n);
  pushX_.resize(n);
  pushY_.resize(n);
  pushZ_.resize(n);
  pushes_.resize(n);
}

void SelfCollider::setFixedVertices(const std::vector<std::uint32_t>& vertices) {
  for (const std::uint32_t v : vertices)
    if (v < inverseMass_.size()) inverseMass_[v] = 0.0;
}

void SelfCollider::setStitches(const std::vector<Stitch>& stitches) {
  // A stitch makes its two vertices one point of the cloth: each takes the other and the
  // other's neighbours as its own.
  const std::size_t n = neighbourStart_.size() - 1;
  std::vector<std::vector<std::uint32_t>> around(n);
  for (std::size_t v = 0; v < n; ++v)
    around[v].assign(neighbours_.begin() + neighbourStart_[v], neighbours_.begin() + neighbourStart_[v + 1]);
  const std::vector<std::vector<std::uint32_t>> edges = around;
  for (const Stitch& s : stitches) {
    if (s.a >= n || s.b >= n) continue;
    around[s.a].push_back(s.b);
    around[s.a].insert(around[s.a].end(), edges[s.b].begin(), edges[s.b].end());
    around[s.b].push_back(s.a);
    around[s.b].insert(around[s.b].end(), edges[s.a].begin(), edges[s.a].end());
  }
  setNeighbours(around);
  pairsBuilt_ = false;
}

void SelfCollider::setNeighbours(std::vector<std::vector<std::uint32_t>>& around) {
  neighbourStart_.assign(1, 0);
  neighbours_.clear();
  for (std::size_t v = 0; v < around.size(); ++v) {
    auto& list = around[v];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    list.erase(std::remove(list.begin(), list.end(), static_cast<std::uint32_t>(v)), list.end());
    neighbours_.insert(neighbours_.end(), list.begin(), list.end());
    neighbourStart_.push_back(static_cast<std::uint32_t>(neighbours_.size()));
  }
}

void SelfCollider::initialise(const ClothState& state) { remember(state); }

bool SelfCollider::excluded(std::uint32_t vertex, std::uint32_t triangle) const {
  const auto first = neighbours_.begin() + neighbourStart_[vertex],
             last = neighbours_.begin() + neighbourStart_[vertex + 1];
  for (const std::uint32_t corner : triangles_[triangle])
    if (corner == vertex || std::binary_search(first, last, corner)) return true;
  return false;
}

bool SelfCollider::movable(std::uint32_t vertex, std::uint32_t) const { return inverseMass_[vertex] > 0; }

void SelfCollider::remember(const ClothState& state) {
  lastX_ = state.x;  // sizes equal after the first: copies, no allocation
  lastY_ = state.y;
  lastZ_ = state.z;
}

void SelfCollider::beginFrame() {
  frameStartCounters_ = counters_;
  frameStartSelf_ = self_;
}

void SelfCollider::restartFrame(const ClothState& state, double) {
  counters_ = frameStartCounters_;
  self_ = frameStartSelf_;
  remember(state);
  pairsBuilt_ = false;  // the attempt's list: built again, so the frame is computed as before
}

std::uint32_t SelfCollider::bucketOf(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
  const auto h = static_cast<std::uint64_t>(ix) * 73856093u ^ static_cast<std::uint64_t>(iy) * 19349663u ^
                 static_cast<std::uint64_t>(iz) * 83492791u;
  return static_cast<std::uint32_t>(h ^ (h >> 32)) & bucketMask_;
}

template <typename Visit>
void SelfCollider::forCells(const double* lo, const double* hi, Visit&& visit) const {
  const double inv = 1.0 / cell_m_;
  const auto x0 = static_cast<std::int64_t>(std::floor(lo[0] * inv)),
             x1 = static_cast<std::int64_t>(std::floor(hi[0] * inv));
  const auto y0 = static_cast<std::int64_t>(std::floor(lo[1] * inv)),
             y1 = static_cast<std::int64_t>(std::floor(hi[1] * inv));
  const auto z0 = static_cast<std::int64_t>(std::floor(lo[2] * inv)),
             z1 = static_cast<std::int64_t>(std::floor(hi[2] * inv));
  for (std::int64_t ix = x0; ix <= x1; ++ix)
    for (std::int64_t iy = y0; iy <= y1; ++iy)
      for (std::int64_t iz = z0; iz <= z1; ++iz) visit(bucketOf(ix, iy, iz));
}

void SelfCollider::buildGrid(const ClothState& after) {
  // Each vertex's box over the interval (where it was at the last test and is now): most
  // lie in one cell.
  const std::size_t n = after.size();
  for (std::size_t v = 0; v < n; ++v) {
    const double p0[3] = {lastX_[v], lastY_[v], lastZ_[v]}, p1[3] = {after.x[v], after.y[v], after.z[v]};
    for (int k = 0; k < 3; ++k) {
      vertexLo_[3 * v + k] = std::min(p0[k], p1[k]);
      vertexHi_[3 * v + k] = std::max(p0[k], p1[k]);
    }
  }
  // Counted, then placed: every bucket's vertices in one array, in vertex order.
  std::fill(bucketStart_.begin(), bucketStart_.end(), 0u);
  for (std::size_t v = 0; v < n; ++v)
    forCells(&vertexLo_[3 * v], &vertexHi_[3 * v], [&](std::uint32_t b) { ++bucketStart_[b + 1]; });
  for (std::size_t b = 1; b < bucketStart_.size(); ++b) bucketStart_[b] += bucketStart_[b - 1];
  if (bucketStart_.back() > entries_.size()) entries_.resize(bucketStart_.back() + bucketStart_.back() / 4);
  std::copy(bucketStart_.begin(), bucketStart_.end() - 1, bucketFill_.begin());
  for (std::size_t v = 0; v < n; ++v)
    forCells(&vertexLo_[3 * v], &vertexHi_[3 * v],
             [&](std::uint32_t b) { entries_[bucketFill_[b]++] = static_cast<std::uint32_t>(v); });
}

void SelfCollider::gatherPairs(const ClothState& after, double grow) {
  pairs_.clear();
  std::fill(seen_.begin(), seen_.end(), 0u);
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    // The triangle's box over the interval, grown: the vertices whose boxes meet it.
    const auto& c = triangles_[t];
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      const double* last = a == 0 ? lastX_.data() : a == 1 ? lastY_.data() : lastZ_.data();
      const double* now = a == 0 ? after.x.data() : a == 1 ? after.y.data() : after.z.data();
      lo[a] = std::min({last[c[0]], last[c[1]], last[c[2]], now[c[0]], now[c[1]], now[c[2]]}) - grow;
      hi[a] = std::max({last[c[0]], last[c[1]], last[c[2]], now[c[0]], now[c[1]], now[c[2]]}) + grow;
    }
    forCells(lo, hi, [&](std::uint32_t b) {
      for (std::uint32_t e = bucketStart_[b]; e < bucketStart_[b + 1]; ++e) {
        const std::uint32_t v = entries_[e];
        if (seen_[v] == t + 1) continue;
        seen_[v] = t + 1;
        const double* vlo = &vertexLo_[3 * v];
        const double* vhi = &vertexHi_[3 * v];
        const bool apart =
            vlo[0] > hi[0] || vhi[0] < lo[0] || vlo[1] > hi[1] || vhi[1] < lo[1] || vlo[2] > hi[2] || vhi[2] < lo[2];
        if (!apart && !excluded(v, t) && movable(v, t)) pairs_.push_back({v, t});
      }
    });
  }
  std::sort(pairs_.begin(), pairs_.end());
}

void SelfCollider::narrow(const ClothState& after) {
  contacts_.clear();
  self_.candidates += pairs_.size();
  for (const auto& [v, t] : pairs_) {
    const auto& c = triangles_[t];
    const std::array<Vec3, 3> t0{at(lastX_, lastY_, lastZ_, c[0]), at(lastX_, lastY_, lastZ_, c[1]),
                                 at(lastX_, lastY_, lastZ_, c[2])};
    const std::array<Vec3, 3> t1{after.position(c[0]), after.position(c[1]), after.position(c[2])};
    if (std::optional<SelfContact> contact =
            selfContact(at(lastX_, lastY_, lastZ_, v), after.position(v), t0, t1, thickness_)) {
      contact->vertex = v;
      contact->triangle = t;
      contacts_.push_back(*contact);
    }
  }
}

Vec3 SelfCollider::meanPosition(const std::vector<double>& x, const std::vector<double>& y,
                                const std::vector<double>& z) {
  double sx = 0, sy = 0, sz = 0;
  for (std::size_t v = 0; v < x.size(); ++v) {
    sx += x[v];
    sy += y[v];
    sz += z[v];
  }
  return Vec3(sx, sy, sz) / static_cast<double>(std::max<std::size_t>(1, x.size()));
}

bool SelfCollider::pairsHold(const ClothState& now) const {
  if (!pairsBuilt_) return false;
  // Translation-free: what moved with the garment as a whole changes no pair's distance.
  // Both ends of the interval: the last test's positions are where its corrections left them.
  const auto within = [&](const double* x, const double* y, const double* z, const Vec3& mean) {
    const Vec3 shift = mean - builtMean_;
    const double reach2 = 0.25 * margin_ * margin_;
    for (std::size_t v = 0; v < now.size(); ++v) {
      const double dx = x[v] - builtX_[v] - shift.x(), dy = y[v] - builtY_[v] - shift.y(),
                   dz = z[v] - builtZ_[v] - shift.z();
      if (dx * dx + dy * dy + dz * dz > reach2) return false;
    }
    return true;
  };
  return within(now.x.data(), now.y.data(), now.z.data(), meanPosition(now.x, now.y, now.z)) &&
         within(lastX_.data(), lastY_.data(), lastZ_.data(), meanPosition(lastX_, lastY_, lastZ_));
}

void SelfCollider::updatePairs(const ClothState& now) {
  if (pairsHold(now)) return;
  // Every pair whose vertex could come within h of the triangle (or through it) while no
  // vertex moves more than margin / 2 from here, the garment's common motion left out.
  buildGrid(now);
  gatherPairs(now, thickness_ + margin_);
  builtX_ = now.x;
  builtY_ = now.y;
  builtZ_ = now.z;
  builtMean_ = meanPosition(now.x, now.y, now.z);
  pairsBuilt_ = true;
  ++self_.rebuilds;
}

const std::vector<SelfContact>& SelfCollider::findContacts(const ClothState& before, const ClothState& after) {
  remember(before);
  buildGrid(after);
  gatherPairs(after, thickness_);
  pairsBuilt_ = false;  // a list for this interval alone
  narrow(after);
  return contacts_;
}

const std::vector<SelfContact>& SelfCollider::nextContacts(const ClothState& now) {
  updatePairs(now);
  narrow(now);
  remember(now);
  return contacts_;
}

bool SelfCollider::now(const SelfContact& c, const ClothState& io, ContactNow& out) const {
  const auto& tri = triangles_[c.triangle];
  out.inverseMass[0] = inverseMass_[c.vertex];
  out.weight = out.inverseMass[0];
  for (int k = 0; k < 3; ++k) {
    out.inverseMass[k + 1] = inverseMass_[tri[k]];
    out.weight += c.weights[k] * c.weights[k] * out.inverseMass[k + 1];
    out.corners[k] = io.position(tri[k]);
  }
  out.normal = c.side * unitNormal(out.corners);
  return out.weight > 0 && !out.normal.isZero();
}

void SelfCollider::clearPushes() {
  std::fill(pushX_.begin(), pushX_.end(), 0.0);
  std::fill(pushY_.begin(), pushY_.end(), 0.0);
  std::fill(pushZ_.begin(), pushZ_.end(), 0.0);
  std::fill(pushes_.begin(), pushes_.end(), 0u);
}

void SelfCollider::pushApart(const SelfContact& c, const std::array<double, 4>& im, const Vec3& lambda) {
  const auto push = [&](std::uint32_t i, const Vec3& by) {
    pushX_[i] += by.x();
    pushY_[i] += by.y();
    pushZ_[i] += by.z();
    ++pushes_[i];
  };
  if (im[0] > 0) push(c.vertex, im[0] * lambda);
  for (int k = 0; k < 3; ++k)
    if (im[k + 1] > 0) push(triangles_[c.triangle][k], -c.weights[k] * im[k + 1] * lambda);
}

void SelfCollider::applyPushes(std::vector<double>& x, std::vector<double>& y, std::vector<double>& z) const {
  for (std::size_t i = 0; i < x.size(); ++i)
    if (pushes_[i] > 0) {
      const double share = 1.0 / pushes_[i];
      x[i] += pushX_[i] * share;
      y[i] += pushY_[i] * share;
      z[i] += pushZ_[i] * share;
    }
}

void SelfCollider::resolvePositions(ClothState& io) {
  for (int sweep = 0; sweep < kPositionSweeps; ++sweep) {
    clearPushes();
    bool any = false;
    for (const SelfContact& c : contacts_) {
      ContactNow f;
      if (!now(c, io, f)) continue;
      const Vec3 q = c.weights[0] * f.corners[0] + c.weights[1] * f.corners[1] + c.weights[2] * f.corners[2];
      const double d = (io.position(c.vertex) - q).dot(f.normal);
      if (d >= thickness_) continue;
      if (sweep == 0) counters_.maxPenetration_m = std::max(counters_.maxPenetration_m, thickness_ - d);
      // The constraint (p - sum w_k t_k) . n >= h projected by inverse masses.
      pushApart(c, f.inverseMass, (thickness_ - d) / f.weight * f.normal);
      any = true;
    }
    if (!any) return;
    applyPushes(io.x, io.y, io.z);
  }
}

void SelfCollider::resolveVelocities(ClothState& io) {
  clearPushes();
  bool any = false;
  for (const SelfContact& c : contacts_) {
    ContactNow f;
    if (!now(c, io, f)) continue;
    const auto& tri = triangles_[c.triangle];
    const Vec3& n = f.normal;
    const Vec3 vq =
        c.weights[0] * io.velocity(tri[0]) + c.weights[1] * io.velocity(tri[1]) + c.weights[2] * io.velocity(tri[2]);
    const Vec3 relative = io.velocity(c.vertex) - vq;
    const double approach = relative.dot(n);
    if (approach >= 0) continue;
    // Inelastic: the pair's relative normal velocity goes to zero. Coulomb friction takes
    // up to mu times that change off the relative sliding velocity, all of it below the
    // static coefficient.
    const Vec3 sliding = relative - approach * n;
    const double speed = sliding.norm(), removed = -approach;
    Vec3 change = removed * n;
    if (speed > 0)
      change -=
          (speed <= staticFriction_ * removed ? 1.0 : std::min(1.0, dynamicFriction_ * removed / speed)) * sliding;
    pushApart(c, f.inverseMass, change / f.weight);
    any = true;
  }
  if (any) applyPushes(io.vx, io.vy, io.vz);
}

void SelfCollider::collide(const ClothModel&, double, double, ClothState& io) {
  ++counters_.calls;
  if ((calls_++ % static_cast<std::uint64_t>(every_)) != 0) return;
  updatePairs(io);
  narrow(io);
  ++self_.tests;
  counters_.pointsTested += io.size();
  self_.contacts += contacts_.size();
  counters_.contacts += contacts_.size();
  for (const SelfContact& c : contacts_) self_.crossings += c.crossed;
  if (!contacts_.empty()) {
    resolvePositions(io);
    resolveVelocities(io);
  }
  remember(io);
}

}  // namespace drape::cloth
