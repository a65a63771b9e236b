#include "drape/cloth/field_collider.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/threads.hpp"

namespace drape::cloth {
namespace {

// Outward impulse per collision interval below T1, as a fraction of the depth below T1
// per interval: strong enough to lift a point out within a few substeps, weak enough to
// stay well inside the explicit step's stability limit (a rate of 1 would be a projection).
constexpr double kPenaltyRate = 0.25;
/// How fast a point that started below T2 is eased out (releaseEmbedded), m/s.
constexpr double kEmbeddedSpeed_m_s = 0.1;
/// An eased pair that has not reached T2 in this many times the time its depth takes at
/// kEmbeddedSpeed collides as any other from then on.
constexpr double kEaseTimeFactor = 2.0;
/// Voxels by which a stored distance may exceed the distance to the surface voxels (the
/// propagation beyond the shell: at most 0.25, FIELDS.md; the fixed-point rounding 1/128):
/// the resting balls' margin.
constexpr double kFieldSlack_voxels = 0.5;
/// A projection onto T2 longer than this reads the field again where it lands (ontoT2), up
/// to kProjectionReads reads in all.
constexpr double kOneMoveReach_voxels = 1.0;
constexpr int kProjectionReads = 3;
constexpr double kSqrt3 = 1.7320508075688772;
/// The share of a face sample's depth below T2 its triangle is moved out by per test
/// (collideFaces).
constexpr double kFaceRate = 0.25;

int toIndex(PointState s) { return static_cast<int>(s); }

/// The voxel whose cell holds continuous voxel coordinates c (centres at integers).
Vec3i roundVoxel(const Vec3& c) {
  return Vec3i(static_cast<int>(std::floor(c.x() + 0.5)), static_cast<int>(std::floor(c.y() + 0.5)),
               static_cast<int>(std::floor(c.z() + 0.5)));
}

/// x -> linear x + offset.
struct Affine {
  Mat3 linear = Mat3::Identity();
  Vec3 offset = Vec3::Zero();
  [[nodiscard]] Vec3 apply(const Vec3& x) const { return linear * x + offset; }
};

/// World point -> the part's continuous voxel coordinates, the part being at `pose`:
/// c = (R^T (p - t) - origin) / h - 1/2.
Affine worldToVoxel(const field::DistanceField& f, const RigidTransform& pose) {
  const Mat3 rt = pose.rotation.conjugate().toRotationMatrix();
  const double h = f.voxelSize();
  return {rt / h, -(rt * pose.translation + f.origin()) / h - Vec3::Constant(0.5)};
}

/// The inverse: p = R (origin + (c + 1/2) h) + t.
Affine voxelToWorld(const field::DistanceField& f, const RigidTransform& pose) {
  const Mat3 r = pose.rotation.toRotationMatrix();
  const double h = f.voxelSize();
  return {r * h, r * (f.origin() + Vec3::Constant(0.5 * h)) + pose.translation};
}

// The two passes of the per-part cull take their arrays as restrict parameters: GCC 12
// vectorises them so, and not with the same pointers as locals of the member function.

/// c = m x for every point (SoA).
void mapPoints(const Affine& m, std::size_t n, const double* __restrict x, const double* __restrict y,
               const double* __restrict z, double* __restrict cx, double* __restrict cy, double* __restrict cz) {
  const double a00 = m.linear(0, 0), a01 = m.linear(0, 1), a02 = m.linear(0, 2);
  const double a10 = m.linear(1, 0), a11 = m.linear(1, 1), a12 = m.linear(1, 2);
  const double a20 = m.linear(2, 0), a21 = m.linear(2, 1), a22 = m.linear(2, 2);
  const double b0 = m.offset.x(), b1 = m.offset.y(), b2 = m.offset.z();
  for (std::size_t i = 0; i < n; ++i) {
    const double px = x[i], py = y[i], pz = z[i];
    cx[i] = a00 * px + a01 * py + a02 * pz + b0;
    cy[i] = a10 * px + a11 * py + a12 * pz + b1;
    cz[i] = a20 * px + a21 * py + a22 * pz + b2;
  }
}

/// The same map for one point, with the same arithmetic as mapPoints (a resting pair's
/// cached position must be bit for bit what the cull would have computed).
Vec3 mapPoint(const Affine& m, double px, double py, double pz) {
  return {m.linear(0, 0) * px + m.linear(0, 1) * py + m.linear(0, 2) * pz + m.offset.x(),
          m.linear(1, 0) * px + m.linear(1, 1) * py + m.linear(1, 2) * pz + m.offset.y(),
          m.linear(2, 0) * px + m.linear(2, 1) * py + m.linear(2, 2) * pz + m.offset.z()};
}

/// A pair's resting ball (FieldCollider::rest), structure of arrays over the vertices.
struct Balls {
  const double* __restrict x;
  const double* __restrict y;
  const double* __restrict z;
  const double* __restrict r2;  ///< squared radius; negative: no ball
};

/// keep[i]: the point is free and ends in the box [0.5, boxMax) of voxel coordinates, or
/// its state is not OutsideVol, or `all` (a fixed point is always OutsideVol); and it does
/// not end inside its resting ball. Returns how many end inside their balls.
std::size_t markCandidates(std::size_t n, const double* __restrict cx, const double* __restrict cy,
                           const double* __restrict cz, const Vec3& boxMax, const std::uint8_t* __restrict state,
                           bool all, const std::uint8_t* __restrict free, Balls balls, std::uint8_t* __restrict keep) {
  const double hx = boxMax.x(), hy = boxMax.y(), hz = boxMax.z();
  std::size_t resting = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const bool inBox = (cx[i] >= 0.5) & (cx[i] < hx) & (cy[i] >= 0.5) & (cy[i] < hy) & (cz[i] >= 0.5) & (cz[i] < hz);
    const double dx = cx[i] - balls.x[i], dy = cy[i] - balls.y[i], dz = cz[i] - balls.z[i];
    const bool inBall = dx * dx + dy * dy + dz * dz < balls.r2[i];
    keep[i] = static_cast<std::uint8_t>((inBox | (state[i] != 0) | all) & (free[i] != 0) & !inBall);
    resting += inBall;
  }
  return resting;
}

/// b = min(a[i - stride], a[i], a[i + stride]) for every voxel, along the axis whose index
/// step is `stride` and which has n voxels; a voxel at either end of it takes the minimum
/// of the voxels that exist.
void minOfThree(const std::vector<std::int32_t>& a, std::vector<std::int32_t>& b, std::size_t stride, int n) {
  const std::size_t line = stride * static_cast<std::size_t>(n);  // one run of the axis, all lower axes inside
  for (std::size_t start = 0; start < a.size(); start += line) {
    const std::int32_t* in = a.data() + start;
    std::int32_t* out = b.data() + start;
    for (std::size_t i = 0; i < stride; ++i) out[i] = std::min(in[i], in[i + stride]);
    for (std::size_t i = stride; i < line - stride; ++i) out[i] = std::min({in[i - stride], in[i], in[i + stride]});
    for (std::size_t i = line - stride; i < line; ++i) out[i] = std::min(in[i - stride], in[i]);
  }
}

/// The clearance bits of a part (FieldCollider::clearOfT2_): a 3x3x3 minimum filter of the
/// stored distances, as three passes of three, against T2 plus one distance unit, so that
/// the rounding of a trilinear blend cannot bring a value of the neighbourhood below T2.
std::vector<std::uint64_t> clearanceBits(const field::DistanceField& f, double t2Voxels) {
  const field::GridDims& d = f.dims();
  const std::size_t n = f.voxelCount();
  std::vector<std::uint64_t> bits((n + 63) / 64, 0);
  if (d.nx < 3 || d.ny < 3 || d.nz < 3) return bits;  // no walkable voxel
  std::vector<std::int32_t> a(n), b(n);
  for (std::size_t i = 0; i < n; ++i)
    a[i] = static_cast<std::int32_t>(f.distanceVoxels(static_cast<std::uint32_t>(i)) *
                                     field::DistanceField::kUnitsPerVoxel);  // exact: whole units
  const std::size_t sy = static_cast<std::size_t>(d.nx), sz = sy * static_cast<std::size_t>(d.ny);
  minOfThree(a, b, 1, d.nx);
  minOfThree(b, a, sy, d.ny);
  minOfThree(a, b, sz, d.nz);
  const auto limit = static_cast<std::int32_t>(std::ceil(t2Voxels * field::DistanceField::kUnitsPerVoxel));
  for (int z = 1; z < d.nz - 1; ++z)
    for (int y = 1; y < d.ny - 1; ++y)
      for (int x = 1; x < d.nx - 1; ++x) {
        const std::uint32_t v = d.index(x, y, z);
        if (b[v] > limit) bits[v >> 6] |= std::uint64_t{1} << (v & 63);
      }
  return bits;
}

/// The least resting radius worth a ball, voxels.
constexpr double kLeastRadius_voxels = 0.25;

/// The least stored distance (voxels) below which no point of a voxel gets a resting ball
/// of kLeastRadius (FieldCollider::restingRadius, |c - v| at most sqrt(3)/2); infinite when
/// the part's shell is too narrow for balls.
double restingDistance(const field::DistanceField& f, double t2Voxels) {
  if (0.75 * f.shell_m() / f.voxelSize() <= t2Voxels + kFieldSlack_voxels) return std::numeric_limits<double>::infinity();
  return kFieldSlack_voxels + std::max(t2Voxels, 0.5 * kSqrt3) + 1.5 * kSqrt3 + kLeastRadius_voxels;
}

/// Per walkable voxel, one bit: its stored distance reaches restingDistance, so that a
/// point ending in it may rest (FieldCollider::restable_). Distances are read where the bit
/// is set only: the points near the body, which change voxels most, read nothing more.
std::vector<std::uint64_t> restableBits(const field::DistanceField& f, double t2Voxels) {
  const field::GridDims& d = f.dims();
  std::vector<std::uint64_t> bits((f.voxelCount() + 63) / 64, 0);
  const double least = restingDistance(f, t2Voxels);
  for (int z = 1; z < d.nz - 1; ++z)
    for (int y = 1; y < d.ny - 1; ++y)
      for (int x = 1; x < d.nx - 1; ++x) {
        const std::uint32_t v = d.index(x, y, z);
        if (f.distanceVoxels(v) >= least) bits[v >> 6] |= std::uint64_t{1} << (v & 63);
      }
  return bits;
}

}  // namespace

