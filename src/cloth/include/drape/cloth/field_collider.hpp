#pragma once
// Collision of cloth mass points with moving body parts through their distance fields
// (paper section 4.3.3, DESIGN.md section 5).
//
// Each body part is a DistanceField in the part's local frame plus the part's rigid pose in
// the world at any time (a FixtureMotion: the same "rigid frame moving in time" fixtures
// use). Over one collision interval the motion of a mass point relative to the part is taken
// as linear in the part's voxel space and walked voxel by voxel (3D Bresenham).
//
// Four offset surfaces at distances T0 < T1 < T2 < T3 from the body (Figure 6):
//
//        T3 ............................  outer envelope: sliding zone ends, point released
//        T2 ----------------------------  collision surface: an inward crossing stops here
//        T1 ............................  inner envelope: penalty pushes outwards below it
//        T0 ............................  last resort: projected back out to T2
//      ~~~~~~ body surface ~~~~~~~~~~~~~
//
// Per mass point and part the collider keeps a state (OutsideVol, InsideVol, OnSurf) and the
// point's last position in the part's continuous voxel coordinates. Transitions:
//   OutsideVol -> OutsideVol   no trace: the point ends the interval outside the part's
//                              walkable box (culled per part and substep, see below)
//   OutsideVol -> In/OnSurf    trace backwards from the end until it exits: the entry voxel;
//                              then forwards from the entry
//   In/OnSurf  -> OutsideVol   the trace stops where it leaves the volume (convex box)
//   InsideVol  -> *            a walk that meets a voxel below T2 registers a collision: the
//                              point stops on T2, loses its inward normal velocity (relative
//                              to the moving part), keeps its tangential velocity reduced by
//                              Coulomb friction, and becomes OnSurf
//   OnSurf     -> OnSurf       sliding on T2: a point the part has pushed below T2 is moved
//                              back onto it, its inward velocity removed with friction;
//                              below T1 the outward relative velocity gets a penalty floor;
//                              below T0 the last-resort projection is counted
//   OnSurf     -> InsideVol    when forces carry it beyond T3
// A point that starts below T2 of a part is eased out onto T2 at a bounded speed first; one
// the garment still holds below T2 after twice the time its depth takes at that speed
// collides as any other from then on.
//
// Position corrections are gathered over all parts and applied together at the end of the
// collision step, each point moved by the mean of the displacements its parts asked for
// (Jacobi averaging): where two parts' offset surfaces overlap (cloth pinched between arm and
// chest, thigh and hips) the point settles between them instead of being pushed back and
// forth, and a point one part touches moves exactly as that part asks. A point two parts
// ask to move where their surfaces meet at an angle (a crease) moves instead by the shortest
// move outside both, to first order (pinchMove): the mean stopped it halfway, below T2 of
// each. That move is taken only where, read in both parts' fields, it ends no deeper than
// the mean would (creaseMove). Velocity responses apply part by part.
//
// Pinches between reduced-frequency tests (every > 1): the Jacobi mean leaves a point that
// two parts press from both sides off the offset surface it would take with either alone,
// and the garment pulls it back towards one of them; tested every substep, each test answers
// the pull, but between tests the cloth's forces throw it at metres per second into a part
// (traced on the walks: into a thigh from the crease of hip or knee, 2 to 3 m/s, a few
// millimetres deep by the next test). So a point two or more parts asked to move at a test is
// held by those parts until the next: each untested substep moves it by the mean of their
// rigid motions over the substep and gives it that velocity, as friction between them would
// (setPinchHold). With tests on every substep nothing is held.
//
// At the test itself a pinched point takes the mean velocity of its parts at the point. Its
// own velocity there is what the cloth's forces gave it since the last test; where the
// parts' offset surfaces overlap by more than the cloth can fit (a sleeve between arm and
// chest, an armpit pressed by three parts), every test moves the point back by millimetres
// and none takes that velocity away, so it grew from test to test with the cloth's pull
// until the run diverged (the walking dress on other walks, traced to such points).
//
// Culling (the paper's non-hierarchical boxes): once per part and collision substep, one
// vectorised pass maps every point's end position into the part's voxel coordinates (the
// part's rigid transform at t1 and the grid placement folded into one affine map) and keeps
// only the points that end inside the part's walkable box or are not OutsideVol. The others
// are exactly the OutsideVol -> OutsideVol pairs of the per-pair test, counted in bulk, so
// culling changes no state, counter or position (tested against the unculled path).
//
// Clearance (most kept pairs are InsideVol points far from the body): per part, one bit per
// voxel says that every voxel of its 3x3x3 neighbourhood lies above T2 (by at least one
// distance unit). A trilinear distance at a point whose nearest voxel is v blends only voxels
// of v's neighbourhood, so it is a convex combination of values above T2: a point whose walk
// ends in such a voxel without meeting T2 stays InsideVol without the 8-voxel read, and the
// walk itself skips the distance read of such voxels. States, positions and the collision
// counters are those of the full test (tested against it); the penetration statistics only
// miss distances above T2, which no threshold below T2 can see. A pair that stayed so keeps
// its voxel, and while it ends its tests in that voxel they are settled from the cache
// (settle): no range test, no clearance bit, no call of the per-pair test.
//
// Resting balls (most tested pairs are still InsideVol points far from the body, moving a
// little relative to their part): a pair that ends a test InsideVol, unmoved, gets a ball
// around where it ended, in the part's voxel coordinates, inside the walkable box and so far
// from T2 that no walk within it can meet a voxel below T2 and no trilinear distance within
// it is below T2 (restingRadius). While the pair ends its tests inside that ball, every walk
// of the full test (from the last test's end to this one's, both in the ball, which is
// convex) stays in it and finds nothing: the pair stays InsideVol and nothing moves. The
// cull's vector pass, which maps every point into the part anyway, leaves such pairs out
// (restingSkips). A pair that leaves its ball is tested again from where the full test would
// start its walk: the point's position at the previous test, before that test's corrections,
// mapped with the part's pose then. States, positions, velocities and every counter but the
// walked voxels (traceVoxels) and the clearance skips are those of the full test (tested
// against it).
//
// Contact planes (most of the remaining field reads are sliding pairs'): a sliding point
// moves a few hundredths of a voxel per substep relative to its part, and the field is
// fixed in the part's frame. Each sliding pair keeps its last read (distance, the trilinear
// distance's gradient, the normal) and answers its tests from it while it stays within half
// a voxel of the read (ContactPlane): the distance from the tangent plane, the normal as
// read. Collisions, first contacts and releases read the field; the planes' error against
// the field is measured in the tests. A sliding point left where it is counts in the
// penetration figures at its plane's distance (above T2, within the planes' error); a
// moved one is read where it ended.
//
// Face samples (beyond the paper; CollisionPart::faceSamples): the vertices alone collide, so
// a part bulges through a triangle larger than its curvature allows at T2 between vertices
// that all rest on it. For the parts a garment marks, each test after the vertices'
// corrections also reads the centroid of every triangle with a vertex sliding on such a part,
// and one below T2 moves its triangle out by a quarter of the depth and loses its inward
// velocity relative to the part (collideFaces says which triangles are left out, and why).

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <optional>
#include <utility>
#include <vector>

