#pragma once
// Cloth layers kept apart (beyond the paper, which collides cloth with the body only): a
// garment's own layers (self collision: a skirt folding between the legs, a jacket's hem over
// its skirt, a sleeve against the side) and the garments it is worn over (a jacket over a
// shirt, a skirt over a petticoat). Without it one layer passes through the other.
//
// Vertex against face, with a thickness h (its own layers) or a gap g (the garments below).
// At each test (every k substeps, as the body's collision) the candidate pairs are checked:
// every (vertex, triangle) pair that could come within its thickness while no vertex moves
// farther than its reach from where the list was made (at first m / 2, m = twice the larger
// of h and g), the common motion left out (a walk carries the whole skirt along without
// changing a distance). The list is made again when a vertex has moved farther: each
// triangle's corners' boxes over the interval, grown by their reach and the thickness,
// against the vertices' boxes grown by theirs, in a hashed uniform grid (arrays sized once).
// A vertex that went past its reach gets more at the next list (a swinging hem), one that
// did not gives some back. When only a few went past, the list is mended instead: they are
// anchored where they are, and their pairs and those of the triangles around them are found
// again (against every box, in one vectorised pass each). A vertex and a triangle are a
// contact when the vertex
// ends within the thickness of the triangle's face (its projection inside the triangle) on
// the side it was on at the last test, or has crossed to the other side since. Contacts are
// resolved in three Jacobi sweeps (every pair's push summed per vertex, then averaged, so the
// result does not depend on the order): the vertex and the triangle's corners move apart
// along the face normal to the thickness, shared by inverse mass and barycentric weight (the
// corners a fixture moves, and every vertex of a garment below, count as infinitely heavy);
// then the pair loses its approaching normal velocity and, by Coulomb friction with the
// material's coefficients, up to mu times that of its sliding velocity.
//
// A garment below is one way: its own solver steps it first, each frame, and here it moves
// from where it was at the frame's start to where that step left it, linearly over the frame
// (sim::stepInParallel steps garments in layers). Its vertices are tested against this
// garment's triangles and this garment's vertices against its triangles, so a coarse garment
// over a fine one holds as well as a fine one over a coarse one; only this garment moves.
//
// Left out: edge against edge (two edges crossing with no vertex over a face: rare at cloth
// resolutions, where the neighbouring vertex-face pairs catch the layers first), a vertex a
// fixture moves against its own free layers (their own vertices are tested against its
// triangles), and two garments pushing each other (the one below does not feel the one
// above). docs/PHYSICS.md says what each means for a scene.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drape/cloth/collider.hpp"
#include "drape/cloth/strain_limit.hpp"
#include "drape/core/math.hpp"

namespace drape::cloth {

/// A vertex within the thickness of a triangle's face, or through it.
struct LayerContact {
  std::uint32_t vertex = 0;
  std::uint32_t triangle = 0;
  /// +1 or -1: the side of the face (along its normal) the vertex keeps to: the one it was
  /// on at the last test.
  double side = 1.0;
  bool crossed = false;  ///< it ended on the other side
  /// Barycentric weights of its projection on the face (crossed: of where it went through).
  std::array<double, 3> weights{};
};

/// The narrow test of one pair: vertex p moving p0 -> p1 while the triangle moves t0 -> t1
/// (its corners). A contact when p1 lies less than `thickness` from the face on the side p0
/// was on and projects inside the triangle; or when p1 is on the other side (crossed) and,
/// where its distance to the plane (taken as linear over the interval) was zero, it lay in
/// the triangle as it was then, within `thickness` of its plane. None for a degenerate
/// triangle.
[[nodiscard]] std::optional<LayerContact> layerContact(const Vec3& p0, const Vec3& p1, const std::array<Vec3, 3>& t0,
                                                     const std::array<Vec3, 3>& t1, double thickness);

/// What the layer collision did so far (accumulated over calls).
struct LayerCounters {
  std::uint64_t tests = 0;       ///< substeps it tested
  std::uint64_t candidates = 0;  ///< (vertex, triangle) pairs whose boxes met
  std::uint64_t contacts = 0;    ///< pairs of its own layers within the thickness or crossed, resolved
  std::uint64_t crossings = 0;   ///< of those, crossed
  std::uint64_t contactsBelow = 0;   ///< pairs with a garment below within the gap or crossed, resolved
  std::uint64_t crossingsBelow = 0;  ///< of those, crossed
  std::uint64_t rebuilds = 0;    ///< tests that made the candidate list again
  std::uint64_t mends = 0;       ///< tests that found again the pairs of the few points past their reach