Vec3i entryVoxel(const field::DistanceField& f, const Vec3i& inside, const Vec3i& outside) {
  Vec3i entry = inside;
  walkVoxelsByTable(inside, outside, [&](const Vec3i& p) {
    if (!walkable(f, p)) return false;
    entry = p;
    return true;
  });
  return entry;
}

void OffsetSurfaces::validate(const std::string& prefix) const {
  if (!(t0_m >= 0 && t0_m < t1_m && t1_m < t2_m && t2_m < t3_m) || !std::isfinite(t3_m)) {
    throw Error(fmt::format("{}offsets must satisfy 0 <= T0 < T1 < T2 < T3 (m), got {:g} {:g} {:g} {:g}", prefix, t0_m,
                            t1_m, t2_m, t3_m));
  }
}

/// One part's transforms over a collision interval, built once per part and substep so
/// that no pair transforms or inverts anything.
struct FieldCollider::PartFrame {
  Affine toVoxel0, toVoxel1;  ///< world -> voxel coordinates at the interval's start and end
  Affine toWorld0, toWorld1;  ///< voxel coordinates -> world
  Mat3 rotation1;             ///< the part's directions -> world at the end (normals)
  double t2Voxels = 0;        ///< the collision surface T2 in voxels (the walk's test)
};

/// A part's rigid motion over one substep, world to world.
struct FieldCollider::PartStep {
  Affine motion;
};

FieldCollider::FieldCollider(std::string garmentName, std::vector<CollisionPart> parts, const OffsetSurfaces& offsets,
                             double staticFriction, double dynamicFriction, int every)
    : garment_(std::move(garmentName)),
      parts_(std::move(parts)),
      offsets_(offsets),
      staticFriction_(staticFriction),
      dynamicFriction_(dynamicFriction),
      every_(std::max(1, every)) {
  offsets_.validate("garment '" + garment_ + "': ");
  for (const CollisionPart& p : parts_) {
    if (!p.field || !p.motion) throw Error(fmt::format("garment '{}': body part '{}' has no distance field or motion", garment_, p.name), ExitCode::Internal);
    if (p.field->shell_m() + 1e-12 < offsets_.t3_m) {
      throw Error(fmt::format("garment '{}': body part '{}': its distance field keeps Voronoi normals within {:.4f} m, "
                              "less than the outer offset T3 = {:.4f} m",
                              garment_, p.name, p.field->shell_m(), offsets_.t3_m));
    }
    if (p.faceSamples) {
      const auto k = static_cast<std::size_t>(&p - parts_.data());
      if (k >= 64)
        throw Error(fmt::format("garment '{}': body part '{}' takes face samples, but only the first 64 collidable "
                                "parts can (it is number {})",
                                garment_, p.name, k + 1));
      faceParts_ |= std::uint64_t{1} << k;
    }
    clearOfT2_.push_back(clearanceBits(*p.field, offsets_.t2_m / p.field->voxelSize()));
    restable_.push_back(restableBits(*p.field, offsets_.t2_m / p.field->voxelSize()));
  }
  frames_.resize(parts_.size());
  poses_.resize(2 * parts_.size());
  steps_.resize(parts_.size());
  holds_.assign(parts_.size(), 0);
  outOfReach_.assign(parts_.size(), 0);
  idle_.assign(parts_.size(), 0);
}

FieldCollider::~FieldCollider() = default;

void FieldCollider::setFixedVertices(const std::vector<std::uint32_t>& vertices, std::size_t vertexCount) {
  free_.assign(vertexCount, 1);
  for (std::uint32_t v : vertices) {
    if (v >= vertexCount)
      throw Error(fmt::format("garment '{}': fixed vertex {} is out of range ({} vertices)", garment_, v, vertexCount),
                  ExitCode::Internal);
    free_[v] = 0;
  }
  freeCount_ = static_cast<std::size_t>(std::count(free_.begin(), free_.end(), std::uint8_t{1}));
  std::fill(idle_.begin(), idle_.end(), std::uint8_t{0});
}

void FieldCollider::initialise(const ClothState& state, double t_s) {
  const std::size_t n = state.size();
  if (free_.size() != n) setFixedVertices({}, n);
  states_.assign(parts_.size(), std::vector<PointState>(n, PointState::OutsideVol));
  lastVoxel_.assign(parts_.size(), std::vector<Vec3>(n, Vec3::Zero()));
  planes_.assign(parts_.size(), std::vector<ContactPlane>(n));
  penalty_.assign(n, 0);
  embedded_.assign(parts_.size(), std::vector<std::uint8_t>(n, 0));
  easeUntil_s_.assign(parts_.size(), std::vector<double>(n, 0.0));
  for (std::vector<double>* v : {&correctionX_, &correctionY_, &correctionZ_}) v->assign(n, 0.0);
  corrections_.assign(n, 0);
  firstAsk_.assign(n, Vec3::Zero());
  askParts_.assign(n, {0, 0});
  secondAsk_.assign(n, Vec3::Zero());
  correctedPoints_.clear();
  correctedPoints_.reserve(n);  // each point once per test: no allocation in the tests
  slidingParts_.assign(n, 0);
  for (std::vector<double>* v : {&faceDX_, &faceDY_, &faceDZ_, &faceDVX_, &faceDVY_, &faceDVZ_}) v->assign(n, 0.0);
  faceCount_.assign(n, 0);
  corrected_.clear();
  corrected_.reserve(n * parts_.size());  // the step does not allocate
  held_.clear();
  held_.reserve(n);
  heldParts_.clear();
  heldParts_.reserve(n * parts_.size());
  pinched_.clear();
  pinched_.reserve(n * parts_.size());
  askers_.assign(n, 0);
  pinchCall_.assign(n, -1);
  pinchParts_.assign(n, 0);
  pinchedNow_.assign(n, 0);
  pinchedPoints_.clear();
  pinchedPoints_.reserve(n);
  partVelocity_.assign(n, Vec3::Zero());
  field_.embeddedAtStart = 0;
  for (std::vector<double>* v : {&endVoxelX_, &endVoxelY_, &endVoxelZ_, &nearest_}) v->assign(n, 0.0);
  keep_.assign(n + 8, 0);  // padded: the candidate scan reads eight flags at a time
  candidates_.assign(n, 0);
  setRanges(n, rangeVertices_);
  settledVoxel_.assign(parts_.size(), std::vector<Vec3i>(n, kNotSettled));
  for (auto* b : {&ballX_, &ballY_, &ballZ_}) b->assign(parts_.size(), std::vector<double>(n, 0.0));
  ballR2_.assign(parts_.size(), std::vector<double>(n, -1.0));
  ballTest_.assign(parts_.size(), std::vector<long>(n, 0));
  for (std::vector<double>* v : {&testX_, &testY_, &testZ_, &nextTestX_, &nextTestY_, &nextTestZ_}) v->assign(n, 0.0);
  tests_ = 0;
  std::fill(idle_.begin(), idle_.end(), std::uint8_t{0});
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    const field::DistanceField& f = *parts_[k].field;
    const Affine toVoxel = worldToVoxel(f, parts_[k].motion->poseAt(t_s));
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 c = toVoxel.apply(state.position(i));
      lastVoxel_[k][i] = c;
      if (!free_[i] || !walkable(f, roundVoxel(c))) continue;
      const double d = f.distanceAtVoxel(c);
      states_[k][i] = PointState::InsideVol;
      if (d < offsets_.t2_m) {
        embedded_[k][i] = 1;
        easeUntil_s_[k][i] = t_s + kEaseTimeFactor * (offsets_.t2_m - d) / kEmbeddedSpeed_m_s;
        ++field_.embeddedAtStart;
      }
    }
  }
  lastTime_s_ = t_s;
}

void FieldCollider::beginFrame() {
  frameStartCounters_ = counters_;
  frameStartField_ = field_;
}