#include "drape/cloth/collider.hpp"
#include "drape/cloth/fixture.hpp"
#include "drape/cloth/voxel_walk.hpp"
#include "drape/core/stage_clock.hpp"
#include "drape/core/threads.hpp"
#include "drape/field/distance_field.hpp"

namespace drape::cloth {

/// Offset surfaces, m from the body surface.
struct OffsetSurfaces {
  double t0_m = 0.005, t1_m = 0.010, t2_m = 0.015, t3_m = 0.030;
  /// The paper's proportions for a voxel size: T0..T3 = 1, 2, 3, 6 voxels.
  [[nodiscard]] static OffsetSurfaces fromVoxelSize(double voxel_m) {
    return {voxel_m, 2 * voxel_m, 3 * voxel_m, 6 * voxel_m};
  }
  /// Throws drape::Error unless 0 <= T0 < T1 < T2 < T3; `prefix` starts the message.
  void validate(const std::string& prefix) const;
};

enum class PointState : std::uint8_t { OutsideVol = 0, InsideVol = 1, OnSurf = 2 };

/// A sliding pair's first-order picture of its part's field: the distance, its gradient and
/// the offset-surface normal read at `at` (the part's continuous voxel coordinates). The
/// field is fixed in the part's frame, so the picture never goes stale; it answers for points
/// within kReach_voxels of `at` (FieldCollider::setContactPlanes).
struct ContactPlane {
  Vec3 at = Vec3::Constant(1e30);  ///< far from everything: no plane yet
  Vec3 gradient = Vec3::Zero();    ///< of the trilinear distance, m per voxel
  Vec3 normal = Vec3::UnitZ();     ///< unit, the part's frame: the response's direction
  double distance_m = 0;

  /// How far from `at` (voxels) the plane answers for the field.
  static constexpr double kReach_voxels = 0.5;