  /// Another garment's counts with these (a benchmark's sum).
  LayerCounters& operator+=(const LayerCounters& other) {
    tests += other.tests;
    candidates += other.candidates;
    contacts += other.contacts;
    crossings += other.crossings;
    contactsBelow += other.contactsBelow;
    crossingsBelow += other.crossingsBelow;
    rebuilds += other.rebuilds;
    mends += other.mends;
    return *this;
  }
};

/// The vertices of a garment that start on the other side of the garments it is worn over
/// than the rest of it (modelled partly under them): the layers keep the side they start on.
struct StartUnder {
  /// Free vertices near the garments below (within 4 gaps of a triangle, 10 cm when the
  /// body is known, more along its normal than beside it).
  std::size_t over = 0;
  std::size_t vertices = 0;  ///< of those, on the side fewer are on
  std::uint32_t deepestVertex = 0;
  double deepest_m = 0.0;  ///< its distance from the triangle it is under
};

/// The vertices liftOver moved out over the garments below.
struct LiftedOver {
  std::size_t vertices = 0;
  double largest_m = 0.0;  ///< the largest move
  std::size_t leftUnder = 0;   ///< of those starting under, too deep to move (all, when none could be)
};

class LayerCollider final : public Collider {
 public:
  /// Keeps `model`'s own layers `thickness_m` apart (0: they pass through each other; the
  /// collider then keeps it off the garments below alone), testing every `every` substeps. A
  /// vertex is never tested against the triangles around it or around its neighbours (those
  /// lie on the same sheet). Throws drape::Error naming `garment` for a negative thickness.
  LayerCollider(const ClothModel& model, std::string garment, double thickness_m, int every = 1);

  /// A garment this one is worn over, kept `gap_m` below it: its model, the name errors
  /// and counts give it, and its solver's state, which must outlive the collider and be
  /// stepped through each frame (frame_s long, frames ending at multiples of frame_s) before
  /// this garment's. Before initialise(). Throws drape::Error for a gap <= 0 or a frame
  /// length <= 0.
  void addGarmentBelow(const ClothModel& model, std::string name, const ClothState& state, double gap_m,
                       double frame_s);
  /// Vertices a fixture moves after the colliders: infinitely heavy here.
  void setFixedVertices(const std::vector<std::uint32_t>& vertices);
  /// Stitched vertices are one point of the cloth: neither is tested against the triangles
  /// around the other (which a stitch holds it among).
  void setStitches(const std::vector<Stitch>& stitches);
  /// The body the garment is worn on, as points at rest (its collidable parts; before
  /// initialise): which side of the garments below a vertex near them is over is then the
  /// side away from the body there, found up to kBodyUnderDepth_m from them, however their
  /// faces are wound. Without it, the side most of its vertices within 4 gaps of them take
  /// on each connected piece of them.
  void setBody(std::vector<Vec3> points);
  /// How far from the garments below a vertex is looked at by the body's side (setBody).
  static constexpr double kBodyUnderDepth_m = 0.1;
  /// How deep under them, in gaps, a vertex is moved out over them (liftOver); without the
  /// body, also how far from them the sides are looked at.
  static constexpr double kLiftDepthGaps = 4.0;
  /// The most one sweep of a contact's resolution moves any one point, in units of its
  /// correction (where only corners of small weight can move; docs/PHYSICS.md).
  static constexpr double kMostLever = 2.0;
  /// Where the garment starts (the sides of its first test): its rest shape unless given;
  /// the garments below where their states are now.
  void initialise(const ClothState& state);

  [[nodiscard]] std::string name() const override { return "layers"; }
  void collide(const ClothModel& model, double t0_s, double t1_s, ClothState& io) override;
  [[nodiscard]] ColliderCounters counters() const override { return counters_; }
  [[nodiscard]] const LayerCounters& layerCounters() const { return self_; }
  void beginFrame() override;
  void restartFrame(const ClothState& state, double t_s) override;