void FieldCollider::restartFrame(const ClothState& state, double t_s) {
  counters_ = frameStartCounters_;
  field_ = frameStartField_;
  if (states_.empty() || states_.front().size() != state.size()) return;  // not yet initialised
  held_.clear();
  heldParts_.clear();
  std::fill(holds_.begin(), holds_.end(), std::uint8_t{0});
  for (const PinchedPoint& p : pinchedPoints_) pinchedNow_[p.vertex] = 0;
  pinchedPoints_.clear();
  std::fill(idle_.begin(), idle_.end(), std::uint8_t{0});
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    const field::DistanceField& f = *parts_[k].field;
    const Affine toVoxel = worldToVoxel(f, parts_[k].motion->poseAt(t_s));
    for (std::size_t i = 0; i < state.size(); ++i) {
      const Vec3 c = toVoxel.apply(state.position(i));
      lastVoxel_[k][i] = c;
      settledVoxel_[k][i] = kNotSettled;
      ballR2_[k][i] = -1.0;
      if (!free_[i] || embedded_[k][i]) continue;
      if (!walkable(f, roundVoxel(c))) {
        states_[k][i] = PointState::OutsideVol;
        continue;
      }
      states_[k][i] = f.distanceAtVoxel(c) < offsets_.t3_m ? PointState::OnSurf : PointState::InsideVol;
    }
  }
  lastTime_s_ = t_s;
}

FieldCollider::PartFrame FieldCollider::framePart(const CollisionPart& part, const RigidTransform& pose0,
                                                  const RigidTransform& pose1) const {
  const field::DistanceField& f = *part.field;
  PartFrame frame;
  frame.toVoxel0 = worldToVoxel(f, pose0);
  frame.toWorld0 = voxelToWorld(f, pose0);
  framePartEnd(part, pose1, frame);
  return frame;
}

void FieldCollider::framePartEnd(const CollisionPart& part, const RigidTransform& pose1, PartFrame& frame) const {
  const field::DistanceField& f = *part.field;
  frame.toVoxel1 = worldToVoxel(f, pose1);
  frame.toWorld1 = voxelToWorld(f, pose1);
  frame.rotation1 = pose1.rotation.toRotationMatrix();
  frame.t2Voxels = offsets_.t2_m / f.voxelSize();
}

void FieldCollider::collide(const ClothModel& model, double t0_s, double t1_s, ClothState& io) {
  ++counters_.calls;
  if (states_.empty() || states_.front().size() != io.size()) initialise(io, t0_s);
  if ((calls_++ % every_) != 0) {  // reduced-frequency collision tests
    holdPinches(t0_s, t1_s, io);
    if (countEverySubstep_ && measurePenetration_) {
      const StageClock::Ticks start = StageClock::now();
      countUntested(io, t1_s);
      StageClock::lap(measureTicks_, start);
    }
    return;
  }
  const double interval_s = t1_s - lastTime_s_;
  if (!(interval_s > 0)) return;

  if (measurePenetration_) std::fill(nearest_.begin(), nearest_.end(), std::numeric_limits<double>::infinity());
  corrected_.clear();
  // A test that starts where the last one ended (all but the first of a run, or of a frame
  // computed again) takes its start transforms from that test's end: a pose is a function
  // of the time alone (FixtureMotion), and this halves the pose evaluations and transforms.
  const bool continued = framesEnd_s_ == lastTime_s_;
  const StageClock::Ticks poseStart = StageClock::now();
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    if (!continued) poses_[2 * k] = parts_[k].motion->poseAt(lastTime_s_);
    poses_[2 * k + 1] = parts_[k].motion->poseAt(t1_s);
  }
  StageClock::lap(poseTicks_, poseStart);
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    PartFrame& frame = frames_[k];
    if (continued) {
      frame.toVoxel0 = frame.toVoxel1;
      frame.toWorld0 = frame.toWorld1;
      framePartEnd(parts_[k], poses_[2 * k + 1], frame);
    } else {
      frame = framePart(parts_[k], poses_[2 * k], poses_[2 * k + 1]);
    }
  }
  framesEnd_s_ = t1_s;
  ++tests_;
  // Parts the free points cannot reach at this test are left out of it (exact: the cull
  // would keep none of their pairs).
  if (boxCulling_) {
    Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
    for (std::size_t i = 0; i < io.size(); ++i)
      if (free_[i]) {
        lo = lo.cwiseMin(io.position(i));
        hi = hi.cwiseMax(io.position(i));
      }
    for (std::size_t k = 0; k < parts_.size(); ++k) {
      outOfReach_[k] = outOfReach(k, frames_[k], lo, hi) ? 1 : 0;
      field_.partsOutOfReach += outOfReach_[k];
    }
  }
  for (std::size_t k = 0; k < parts_.size(); ++k)
    if (!outOfReach_[k]) idle_[k] = 0;  // tested: its pairs may change
  // Where the points are before this test's corrections: where the walks of the pairs
  // resting now would start at the next test (wake).
  std::copy(io.x.begin(), io.x.end(), nextTestX_.begin());
  std::copy(io.y.begin(), io.y.end(), nextTestY_.begin());
  std::copy(io.z.begin(), io.z.end(), nextTestZ_.begin());
  const std::size_t ranges = rangeStart_.size() - 1;
  if (ranges == 1) {
    collideRange(0, interval_s, io);
  } else {
    // Each range's pairs touch only its own vertices' data (a point meets its parts in part
    // order, as in one range): the same result to the bit for any number of threads.
    rangeLoop_(ranges, 1, [&](std::size_t first, std::size_t last) {
      for (std::size_t range = first; range != last; ++range) collideRange(range, interval_s, io);
    });
  }
  mergeTallies(ranges);
  testX_.swap(nextTestX_);
  testY_.swap(nextTestY_);
  testZ_.swap(nextTestZ_);
  applyCorrections(io);
  if (faceParts_) collideFaces(model, interval_s, io);
  collectPinches(interval_s, io);
  if (measurePenetration_) {
    const StageClock::Ticks start = StageClock::now();
    measureCorrected(io);
    countPenetration();
    StageClock::lap(measureTicks_, start);
  }
  lastTime_s_ = t1_s;
}

void FieldCollider::collideRange(std::size_t range, double dt_s, ClothState& io) {
  RangeTally& t = tallies_[range];
  t.field = {};
  t.contacts = t.kept = t.resting = 0;
  t.corrected.clear();
  t.correctedPoints.clear();
  const std::size_t first = rangeStart_[range], last = rangeStart_[range + 1];
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    if (outOfReach_[k]) continue;
    const PartFrame& frame = frames_[k];
    std::size_t resting = 0;
    const std::size_t kept = selectCandidates(k, frame, io, first, last, resting);
    t.kept += kept;
    t.resting += resting;
    const std::vector<Vec3i>& settled = settledVoxel_[k];
    const std::vector<double>& ballR2 = ballR2_[k];
    for (std::size_t j = first; j < first + kept; ++j) {
      const std::uint32_t i = candidates_[j];
      const Vec3 c1(endVoxelX_[i], endVoxelY_[i], endVoxelZ_[i]);
      if (ballR2[i] >= 0) wake(k, i);
      if (roundVoxel(c1) == settled[i]) {
        settle(t, k, i, c1);
      } else if (!slideOnPlane(t, k, frame, i, c1, dt_s, io)) {
        collidePoint(t, k, frame, i, c1, dt_s, io);
      }
    }
  }
  if (faceParts_) markSlidingParts(first, last);
}

void FieldCollider::markSlidingParts(std::size_t first, std::size_t last) {
  std::fill(slidingParts_.begin() + first, slidingParts_.begin() + last, std::uint64_t{0});
  for (std::size_t k = 0; k < std::min<std::size_t>(parts_.size(), 64); ++k) {
    const PointState* s = states_[k].data();
    for (std::size_t i = first; i < last; ++i)
      slidingParts_[i] |= static_cast<std::uint64_t>(s[i] == PointState::OnSurf) << k;
  }
}

void FieldCollider::mergeTallies(std::size_t ranges) {
  std::size_t kept = 0, resting = 0;
  for (std::size_t r = 0; r < ranges; ++r) {
    const RangeTally& t = tallies_[r];
    field_ += t.field;
    counters_.contacts += t.contacts;
    kept += t.kept;
    resting += t.resting;
    corrected_.insert(corrected_.end(), t.corrected.begin(), t.corrected.end());
    correctedPoints_.insert(correctedPoints_.end(), t.correctedPoints.begin(), t.correctedPoints.end());
  }
  // corrected_ now lists the pairs range by range, not part by part as one range would;
  // what reads it (collectPinches, measureCorrected) needs only each point's pairs in part
  // order, and a point's pairs all come from its range, in part order.

  // The culled pairs are OutsideVol -> OutsideVol without a trace; the resting ones
  // InsideVol -> InsideVol, walked within their balls.
  const std::size_t pairs = freeCount_ * parts_.size();
  field_.tests += pairs;
  counters_.pointsTested += pairs;
  field_.transitions[0][0] += pairs - kept - resting;
  field_.transitions[1][1] += resting;
  field_.traces += resting;
  field_.restingSkips += resting;
}