  [[nodiscard]] bool reaches(const Vec3& c) const { return (c - at).squaredNorm() <= kReach_voxels * kReach_voxels; }
  /// The trilinear distance at c, to first order.
  [[nodiscard]] double distanceAt(const Vec3& c) const { return distance_m + gradient.dot(c - at); }
};

/// One collidable body part. The field must outlive the collider.
struct CollisionPart {
  std::string name;
  const field::DistanceField* field = nullptr;
  std::shared_ptr<const FixtureMotion> motion;  ///< the part's pose in the world at time t
  /// Beyond the paper, whose collision is vertex against body: the centroids of the
  /// garment's triangles collide with this part too (FieldCollider, face samples). Where a
  /// garment's triangles are large against the part's curvature (a pencil skirt stretched
  /// over a swinging thigh), the part bulges through them between vertices that all stay
  /// outside it. One of the first 64 parts.
  bool faceSamples = false;
};

/// The paper's Table 3 figures and ours, accumulated over the run.
struct FieldCollisionCounters {
  std::uint64_t tests = 0;          ///< (vertex, part) pairs handled, culled ones included
  std::uint64_t traces = 0;         ///< pairs whose motion was walked through the volume
  std::uint64_t traceVoxels = 0;    ///< voxel steps walked in all
  std::uint64_t collisions = 0;     ///< T2 crossings registered
  std::uint64_t projections = 0;    ///< T0 last-resort projections
  std::uint64_t vertexSubstepsBelowT1 = 0;   ///< after the response, nearest part below T1
  std::uint64_t vertexSubstepsBelowT0 = 0;
  std::uint64_t vertexSubstepsInsideBody = 0;  ///< signed distance < 0 after the response
  /// Of those below T1 and inside the body, the points two or more parts moved at the last
  /// test (a pinch: where the parts' offset surfaces overlap, no place is outside them all,
  /// and the mean of their corrections leaves the point below T1 of each; a point in a
  /// crease moves outside both, pinchMove).
  std::uint64_t vertexSubstepsBelowT1Pinched = 0;
  std::uint64_t vertexSubstepsInsideBodyPinched = 0;
  std::uint64_t vertexSubsteps = 0;            ///< vertices x collision substeps
  double maxPenetration_m = 0;      ///< deepest point below the body surface after the response
  std::uint64_t clearanceSkips = 0;  ///< pairs that stayed InsideVol without a trilinear read
  std::uint64_t restingSkips = 0;    ///< pairs left out by the cull: they ended inside their resting ball
  std::uint64_t embeddedAtStart = 0;  ///< (vertex, part) pairs below T2 at the start, eased out onto T2
  std::uint64_t embeddedTimedOut = 0;  ///< eased pairs that had not reached T2 in time and then collided as any other
  std::uint64_t planeEstimates = 0;  ///< sliding pairs' field reads answered by their contact plane
  std::uint64_t planeReads = 0;      ///< sliding pairs' field reads that went to the field
  std::uint64_t heldVertexSubsteps = 0;  ///< untested substeps of points held in a pinch (setPinchHold)
  std::uint64_t pinchedVertexTests = 0;  ///< tests at which two or more parts moved a point (setPinchHold)
  std::uint64_t creaseMoves = 0;  ///< of the points two parts moved at a test, those moved outside both (creaseMove)
  std::uint64_t creaseMovesRefused = 0;  ///< those whose crease move would have ended deeper than the mean: the mean
  std::uint64_t faceTests = 0;     ///< (triangle, part) pairs whose centroid was read (face samples)
  std::uint64_t faceContacts = 0;  ///< of those, centroids below T2: their triangle moved out
  std::uint64_t facesInsideBody = 0;  ///< of those, centroids inside the body (signed distance < 0) before the move
  std::uint64_t partsOutOfReach = 0;  ///< (test, part) pairs left out: no point could reach the part (its pairs culled)
  std::array<std::array<std::uint64_t, 3>, 3> transitions{};  ///< [from][to] PointState counts

  /// Mean voxel path per tested (vertex, part) pair: the paper's "average collision path
  /// distance" (0.166 voxels in Table 3).
  [[nodiscard]] double meanPathVoxels() const { return tests ? double(traceVoxels) / double(tests) : 0.0; }
  /// The share of sliding pairs' field reads their contact planes answered.
  [[nodiscard]] double slidingReadsFromPlanes() const {
    const std::uint64_t reads = planeEstimates + planeReads;
    return reads ? double(planeEstimates) / double(reads) : 0.0;
  }
  /// Adds another collider's counters (several garments): sums, and the deepest penetration.
  FieldCollisionCounters& operator+=(const FieldCollisionCounters& o);
};

class FieldCollider final : public Collider {
 public:
  /// `every`: run the collision test every k-th call (the paper's reduced frequency).
  FieldCollider(std::string garmentName, std::vector<CollisionPart> parts, const OffsetSurfaces& offsets,
                double staticFriction, double dynamicFriction, int every = 1);
  ~FieldCollider() override;

  /// Vertices that fixtures move (constraint masks, pins): the collider leaves them out,
  /// since the fixtures set their positions and velocities after it in every substep. They
  /// count in no test, state or penetration figure. Call before initialise.
  void setFixedVertices(const std::vector<std::uint32_t>& vertices, std::size_t vertexCount);

  /// Establishes every point's initial state against every part at time t (before the
  /// first step).
  void initialise(const ClothState& state, double t_s);