  /// Its vertices that start under the garments below, as initialise() found them.
  [[nodiscard]] const StartUnder& startUnder() const { return startUnder_; }
  /// Moves the vertices that start under the garments below (startUnder) out over them,
  /// `gap` above the triangle each is under, with no velocity, and starts them there: those
  /// within 4 gaps of it (deeper, the move would stretch its triangles across the garment
  /// below; they stay under it). Without a body (setBody), none when the faces of the
  /// garments below are not all wound one way (their sides could not be told). Those it
  /// leaves under them, and their triangles, then pass through them: kept on both sides at
  /// once, the triangles between them and the rest would be torn. How many it moved. After initialise(); startUnder() keeps what was
  /// modelled.
  std::size_t liftOver(ClothState& state);
  [[nodiscard]] const LiftedOver& liftedOver() const { return lifted_; }
  /// Whether the sides over the garments below are told by the body (setBody).
  [[nodiscard]] bool sidesFromBody() const { return !body_.empty(); }
  /// Whether the garments below go along each edge two of their faces share once each way.
  [[nodiscard]] bool belowWoundOneWay() const;
  /// Its own layers' thickness (0: not kept apart).
  [[nodiscard]] double thickness_m() const { return thickness_; }
  /// How far above the garments below it keeps (0: none below).
  [[nodiscard]] double gap_m() const { return gap_; }
  /// The garments below, in the order given.
  [[nodiscard]] const std::vector<std::string>& garmentsBelow() const { return belowNames_; }
  [[nodiscard]] int every() const { return every_; }
  /// Vertices and triangles are numbered over its own and then each garment's below, in
  /// the order given (the states findContacts and nextContacts take).
  [[nodiscard]] std::size_t vertexCount() const { return inverseMass_.size(); }
  [[nodiscard]] std::size_t triangleCount() const { return triangles_.size(); }
  /// Whether the pair is never tested (the triangle has v, or a neighbour of v, as a corner;
  /// stitched vertices are neighbours).
  [[nodiscard]] bool excluded(std::uint32_t vertex, std::uint32_t triangle) const;
  /// The thickness the pair is kept at: its own layers' for its own vertex and triangle
  /// (when not excluded and the vertex is free), the gap between one of its vertices and a
  /// triangle below, or between a vertex below and one of its triangles that can move; 0:
  /// never tested. A vertex a fixture moves is never pushed into its own free layers around
  /// it (they are tested by their own vertices against its triangles): its fixture would
  /// move it back through them at every substep.
  [[nodiscard]] double pairThickness(std::uint32_t vertex, std::uint32_t triangle) const;
  /// The contacts between positions `before` (the last test's) and `after`, as a test finds
  /// them (by vertex, then triangle), without resolving them. Both hold vertexCount() points.
  const std::vector<LayerContact>& findContacts(const ClothState& before, const ClothState& after);
  /// The contacts of the next test at positions `now` (vertexCount() points), as collide()
  /// finds them (from the candidate list, kept or made again), without resolving them; `now`
  /// is then the last test's.
  const std::vector<LayerContact>& nextContacts(const ClothState& now);