void FieldCollider::setRanges(std::size_t vertices, std::size_t rangeVertices) {
  rangeStart_.assign(1, 0);
  if (vertices >= parallelFrom_ && rangeVertices > 0 && threadsAllowed() > 1) {
    // Whole vectors of the cull's flags in every range but the last (its scan reads eight
    // at a time).
    const std::size_t step = std::max<std::size_t>(64, rangeVertices / 64 * 64);
    for (std::size_t v = step; v + step / 2 < vertices; v += step)
      rangeStart_.push_back(static_cast<std::uint32_t>(v));
  }
  rangeStart_.push_back(static_cast<std::uint32_t>(vertices));
  const std::size_t ranges = rangeStart_.size() - 1;
  tallies_.resize(ranges);
  for (std::size_t r = 0; r < ranges; ++r) {  // the step does not allocate
    const std::size_t size = rangeStart_[r + 1] - rangeStart_[r];
    tallies_[r].corrected.reserve(size * parts_.size());
    tallies_[r].correctedPoints.reserve(size);
  }
}

bool FieldCollider::outOfReach(std::size_t k, const PartFrame& frame, const Vec3& lo, const Vec3& hi) {
  if (!(lo.x() <= hi.x())) return true;  // no free point
  // The box's corners in the part's voxels, bounded, a voxel wider than rounding could need.
  Vec3 vlo = Vec3::Constant(std::numeric_limits<double>::infinity()), vhi = -vlo;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    const Vec3 v = frame.toVoxel1.apply(corner);
    vlo = vlo.cwiseMin(v);
    vhi = vhi.cwiseMax(v);
  }
  const field::GridDims& d = parts_[k].field->dims();
  const Vec3 boxMax(d.nx - 1.5, d.ny - 1.5, d.nz - 1.5);  // as selectCandidates' walkable box
  const bool clear = (vhi.array() + 1.0 < 0.5).any() || (vlo.array() - 1.0 >= boxMax.array()).any();
  if (!clear) return false;
  if (idle_[k]) return true;  // left out since its pairs were found idle: nothing has changed them
  const std::vector<PointState>& states = states_[k];
  const std::vector<double>& balls = ballR2_[k];
  for (std::size_t i = 0; i < states.size(); ++i)
    if ((free_[i] && states[i] != PointState::OutsideVol) || balls[i] >= 0) return false;
  idle_[k] = 1;
  return true;
}

std::size_t FieldCollider::selectCandidates(std::size_t k, const PartFrame& frame, const ClothState& io,
                                            std::size_t first, std::size_t last, std::size_t& resting) {
  const std::size_t n = last - first;
  double *cx = endVoxelX_.data() + first, *cy = endVoxelY_.data() + first, *cz = endVoxelZ_.data() + first;
  mapPoints(frame.toVoxel1, n, io.x.data() + first, io.y.data() + first, io.z.data() + first, cx, cy, cz);
  // The walkable box: voxels 1 .. n-2 along each axis (the border layer is the outermost).
  const field::GridDims& d = parts_[k].field->dims();
  const Vec3 boxMax(d.nx - 1.5, d.ny - 1.5, d.nz - 1.5);
  const Balls balls{ballX_[k].data() + first, ballY_[k].data() + first, ballZ_[k].data() + first,
                    ballR2_[k].data() + first};
  resting = markCandidates(n, cx, cy, cz, boxMax, reinterpret_cast<const std::uint8_t*>(states_[k].data()) + first,
                           !boxCulling_, free_.data() + first, balls, keep_.data() + first);
  const std::uint8_t* keep = keep_.data();
  std::uint32_t* candidates = candidates_.data() + first;
  // Most flags are zero: skip them eight at a time.
  std::size_t kept = 0;
  for (std::size_t i = first; i < last; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, keep + i, sizeof word);
    if (word == 0) continue;
    for (std::size_t j = i; j < std::min(last, i + 8); ++j) {
      candidates[kept] = static_cast<std::uint32_t>(j);
      kept += keep[j];
    }
  }
  return kept;
}

void FieldCollider::countPenetration() {
  for (std::size_t i = 0; i < nearest_.size(); ++i) penalty_[i] = nearest_[i] < offsets_.t1_m;
  countNearest();
}

void FieldCollider::countNearest() {
  field_.vertexSubsteps += freeCount_;
  for (std::size_t i = 0; i < nearest_.size(); ++i) {
    const double nearest = nearest_[i];
    const bool belowT1 = nearest < offsets_.t1_m, pinched = pinchedNow_[i] != 0;
    field_.vertexSubstepsBelowT1 += belowT1;
    field_.vertexSubstepsBelowT1Pinched += belowT1 && pinched;
    field_.vertexSubstepsBelowT0 += nearest < offsets_.t0_m;
    if (nearest < 0) {
      ++field_.vertexSubstepsInsideBody;
      field_.vertexSubstepsInsideBodyPinched += pinched;
      field_.maxPenetration_m = std::max(field_.maxPenetration_m, -nearest);
    }
  }
  counters_.maxPenetration_m = field_.maxPenetration_m;
}

void FieldCollider::countUntested(const ClothState& io, double t_s) {
  std::fill(nearest_.begin(), nearest_.end(), std::numeric_limits<double>::infinity());
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    const field::DistanceField& f = *parts_[k].field;
    const Affine toVoxel = worldToVoxel(f, parts_[k].motion->poseAt(t_s));
    for (std::size_t i = 0; i < io.size(); ++i) {
      if (!free_[i] || embedded_[k][i]) continue;  // as the tests count: eased pairs stay out
      const Vec3 c = toVoxel.apply(io.position(i));
      if (walkable(f, roundVoxel(c))) nearest_[i] = std::min(nearest_[i], f.distanceAtVoxel(c));
    }
  }
  countNearest();  // not the penalty flags: those belong to the tests' responses
}

// Flattened: at -O3 GCC 12 left Eigen's fixed-size vector arithmetic and the sliding
// response as calls in a function this large, a fifth of the walking dress's collision
// time (docs/PERFORMANCE.md, ninth round).
[[gnu::flatten]] void FieldCollider::collidePoint(RangeTally& __restrict t, std::size_t k, const PartFrame& frame,
                                                  std::size_t i, const Vec3& c1, double dt_s, ClothState& io) {
  const field::DistanceField& f = *parts_[k].field;
  PointState& state = states_[k][i];
  Vec3& last = lastVoxel_[k][i];
  const PointState from = state;
  settledVoxel_[k][i] = kNotSettled;  // stayInside sets it again
  if (embedded_[k][i]) {
    releaseEmbedded(t, k, frame, i, c1, dt_s, io);
    if (embedded_[k][i] && lastTime_s_ + dt_s >= easeUntil_s_[k][i]) {
      // Still below T2 when it should long have reached it: the garment holds it there (a
      // sleeve narrower than the arm's offset surface, a pinch, bound vertices inside).
      // Eased on, it would never collide with the part nor count in the penetration
      // figures: it collides as any other from the next test.
      embedded_[k][i] = 0;
      state = PointState::OnSurf;
      ++t.field.embeddedTimedOut;
    }
    ++t.field.transitions[toIndex(from)][toIndex(state)];
    return;
  }

  const Vec3i v1 = roundVoxel(c1);
  const bool in1 = walkable(f, v1);
  if (state == PointState::OutsideVol && !in1) {
    ++t.field.transitions[0][0];
    last = c1;
    return;
  }
  // A point outside the volume has no cached position: where it was at the start of the
  // interval follows from its velocity (x1 = x0 + v dt after the integrator).
  const Vec3 c0 = state == PointState::OutsideVol
                      ? frame.toVoxel0.apply(io.position(i) - io.velocity(i) * dt_s)
                      : last;
  const Vec3i v0 = roundVoxel(c0);
  if (state == PointState::InsideVol && in1 && v0 == v1 && clearOfT2(k, f.index(v1.x(), v1.y(), v1.z()))) {
    // The commonest pair: still in its voxel, far above T2. The walk would be that one
    // voxel, found clear, and would add no voxel step to the path.
    ++t.field.traces;
    stayInside(t, k, i, c1);
    return;
  }

  // Where the walk starts: the start voxel, or, entering from outside, the entry voxel
  // found by walking backwards from the end until the walk leaves the volume.
  const Vec3i start = state == PointState::OutsideVol ? entryVoxel(f, v1, v0) : v0;
  // Forward walk: stop where it leaves the volume (it cannot re-enter a box) or, unless the
  // point already slides on the surface, at the first voxel below T2.
  bool hit = false;
  Vec3i hitVoxel = start;
  const auto walk = [&] {
    return walkVoxelsByTable(start, v1, [&](const Vec3i& p) {
      if (!walkable(f, p)) return false;
      if (state == PointState::OnSurf) return true;
      const std::uint32_t voxel = f.index(p.x(), p.y(), p.z());
      if (!clearOfT2(k, voxel) && f.distanceVoxels(voxel) < frame.t2Voxels) {
        hit = true;
        hitVoxel = p;
        return false;
      }
      return true;
    });
  };
  // A sliding point's walk only looks for the volume's edge. Between two walkable voxels it
  // cannot meet one (the walk keeps to their bounding box, inside the convex walkable box),
  // so it would visit one voxel per step of its longest axis: count them without walking.
  const bool slidesWithin = clearanceSkip_ && state == PointState::OnSurf && in1 && walkable(f, start);
  const int walked = slidesWithin ? (v1 - start).cwiseAbs().maxCoeff() + 1 : walk();
  ++t.field.traces;
  t.field.traceVoxels += static_cast<std::uint64_t>(walked - 1);

  if (!in1 && !hit) {  // left the volume
    state = PointState::OutsideVol;
    last = c1;
    ++t.field.transitions[toIndex(from)][toIndex(state)];
    return;
  }
  if (state != PointState::OnSurf && !hit && clearOfT2(k, f.index(v1.x(), v1.y(), v1.z()))) {
    stayInside(t, k, i, c1);
    return;
  }

  const double h = f.voxelSize();
  Vec3 c = c1;
  bool moved = false;
  // Most pairs are InsideVol far from the body: they need the distance only. The normal
  // comes with it (one gather) where a response will read it.
  field::FieldSample at = state == PointState::OnSurf ? slidingSample(t, k, i, c)
                          : hit                       ? f.sampleAtVoxel(c)
                                                      : field::FieldSample{f.distanceAtVoxel(c), Vec3::Zero()};
  if (state != PointState::OnSurf && (hit || at.distance_m < offsets_.t2_m)) {
    // Collision: stop where the path meets T2. The contact point is the path point nearest
    // the first voxel below T2, moved along the offset-surface normal onto T2.
    if (hit) {
      const Vec3 seg = c1 - c0;
      const double len2 = seg.squaredNorm();
      const double s = len2 > 0 ? std::clamp((hitVoxel.cast<double>() - c0).dot(seg) / len2, 0.0, 1.0) : 1.0;
      c = c0 + s * seg;
    }
    c = ontoT2(f, c, f.sampleAtVoxel(c));
    moved = true;
    state = PointState::OnSurf;
    ++t.field.collisions;
    ++t.contacts;
  } else if (state == PointState::OnSurf) {
    if (at.distance_m > offsets_.t3_m) {
      state = PointState::InsideVol;  // carried away by forces
    } else if (at.distance_m < offsets_.t0_m) {
      c = ontoT2(f, c, at);  // last resort
      moved = true;
      ++t.field.projections;
      ++t.contacts;
    } else if (at.distance_m < offsets_.t2_m) {
      // Sliding: the point stays on T2 while the part moves into it; the envelope down to
      // T1 absorbs what one substep's normal cannot (the penalty below).
      c += (offsets_.t2_m - at.distance_m) / h * at.normal;
      moved = true;
    }
  } else {
    state = PointState::InsideVol;
  }

  if (moved) at = slidingSample(t, k, i, c);  // the response reads the field where the point is to be
  moveAndRespond(t, k, frame, i, c, at, moved, state == PointState::OnSurf, dt_s, io);
  last = c;
  ++t.field.transitions[toIndex(from)][toIndex(state)];
  if (state == PointState::InsideVol && !moved) rest(k, i, c);
}