  /// Garments of at least kParallelFrom_vertices vertices split each test's pairs into
  /// ranges of kRange_vertices vertices, which run in parallel on TBB's threads.
  static constexpr std::size_t kParallelFrom_vertices = 1024;
  static constexpr std::size_t kRange_vertices = 256;
  /// Splits each test's pairs into ranges of about `rangeVertices` vertices (rounded down to
  /// a multiple of 64, at least 64) when the garment has at least `fromVertices`; else, or
  /// with rangeVertices 0, one range. Each range's pairs touch only its own vertices' data
  /// (a point meets its parts in part order, as in one range), and the ranges' counters and
  /// corrections are merged in a fixed order: states, positions and counters are the same to
  /// the bit with any ranges and any number of threads. Call before initialise.
  void setParallelRanges(std::size_t rangeVertices, std::size_t fromVertices = kParallelFrom_vertices) {
    rangeVertices_ = rangeVertices;
    parallelFrom_ = fromVertices;
  }
  /// How many ranges a test splits into (1 until initialise).
  [[nodiscard]] std::size_t ranges() const { return rangeStart_.size() - 1; }
  /// Off: every (point, part) pair goes through the full per-pair test (the reference the
  /// culled path is tested against). On by default.
  void setBoxCulling(bool on) { boxCulling_ = on; }
  /// With reduced-frequency tests (every > 1), also count the penetration figures on the
  /// substeps between tests, reading where the points are and moving none: the figures then
  /// cover every substep, at the cost of a distance read per point and part on each.
  void setCountEverySubstep(bool on) { countEverySubstep_ = on; }
  [[nodiscard]] bool countsEverySubstep() const {
    return measurePenetration_ && (countEverySubstep_ || every_ == 1);
  }
  /// The collision tests run every every() substeps.
  [[nodiscard]] int every() const { return every_; }
  /// Off: a sliding pair reads the field on every test (the reference the planes are tested
  /// against). On by default: a sliding pair reads the field where it slides and answers
  /// its next tests from that read's tangent plane while it stays within the plane's reach
  /// (ContactPlane::kReach_voxels).
  void setContactPlanes(bool on) { contactPlanes_ = on; }
  /// Off: the collider keeps no penetration figures (vertex_substeps_*, max_penetration_m,
  /// the penalty display flags): a timed run then times the collision work alone, and the
  /// figures come from another run of the same motion, which they do not change. On by
  /// default.
  void setMeasurePenetration(bool on) { measurePenetration_ = on; }
  [[nodiscard]] bool measuresPenetration() const { return measurePenetration_; }
  /// With reduced-frequency tests (every > 1): a point that two or more parts asked to move
  /// at a test (pressed from both sides, where their offset surfaces overlap: between the
  /// thighs, in the crease of hip or knee) is held by them on the substeps until the next
  /// test, moving with the mean of their rigid motions, as friction between them would hold
  /// it. At every test, with every frequency, a pinched point takes its parts' mean velocity.
  /// Off: it keeps its own velocity and moves freely between tests (the paper's collision
  /// response and reduced-frequency tests as they are), where the cloth's forces can throw
  /// it into a part before the next test. On by default.
  void setPinchHold(bool on) { pinchHold_ = on; }
  /// Off: a point two parts asked to move at a test always moves by the mean of their asks
  /// (Jacobi averaging), as before crease moves. On by default: where the two parts' offset
  /// surfaces meet at an angle, it moves outside both (pinchMove), where that ends no deeper
  /// in either part than the mean (creaseMove).
  void setCreaseMoves(bool on) { creaseMoves_ = on; }
  /// With the pinch hold on (setPinchHold); without it a pinched point moves as it would.
  [[nodiscard]] std::span<const PinchedPoint> pinched() const override {
    return pinchHold_ ? std::span<const PinchedPoint>(pinchedPoints_) : std::span<const PinchedPoint>();
  }
  /// The points held now (pinched at the last test).
  [[nodiscard]] std::size_t heldPoints() const { return held_.size(); }
  /// Off: no pair skips its distance reads through the clearance bits (nor, so, settles
  /// from a cached clear voxel), and no sliding pair counts its walk instead of walking it:
  /// the reference these shortcuts are tested against. On by default.
  void setClearanceSkip(bool on) { clearanceSkip_ = on; }
  /// Whether every voxel of the 3x3x3 neighbourhood of part k's voxel lies above T2, so that
  /// no trilinear distance nearest to it can be below T2 (false with the skip off).
  [[nodiscard]] bool clearOfT2(std::size_t k, std::uint32_t voxel) const {
    return clearanceSkip_ && ((clearOfT2_[k][voxel >> 6] >> (voxel & 63)) & 1);
  }
  /// Whether some part takes face samples (CollisionPart::faceSamples).
  [[nodiscard]] bool faceSamples() const { return faceParts_ != 0; }
  /// Off: no pair rests in a ball (the reference they are tested against). On by default.
  void setRestingBalls(bool on) { restingBalls_ = on; }
  /// The radius, in voxels, of the resting ball of a pair of part k that ends a test
  /// unmoved and InsideVol at voxel coordinates c: within it no walk meets a voxel below T2
  /// and no trilinear distance is below T2, and it lies inside the walkable box. Not
  /// positive: no ball.
  [[nodiscard]] double restingRadius(std::size_t k, const Vec3& c) const;

  [[nodiscard]] std::string name() const override { return "distance fields"; }
  void collide(const ClothModel& model, double t0_s, double t1_s, ClothState& io) override;
  [[nodiscard]] ColliderCounters counters() const override { return counters_; }
  void beginFrame() override;
  /// The counters go back to the frame's start. Every pair's state is established again
  /// from where the point is at t_s, as at the first step, except that a pair within T3 of
  /// its part slides (OnSurf) rather than being eased out (a frame's start finds most
  /// sliding points between T1 and T2): no pair rests or is settled, no point is held, and
  /// the pairs being eased out stay so.
  void restartFrame(const ClothState& state, double t_s) override;
  [[nodiscard]] const FieldCollisionCounters& fieldCounters() const { return field_; }
  /// Time spent fetching the parts' poses at the ends of each collision interval, s: the
  /// animation and its micro-interpolation when the collider is the first to ask for a time
  /// (the transforms built from the poses count as collision).
  /// Part of collide()'s time; the paper's collision share leaves it out.
  [[nodiscard]] double poseSeconds() const { return StageClock::seconds(poseTicks_); }
  /// Time spent measuring the penetration figures, s (setMeasurePenetration): part of
  /// collide()'s time, and not the collision's work.
  [[nodiscard]] double measureSeconds() const { return StageClock::seconds(measureTicks_); }
  /// Starts poseSeconds and measureSeconds again from zero (work before the frames timed).
  void resetTimes() { poseTicks_ = measureTicks_ = 0; }

