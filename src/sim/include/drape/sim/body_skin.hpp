#pragma once
// The avatar's skinned body as players draw it, kept to what the cloth collides with.
//
// The cloth collides with rigid segments (paper section 4.2), cut from the skinned mesh at
// rest. Posed by linear blend skinning, the smooth mesh leaves those segments near the
// joints: at a flexed hip the skin bulges up to a few centimetres out of both the pelvis and
// the thigh, through cloth that rests correctly on the segments' offset surfaces. So each
// posed vertex whose influences all have a distance field (collidable parts) and which
// stands out of the nearest of them by more than an allowance is drawn back to the
// allowance, by Newton steps on that field's distance. Vertices skinned to parts the cloth
// does not collide with, and skin that sinks into the segments (which hides nothing), are
// left as skinned. The fields' reads are the measure, as they are the collision's.
//
// Fitted, the skin still shows through cloth that lies correctly outside the parts where
// the parts meet in a crease (the front of a flexed hip, between the pelvis and the thigh):
// the skin's vertices sit in the crease, but its triangles, centimetres across, span it
// and stand out of it, and the cloth lies in it, clear of both parts. So, given the
// garments, each skin triangle nearest a point of the cloth that the cloth stands less
// than a margin outside of is pushed in under it, along its vertices' normals ("tucked").
// Only where the cloth is outside every part's field (the collision's own verdict): cloth
// the collision let into the body is left showing the body through it, as it is. And only
// skin skinned to collidable parts for at least half its weight: a hand resting on a skirt
// is not pushed into itself.
//
// Display only: the simulation never reads the skin.

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/scene/avatar.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {

/// A garment as the skin is tucked under it: where its vertices are this frame.
struct GarmentSurface {
  std::span<const Vec3> positions;
  std::span<const mesh::Triangle> triangles;
};

class BodySkin {
 public:
  /// `avatar` must have a skin; it and `fields` (the world's part fields) must outlive
  /// this. `allowance_m` is how far out of its parts' surfaces a vertex may stand: the
  /// garments' least T0, below which the collision never leaves cloth, so that the body does
  /// not show through cloth the collision keeps out.
  BodySkin(const scene::Avatar& avatar, const std::vector<PartField>& fields, double allowance_m);

  /// The skin with the joints at `jointWorld`, fitted to the parts as above, and tucked
  /// under `garments` (where they are at the same time).
  void pose(std::span<const RigidTransform> jointWorld, std::span<const GarmentSurface> garments,
            std::vector<Vec3>& out);
  /// Fitted only (no garments to tuck under).
  void pose(std::span<const RigidTransform> jointWorld, std::vector<Vec3>& out) { pose(jointWorld, {}, out); }

  /// How far out of the cloth the skin is tucked: the cloth stands at least this much out of
  /// the skin at the points of it the tuck looks at (its vertices, and the centroids of
  /// each triangle split into pieces no longer than kTuckSpacing_m).
  static constexpr double kTuckMargin_m = 0.002;
  static constexpr double kTuckSpacing_m = 0.04;
  /// The most a vertex of the skin is pushed in; cloth further into the skin is left showing it.
  static constexpr double kTuckMost_m = 0.04;

 private:
  struct Nearest {
    double distance_m = std::numeric_limits<double>::infinity();
    Vec3 away = Vec3::Zero();  ///< world: out of the nearest part, per metre of distance
  };
  /// The nearest of vertex v's parts to world point p, read from their fields.
  [[nodiscard]] Nearest nearestPart(std::size_t v, const Vec3& p, std::span<const RigidTransform> jointWorld) const;

  void buildRings();
  void fit(std::vector<Vec3>& out, std::span<const RigidTransform> jointWorld);
  /// The points of the cloth the tuck looks at, into samples_ (all active).
  void sampleGarments(std::span<const GarmentSurface> garments);
  /// One pass of the tuck over the active samples; false when nothing was pushed.
  bool tuck(std::vector<Vec3>& out);
  /// What cloth point p asks of the skin: how far in the skin must go under it (negative:
  /// p stands that much further out than the margin; -infinity: no skin within reach), the
  /// skin triangle nearest p, and whether that triangle is to be pushed in by the depth.
  struct Ask {
    double depth = 0.0;
    std::uint32_t face = 0;
    bool push = false;
  };
  [[nodiscard]] Ask tuckUnder(const Vec3& p, const std::vector<Vec3>& out) const;
  void buildGrid(const std::vector<Vec3>& out);
  /// The tuckable vertex nearest p within a grid cell's reach, or -1.
  [[nodiscard]] std::int64_t nearestTuckable(const Vec3& p) const;
  /// Whether p is outside every part, as the fields read (outside a field's grid is outside).
  [[nodiscard]] bool outsideTheParts(const Vec3& p) const;

  /// Per vertex, fields [first_[v], first_[v + 1]) of fieldOf_ are its parts; none: not fitted.
  std::vector<std::uint32_t> first_;
  std::vector<std::uint32_t> fieldOf_;
  std::vector<RigidTransform> toLocal_;  ///< per field, world -> the part's frame, this pose
  /// Per vertex: skinned to collidable parts for at least half its weight, so it may be
  /// tucked (a hand resting on a skirt is not pushed into itself).
  std::vector<std::uint8_t> tuckable_;
  /// Per vertex, its triangles: [ringFirst_[v], ringFirst_[v + 1]) of ring_.
  std::vector<std::uint32_t> ringFirst_;
  std::vector<std::uint32_t> ring_;
  // Per pose, reused: vertex normals, pushes, and a grid of the tuckable vertices.
  std::vector<Vec3> normals_;
  std::vector<double> push_;            ///< per vertex, this pass
  std::vector<double> pushed_;          ///< per vertex, so far this pose
  std::vector<Vec3> samples_;           ///< points of the cloth
  std::vector<std::uint8_t> used_;      ///< per garment vertex: in a triangle
  std::vector<std::uint32_t> active_;  ///< the samples a pass looks at
  std::vector<Ask> asks_;               ///< per active sample, this pass
  std::vector<std::uint32_t> cellFirst_, cellVertices_, cellNext_;
  std::vector<double> cellX_, cellY_, cellZ_;  ///< the vertices' positions in cell order
  Vec3 gridOrigin_ = Vec3::Zero();
  std::array<std::int64_t, 3> gridDims_{0, 0, 0};
  const scene::Avatar& avatar_;
  const std::vector<PartField>& fields_;
  double allowance_m_;
};

}  // namespace drape::sim