// Flattened as collidePoint is, for the same reason.
[[gnu::flatten]] bool FieldCollider::slideOnPlane(RangeTally& __restrict t, std::size_t k, const PartFrame& frame,
                                                  std::size_t i, const Vec3& c1, double dt_s, ClothState& io) {
  if (states_[k][i] != PointState::OnSurf || embedded_[k][i] || !contactPlanes_ || !clearanceSkip_) return false;
  const ContactPlane& plane = planes_[k][i];
  if (!plane.reaches(c1)) return false;
  const field::DistanceField& f = *parts_[k].field;
  Vec3& last = lastVoxel_[k][i];
  const Vec3i v1 = roundVoxel(c1), v0 = roundVoxel(last);
  if (!walkable(f, v1) || !walkable(f, v0)) return false;
  field::FieldSample at{plane.distanceAt(c1), plane.normal};
  if (at.distance_m > offsets_.t3_m || at.distance_m < offsets_.t0_m) return false;  // released, or projected
  Vec3 c = c1;
  const bool moved = at.distance_m < offsets_.t2_m;
  if (moved) {
    c += (offsets_.t2_m - at.distance_m) / f.voxelSize() * at.normal;
    if (!plane.reaches(c)) return false;  // the full test reads the field there
    at = {plane.distanceAt(c), plane.normal};
  }
  // From here on, collidePoint's sliding branch step for step (a walk within the box counted
  // as there, each plane answer counted as slidingSample counts it).
  settledVoxel_[k][i] = kNotSettled;
  ++t.field.traces;
  t.field.traceVoxels += static_cast<std::uint64_t>((v1 - v0).cwiseAbs().maxCoeff());
  t.field.planeEstimates += moved ? 2 : 1;
  moveAndRespond(t, k, frame, i, c, at, moved, true, dt_s, io);
  last = c;
  ++t.field.transitions[toIndex(PointState::OnSurf)][toIndex(PointState::OnSurf)];
  return true;
}

void FieldCollider::moveAndRespond(RangeTally& __restrict t, std::size_t k, const PartFrame& frame, std::size_t i,
                                   const Vec3& c, const field::FieldSample& at, bool moved, bool onSurf, double dt_s,
                                   ClothState& io) {
  Vec3 world1;  // where the point is to be, in the world at the interval's end
  if (moved) {
    world1 = frame.toWorld1.apply(c);
    addCorrection(t, k, i, world1 - io.position(i));
    t.corrected.push_back({static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(i)});
  } else {
    nearest_[i] = std::min(nearest_[i], at.distance_m);  // corrected pairs: applyCorrections
  }
  // A sliding point left above T2 keeps its velocity: the response would change nothing.
  if (onSurf && (moved || inContact(at))) {
    if (!moved) world1 = frame.toWorld1.apply(c);
    respondOnSurface(frame, c, world1, at, i, dt_s, io);
  }
}

// One move along the normal where the point lies is exact while the offset surface is flat
// over the move. A longer one, from deep below it (a collision between tests far apart, a
// pair the garment held down past its easing time), can cross where the normal turns and
// land short of T2, or inside the body: read the field again where it lands and move again.
Vec3 FieldCollider::ontoT2(const field::DistanceField& f, Vec3 c, field::FieldSample at) const {
  for (int read = 1;; ++read) {
    const double move_voxels = (offsets_.t2_m - at.distance_m) / f.voxelSize();
    c += move_voxels * at.normal;
    if (std::abs(move_voxels) <= kOneMoveReach_voxels || read == kProjectionReads) return c;
    at = f.sampleAtVoxel(c);
  }
}

field::FieldSample FieldCollider::slidingSample(RangeTally& __restrict t, std::size_t k, std::size_t i, const Vec3& c) {
  ContactPlane& plane = planes_[k][i];
  if (contactPlanes_ && plane.reaches(c)) {
    ++t.field.planeEstimates;
    return {plane.distanceAt(c), plane.normal};
  }
  ++t.field.planeReads;
  const field::FieldJet jet = parts_[k].field->jetAtVoxel(c);
  plane = {c, jet.gradient, jet.sample.normal, jet.sample.distance_m};
  return jet.sample;
}

// A point that ends in a voxel marked clear of T2, without a collision on its way, is where
// the trilinear distance would find it: above T2, so InsideVol. Its penetration figure is
// left out: it cannot be below T1.
void FieldCollider::stayInside(RangeTally& __restrict t, std::size_t k, std::size_t i, const Vec3& c1) {
  PointState& state = states_[k][i];
  ++t.field.transitions[toIndex(state)][toIndex(PointState::InsideVol)];
  state = PointState::InsideVol;
  lastVoxel_[k][i] = c1;
  ++t.field.clearanceSkips;
  // Until the pair leaves this voxel its test is this one: settle() repeats it.
  settledVoxel_[k][i] = roundVoxel(c1);
  rest(k, i, c1);
}

// Pair (k, vertex) stayed InsideVol in a voxel clear of T2 at its last test and ends this
// one in the same voxel: collidePoint would walk that one voxel, find it clear and call
// stayInside. The same, from the cached voxel: no range test, no clearance bit, no call.
void FieldCollider::settle(RangeTally& __restrict t, std::size_t k, std::size_t i, const Vec3& c1) {
  ++t.field.traces;
  ++t.field.transitions[toIndex(PointState::InsideVol)][toIndex(PointState::InsideVol)];
  lastVoxel_[k][i] = c1;
  ++t.field.clearanceSkips;
}

// The full test of a pair resting at the previous test would start its walk where the
// point was then, before that test's corrections, in the part's voxel coordinates of then;
// its state was InsideVol throughout (its ball lies inside the walkable box and clear of T2).
void FieldCollider::wake(std::size_t k, std::size_t i) {
  const bool restedLastTest = ballTest_[k][i] < tests_ - 1;
  ballR2_[k][i] = -1.0;
  if (!restedLastTest) return;
  lastVoxel_[k][i] = mapPoint(frames_[k].toVoxel0, testX_[i], testY_[i], testZ_[i]);
  states_[k][i] = PointState::InsideVol;
  settledVoxel_[k][i] = kNotSettled;
}