  [[nodiscard]] const std::vector<CollisionPart>& parts() const { return parts_; }
  [[nodiscard]] const OffsetSurfaces& offsets() const { return offsets_; }
  [[nodiscard]] PointState state(std::size_t part, std::size_t vertex) const { return states_[part][vertex]; }
  /// The last test at which two or more parts moved `vertex` (a pinch): those parts, in part
  /// order, and how many substeps before the last one handled it came; no parts if never.
  struct LastPinch {
    std::vector<std::string> parts;
    long substepsAgo = 0;
  };
  [[nodiscard]] LastPinch lastPinch(std::size_t vertex) const;
  /// The pair's cached position in the part's voxel coordinates (where its next walk starts;
  /// for a pair resting in its ball, where the full test would start it).
  [[nodiscard]] Vec3 cachedVoxel(std::size_t part, std::size_t vertex) const;
  /// Per part, the (vertex, part) pairs being eased out onto T2 now: right after initialise,
  /// those that start below T2.
  [[nodiscard]] std::vector<std::size_t> easedPairsPerPart() const;
  /// When the last pair being eased out is due to have reached T2 or to time out (collide
  /// as any other from then on), s; nothing when no pair is being eased.
  [[nodiscard]] std::optional<double> easingEnds_s() const;
  /// Points per state now, summed over parts: [OutsideVol, InsideVol, OnSurf].
  [[nodiscard]] std::array<std::size_t, 3> pointsPerState() const;
  /// Per vertex, for display: 0 outside every volume, 1 inside a volume, 2 on a surface,
  /// 3 in the penalty zone (below T1) of some part.
  void vertexDisplayStates(std::vector<std::uint8_t>& out) const;

