#include "drape/cloth/layer_collider.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>

#include <fmt/format.h>

#include "drape/cloth/model.hpp"
#include "drape/core/error.hpp"
#include "drape/mesh/closest_point.hpp"

namespace drape::cloth {
namespace {

/// Jacobi sweeps over the contacts' positions: each moves every pair by the average of its
/// pushes, so that a vertex in several contacts converges instead of overshooting.
constexpr int kPositionSweeps = 3;
/// The candidate pairs hold while no vertex moves more than half this many thicknesses (the
/// larger of its own layers' and the gap; beyond the garments' common motion) from where
/// they were found.
constexpr double kMarginThicknesses = 2.0;
/// A point that moves past its reach (half its margin) gets twice the reach at the next list,
/// up to this many times the first, and a point that did not gives back a quarter of what
/// it has above the first: a swinging hem gets room, and the list is made again less often.
constexpr double kMostReach = 8.0, kReachKept = 0.75;
/// When at most this many points went past their reach, the list is mended (their pairs
/// found again) instead of made again: a hem's few swinging points, not the whole list.
/// Measured at 2 to 64 on the layered skirts: 8 is the fastest; past 16 a mend costs more
/// than a new list.
constexpr std::size_t kMostMended = 8;
/// How far outside a triangle (in barycentric weight) a projection may fall and still count:
/// a vertex over the edge between two faces belongs to both.
constexpr double kEdgeTolerance = 1e-9;
/// A box touching more grid cells than this is not looked up cell by cell: it is paired by
/// its box alone. (A point flung a metre by an unstable substep would otherwise be listed in
/// millions of cells, and fill the memory.)
constexpr double kMostCellsPerBox = 512.0;
/// The candidate list's order: by triangle, then vertex (the narrow test reads each
/// triangle's plane once for all its vertices).
constexpr auto kByTriangle = [](const std::pair<std::uint32_t, std::uint32_t>& a,
                                const std::pair<std::uint32_t, std::uint32_t>& b) {
  return a.second != b.second ? a.second < b.second : a.first < b.first;
};
/// The contacts' order, whatever the list's: by vertex, then triangle. Their pushes are
/// summed in it.
constexpr auto kByVertex = [](const LayerContact& a, const LayerContact& b) {
  return a.vertex != b.vertex ? a.vertex < b.vertex : a.triangle < b.triangle;
};
/// LayerCollider::tested_: a point of its own in some pair, a point below in some pair.
constexpr std::uint8_t kOwnPoint = 1, kPointBelow = 2;

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

std::optional<LayerContact> layerContact(const Vec3& p0, const Vec3& p1, const std::array<Vec3, 3>& t0,
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
  LayerContact contact;
  contact.side = side;
  contact.crossed = d1 < 0;
  std::optional<std::array<double, 3>> weights;
  if (!contact.crossed) {
    weights = barycentric(p1, t1);  // within h over the face
  } else {
    // Through the plane: where its distance, taken as linear over the interval, was zero,
    // the point must lie in the triangle as it was then, within the thickness of its plane.
    // (A triangle that turns over in the interval flips its normal, not the point's side:
    // then the point may be far from it when the linear distance says zero.)
    const double s = side * d0 / std::sqrt(n0.squaredNorm() > 0 ? n0.squaredNorm() : area2);
    const double e = d1 / std::sqrt(area2);
    const double when = s / (s - e);
    const auto mix = [when](const Vec3& a, const Vec3& b) -> Vec3 { return a + when * (b - a); };
    const Vec3 p = mix(p0, p1);
    const std::array<Vec3, 3> t{mix(t0[0], t1[0]), mix(t0[1], t1[1]), mix(t0[2], t1[2])};
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
    const double d = (p - t[0]).dot(n);
    if (d * d > thickness * thickness * n.squaredNorm()) return std::nullopt;
    weights = barycentric(p, t);
  }
  if (!weights) return std::nullopt;
  contact.weights = *weights;
  return contact;
}

LayerCollider::LayerCollider(const ClothModel& model, std::string garment, double thickness_m, int every)
    : garment_(std::move(garment)),
      thickness_(thickness_m),
      every_(std::max(1, every)),
      staticFriction_(model.material().staticFriction),
      dynamicFriction_(model.material().dynamicFriction) {
  if (!(thickness_m >= 0) || !std::isfinite(thickness_m))
    throw Error(fmt::format("garment '{}': self-collision thickness {} m must be 0 (none) or a positive length",
                            garment_, thickness_m));
  const std::size_t n = model.vertexCount();
  ownVertices_ = static_cast<std::uint32_t>(n);
  ownTriangles_ = static_cast<std::uint32_t>(model.triangleCount());
  triangles_.assign(model.triangles().begin(), model.triangles().end());
  // Neighbours (CSR), from the triangles' edges.
  std::vector<std::vector<std::uint32_t>> around(n);
  for (const auto& t : triangles_)
    for (int e = 0; e < 3; ++e) {
      around[t[e]].push_back(t[(e + 1) % 3]);
      around[t[(e + 1) % 3]].push_back(t[e]);
    }
  setNeighbours(around);
  addEdgeLengths(model);
  inverseMass_ = model.inverseMass();
  passesBelow_.assign(ownVertices_, 0);
  lastX_ = model.restX();
  lastY_ = model.restY();
  lastZ_ = model.restZ();
  sizeForPoints();
}

void LayerCollider::addGarmentBelow(const ClothModel& model, std::string name, const ClothState& state, double gap_m,
                                    double frame_s) {
  if (!(gap_m > 0) || !std::isfinite(gap_m))
    throw Error(fmt::format("garment '{}': the gap over '{}', {} m, must be a positive length", garment_, name, gap_m));
  if (!(frame_s > 0) || !std::isfinite(frame_s))
    throw Error(fmt::format("garment '{}': a frame of {} s over '{}'", garment_, frame_s, name), ExitCode::Internal);
  if (state.size() != model.vertexCount())
    throw Error(fmt::format("garment '{}': the state of '{}' has {} points, its model {}", garment_, name, state.size(),
                            model.vertexCount()),
                ExitCode::Internal);
  gap_ = gap_m;
  frame_s_ = frame_s;
  Below b;
  b.name = std::move(name);
  b.state = &state;
  b.first = static_cast<std::uint32_t>(inverseMass_.size());
  b.count = static_cast<std::uint32_t>(model.vertexCount());
  b.startX = b.endX = state.x;
  b.startY = b.endY = state.y;
  b.startZ = b.endZ = state.z;
  for (const auto& t : model.triangles()) triangles_.push_back({t[0] + b.first, t[1] + b.first, t[2] + b.first});
  addEdgeLengths(model);
  // Its points have no neighbours here (none of its triangles is ever excluded) and do not
  // move here.
  neighbourStart_.insert(neighbourStart_.end(), b.count, neighbourStart_.back());
  inverseMass_.insert(inverseMass_.end(), b.count, 0.0);
  lastX_.insert(lastX_.end(), state.x.begin(), state.x.end());
  lastY_.insert(lastY_.end(), state.y.begin(), state.y.end());
  lastZ_.insert(lastZ_.end(), state.z.begin(), state.z.end());
  belowNames_.push_back(b.name);
  below_.push_back(std::move(b));
  held_ = false;
  sizeForPoints();
}

void LayerCollider::addEdgeLengths(const ClothModel& model) {
  for (const auto& t : model.triangles())
    for (int e = 0; e < 3; ++e) {
      edgeSum_ += (at(model.restX(), model.restY(), model.restZ(), t[e]) -
                   at(model.restX(), model.restY(), model.restZ(), t[(e + 1) % 3]))
                      .norm();
      ++edgeCount_;
    }
}

void LayerCollider::sizeForPoints() {
  const std::size_t n = inverseMass_.size();
  // Cells as wide as a triangle's box grown by the thickness + m on each side (an edge and a
  // little more): a triangle's box touches at most two along each axis, and a vertex's
  // mostly one.
  const double thickest = std::max(thickness_, gap_);
  const double meanEdge = edgeCount_ > 0 ? edgeSum_ / static_cast<double>(edgeCount_) : thickest;
  margin_ = kMarginThicknesses * thickest;
  cell_m_ = std::max(meanEdge + 2.0 * (thickest + margin_), 1e-9);
  reach_.assign(n, 0.5 * margin_);
  for (int a = 0; a < 3; ++a) {
    pointLo_[a].resize(n);
    pointHi_[a].resize(n);
  }
  const std::size_t buckets = std::bit_ceil(std::max<std::size_t>(64, 2 * n));
  bucketMask_ = static_cast<std::uint32_t>(buckets - 1);
  inverseCell_ = 1.0 / cell_m_;
  for (PointGrid& grid : grids_) {
    grid.start.assign(buckets + 1, 0u);
    grid.fill.assign(buckets, 0u);
    grid.point.resize(2 * n);
    grid.box.resize(6 * grid.point.size());
  }
  bucketsOfPoint_.reserve(64);
  const std::size_t triangles = triangles_.size();
  for (int a = 0; a < 3; ++a) {
    triangleLo_[a].assign(triangles, 0.0);
    triangleHi_[a].assign(triangles, 0.0);
  }
  triangleMended_.assign(triangles, 0u);
  mended_.assign(n, 0u);
  meets_.assign(std::max(n, triangles), 0u);
  moved_.reserve(n);
  mendedTriangles_.reserve(triangles);
  merged_.reserve(4 * n);
  // The connected pieces of the garments below (a union-find forest over their vertices).
  componentBelow_.resize(n);
  for (std::uint32_t v = 0; v < n; ++v) componentBelow_[v] = v;
  for (std::size_t t = ownTriangles_; t < triangles; ++t) {
    const std::uint32_t root = componentBelow(triangles_[t][0]);
    for (int k = 1; k < 3; ++k) {
      const std::uint32_t other = componentBelow(triangles_[t][k]);
      if (other != root) componentBelow_[other] = root;
    }
  }
  // The triangles around each point (CSR), whose boxes follow it when it is anchored again.
  trianglesAroundStart_.assign(n + 1, 0u);
  for (const auto& t : triangles_)
    for (const std::uint32_t corner : t) ++trianglesAroundStart_[corner + 1];
  for (std::size_t v = 0; v < n; ++v) trianglesAroundStart_[v + 1] += trianglesAroundStart_[v];
  trianglesAround_.resize(trianglesAroundStart_[n]);
  std::vector<std::uint32_t> fill(trianglesAroundStart_.begin(), trianglesAroundStart_.end() - 1);
  for (std::uint32_t t = 0; t < triangles; ++t)
    for (const std::uint32_t corner : triangles_[t]) trianglesAround_[fill[corner]++] = t;
  tested_.assign(n, 0u);
  contacts_.reserve(n);
  pairs_.reserve(4 * n);
  pushX_.assign(n, 0.0);
  pushY_.assign(n, 0.0);
  pushZ_.assign(n, 0.0);
  pushes_.assign(n, 0u);
  work_.x.resize(n);
  work_.y.resize(n);
  work_.z.resize(n);
  work_.vx.resize(n);
  work_.vy.resize(n);
  work_.vz.resize(n);
  // Which vertices any pair can hold: its own free ones (against its own layers or those
  // below), and those below when a triangle of its own can move.
  bool anyTriangleMoves = false;
  for (std::uint32_t t = 0; t < ownTriangles_ && !anyTriangleMoves; ++t) anyTriangleMoves = triangleMoves(t);
  for (std::size_t v = 0; v < n; ++v)
    tested_[v] = v < ownVertices_ ? (inverseMass_[v] > 0 && (thickness_ > 0 || !below_.empty()) ? kOwnPoint : 0)
                                  : (anyTriangleMoves ? kPointBelow : 0);
  pairsBuilt_ = false;
}

bool LayerCollider::passesBelow(std::uint32_t triangle) const {
  const auto& c = triangles_[triangle];
  return passesBelow_[c[0]] | passesBelow_[c[1]] | passesBelow_[c[2]];
}

bool LayerCollider::triangleMoves(std::uint32_t triangle) const {
  for (const std::uint32_t corner : triangles_[triangle])
    if (inverseMass_[corner] > 0) return true;
  return false;
}

void LayerCollider::setFixedVertices(const std::vector<std::uint32_t>& vertices) {
  for (const std::uint32_t v : vertices)
    if (v < ownVertices_) inverseMass_[v] = 0.0;
  sizeForPoints();
}

void LayerCollider::setStitches(const std::vector<Stitch>& stitches) {
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

void LayerCollider::setNeighbours(std::vector<std::vector<std::uint32_t>>& around) {
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

void LayerCollider::initialise(const ClothState& state) {
  remember(state);
  for (Below& b : below_) {
    b.startX = b.endX = b.state->x;  // sizes equal: copies, no allocation
    b.startY = b.endY = b.state->y;
    b.startZ = b.endZ = b.state->z;
    std::copy(b.endX.begin(), b.endX.end(), lastX_.begin() + b.first);
    std::copy(b.endY.begin(), b.endY.end(), lastY_.begin() + b.first);
    std::copy(b.endZ.begin(), b.endZ.end(), lastZ_.begin() + b.first);
  }
  held_ = false;
  findStartUnder();
}

std::uint32_t LayerCollider::componentBelow(std::uint32_t vertex) const {
  while (componentBelow_[vertex] != vertex) vertex = componentBelow_[vertex];
  return vertex;
}

void LayerCollider::setBody(std::vector<Vec3> points) { body_ = std::move(points); }

namespace {

Vec3 nearestOf(const std::vector<Vec3>& points, const Vec3& p) {
  Vec3 nearest = points.front();
  double best = (p - nearest).squaredNorm();
  for (const Vec3& q : points)
    if (const double d = (p - q).squaredNorm(); d < best) {
      best = d;
      nearest = q;
    }
  return nearest;
}

}  // namespace

void LayerCollider::findStartUnder() {
  // Each free vertex of its own near the garments below takes the side of the nearest of
  // their triangles, along its normal, where it lies over or under it (more along the normal
  // than beside it: not past a hem). The side it is worn on is the one away from the body
  // at that point, when the body is known; else the side most take over a connected piece
  // of them.
  startUnder_ = {};
  under_.clear();
  if (below_.empty()) return;
  const double depth = body_.empty() ? kLiftDepthGaps * gap_ : std::max(kLiftDepthGaps * gap_, kBodyUnderDepth_m);
  struct Side {
    std::uint32_t vertex, triangle;
    double along;
    Vec3 closest;
  };
  std::vector<Side> sides;  // once, at set-up
  // Their triangles' corners and unit normals, once for all vertices.
  std::vector<std::array<Vec3, 3>> corners;
  std::vector<Vec3> normals;
  for (std::uint32_t t = ownTriangles_; t < triangles_.size(); ++t) {
    const auto& c = triangles_[t];
    corners.push_back({at(lastX_, lastY_, lastZ_, c[0]), at(lastX_, lastY_, lastZ_, c[1]), at(lastX_, lastY_, lastZ_, c[2])});
    normals.push_back(unitNormal(corners.back()));
  }
  for (std::uint32_t v = 0; v < ownVertices_; ++v) {
    if (!(inverseMass_[v] > 0)) continue;
    const Vec3 p = at(lastX_, lastY_, lastZ_, v);
    double nearest = depth, along = 0.0;
    std::uint32_t under = 0;
    Vec3 closest = Vec3::Zero();
    for (std::uint32_t t = ownTriangles_; t < triangles_.size(); ++t) {
      const std::array<Vec3, 3>& k = corners[t - ownTriangles_];
      const Vec3& n = normals[t - ownTriangles_];
      const double off = (p - k[0]).dot(n);  // no farther from the triangle than from its plane
      if (n.isZero() || std::abs(off) > nearest) continue;
      const Vec3 q = mesh::closestOnTriangle(p, k[0], k[1], k[2]);
      const double distance = (p - q).norm();
      if (distance > nearest) continue;
      nearest = distance;
      along = off;
      under = t;
      closest = q;
    }
    if (along != 0.0 && std::abs(along) >= 0.5 * nearest) sides.push_back({v, under, along, closest});
  }
  // Without the body: per connected piece below (root vertex), how many take each side.
  std::vector<std::uint32_t> above, total;
  if (body_.empty()) {
    above.assign(vertexCount(), 0u);
    total.assign(vertexCount(), 0u);
    for (const Side& side : sides) {
      const std::uint32_t piece = componentBelow(triangles_[side.triangle][0]);
      above[piece] += side.along > 0 ? 1u : 0u;
      ++total[piece];
    }
  }
  startUnder_.over = sides.size();
  for (const Side& side : sides) {
    double wornSide = 0.0;
    if (body_.empty()) {
      const std::uint32_t piece = componentBelow(triangles_[side.triangle][0]);
      wornSide = 2 * above[piece] >= total[piece] ? 1.0 : -1.0;
    } else {
      const Vec3& n = normals[side.triangle - ownTriangles_];
      wornSide = n.dot(side.closest - nearestOf(body_, side.closest)) >= 0.0 ? 1.0 : -1.0;
    }
    if (side.along * wornSide >= 0) continue;
    under_.push_back({side.vertex, side.triangle, side.along, wornSide});
    ++startUnder_.vertices;
    if (std::abs(side.along) > startUnder_.deepest_m) {
      startUnder_.deepest_m = std::abs(side.along);
      startUnder_.deepestVertex = side.vertex;
    }
  }
}

void LayerCollider::leaveThrough(double deeperThan) {
  // Kept under where they start while the rest is kept over, the triangles between them would
  // be held on both sides of the garment below at once: they pass through it instead.
  for (const Under& u : under_)
    if (std::abs(u.along) > deeperThan) passesBelow_[u.vertex] = 1;
  anyPassBelow_ = std::find(passesBelow_.begin(), passesBelow_.end(), 1) != passesBelow_.end();
  pairsBuilt_ = false;
}

bool LayerCollider::belowWoundOneWay() const {
  // Faces wound one way go along each edge they share in opposite directions: no directed
  // edge twice.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  edges.reserve(3 * (triangles_.size() - ownTriangles_));
  for (std::size_t t = ownTriangles_; t < triangles_.size(); ++t)
    for (int e = 0; e < 3; ++e) edges.emplace_back(triangles_[t][e], triangles_[t][(e + 1) % 3]);
  std::sort(edges.begin(), edges.end());
  return std::adjacent_find(edges.begin(), edges.end()) == edges.end();
}

std::size_t LayerCollider::liftOver(ClothState& state) {
  lifted_ = {};
  if (under_.empty()) return 0;
  if (body_.empty() && !belowWoundOneWay()) {
    lifted_.leftUnder = under_.size();
    leaveThrough(-1.0);  // every one
    return 0;
  }
  const double depth = kLiftDepthGaps * gap_;
  for (const Under& u : under_) {
    // Deeper, the move would tear the garment's triangles across the one below: left there.
    if (std::abs(u.along) > depth) continue;
    const auto& c = triangles_[u.triangle];
    const Vec3 n = unitNormal({at(lastX_, lastY_, lastZ_, c[0]), at(lastX_, lastY_, lastZ_, c[1]),
                               at(lastX_, lastY_, lastZ_, c[2])});
    const double move = u.wornSide * gap_ - u.along;  // to the gap on the side it is worn on
    state.setPosition(u.vertex, state.position(u.vertex) + move * n);
    state.setVelocity(u.vertex, Vec3::Zero());
    lifted_.largest_m = std::max(lifted_.largest_m, std::abs(move));
    ++lifted_.vertices;
  }
  lifted_.leftUnder = under_.size() - lifted_.vertices;
  leaveThrough(depth);
  under_.clear();      // over them now; startUnder_ keeps what was modelled, for the log and stats
  remember(state);     // its own points start where they were moved to
  return lifted_.vertices;
}

bool LayerCollider::excluded(std::uint32_t vertex, std::uint32_t triangle) const {
  const auto first = neighbours_.begin() + neighbourStart_[vertex],
             last = neighbours_.begin() + neighbourStart_[vertex + 1];
  for (const std::uint32_t corner : triangles_[triangle])
    if (corner == vertex || std::binary_search(first, last, corner)) return true;
  return false;
}

double LayerCollider::pairThickness(std::uint32_t vertex, std::uint32_t triangle) const {
  const bool ownVertex = vertex < ownVertices_, ownTriangle = triangle < ownTriangles_;
  if (ownVertex && ownTriangle)
    return thickness_ > 0 && inverseMass_[vertex] > 0 && !excluded(vertex, triangle) ? thickness_ : 0.0;
  // Against a garment below; a point below against its own triangle. (Rarely any pass through.)
  if (ownVertex) return inverseMass_[vertex] > 0 && !(anyPassBelow_ && passesBelow_[vertex]) ? gap_ : 0.0;
  if (ownTriangle) return triangleMoves(triangle) && !(anyPassBelow_ && passesBelow(triangle)) ? gap_ : 0.0;
  return 0.0;                                                    // below against below: not here
}

void LayerCollider::remember(const ClothState& state) {
  std::copy(state.x.begin(), state.x.end(), lastX_.begin());
  std::copy(state.y.begin(), state.y.end(), lastY_.begin());
  std::copy(state.z.begin(), state.z.end(), lastZ_.begin());
}

void LayerCollider::followBelow(double t_s) {
  if (below_.empty()) return;
  // Frames end at multiples of frame_s; a substep starts within its frame, never at its end.
  const auto frame = static_cast<long>(std::floor(t_s / frame_s_ + 1e-6));
  if (held_ && frame == heldFrame_) return;
  for (Below& b : below_) {
    std::swap(b.startX, b.endX);
    std::swap(b.startY, b.endY);
    std::swap(b.startZ, b.endZ);
    b.endX = b.state->x;
    b.endY = b.state->y;
    b.endZ = b.state->z;
  }
  heldFrame_ = frame;
  held_ = true;
}

void LayerCollider::placeBelow(double t_s, std::vector<double>& x, std::vector<double>& y,
                               std::vector<double>& z) const {
  const double s = std::clamp(t_s / frame_s_ - static_cast<double>(heldFrame_), 0.0, 1.0);
  for (const Below& b : below_)
    for (std::uint32_t i = 0; i < b.count; ++i) {
      const std::uint32_t v = b.first + i;
      x[v] = b.startX[i] + s * (b.endX[i] - b.startX[i]);
      y[v] = b.startY[i] + s * (b.endY[i] - b.startY[i]);
      z[v] = b.startZ[i] + s * (b.endZ[i] - b.startZ[i]);
    }
}

void LayerCollider::velocitiesBelow(ClothState& out) const {
  const double rate = 1.0 / frame_s_;
  for (const Below& b : below_)
    for (std::uint32_t i = 0; i < b.count; ++i) {
      const std::uint32_t v = b.first + i;
      out.vx[v] = (b.endX[i] - b.startX[i]) * rate;
      out.vy[v] = (b.endY[i] - b.startY[i]) * rate;
      out.vz[v] = (b.endZ[i] - b.startZ[i]) * rate;
    }
}

void LayerCollider::beginFrame() {
  frameStartCounters_ = counters_;
  frameStartSelf_ = self_;
}

void LayerCollider::restartFrame(const ClothState& state, double t_s) {
  counters_ = frameStartCounters_;
  self_ = frameStartSelf_;
  remember(state);
  if (!below_.empty()) {  // where the garments below were at the frame's start
    followBelow(t_s);
    placeBelow(t_s, lastX_, lastY_, lastZ_);
  }
  pairsBuilt_ = false;  // the attempt's list: built again, so the frame is computed as before
}

std::uint32_t LayerCollider::bucketOf(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
  const auto h = static_cast<std::uint64_t>(ix) * 73856093u ^ static_cast<std::uint64_t>(iy) * 19349663u ^
                 static_cast<std::uint64_t>(iz) * 83492791u;
  return static_cast<std::uint32_t>(h ^ (h >> 32)) & bucketMask_;
}

std::int64_t LayerCollider::cellOf(double coordinate) const {
  return static_cast<std::int64_t>(std::floor(coordinate * inverseCell_));
}

template <typename Visit>
void LayerCollider::forCells(const double* lo, const double* hi, Visit&& visit) const {
  const std::int64_t x0 = cellOf(lo[0]), x1 = cellOf(hi[0]), y0 = cellOf(lo[1]), y1 = cellOf(hi[1]),
                     z0 = cellOf(lo[2]), z1 = cellOf(hi[2]);
  for (std::int64_t ix = x0; ix <= x1; ++ix)
    for (std::int64_t iy = y0; iy <= y1; ++iy)
      for (std::int64_t iz = z0; iz <= z1; ++iz) visit(ix, iy, iz);
}

template <typename Visit>
void LayerCollider::forBucketsOnce(std::size_t v, Visit&& visit) {
  // Two cells of a box can share a bucket: the point is listed in it once, so that a scan
  // of the bucket meets it once.
  bucketsOfPoint_.clear();
  const double lo[3] = {pointLo_[0][v], pointLo_[1][v], pointLo_[2][v]},
               hi[3] = {pointHi_[0][v], pointHi_[1][v], pointHi_[2][v]};
  forCells(lo, hi,
           [&](std::int64_t ix, std::int64_t iy, std::int64_t iz) { bucketsOfPoint_.push_back(bucketOf(ix, iy, iz)); });
  if (bucketsOfPoint_.size() > 1) {
    std::sort(bucketsOfPoint_.begin(), bucketsOfPoint_.end());
    bucketsOfPoint_.erase(std::unique(bucketsOfPoint_.begin(), bucketsOfPoint_.end()), bucketsOfPoint_.end());
  }
  for (const std::uint32_t b : bucketsOfPoint_) visit(b);
}

void LayerCollider::buildGrid(const ClothState& after) {
  // Each vertex's box over the interval (where it was at the last test and is now), grown by
  // its reach: where it may be until the list is made again. Most lie in one cell.
  const std::size_t n = after.size();
  for (std::size_t v = 0; v < n; ++v) {
    const double p0[3] = {lastX_[v], lastY_[v], lastZ_[v]}, p1[3] = {after.x[v], after.y[v], after.z[v]};
    for (int k = 0; k < 3; ++k) {
      pointLo_[k][v] = std::min(p0[k], p1[k]) - reach_[v];
      pointHi_[k][v] = std::max(p0[k], p1[k]) + reach_[v];
    }
  }
  // A grid of its own points and one of the points below (a triangle scans only the grid
  // of the points it can hold pairs with). Counted, then placed: every bucket's points in
  // one array, in point order, each with its box. A point no pair can hold (a fixed one) is
  // in neither.
  for (const std::uint8_t kind : {kOwnPoint, kPointBelow}) {
    PointGrid& grid = grids_[kind == kOwnPoint ? 0 : 1];
    std::vector<std::uint32_t>& offGrid = offGrid_[kind == kOwnPoint ? 0 : 1];
    offGrid.clear();
    std::fill(grid.start.begin(), grid.start.end(), 0u);
    for (std::size_t v = 0; v < n; ++v) {
      if (!(tested_[v] & kind)) continue;
      const double lo[3] = {pointLo_[0][v], pointLo_[1][v], pointLo_[2][v]},
                   hi[3] = {pointHi_[0][v], pointHi_[1][v], pointHi_[2][v]};
      if (fitsGrid(lo, hi))
        forBucketsOnce(v, [&](std::uint32_t b) { ++grid.start[b + 1]; });
      else
        offGrid.push_back(static_cast<std::uint32_t>(v));
    }
    for (std::size_t b = 1; b < grid.start.size(); ++b) grid.start[b] += grid.start[b - 1];
    if (grid.start.back() > grid.point.size()) {
      grid.point.resize(grid.start.back() + grid.start.back() / 4);
      grid.box.resize(6 * grid.point.size());
    }
    std::copy(grid.start.begin(), grid.start.end() - 1, grid.fill.begin());
    std::size_t nextOff = 0;
    for (std::size_t v = 0; v < n; ++v) {
      if (!(tested_[v] & kind)) continue;
      if (nextOff < offGrid.size() && offGrid[nextOff] == v) {
        ++nextOff;
        continue;
      }
      forBucketsOnce(v, [&](std::uint32_t b) {
        const std::uint32_t e = grid.fill[b]++;
        grid.point[e] = static_cast<std::uint32_t>(v);
        for (int a = 0; a < 3; ++a) {
          grid.box[6 * e + a] = pointLo_[a][v];
          grid.box[6 * e + 3 + a] = pointHi_[a][v];
        }
      });
    }
  }
}

bool LayerCollider::fitsGrid(const double* lo, const double* hi) const {
  // At most span / cell + 2 cells along an axis.
  double cells = 1.0;
  for (int a = 0; a < 3; ++a) cells *= (hi[a] - lo[a]) * inverseCell_ + 2.0;
  return cells <= kMostCellsPerBox;  // false for NaN
}

void LayerCollider::pairWithPointsOffGrid(std::uint32_t t, const double* lo, const double* hi, std::uint8_t kinds,
                                          const std::vector<std::uint32_t>* points) {
  const auto consider = [&](std::uint32_t v) {
    if (!(tested_[v] & kinds)) return;
    const bool meets = (pointLo_[0][v] <= hi[0]) & (pointHi_[0][v] >= lo[0]) & (pointLo_[1][v] <= hi[1]) &
                       (pointHi_[1][v] >= lo[1]) & (pointLo_[2][v] <= hi[2]) & (pointHi_[2][v] >= lo[2]);
    if (meets && pairThickness(v, t) > 0) pairs_.push_back({v, t});
  };
  if (points != nullptr) {
    for (const std::uint32_t v : *points) consider(v);
  } else {
    for (std::uint32_t v = 0; v < tested_.size(); ++v) consider(v);
  }
}

void LayerCollider::placeTriangleBox(std::uint32_t t) {
  const double grow = std::max(thickness_, gap_);
  const auto& c = triangles_[t];
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& lo = pointLo_[a];
    const std::vector<double>& hi = pointHi_[a];
    triangleLo_[a][t] = std::min({lo[c[0]], lo[c[1]], lo[c[2]]}) - grow;
    triangleHi_[a][t] = std::max({hi[c[0]], hi[c[1]], hi[c[2]]}) + grow;
  }
}

std::uint8_t LayerCollider::pointsAccepted(std::uint32_t t) const {
  return t < ownTriangles_ ? (thickness_ > 0 ? kOwnPoint : 0) | kPointBelow : kOwnPoint;
}

void LayerCollider::gatherPairs() {
  pairs_.clear();
  // Its own triangles hold pairs with its own layers kept apart or with points below.
  const std::uint32_t first = thickness_ > 0 || !below_.empty() ? 0 : ownTriangles_;
  for (std::uint32_t t = first; t < triangles_.size(); ++t) {
    // Its corners' boxes, grown by the thickness: the vertices whose boxes meet it.
    placeTriangleBox(t);
    const double lo[3] = {triangleLo_[0][t], triangleLo_[1][t], triangleLo_[2][t]},
                 hi[3] = {triangleHi_[0][t], triangleHi_[1][t], triangleHi_[2][t]};
    // The points it can hold pairs with: its own triangles the points below (and its own
    // with its own layers kept apart), a triangle below its own points.
    const std::uint8_t accept = pointsAccepted(t);
    const bool scan[2] = {(accept & kOwnPoint) != 0, (accept & kPointBelow) != 0};
    const std::size_t its = pairs_.size();
    if (!fitsGrid(lo, hi)) {  // a triangle stretched across the scene: every point, by its box
      pairWithPointsOffGrid(t, lo, hi, accept, nullptr);
      std::sort(pairs_.begin() + static_cast<std::ptrdiff_t>(its), pairs_.end());
      continue;
    }
    for (int g = 0; g < 2; ++g)
      if (scan[g] && !offGrid_[g].empty()) pairWithPointsOffGrid(t, lo, hi, g == 0 ? kOwnPoint : kPointBelow, &offGrid_[g]);
    forCells(lo, hi, [&](std::int64_t ix, std::int64_t iy, std::int64_t iz) {
      const std::uint32_t b = bucketOf(ix, iy, iz);
      for (int g = 0; g < 2; ++g) {
        if (!scan[g]) continue;
        const PointGrid& grid = grids_[g];
        for (std::uint32_t e = grid.start[b]; e < grid.start[b + 1]; ++e) {
          const double* box = &grid.box[6 * e];
          // One branch, mostly not taken, instead of six that the data decides.
          const bool meets = (box[0] <= hi[0]) & (box[3] >= lo[0]) & (box[1] <= hi[1]) & (box[4] >= lo[1]) &
                             (box[2] <= hi[2]) & (box[5] >= lo[2]);
          if (!meets) continue;
          // The two boxes meet in a box whose lowest corner lies in one cell, which both
          // touch: the pair is taken there alone (cells that share a bucket, and boxes that
          // touch several cells, would find it again).
          if (cellOf(std::max(lo[0], box[0])) != ix || cellOf(std::max(lo[1], box[1])) != iy ||
              cellOf(std::max(lo[2], box[2])) != iz)
            continue;
          const std::uint32_t v = grid.point[e];
          if (pairThickness(v, t) > 0) pairs_.push_back({v, t});
        }
      }
    });
    // The triangles come in order; each one's few pairs are put in vertex order here.
    std::sort(pairs_.begin() + static_cast<std::ptrdiff_t>(its), pairs_.end());
  }
}

void LayerCollider::narrow(const ClothState& after) {
  contacts_.clear();
  self_.candidates += pairs_.size();
  for (std::size_t i = 0, end; i < pairs_.size(); i = end) {
    const std::uint32_t t = pairs_[i].second;
    for (end = i + 1; end < pairs_.size() && pairs_[end].second == t;) ++end;
    const auto& c = triangles_[t];
    const std::array<Vec3, 3> t0{at(lastX_, lastY_, lastZ_, c[0]), at(lastX_, lastY_, lastZ_, c[1]),
                                 at(lastX_, lastY_, lastZ_, c[2])};
    const std::array<Vec3, 3> t1{after.position(c[0]), after.position(c[1]), after.position(c[2])};
    // layerContact's first test, its planes found once for the triangle's vertices: the same
    // expressions, so the same pairs go on to the whole test.
    const Vec3 n1 = (t1[1] - t1[0]).cross(t1[2] - t1[0]);
    const double area2 = n1.squaredNorm();
    if (!(area2 > 0)) continue;
    const Vec3 n0 = (t0[1] - t0[0]).cross(t0[2] - t0[0]);
    const Vec3& sideNormal = n0.squaredNorm() > 0 ? n0 : n1;
    for (std::size_t k = i; k < end; ++k) {
      const std::uint32_t v = pairs_[k].first;
      const double thickness = listedThickness(v, t);
      const Vec3 p0 = at(lastX_, lastY_, lastZ_, v), p1 = after.position(v);
      const double side = (p0 - t0[0]).dot(sideNormal) >= 0 ? 1.0 : -1.0;
      const double d1 = side * (p1 - t1[0]).dot(n1);
      if (d1 >= 0 && d1 * d1 >= thickness * thickness * area2) continue;
      if (std::optional<LayerContact> contact = layerContact(p0, p1, t0, t1, thickness)) {
        contact->vertex = v;
        contact->triangle = t;
        contacts_.push_back(*contact);
      }
    }
  }
  std::sort(contacts_.begin(), contacts_.end(), kByVertex);
}

Vec3 LayerCollider::meanPosition(const std::vector<double>& x, const std::vector<double>& y,
                                const std::vector<double>& z) {
  double sx = 0, sy = 0, sz = 0;
  for (std::size_t v = 0; v < x.size(); ++v) {
    sx += x[v];
    sy += y[v];
    sz += z[v];
  }
  return Vec3(sx, sy, sz) / static_cast<double>(std::max<std::size_t>(1, x.size()));
}

bool LayerCollider::beyondReach(const ClothState& now, std::size_t v, const Vec3& shiftNow,
                                const Vec3& shiftLast) const {
  // Both ends of the interval: the last test's positions are where its corrections left them.
  const auto farther = [&](double x, double y, double z, const Vec3& shift) {
    const double dx = x - builtX_[v] - shift.x(), dy = y - builtY_[v] - shift.y(), dz = z - builtZ_[v] - shift.z();
    return dx * dx + dy * dy + dz * dz > reach_[v] * reach_[v];
  };
  return farther(now.x[v], now.y[v], now.z[v], shiftNow) || farther(lastX_[v], lastY_[v], lastZ_[v], shiftLast);
}

void LayerCollider::updatePairs(const ClothState& now) {
  // Translation-free: what moved with the garments as a whole changes no pair's distance.
  if (pairsBuilt_) {
    const Vec3 shiftNow = meanPosition(now.x, now.y, now.z) - builtMean_,
               shiftLast = meanPosition(lastX_, lastY_, lastZ_) - builtMean_;
    moved_.clear();
    for (std::size_t v = 0; v < now.size(); ++v)
      if (beyondReach(now, v, shiftNow, shiftLast)) moved_.push_back(static_cast<std::uint32_t>(v));
    if (moved_.empty()) return;  // the list holds
    if (moved_.size() <= kMostMended) {
      mendPairs(now, shiftNow, shiftLast);
      return;
    }
    // Every point's reach for the next list: twice for those beyond it, less for the others.
    const double first = 0.5 * margin_;
    for (std::size_t v = 0; v < now.size(); ++v)
      reach_[v] = beyondReach(now, v, shiftNow, shiftLast) ? std::min(2.0 * reach_[v], kMostReach * first)
                                                           : std::max(first, first + kReachKept * (reach_[v] - first));
  }
  // Every pair whose vertex could come within the thickness of the triangle (or through it)
  // while no point moves farther than its reach from here, the common motion left out.
  buildGrid(now);
  gatherPairs();
  builtX_ = now.x;
  builtY_ = now.y;
  builtZ_ = now.z;
  builtMean_ = meanPosition(now.x, now.y, now.z);
  pairsBuilt_ = true;
  ++self_.rebuilds;
}

void LayerCollider::mendPairs(const ClothState& now, const Vec3& shiftNow, const Vec3& shiftLast) {
  // The moved points are anchored where they are now, in the list's frame (the common
  // motion taken out, as beyondReach measures), keeping their reach (a new list sets it), or
  // what holds where they were at the last test if that is more: then the list covers this
  // test's interval too. Their boxes, and those of the triangles around them, are placed again; every other
  // box is the one the list was made or mended with, and so are the pairs between them.
  const double first = 0.5 * margin_;
  for (const std::uint32_t p : moved_) {
    const Vec3 anchor(now.x[p] - shiftNow.x(), now.y[p] - shiftNow.y(), now.z[p] - shiftNow.z());
    const Vec3 last(lastX_[p] - shiftLast.x(), lastY_[p] - shiftLast.y(), lastZ_[p] - shiftLast.z());
    builtX_[p] = anchor.x();
    builtY_[p] = anchor.y();
    builtZ_[p] = anchor.z();
    reach_[p] = std::max(std::min(reach_[p], kMostReach * first), (last - anchor).norm());
    for (int a = 0; a < 3; ++a) {
      pointLo_[a][p] = anchor[a] - reach_[p];
      pointHi_[a][p] = anchor[a] + reach_[p];
    }
    mended_[p] = 1;
  }
  mendedTriangles_.clear();
  for (const std::uint32_t p : moved_)
    for (std::uint32_t i = trianglesAroundStart_[p]; i < trianglesAroundStart_[p + 1]; ++i) {
      const std::uint32_t t = trianglesAround_[i];
      if (triangleMended_[t]) continue;
      triangleMended_[t] = 1;
      placeTriangleBox(t);
      mendedTriangles_.push_back(t);
    }
  // Their pairs found again: each moved point against every triangle, each triangle around
  // one against every point that did not move (a pair of both is found by the first).
  std::erase_if(pairs_, [&](const auto& pair) { return mended_[pair.first] || triangleMended_[pair.second]; });
  const std::size_t kept = pairs_.size();
  const std::uint32_t firstTriangle = thickness_ > 0 || !below_.empty() ? 0 : ownTriangles_;
  const auto triangles = static_cast<std::uint32_t>(triangles_.size());
  for (const std::uint32_t p : moved_) {
    if (!tested_[p]) continue;
    const double lo[3] = {pointLo_[0][p], pointLo_[1][p], pointLo_[2][p]},
                 hi[3] = {pointHi_[0][p], pointHi_[1][p], pointHi_[2][p]};
    // Its own points pair with the triangles below (and its own, with its own layers kept
    // apart); a point below with its own triangles.
    const std::uint32_t begin = p < ownVertices_ ? (thickness_ > 0 ? firstTriangle : ownTriangles_) : 0;
    const std::uint32_t end = p < ownVertices_ ? triangles : ownTriangles_;
    markMeeting(lo, hi, triangleLo_, triangleHi_, begin, end);
    forEachMet(begin, end, [&](std::uint32_t t) {
      if ((tested_[p] & pointsAccepted(t)) && pairThickness(p, t) > 0) pairs_.push_back({p, t});
    });
  }
  const auto points = static_cast<std::uint32_t>(vertexCount());
  for (const std::uint32_t t : mendedTriangles_) {
    const std::uint8_t accept = pointsAccepted(t);
    if (t < firstTriangle || accept == 0) continue;
    const double lo[3] = {triangleLo_[0][t], triangleLo_[1][t], triangleLo_[2][t]},
                 hi[3] = {triangleHi_[0][t], triangleHi_[1][t], triangleHi_[2][t]};
    const std::uint32_t begin = accept & kOwnPoint ? 0 : ownVertices_;
    const std::uint32_t end = accept & kPointBelow ? points : ownVertices_;
    markMeeting(lo, hi, pointLo_, pointHi_, begin, end);
    forEachMet(begin, end, [&](std::uint32_t v) {
      if (!mended_[v] && (tested_[v] & accept) && pairThickness(v, t) > 0) pairs_.push_back({v, t});
    });
  }
  // In order again (by vertex, then triangle), as a new list would be: the contacts are
  // resolved in this order, so a mended list gives the same positions to the last bit.
  std::sort(pairs_.begin() + static_cast<std::ptrdiff_t>(kept), pairs_.end(), kByTriangle);
  merged_.resize(pairs_.size());
  std::merge(pairs_.begin(), pairs_.begin() + static_cast<std::ptrdiff_t>(kept),
             pairs_.begin() + static_cast<std::ptrdiff_t>(kept), pairs_.end(), merged_.begin(), kByTriangle);
  pairs_.swap(merged_);
  for (const std::uint32_t p : moved_) mended_[p] = 0;
  for (const std::uint32_t t : mendedTriangles_) triangleMended_[t] = 0;
  ++self_.mends;
}

template <typename Visit>
void LayerCollider::forEachMet(std::uint32_t begin, std::uint32_t end, Visit&& visit) const {
  // Eight marks at a time: most are 0.
  std::uint32_t i = begin;
  for (; i + 8 <= end; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, &meets_[i], sizeof word);
    while (word != 0) {
      visit(i + static_cast<std::uint32_t>(std::countr_zero(word) / 8));
      word &= word - 1;
    }
  }
  for (; i < end; ++i)
    if (meets_[i]) visit(i);
}

void LayerCollider::markMeeting(const double* lo, const double* hi, const std::array<std::vector<double>, 3>& boxLo,
                                const std::array<std::vector<double>, 3>& boxHi, std::uint32_t begin,
                                std::uint32_t end) {
  // One pass of compares without branches over the boxes' columns (it vectorises); the few
  // that meet are read after.
  const double *lx = boxLo[0].data(), *ly = boxLo[1].data(), *lz = boxLo[2].data();
  const double *hx = boxHi[0].data(), *hy = boxHi[1].data(), *hz = boxHi[2].data();
  std::uint8_t* out = meets_.data();
  for (std::uint32_t i = begin; i < end; ++i)
    out[i] = static_cast<std::uint8_t>((lx[i] <= hi[0]) & (hx[i] >= lo[0]) & (ly[i] <= hi[1]) & (hy[i] >= lo[1]) &
                                       (lz[i] <= hi[2]) & (hz[i] >= lo[2]));
}

const std::vector<LayerContact>& LayerCollider::findContacts(const ClothState& before, const ClothState& after) {
  remember(before);
  buildGrid(after);
  gatherPairs();
  pairsBuilt_ = false;  // a list for this interval alone
  narrow(after);
  return contacts_;
}

const std::vector<LayerContact>& LayerCollider::nextContacts(const ClothState& now) {
  updatePairs(now);
  narrow(now);
  remember(now);
  return contacts_;
}

bool LayerCollider::now(const LayerContact& c, const ClothState& io, ContactNow& out) const {
  const auto& tri = triangles_[c.triangle];
  out.inverseMass[0] = inverseMass_[c.vertex];
  out.weight = out.inverseMass[0];
  double lever = out.inverseMass[0];  // the most any one point moves per unit of lambda
  for (int k = 0; k < 3; ++k) {
    out.inverseMass[k + 1] = inverseMass_[tri[k]];
    out.weight += c.weights[k] * c.weights[k] * out.inverseMass[k + 1];
    lever = std::max(lever, c.weights[k] * out.inverseMass[k + 1]);
    out.corners[k] = io.position(tri[k]);
  }
  // Where only a corner of small weight can move (the vertex, or the other corners, held by
  // a fixture or a garment below: a waistband over another's), the exact projection moves
  // it by the correction over its weight: a tenth, ten times as far, and the cloth there
  // explodes. No point moves more than kMostLever times the correction; the rest is left
  // to the next sweeps and tests.
  out.weight = std::max(out.weight, lever / kMostLever);
  out.normal = c.side * unitNormal(out.corners);
  return out.weight > 0 && !out.normal.isZero();
}

void LayerCollider::clearPushes() {
  std::fill(pushX_.begin(), pushX_.end(), 0.0);
  std::fill(pushY_.begin(), pushY_.end(), 0.0);
  std::fill(pushZ_.begin(), pushZ_.end(), 0.0);
  std::fill(pushes_.begin(), pushes_.end(), 0u);
}

void LayerCollider::pushApart(const LayerContact& c, const std::array<double, 4>& im, const Vec3& lambda) {
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

void LayerCollider::applyPushes(std::vector<double>& x, std::vector<double>& y, std::vector<double>& z) const {
  for (std::size_t i = 0; i < x.size(); ++i)
    if (pushes_[i] > 0) {
      const double share = 1.0 / pushes_[i];
      x[i] += pushX_[i] * share;
      y[i] += pushY_[i] * share;
      z[i] += pushZ_[i] * share;
    }
}

void LayerCollider::resolvePositions(ClothState& io) {
  for (int sweep = 0; sweep < kPositionSweeps; ++sweep) {
    clearPushes();
    bool any = false;
    for (const LayerContact& c : contacts_) {
      ContactNow f;
      if (!now(c, io, f)) continue;
      const Vec3 q = c.weights[0] * f.corners[0] + c.weights[1] * f.corners[1] + c.weights[2] * f.corners[2];
      const double d = (io.position(c.vertex) - q).dot(f.normal), h = listedThickness(c.vertex, c.triangle);
      if (d >= h) continue;
      if (sweep == 0) counters_.maxPenetration_m = std::max(counters_.maxPenetration_m, h - d);
      // The constraint (p - sum w_k t_k) . n >= h projected by inverse masses.
      pushApart(c, f.inverseMass, (h - d) / f.weight * f.normal);
      any = true;
    }
    if (!any) return;
    applyPushes(io.x, io.y, io.z);
  }
}

void LayerCollider::resolveVelocities(ClothState& io) {
  clearPushes();
  bool any = false;
  for (const LayerContact& c : contacts_) {
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

void LayerCollider::collide(const ClothModel&, double t0_s, double t1_s, ClothState& io) {
  ++counters_.calls;
  if ((calls_++ % static_cast<std::uint64_t>(every_)) != 0) return;
  // With garments below, the test runs on its own points followed by theirs as they are at
  // t1 (copies of a few arrays per test); without, on the state itself.
  ClothState& state = below_.empty() ? io : work_;
  if (!below_.empty()) {
    followBelow(t0_s);
    for (auto [from, to] : {std::pair{&io.x, &work_.x}, {&io.y, &work_.y}, {&io.z, &work_.z}, {&io.vx, &work_.vx},
                            {&io.vy, &work_.vy}, {&io.vz, &work_.vz}})
      std::copy(from->begin(), from->end(), to->begin());
    placeBelow(t1_s, work_.x, work_.y, work_.z);
    velocitiesBelow(work_);
  }
  updatePairs(state);
  narrow(state);
  ++self_.tests;
  counters_.pointsTested += io.size();
  counters_.contacts += contacts_.size();
  for (const LayerContact& c : contacts_) {
    const bool own = c.vertex < ownVertices_ && c.triangle < ownTriangles_;
    (own ? self_.contacts : self_.contactsBelow) += 1;
    (own ? self_.crossings : self_.crossingsBelow) += c.crossed;
  }
  if (!contacts_.empty()) {
    resolvePositions(state);
    resolveVelocities(state);
  }
  remember(state);
  if (!below_.empty())
    for (auto [from, to] : {std::pair{&work_.x, &io.x}, {&work_.y, &io.y}, {&work_.z, &io.z}, {&work_.vx, &io.vx},
                            {&work_.vy, &io.vy}, {&work_.vz, &io.vz}})
      std::copy(from->begin(), from->begin() + static_cast<std::ptrdiff_t>(io.size()), to->begin());
}

}  // namespace drape::cloth