void FieldCollider::rest(std::size_t k, std::size_t i, const Vec3& c1) {
  const double r = restingRadius(k, c1);
  if (!(r > 0)) return;
  ballX_[k][i] = c1.x();
  ballY_[k][i] = c1.y();
  ballZ_[k][i] = c1.z();
  ballR2_[k][i] = r * r;
  ballTest_[k][i] = tests_;
}

// Why the radius holds (voxel units; v the voxel nearest c, d_v its stored distance, D the
// distance to the surface voxels' centres, which changes by at most the distance moved):
// - a walk within the ball visits voxels within sqrt(3)/2 of its points, and a trilinear
//   distance there blends voxels within sqrt(3) of the point, so every voxel that counts
//   lies within R = sqrt(3) + r + |c - v| of v;
// - stored distances are D rounded, within the shell, and beyond it between 0.75 D and
//   D + 0.25 (FIELDS.md): a voxel u outside the body has d_u >= d_v - slack - |u - v|, above
//   T2 while |u - v| < d_v - slack - T2; beyond the shell d_u >= 0.75 shell, above T2 when
//   the shell is wide enough (otherwise no part rests);
// - a voxel inside the body (negative) is at least D_v - sqrt(3)/2 from v, since the segment
//   between them crosses the surface in a surface voxel: out of reach while
//   |u - v| < d_v - slack - sqrt(3)/2.
double FieldCollider::restingRadius(std::size_t k, const Vec3& c) const {
  if (!restingBalls_) return 0;
  const field::DistanceField& f = *parts_[k].field;
  const Vec3i v = roundVoxel(c);
  if (!walkable(f, v)) return 0;
  const std::uint32_t voxel = f.index(v.x(), v.y(), v.z());
  if (!((restable_[k][voxel >> 6] >> (voxel & 63)) & 1)) return 0;
  const double t2Voxels = offsets_.t2_m / f.voxelSize();
  const field::GridDims& d = f.dims();
  const double toBox = std::min({c.x() - 0.5, c.y() - 0.5, c.z() - 0.5, d.nx - 1.5 - c.x(), d.ny - 1.5 - c.y(),
                                 d.nz - 1.5 - c.z()});
  const double dv = f.distanceVoxels(voxel);
  const double r = dv - kFieldSlack_voxels - std::max(t2Voxels, 0.5 * kSqrt3) - kSqrt3 - (c - v.cast<double>()).norm();
  return std::min(r, toBox);
}

Vec3 FieldCollider::cachedVoxel(std::size_t k, std::size_t i) const {
  if (ballR2_[k][i] >= 0 && ballTest_[k][i] < tests_)  // resting now: where the full test left it
    return mapPoint(frames_[k].toVoxel1, testX_[i], testY_[i], testZ_[i]);
  return lastVoxel_[k][i];
}

void FieldCollider::respondOnSurface(const PartFrame& frame, const Vec3& c, const Vec3& world,
                                     const field::FieldSample& at, std::size_t i, double dt_s, ClothState& io) const {
  const Vec3 n = frame.rotation1 * at.normal;
  const Vec3 partVelocity = (world - frame.toWorld0.apply(c)) / dt_s;
  Vec3 v = io.velocity(i);
  // In contact: remove the inward normal velocity relative to the part, with Coulomb
  // friction on the tangential part (stick below the static coefficient).
  const Vec3 rel = v - partVelocity;
  const double vn = rel.dot(n);
  if (vn < 0) {
    Vec3 vt = rel - vn * n;
    const double speed = vt.norm();
    if (speed <= staticFriction_ * -vn) {
      vt.setZero();
    } else {
      vt *= 1.0 - dynamicFriction_ * -vn / speed;
    }
    v = partVelocity + vt;
  }
  const double belowT1 = offsets_.t1_m - at.distance_m;
  if (belowT1 > 0) {
    // Penalty: separate from the part at least at the rate that removes kPenaltyRate of
    // the depth per substep. A floor on the relative normal velocity, not an added impulse,
    // so that two parts meeting in a corner, or many substeps below T1, cannot pump energy.
    const double wanted = kPenaltyRate * belowT1 / dt_s;
    const double vn = (v - partVelocity).dot(n);
    if (vn < wanted) v += n * (wanted - vn);
  }
  io.setVelocity(i, v);
}

void FieldCollider::collectPinches(double dt_s, ClothState& io) {
  held_.clear();
  heldParts_.clear();
  std::fill(holds_.begin(), holds_.end(), std::uint8_t{0});
  for (const PinchedPoint& p : pinchedPoints_) pinchedNow_[p.vertex] = 0;
  pinchedPoints_.clear();
  for (const auto& [k, i] : corrected_) {
    ++askers_[i];
    partVelocity_[i].setZero();
  }
  const auto direction = [](const Vec3& ask) {
    const double length = ask.norm();
    return length > 0.0 ? Vec3(ask / length) : Vec3::Zero();
  };
  for (const auto& [k, i] : corrected_)
    if (askers_[i] >= 2 && !pinchedNow_[i]) {
      pinchedNow_[i] = 1;
      pinchedPoints_.push_back({i, {direction(firstAsk_[i]), direction(secondAsk_[i])}});
    }
  if (!pinchHold_) {
    for (const auto& [k, i] : corrected_) askers_[i] = 0;
    return;
  }
  pinched_.clear();
  for (const auto& [k, i] : corrected_) {
    if (askers_[i] < 2) continue;
    pinched_.push_back({i, k});
    if (pinchCall_[i] != calls_) pinchParts_[i] = 0;
    pinchCall_[i] = calls_;
    if (k < 64) pinchParts_[i] |= std::uint64_t{1} << k;
    const Vec3 c = frames_[k].toVoxel1.apply(io.position(i));  // where the corrections put it
    partVelocity_[i] += (frames_[k].toWorld1.apply(c) - frames_[k].toWorld0.apply(c)) / dt_s;
  }
  for (const auto& [k, i] : corrected_) {
    if (askers_[i] >= 2) {
      io.setVelocity(i, partVelocity_[i] / static_cast<double>(askers_[i]));
      ++field_.pinchedVertexTests;
    }
    askers_[i] = 0;  // once per point: the velocity is set and counted on its first pair
  }
  if (every_ == 1) return;  // nothing to hold between tests
  std::sort(pinched_.begin(), pinched_.end());
  for (const auto& [i, k] : pinched_) {
    if (held_.empty() || held_.back().vertex != i)
      held_.push_back({i, static_cast<std::uint32_t>(heldParts_.size()), 0, io.position(i)});
    heldParts_.push_back(k);
    ++held_.back().partCount;
    holds_[k] = 1;
  }
}

void FieldCollider::holdPinches(double t0_s, double t1_s, ClothState& io) {
  if (held_.empty() || !(t1_s > t0_s)) return;
  // Each holding part's rigid motion over the substep, world to world:
  // x -> R1 R0^T (x - p0) + p1.
  const StageClock::Ticks poseStart = StageClock::now();
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    if (!holds_[k]) continue;
    poses_[2 * k] = parts_[k].motion->poseAt(t0_s);
    poses_[2 * k + 1] = parts_[k].motion->poseAt(t1_s);
  }
  StageClock::lap(poseTicks_, poseStart);
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    if (!holds_[k]) continue;
    const RigidTransform& a = poses_[2 * k];
    const RigidTransform& b = poses_[2 * k + 1];
    const Mat3 r = (b.rotation * a.rotation.conjugate()).toRotationMatrix();
    steps_[k].motion = {r, b.translation - r * a.translation};
  }
  const double invDt = 1.0 / (t1_s - t0_s);
  for (HeldPoint& h : held_) {
    Vec3 sum = Vec3::Zero();
    for (std::uint32_t j = 0; j < h.partCount; ++j) sum += steps_[heldParts_[h.firstPart + j]].motion.apply(h.at);
    const Vec3 next = sum / static_cast<double>(h.partCount);
    io.setVelocity(h.vertex, (next - h.at) * invDt);
    io.setPosition(h.vertex, next);
    h.at = next;
  }
  field_.heldVertexSubsteps += held_.size();
}

FieldCollider::LastPinch FieldCollider::lastPinch(std::size_t vertex) const {
  LastPinch pinch;
  if (vertex >= pinchCall_.size() || pinchCall_[vertex] < 0) return pinch;
  for (std::size_t k = 0; k < std::min<std::size_t>(parts_.size(), 64); ++k)
    if (pinchParts_[vertex] >> k & 1) pinch.parts.push_back(parts_[k].name);
  pinch.substepsAgo = calls_ - pinchCall_[vertex];
  return pinch;
}