 private:
  struct PartFrame;  // one part's transforms over the interval (field_collider.cpp)
  /// Whether part k, at the end of this test's interval, can hold none of the points ending
  /// in the box [lo, hi] (world): every pair of it OutsideVol without a resting ball, and the
  /// box, mapped into the part's voxels and widened by a voxel, clear of its walkable box.
  /// The cull would then keep none of its pairs, which go OutsideVol -> OutsideVol untraced:
  /// leaving the part out of the test changes nothing but time (a part of another character
  /// across the room, a shin far below a cape). The pairs are read once: a part found idle
  /// stays so (idle_) while it is left out, since only its own tests change its pairs.
  [[nodiscard]] bool outOfReach(std::size_t k, const PartFrame& frame, const Vec3& lo, const Vec3& hi);
  struct PartStep;   // one part's rigid motion over an untested substep (field_collider.cpp)
  PartFrame framePart(const CollisionPart& part, const RigidTransform& pose0, const RigidTransform& pose1) const;
  /// The interval's end transforms of `frame` (framePart's, the start's left as they are).
  void framePartEnd(const CollisionPart& part, const RigidTransform& pose1, PartFrame& frame) const;
  /// What the pairs of one range of vertices add to a test: its counters and the
  /// corrections it asked for, merged after all ranges (mergeTallies).
  struct RangeTally {
    FieldCollisionCounters field;
    std::uint64_t contacts = 0;
    std::size_t kept = 0, resting = 0;  ///< pairs the cull kept, and left resting, over the parts
    std::vector<std::pair<std::uint32_t, std::uint32_t>> corrected;  ///< (part, vertex)
    std::vector<std::uint32_t> correctedPoints;
  };
  /// The ranges for a garment of `vertices` vertices (setParallelRanges), with their tallies.
  void setRanges(std::size_t vertices, std::size_t rangeVertices);
  /// One range's pairs against every part, in part order.
  void collideRange(std::size_t range, double dt_s, ClothState& io);
  /// slidingParts_ of points [first, last) from their states after the test (collideFaces).
  void markSlidingParts(std::size_t first, std::size_t last);
  /// The ranges' tallies into the collider's counters and correction lists, in range order.
  void mergeTallies(std::size_t ranges);
  /// Fills endVoxel* with the end positions of points [first, last) in part k's voxel
  /// coordinates and candidates_ from `first` on with the points the per-pair test must see;
  /// returns their number. `resting`: how many of the points rest in their balls (left out).
  std::size_t selectCandidates(std::size_t k, const PartFrame& frame, const ClothState& io, std::size_t first,
                               std::size_t last, std::size_t& resting);
  void releaseEmbedded(RangeTally& t, std::size_t k, const PartFrame& frame, std::size_t vertex,
                       const Vec3& endVoxel, double dt_s, ClothState& io);
  void collidePoint(RangeTally& t, std::size_t k, const PartFrame& frame, std::size_t vertex, const Vec3& endVoxel,
                    double dt_s, ClothState& io);
  /// collidePoint for a pair sliding on its contact plane, where the plane answers both its
  /// reads and the point neither leaves the walkable box nor T3 nor goes below T0 (most of
  /// the pairs that need a test): the same, step for step, without the rest of the per-pair
  /// test. False, with nothing changed, for any other pair. Part of the clearance skip (its
  /// walk is counted, not walked): off with it, and tested against the full test with it.
  bool slideOnPlane(RangeTally& t, std::size_t k, const PartFrame& frame, std::size_t vertex, const Vec3& endVoxel,
                    double dt_s, ClothState& io);
  /// The end of a pair's test at voxel coordinates c, with the field `at` read there: a moved
  /// point's correction (else its distance for the penetration figures), and the velocity
  /// response of a point on the surface in contact.
  void moveAndRespond(RangeTally& t, std::size_t k, const PartFrame& frame, std::size_t vertex, const Vec3& c,
                      const field::FieldSample& at, bool moved, bool onSurf, double dt_s, ClothState& io);
  /// Pair (k, vertex) ends at voxel coordinates c1 in a voxel clear of T2: InsideVol.
  void stayInside(RangeTally& t, std::size_t k, std::size_t vertex, const Vec3& c1);
  /// Pair (k, vertex), settled in its voxel by stayInside, ends in it again: the same.
  void settle(RangeTally& t, std::size_t k, std::size_t vertex, const Vec3& c1);
  /// Pair (k, vertex) is about to be tested: if it rested in its ball at the previous test,
  /// its state and cached position become the full test's; its ball is dropped either way.
  void wake(std::size_t k, std::size_t vertex);
  /// Pair (k, vertex) ended this test InsideVol and unmoved at c1: its resting ball.
  void rest(std::size_t k, std::size_t vertex, const Vec3& c1);
  /// c, where the field reads `at`, moved along the normal onto T2; a move longer than a
  /// voxel is read again where it lands and mended.
  [[nodiscard]] Vec3 ontoT2(const field::DistanceField& f, Vec3 c, field::FieldSample at) const;
  /// The field at c for sliding pair (k, vertex): from its contact plane when the plane
  /// reaches c, else read (and the plane moved there).
  [[nodiscard]] field::FieldSample slidingSample(RangeTally& t, std::size_t k, std::size_t vertex, const Vec3& c);
  /// Whether a sliding point the collider did not move is in contact with its part: at or
  /// below T2 by the read `at`. A point just moved onto T2 is in contact whatever the read
  /// there says: the read (trilinear, or the contact plane) can put it a few micrometres
  /// above T2, and then its inward velocity, which the correction did not touch, would
  /// survive every substep and grow with the forces pressing it in (at many substeps per
  /// frame, to the speed bound).
  [[nodiscard]] bool inContact(const field::FieldSample& at) const { return offsets_.t2_m - at.distance_m > -1e-12; }
  /// The velocity response of a point in contact with a part (friction, penalty floor), at
  /// voxel coordinates `voxel`, which are `world` in the world at the interval's end.
  void respondOnSurface(const PartFrame& frame, const Vec3& voxel, const Vec3& world, const field::FieldSample& at,
                        std::size_t vertex, double dt_s, ClothState& io) const;
  /// Part k asks to move the point by `displacement` (world, m) this collision step.
  void addCorrection(RangeTally& t, std::size_t k, std::size_t vertex, const Vec3& displacement);
  /// Vertex's move at this test when two parts asked it to move: pinchMove's, where it ends
  /// farther out of both parts (read in their fields) than the mean of the asks; else none.
  [[nodiscard]] std::optional<Vec3> creaseMove(std::uint32_t vertex, const ClothState& io);
  /// Moves every point by the mean of its parts' displacements.
  void applyCorrections(ClothState& io);
  /// The lists collideFaces walks, from the garment's triangles (at its first call).
  void buildFaceTopology(const ClothModel& model);
  /// The triangles' centroids against the face-sample parts their vertices slide on.
  void collideFaces(const ClothModel& model, double dt_s, ClothState& io);
  /// The penetration figures of the corrected pairs, where the points ended.
  void measureCorrected(const ClothState& io);
  /// Penetration after the response, against the nearest part (the counters of Table 3),
  /// and the penalty flags of the points below T1.
  void countPenetration();
  /// The penetration counters from nearest_ (countPenetration, countUntested).
  void countNearest();
  /// The penetration figures of an untested substep ending at t_s (setCountEverySubstep).
  void countUntested(const ClothState& io, double t_s);
  /// After a test's corrections: the points two or more parts asked to move are marked
  /// pinched (pinchedNow_) and, with the pinch hold on, take the mean of those parts'
  /// velocities at them and, with reduced-frequency tests, are held until the next
  /// (setPinchHold). dt_s: the interval the test covered.
  void collectPinches(double dt_s, ClothState& io);
  /// On an untested substep t0 -> t1: the held points move with their parts.
  void holdPinches(double t0_s, double t1_s, ClothState& io);