 private:
  /// A garment below: where its points start in the numbering, and where it was at the start
  /// and end of the frame being stepped.
  struct Below {
    std::string name;
    const ClothState* state = nullptr;
    std::uint32_t first = 0, count = 0;
    std::vector<double> startX, startY, startZ, endX, endY, endZ;
  };
  /// The model's triangles' edges into the mean edge length (cells are sized from it).
  void addEdgeLengths(const ClothModel& model);
  /// Sizes the per-vertex arrays, the grid and the margin for the vertices and triangles
  /// numbered so far.
  void sizeForPoints();
  /// Copies the state's positions (its own vertices, or all) as the last test's.
  void remember(const ClothState& state);
  /// The garments below, for the frame that contains time t_s: when it is a frame after the
  /// one they were held for, their end becomes its start and their states now its end (they
  /// were stepped through it first).
  void followBelow(double t_s);
  /// The garments below as they are at time t_s (linear over the frame) into positions
  /// x, y, z (numbered as here).
  void placeBelow(double t_s, std::vector<double>& x, std::vector<double>& y, std::vector<double>& z) const;
  /// Their velocities over the frame into `out`.
  void velocitiesBelow(ClothState& out) const;
  /// The thickness of a pair the list holds: its own layers' or the gap.
  [[nodiscard]] double listedThickness(std::uint32_t vertex, std::uint32_t triangle) const {
    return vertex < ownVertices_ && triangle < ownTriangles_ ? thickness_ : gap_;
  }
  /// Whether a corner of the triangle can move (a vertex below is kept off it).
  [[nodiscard]] bool triangleMoves(std::uint32_t triangle) const;
  /// Whether a corner of its own triangle passes through the garments below (leaveThrough).
  [[nodiscard]] bool passesBelow(std::uint32_t triangle) const;
  /// The vertices that start under the garments below deeper than `deeperThan` (m), which
  /// liftOver leaves there, pass through them, and so do their triangles.
  void leaveThrough(double deeperThan);
  /// The neighbour lists (sorted and made unique here) as the CSR arrays.
  void setNeighbours(std::vector<std::vector<std::uint32_t>>& around);
  void buildGrid(const ClothState& after);
  /// The pairs whose vertex's box (buildGrid's) comes within the thickness of its triangle's
  /// corners' boxes.
  void gatherPairs();
  /// The candidate pairs' contacts.
  void narrow(const ClothState& after);
  [[nodiscard]] static Vec3 meanPosition(const std::vector<double>& x, const std::vector<double>& y,
                                         const std::vector<double>& z);
  /// Whether point v is farther than its reach from where it was when the list was made, at
  /// either end of the interval to `now`, the common motion (the shifts of the mean) left out.
  [[nodiscard]] bool beyondReach(const ClothState& now, std::size_t v, const Vec3& shiftNow,
                                 const Vec3& shiftLast) const;
  void updatePairs(const ClothState& now);
  /// startUnder_ from the positions of the last test (initialise()'s).
  void findStartUnder();
  /// The root of a vertex's connected piece of the garments below (itself for its own).
  [[nodiscard]] std::uint32_t componentBelow(std::uint32_t vertex) const;
  /// The list mended for the points in moved_: anchored again and their pairs found again.
  void mendPairs(const ClothState& now, const Vec3& shiftNow, const Vec3& shiftLast);
  /// meets_[i] for i in [begin, end): whether box i of the columns boxLo, boxHi meets [lo, hi].
  void markMeeting(const double* lo, const double* hi, const std::array<std::vector<double>, 3>& boxLo,
                   const std::array<std::vector<double>, 3>& boxHi, std::uint32_t begin, std::uint32_t end);
  /// Calls visit(i) for each i in [begin, end) that markMeeting marked (in order).
  template <typename Visit>
  void forEachMet(std::uint32_t begin, std::uint32_t end, Visit&& visit) const;
  /// Triangle t's box (its corners' boxes grown by the thickness) into triangleLo_/Hi_.
  void placeTriangleBox(std::uint32_t t);
  /// The points (kOwnPoint, kPointBelow) triangle t can hold pairs with.
  [[nodiscard]] std::uint8_t pointsAccepted(std::uint32_t t) const;
  void resolvePositions(ClothState& io);
  void resolveVelocities(ClothState& io);
  void clearPushes();
  /// Adds the contact's push, `lambda` along its normal per unit of inverse mass, to its
  /// vertex and (by weight) to its triangle's corners.
  void pushApart(const LayerContact& c, const std::array<double, 4>& im, const Vec3& lambda);
  /// Moves every pushed vertex's (x, y, z) by the average of its pushes.
  void applyPushes(std::vector<double>& x, std::vector<double>& y, std::vector<double>& z) const;
  /// A contact as the state stands now: the inverse masses of its vertex and corners and
  /// their weighted sum (the constraint's), the corners, and the face normal on the vertex's
  /// side.
  struct ContactNow {
    std::array<double, 4> inverseMass{};
    double weight = 0;
    std::array<Vec3, 3> corners;
    Vec3 normal;
  };
  /// The contact at `io` into `out`; false when nothing of it can move or its triangle has
  /// collapsed.
  [[nodiscard]] bool now(const LayerContact& c, const ClothState& io, ContactNow& out) const;
  [[nodiscard]] std::uint32_t bucketOf(std::int64_t ix, std::int64_t iy, std::int64_t iz) const;
  /// The grid cell a coordinate falls in, along any axis.
  [[nodiscard]] std::int64_t cellOf(double coordinate) const;
  /// Calls visit(ix, iy, iz) for every cell the box [lo, hi] touches.
  template <typename Visit>
  void forCells(const double* lo, const double* hi, Visit&& visit) const;
  /// Calls visit(bucket) once for every bucket a cell of point v's box lies in.
  template <typename Visit>
  void forBucketsOnce(std::size_t v, Visit&& visit);
  /// Whether the box [lo, hi] touches few enough cells to be looked up cell by cell (false
  /// for a box with a coordinate that is not finite).
  [[nodiscard]] bool fitsGrid(const double* lo, const double* hi) const;
  /// Appends the pairs of triangle t (box [lo, hi]) with points listed in no grid: the
  /// points of `kinds` that are among `points`, or every point of `kinds` when `points` is null.
  void pairWithPointsOffGrid(std::uint32_t t, const double* lo, const double* hi, std::uint8_t kinds,
                             const std::vector<std::uint32_t>* points);