NearestPinch nearestPinch(const ClothModel& model, const FieldCollider& collider, std::uint32_t vertex,
                          long withinSubsteps) {
  constexpr double kReach_m = 0.05;
  NearestPinch found;
  if (vertex >= model.vertexCount()) return found;
  const auto restAt = [&](std::uint32_t v) { return Vec3(model.restX()[v], model.restY()[v], model.restZ()[v]); };
  double nearest = kReach_m;
  for (std::uint32_t v = 0; v < model.vertexCount(); ++v) {
    const double d = (restAt(v) - restAt(vertex)).norm();
    if (d >= nearest) continue;
    FieldCollider::LastPinch p = collider.lastPinch(v);
    if (p.parts.empty() || p.substepsAgo > withinSubsteps) continue;
    nearest = d;
    found = {v, d, std::move(p)};
    if (v == vertex) break;  // its own pinch is the one to name
  }
  return found;
}

std::string pinchNear(const ClothModel& model, const FieldCollider& collider, std::uint32_t vertex,
                      long withinSubsteps) {
  return describePinch(nearestPinch(model, collider, vertex, withinSubsteps), vertex);
}

std::string describePinch(const NearestPinch& near, std::uint32_t vertex) {
  const FieldCollider::LastPinch& pinch = near.pinch;
  if (pinch.parts.empty()) return "";
  const std::string who =
      near.vertex == vertex ? "it" : fmt::format("vertex {}, {:.0f} mm from it,", near.vertex, 1e3 * near.distance_m);
  const std::string when = pinch.substepsAgo == 0   ? "in that substep"
                           : pinch.substepsAgo == 1 ? "1 substep before"
                                                    : fmt::format("{} substeps before", pinch.substepsAgo);
  return fmt::format("; {}, {} was pressed by {} at once (a pinch: their offset surfaces overlap there, and no "
                     "place is outside them all)",
                     when, who, fmt::join(pinch.parts, ", "));
}

std::optional<Vec3> pinchMove(const Vec3& a, const Vec3& b) {
  const double da = a.norm(), db = b.norm();
  if (!(da > 0.0) || !(db > 0.0)) return std::nullopt;  // an ask with no direction
  const Vec3 na = a / da, nb = b / db;
  // The nearest point of one half-space that lies in the other is the nearest of both.
  if (nb.dot(a) >= db) return a;
  if (na.dot(b) >= da) return b;
  // Otherwise both bound it: x = la na + lb nb on both planes, with la, lb >= 0.
  const double c = na.dot(nb), det = 1.0 - c * c;
  if (!(det > 1e-9)) return std::nullopt;  // parallel planes facing each other: no point outside both
  const double la = (da - c * db) / det, lb = (db - c * da) / det;
  if (la < 0.0 || lb < 0.0) return std::nullopt;
  const Vec3 x = la * na + lb * nb;
  if (x.norm() > kCreaseReach * std::max(da, db)) return std::nullopt;
  return x;
}

void FieldCollider::addCorrection(RangeTally& __restrict t, std::size_t k, std::size_t i, const Vec3& displacement) {
  correctionX_[i] += displacement.x();
  correctionY_[i] += displacement.y();
  correctionZ_[i] += displacement.z();
  const std::uint16_t asked = corrections_[i]++;
  if (asked == 0) {
    firstAsk_[i] = displacement;
    askParts_[i][0] = static_cast<std::uint16_t>(k);
    t.correctedPoints.push_back(static_cast<std::uint32_t>(i));
  } else if (asked == 1) {
    secondAsk_[i] = displacement;
    askParts_[i][1] = static_cast<std::uint16_t>(k);
  }
}

// The crease move is first order: each part's surface taken for the plane its ask ends on.
// Across a long move the surfaces curve away from those planes, most where the two face each
// other at a wide angle (the move then runs far along the gap between them), and the move can
// end deeper in one part than the mean would. So both places are read in both parts' fields,
// and the crease move is taken only where it ends the farther out of the two.
std::optional<Vec3> FieldCollider::creaseMove(std::uint32_t i, const ClothState& io) {
  const std::optional<Vec3> move = pinchMove(firstAsk_[i], secondAsk_[i]);
  if (!move) return std::nullopt;
  const Vec3 x = io.position(i);
  const auto clearance = [&](const Vec3& at) {
    double least = std::numeric_limits<double>::infinity();
    for (const std::uint16_t k : askParts_[i]) {
      const field::DistanceField& f = *parts_[k].field;
      const Vec3 c = frames_[k].toVoxel1.apply(at);
      if (walkable(f, roundVoxel(c))) least = std::min(least, f.distanceAtVoxel(c));
    }
    return least;
  };
  const Vec3 mean = x + 0.5 * (firstAsk_[i] + secondAsk_[i]);
  if (clearance(x + *move) >= clearance(mean)) {
    ++field_.creaseMoves;
    return move;
  }
  ++field_.creaseMovesRefused;
  return std::nullopt;
}

void FieldCollider::applyCorrections(ClothState& io) {
  // A few dozen points of hundreds: by their list, leaving the sums at zero for the next test.
  for (const std::uint32_t i : correctedPoints_) {
    const std::optional<Vec3> crease = corrections_[i] == 2 && creaseMoves_ ? creaseMove(i, io) : std::nullopt;
    if (crease) {
      io.x[i] += crease->x();
      io.y[i] += crease->y();
      io.z[i] += crease->z();
    } else {
      const double share = 1.0 / corrections_[i];
      io.x[i] += share * correctionX_[i];
      io.y[i] += share * correctionY_[i];
      io.z[i] += share * correctionZ_[i];
    }
    correctionX_[i] = correctionY_[i] = correctionZ_[i] = 0.0;
    corrections_[i] = 0;
  }
  correctedPoints_.clear();
}

void FieldCollider::buildFaceTopology(const ClothModel& model) {
  const std::size_t n = model.vertexCount();
  const std::vector<mesh::Triangle>& triangles = model.triangles();
  // Vertex -> its triangles, and vertex -> its neighbours (itself included), as CSR lists.
  std::vector<std::vector<std::uint32_t>> around(n), ring(n);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const std::uint32_t i : triangles[t]) {
      around[i].push_back(static_cast<std::uint32_t>(t));
      for (const std::uint32_t j : triangles[t]) ring[i].push_back(j);
    }
  const auto flatten = [n](std::vector<std::vector<std::uint32_t>>& lists, std::vector<std::uint32_t>& start,
                           std::vector<std::uint32_t>& flat) {
    start.assign(n + 1, 0);
    flat.clear();
    for (std::size_t i = 0; i < n; ++i) {
      std::sort(lists[i].begin(), lists[i].end());
      lists[i].erase(std::unique(lists[i].begin(), lists[i].end()), lists[i].end());
      flat.insert(flat.end(), lists[i].begin(), lists[i].end());
      start[i + 1] = static_cast<std::uint32_t>(flat.size());
    }
  };
  flatten(around, vertexTrianglesStart_, vertexTriangles_);
  flatten(ring, vertexRingStart_, vertexRing_);
  faceStamp_.assign(triangles.size(), -1);
}