  std::string garment_;
  std::vector<CollisionPart> parts_;
  OffsetSurfaces offsets_;
  double staticFriction_, dynamicFriction_;
  int every_;
  bool boxCulling_ = true;
  bool countEverySubstep_ = false;
  bool clearanceSkip_ = true;
  bool contactPlanes_ = true;
  bool measurePenetration_ = true;
  bool pinchHold_ = true;
  bool creaseMoves_ = true;
  bool restingBalls_ = true;
  std::uint64_t faceParts_ = 0;  ///< bit k: part k takes face samples
  long calls_ = 0;
  long tests_ = 0;  ///< collision tests run
  /// The counters when the frame began (beginFrame), for restartFrame.
  ColliderCounters frameStartCounters_;
  FieldCollisionCounters frameStartField_;
  StageClock::Ticks poseTicks_ = 0;
  StageClock::Ticks measureTicks_ = 0;
  std::vector<PartFrame> frames_;  ///< per part, this interval's transforms (collide)
  /// The time at which frames_ end (the last test's end): a test from there reuses them.
  double framesEnd_s_ = std::numeric_limits<double>::quiet_NaN();
  /// Per part, its poses at the interval's start and end (or the untested substep's: holdPinches).
  std::vector<RigidTransform> poses_;
  double lastTime_s_ = 0;
  std::vector<std::vector<PointState>> states_;   ///< [part][vertex]
  std::vector<std::vector<Vec3>> lastVoxel_;      ///< [part][vertex], part's voxel coordinates at lastTime
  std::vector<std::vector<ContactPlane>> planes_;  ///< [part][vertex], the last field read of a sliding pair
  std::vector<std::uint8_t> penalty_;             ///< per vertex: below T1 of some part now
  /// [part][vertex]: the point started below T2 of the part and is being eased out onto it
  /// (releaseEmbedded) rather than thrown there in one substep.
  std::vector<std::vector<std::uint8_t>> embedded_;
  std::vector<std::vector<double>> easeUntil_s_;  ///< [part][vertex]: when an eased pair collides as any other
  /// Per vertex, this collision step: the sum of the displacements parts asked for (m) and
  /// their number (addCorrection); the (part, vertex) pairs that asked.
  std::vector<double> correctionX_, correctionY_, correctionZ_;
  std::vector<std::uint16_t> corrections_;
  std::vector<Vec3> firstAsk_, secondAsk_;  ///< per vertex, this test: the first two displacements asked (pinchMove)
  std::vector<std::array<std::uint16_t, 2>> askParts_;  ///< per vertex, this test: the parts that asked them
  std::vector<std::uint32_t> correctedPoints_;  ///< the points with corrections this test, each once
  std::vector<std::pair<std::uint32_t, std::uint32_t>> corrected_;
  /// Per vertex, this test: the parts it slides on, one bit each (parts < 64), and the face
  /// samples' summed displacements (m) and velocity changes (m/s) and their number.
  std::vector<std::uint64_t> slidingParts_;
  std::vector<double> faceDX_, faceDY_, faceDZ_, faceDVX_, faceDVY_, faceDVZ_;
  std::vector<std::uint16_t> faceCount_;
  /// The garment's topology for the face samples (buildFaceTopology): each vertex's
  /// triangles and its neighbours (itself included), as CSR lists; per triangle, the test
  /// that last met it.
  std::vector<std::uint32_t> vertexTrianglesStart_, vertexTriangles_, vertexRingStart_, vertexRing_;
  std::vector<long> faceStamp_;
  std::vector<std::uint8_t> free_;       ///< per vertex: 1 unless a fixture moves it (setFixedVertices)
  std::size_t freeCount_ = 0;            ///< vertices the collider tests
  /// [part][voxel / 64], bit voxel % 64: the voxel's whole 3x3x3 neighbourhood lies above
  /// T2 (walkable voxels only). Built with the collider: the fields are fixed, and so is T2.
  std::vector<std::vector<std::uint64_t>> clearOfT2_;
  /// [part][voxel / 64], bit voxel % 64: a point ending in the voxel may get a resting ball
  /// (its stored distance is far enough above T2; restingRadius reads it only then).
  std::vector<std::vector<std::uint64_t>> restable_;
  // Per-substep scratch, sized by initialise (the step does not allocate).
  std::vector<double> endVoxelX_, endVoxelY_, endVoxelZ_;  ///< per vertex, the current part's voxel coordinates
  std::vector<std::uint8_t> keep_;                ///< per vertex: the current part must test it
  /// Per part, at this test: out of the garment's reach (outOfReach), its pairs left as they are.
  std::vector<std::uint8_t> outOfReach_;
  /// Per part: every pair found OutsideVol without a ball by outOfReach, and the part left out
  /// of every test since (cleared when it is tested, and by initialise, restartFrame and
  /// setFixedVertices).
  std::vector<std::uint8_t> idle_;
  std::vector<std::uint32_t> candidates_;         ///< the vertices kept, ascending, each range's from its first
  std::size_t rangeVertices_ = kRange_vertices;   ///< setParallelRanges
  std::size_t parallelFrom_ = kParallelFrom_vertices;
  std::vector<std::uint32_t> rangeStart_{0, 0};   ///< the ranges' first vertices, and the vertex count
  std::vector<RangeTally> tallies_;               ///< per range
  PieceLoop rangeLoop_;                           ///< runs the ranges, each on the thread it had last
  /// [part][vertex]: the voxel in which the pair's last test found it staying InsideVol,
  /// clear of T2 (stayInside); kNotSettled otherwise.
  std::vector<std::vector<Vec3i>> settledVoxel_;
  /// [part][vertex]: the pair's resting ball (centre in voxel coordinates, squared radius;
  /// negative: none) and the test that set it (rest).
  std::vector<std::vector<double>> ballX_, ballY_, ballZ_, ballR2_;
  std::vector<std::vector<long>> ballTest_;
  /// Per vertex, m: the point's position at the last test, before its corrections (where a
  /// resting pair's full test would start its next walk).
  std::vector<double> testX_, testY_, testZ_;
  std::vector<double> nextTestX_, nextTestY_, nextTestZ_;  ///< scratch: this test's, until it ends
  static inline const Vec3i kNotSettled = Vec3i::Constant(-1000000);
  std::vector<double> nearest_;                   ///< per vertex, m: distance to the nearest part after the response
  /// A point held in a pinch: its parts are heldParts_[firstPart, firstPart + partCount).
  struct HeldPoint {
    std::uint32_t vertex = 0, firstPart = 0, partCount = 0;
    Vec3 at = Vec3::Zero();  ///< world, m: where it is held now
  };
  std::vector<HeldPoint> held_;
  std::vector<std::uint32_t> heldParts_;
  std::vector<std::uint8_t> holds_;   ///< per part: some held point is held by it
  std::vector<PartStep> steps_;       ///< per part: its motion over the current untested substep
  std::vector<std::uint8_t> askers_;  ///< per vertex, scratch: how many parts asked to move it this test
  std::vector<long> pinchCall_;             ///< per vertex: the call (calls_) of its last pinch, -1 if none
  std::vector<std::uint64_t> pinchParts_;   ///< per vertex: the parts of that pinch, one bit each (parts < 64)
  /// Per vertex: two or more parts moved it at the last test (whether or not they hold it),
  /// for the penetration counters; pinchedPoints_ lists the set ones.
  std::vector<std::uint8_t> pinchedNow_;
  std::vector<PinchedPoint> pinchedPoints_;
  std::vector<Vec3> partVelocity_;    ///< per vertex, scratch: the sum of its pinching parts' velocities there
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pinched_;  ///< scratch: (vertex, part), sorted
  ColliderCounters counters_;
  FieldCollisionCounters field_;
};

/// The entry voxel of a walk that comes from outside the volume: walking backwards from
/// `inside` (walkable) towards `outside`, the last walkable voxel before the walk leaves the
/// volume. Exposed for tests.
[[nodiscard]] Vec3i entryVoxel(const field::DistanceField& field, const Vec3i& inside, const Vec3i& outside);

/// Whether a walk may stand on voxel p: in the grid and not in its tagged border layer. The
/// border is exactly the outermost layer (voxelize tags it so), so this is a range test and
/// reads no voxel data: one cache miss less per pair. Tested against the flags.
[[nodiscard]] inline bool walkable(const field::DistanceField& field, const Vec3i& p) {
  const field::GridDims& d = field.dims();
  return p.x() >= 1 && p.y() >= 1 && p.z() >= 1 && p.x() < d.nx - 1 && p.y() < d.ny - 1 && p.z() < d.nz - 1;
}

/// How far, in multiples of the longer of two parts' asks, a crease's move may take a point
/// (pinchMove): beyond it the offset surfaces are taken to overlap.
inline constexpr double kCreaseReach = 2.0;

/// The move for a point that two parts asked to move at one test, by `a` and `b` (each onto
/// its own offset surface T2, from where the point ended the substep). Where the parts'
/// surfaces meet at an angle (a crease: the hip's crease, a thigh against the lower back's
/// side), the shortest move that puts the point outside both to first order: the projection
/// of the point onto the intersection of the half-spaces x . a / |a| >= |a| and
/// x . b / |b| >= |b|. The Jacobi mean of the asks, which the collider used alone before,
/// stops such a point halfway, below T2 (and often T1) of each. Where no such move within
/// kCreaseReach times the longer ask exists (the surfaces face each other: the thighs, a
/// cloth squeezed between two parts that overlap), no place near is outside both, and
/// nothing is returned: the mean is the compromise there.
[[nodiscard]] std::optional<Vec3> pinchMove(const Vec3& a, const Vec3& b);

/// The pinch nearest to `vertex` (on the garment as modelled, within 5 cm) in the last
/// `withinSubsteps` substeps: the pinched vertex, how far from `vertex` it is (m), its parts
/// and when; no parts if there was none.
struct NearestPinch {
  std::uint32_t vertex = 0;
  double distance_m = 0;
  FieldCollider::LastPinch pinch;
};
[[nodiscard]] NearestPinch nearestPinch(const ClothModel& model, const FieldCollider& collider, std::uint32_t vertex,
                                        long withinSubsteps);
/// pinchNear's words for a pinch nearestPinch found for `vertex`.
[[nodiscard]] std::string describePinch(const NearestPinch& near, std::uint32_t vertex);

/// For an instability report: the pinch nearest to `vertex` (on the garment as modelled,
/// within 5 cm) in the last `withinSubsteps` substeps, as "; N substeps before, vertex W, D mm
/// from it, was pressed by A, B at once (...)", or "" if there was none. The vertex that runs
/// away is often a neighbour of the pinched one, pulled by the cloth around it.
[[nodiscard]] std::string pinchNear(const ClothModel& model, const FieldCollider& collider, std::uint32_t vertex,
                                    long withinSubsteps);

}  // namespace drape::cloth