  std::string garment_;
  double thickness_;
  int every_;
  std::uint32_t ownVertices_ = 0, ownTriangles_ = 0;
  double gap_ = 0.0;      ///< above the garments below
  double frame_s_ = 0.0;  ///< their frames' length
  std::vector<Below> below_;
  std::vector<std::string> belowNames_;  ///< their names, in the order given
  long heldFrame_ = 0;    ///< the frame (numbered from 0 at time 0) the garments below are held for
  bool held_ = false;     ///< whether they are held for one yet
  ClothState work_;       ///< its own points and those below, for a test with garments below
  double edgeSum_ = 0.0;  ///< of the triangles' edges (cells sized from their mean)
  std::size_t edgeCount_ = 0;
  double staticFriction_, dynamicFriction_;  ///< the material's, layer on layer as on the body
  double cell_m_;                            ///< edge of a grid cell
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  std::vector<std::uint32_t> neighbourStart_, neighbours_;  ///< per vertex (CSR), sorted
  std::vector<double> inverseMass_;                         ///< 0 for the fixed vertices and those below
  std::vector<std::uint8_t> tested_;  ///< per vertex: whether it can be in a pair, and as whose (kOwnPoint, kPointBelow)
  std::vector<double> lastX_, lastY_, lastZ_;               ///< positions at the last test
  // The grids: per bucket (a hash of the cell) the points whose boxes touch a cell of it,
  // each once, with its box beside it so that a scan reads in order.
  struct PointGrid {
    std::vector<std::uint32_t> start, fill, point;  ///< per bucket: where its points start; per entry: the point
    std::vector<double> box;                         ///< per entry: lo xyz, hi xyz
  };
  std::array<std::vector<double>, 3> pointLo_, pointHi_;        ///< per axis, per point: its box in the list
  std::array<std::vector<double>, 3> triangleLo_, triangleHi_;  ///< per axis, per triangle: its box in the list
  std::array<PointGrid, 2> grids_;           ///< [0]: its own points; [1]: the points below
  /// Per grid, the points whose boxes touch too many cells to be listed in it (a point
  /// flung far by an unstable substep): every triangle that can pair with them looks at them.
  std::array<std::vector<std::uint32_t>, 2> offGrid_;
  std::uint32_t bucketMask_ = 0;
  double inverseCell_ = 1.0;
  std::vector<std::uint32_t> bucketsOfPoint_;  ///< forBucketsOnce's
  // The candidate list and where the vertices were when it was made.
  double margin_;
  std::vector<double> reach_;  ///< per point: how far it may move before the list is made again (first margin_ / 2)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs_;  ///< (vertex, triangle), by triangle then vertex
  std::vector<double> builtX_, builtY_, builtZ_;  ///< where each point was anchored, in the list's frame
  std::vector<std::uint32_t> trianglesAroundStart_, trianglesAround_;  ///< per point (CSR)
  std::vector<std::uint32_t> moved_, mendedTriangles_;  ///< a mend's points and triangles
  std::vector<std::uint8_t> mended_, triangleMended_;   ///< per point and triangle: in the mend
  std::vector<std::uint8_t> meets_;                     ///< markMeeting's
  std::vector<std::pair<std::uint32_t, std::uint32_t>> merged_;  ///< a mended list, merged
  Vec3 builtMean_ = Vec3::Zero();
  bool pairsBuilt_ = false;
  std::vector<LayerContact> contacts_;
  std::vector<double> pushX_, pushY_, pushZ_;  ///< per vertex, summed over a sweep's contacts
  std::vector<std::uint32_t> pushes_;
  std::uint64_t calls_ = 0;
  ColliderCounters counters_, frameStartCounters_;
  LayerCounters self_, frameStartSelf_;
  StartUnder startUnder_;
  /// A vertex that starts under a garment below: the triangle, its distance along the
  /// triangle's normal, and the side it is worn on.
  struct Under {
    std::uint32_t vertex, triangle;
    double along, wornSide;
  };
  std::vector<Under> under_;
  LiftedOver lifted_;
  std::vector<std::uint32_t> componentBelow_;  ///< per point: its parent in the pieces below
  std::vector<Vec3> body_;  ///< the body at rest (setBody); empty: sides by the most vertices
  std::vector<std::uint8_t> passesBelow_;  ///< per own vertex: left under the garments below, passing through them
  bool anyPassBelow_ = false;              ///< whether any does
};

}  // namespace drape::cloth