// Face samples (CollisionPart::faceSamples). Which triangles: those with a vertex sliding on
// a face-sample part, all three vertices free (a bound vertex is the fixtures' to place) and
// none being eased out of that part (it started below T2: its triangle would be thrown onto
// T2 at once, which the easing is there to avoid); and no vertex within one ring of them
// sliding on another part. Where two parts' offset surfaces meet (a sleeve between arm and
// chest) no place is outside both, and pushing the triangle off one of them pushes it into
// the other: measured on the walking dress, the face samples there stopped the Daz-style
// walk in frame 74.
//
// The push: the centroid c = (x_a + x_b + x_c) / 3 below T2 by `below` moves its three
// vertices by kFaceRate below along the normal, and the centroid loses its inward velocity
// relative to the part (each vertex by the same change). A part of the depth per test, not
// all of it: the vertices' own contacts are already answered, and a triangle thrown onto T2
// at once yanks its neighbours (measured: with the whole depth the walking dress stopped in
// frame 20). The bulge rises by a fraction of a millimetre per substep, so the triangle
// keeps up with it.
void FieldCollider::collideFaces(const ClothModel& model, double dt_s, ClothState& io) {
  const std::size_t n = io.size();
  if (vertexTrianglesStart_.size() != n + 1) buildFaceTopology(model);  // once, at the first test
  // Every part a vertex within one ring of v slides on.
  const auto ringParts = [&](std::uint32_t v) {
    std::uint64_t parts = 0;
    for (std::uint32_t j = vertexRingStart_[v]; j < vertexRingStart_[v + 1]; ++j) parts |= slidingParts_[vertexRing_[j]];
    return parts;
  };
  const std::vector<mesh::Triangle>& triangles = model.triangles();
  bool any = false;
  for (std::uint32_t v = 0; v < n; ++v) {
    if (!(slidingParts_[v] & faceParts_)) continue;
    for (std::uint32_t j = vertexTrianglesStart_[v]; j < vertexTrianglesStart_[v + 1]; ++j) {
      const std::uint32_t tri = vertexTriangles_[j];
      if (faceStamp_[tri] == tests_) continue;  // met through another of its vertices
      faceStamp_[tri] = tests_;
      const mesh::Triangle& t = triangles[tri];
      if (!(free_[t[0]] & free_[t[1]] & free_[t[2]])) continue;
      const std::uint64_t near = ringParts(t[0]) | ringParts(t[1]) | ringParts(t[2]);
      if (near & (near - 1)) continue;
      const auto k = static_cast<std::size_t>(std::countr_zero(near));  // the one part near, a face part
      if (embedded_[k][t[0]] | embedded_[k][t[1]] | embedded_[k][t[2]]) continue;
      const field::DistanceField& f = *parts_[k].field;
      const PartFrame& frame = frames_[k];
      const Vec3 p = (io.position(t[0]) + io.position(t[1]) + io.position(t[2])) / 3.0;
      const Vec3 c = frame.toVoxel1.apply(p);
      const Vec3i voxel = roundVoxel(c);
      if (!walkable(f, voxel) || clearOfT2(k, f.index(voxel.x(), voxel.y(), voxel.z()))) continue;
      ++field_.faceTests;
      const field::FieldSample at = f.sampleAtVoxel(c);
      const double below = offsets_.t2_m - at.distance_m;
      if (below <= 0) continue;
      ++field_.faceContacts;
      field_.facesInsideBody += at.distance_m < 0;
      const Vec3 normal = frame.rotation1 * at.normal;
      const Vec3 partVelocity = (frame.toWorld1.apply(c) - frame.toWorld0.apply(c)) / dt_s;
      const Vec3 velocity = (io.velocity(t[0]) + io.velocity(t[1]) + io.velocity(t[2])) / 3.0;
      const double vn = (velocity - partVelocity).dot(normal);
      const Vec3 dx = kFaceRate * below * normal;
      const Vec3 dv = vn < 0 ? Vec3(-vn * normal) : Vec3::Zero();
      for (const std::uint32_t i : t) {
        faceDX_[i] += dx.x();
        faceDY_[i] += dx.y();
        faceDZ_[i] += dx.z();
        faceDVX_[i] += dv.x();
        faceDVY_[i] += dv.y();
        faceDVZ_[i] += dv.z();
        ++faceCount_[i];
      }
      any = true;
    }
  }
  if (!any) return;
  // A vertex several triangles push takes their mean (Jacobi, as the vertices' corrections).
  for (std::size_t i = 0; i < n; ++i) {
    if (!faceCount_[i]) continue;
    const double share = 1.0 / faceCount_[i];
    io.x[i] += share * faceDX_[i];
    io.y[i] += share * faceDY_[i];
    io.z[i] += share * faceDZ_[i];
    io.vx[i] += share * faceDVX_[i];
    io.vy[i] += share * faceDVY_[i];
    io.vz[i] += share * faceDVZ_[i];
    faceDX_[i] = faceDY_[i] = faceDZ_[i] = faceDVX_[i] = faceDVY_[i] = faceDVZ_[i] = 0.0;
    faceCount_[i] = 0;
  }
}

void FieldCollider::measureCorrected(const ClothState& io) {
  // A range's corrected pairs are its own points' (mergeTallies), so the ranges measure side
  // by side: a field read each, about a tenth of the walking dress's test on one thread.
  const auto measureRange = [&](std::size_t range) {
    for (const auto& [k, i] : tallies_[range].corrected) {
      const double d = parts_[k].field->distanceAtVoxel(frames_[k].toVoxel1.apply(io.position(i)));
      nearest_[i] = std::min(nearest_[i], d);
    }
  };
  const std::size_t ranges = rangeStart_.size() - 1;
  if (ranges == 1) {
    measureRange(0);
    return;
  }
  rangeLoop_(ranges, 1, [&](std::size_t first, std::size_t last) {
    for (std::size_t range = first; range != last; ++range) measureRange(range);
  });
}

// A point that started below T2 of the part (a garment modelled tight on a smooth body lies
// inside a rigid segment's offset surfaces, or its capped volume, near the joints) is eased
// out along the normal at most kEmbeddedSpeed, losing its inward velocity relative to the
// part, instead of being thrown onto T2 in one substep; once on T2 it collides like any other.
// (Easing only those below T1, as at first, threw the ones between T1 and T2 onto T2 in the
// first substep: up to T2 - T1 at once, which with offsets of 3, 6, 9 and 20 mm stopped the
// walking dress in its first frame.)
// Eased pairs stay out of the penetration counts: they are reported as pairs_embedded_at_start.
void FieldCollider::releaseEmbedded(RangeTally& __restrict t, std::size_t k, const PartFrame& frame, std::size_t i,
                                    const Vec3& c1, double dt_s, ClothState& io) {
  const field::DistanceField& f = *parts_[k].field;
  PointState& state = states_[k][i];
  Vec3& last = lastVoxel_[k][i];
  Vec3 c = c1;
  last = c;
  if (!walkable(f, roundVoxel(c))) {
    embedded_[k][i] = 0;
    state = PointState::OutsideVol;
    return;
  }
  const field::FieldSample at = f.sampleAtVoxel(c);
  const double rest = offsets_.t2_m - at.distance_m;
  if (rest <= 0) {
    embedded_[k][i] = 0;
    state = at.distance_m > offsets_.t3_m ? PointState::InsideVol : PointState::OnSurf;
    return;
  }
  const double step = std::min(rest, kEmbeddedSpeed_m_s * dt_s);
  c += step / f.voxelSize() * at.normal;
  last = c;
  const Vec3 n = frame.rotation1 * at.normal;
  const Vec3 world = frame.toWorld1.apply(c);
  const Vec3 partVelocity = (world - frame.toWorld0.apply(c)) / dt_s;
  const Vec3 v = io.velocity(i);
  const double vn = (v - partVelocity).dot(n);
  if (vn < 0) io.setVelocity(i, v - vn * n);
  addCorrection(t, k, i, world - io.position(i));
  if (step == rest) {  // on T2 now (to the field's accuracy): slide from here
    embedded_[k][i] = 0;
    state = PointState::OnSurf;
  }
}

FieldCollisionCounters& FieldCollisionCounters::operator+=(const FieldCollisionCounters& o) {
  for (auto [a, b] : {std::pair{&tests, o.tests}, {&traces, o.traces}, {&traceVoxels, o.traceVoxels},
                      {&collisions, o.collisions}, {&projections, o.projections},
                      {&vertexSubstepsBelowT1, o.vertexSubstepsBelowT1}, {&vertexSubstepsBelowT0, o.vertexSubstepsBelowT0},
                      {&vertexSubstepsInsideBody, o.vertexSubstepsInsideBody},
                      {&vertexSubstepsBelowT1Pinched, o.vertexSubstepsBelowT1Pinched},
                      {&vertexSubstepsInsideBodyPinched, o.vertexSubstepsInsideBodyPinched},
                      {&vertexSubsteps, o.vertexSubsteps},
                      {&clearanceSkips, o.clearanceSkips}, {&restingSkips, o.restingSkips},
                      {&embeddedAtStart, o.embeddedAtStart},
                      {&embeddedTimedOut, o.embeddedTimedOut},
                      {&planeEstimates, o.planeEstimates}, {&planeReads, o.planeReads},
                      {&heldVertexSubsteps, o.heldVertexSubsteps}, {&pinchedVertexTests, o.pinchedVertexTests},
                      {&creaseMoves, o.creaseMoves}, {&creaseMovesRefused, o.creaseMovesRefused},
                      {&faceTests, o.faceTests}, {&faceContacts, o.faceContacts}, {&facesInsideBody, o.facesInsideBody},
                      {&partsOutOfReach, o.partsOutOfReach}})
    *a += b;
  maxPenetration_m = std::max(maxPenetration_m, o.maxPenetration_m);
  for (int from = 0; from < 3; ++from)
    for (int to = 0; to < 3; ++to) transitions[from][to] += o.transitions[from][to];
  return *this;
}

std::vector<std::size_t> FieldCollider::easedPairsPerPart() const {
  std::vector<std::size_t> counts(parts_.size(), 0);
  for (std::size_t k = 0; k < embedded_.size(); ++k)
    counts[k] = static_cast<std::size_t>(std::count(embedded_[k].begin(), embedded_[k].end(), std::uint8_t{1}));
  return counts;
}

std::optional<double> FieldCollider::easingEnds_s() const {
  std::optional<double> last;
  for (std::size_t k = 0; k < embedded_.size(); ++k)
    for (std::size_t i = 0; i < embedded_[k].size(); ++i)
      if (embedded_[k][i]) last = std::max(last.value_or(easeUntil_s_[k][i]), easeUntil_s_[k][i]);
  return last;
}

std::array<std::size_t, 3> FieldCollider::pointsPerState() const {
  std::array<std::size_t, 3> counts{};
  for (const auto& part : states_)
    for (PointState s : part) ++counts[toIndex(s)];
  return counts;
}

void FieldCollider::vertexDisplayStates(std::vector<std::uint8_t>& out) const {
  const std::size_t n = states_.empty() ? 0 : states_.front().size();
  out.assign(n, 0);
  for (const auto& part : states_)
    for (std::size_t i = 0; i < n; ++i) out[i] = std::max<std::uint8_t>(out[i], static_cast<std::uint8_t>(part[i]));
  for (std::size_t i = 0; i < n && i < penalty_.size(); ++i)
    if (penalty_[i]) out[i] = 3;
}

}  // namespace drape::cloth
