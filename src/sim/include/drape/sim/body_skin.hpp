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
// Display only: the simulation never reads the skin.

#include <limits>
#include <span>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/scene/avatar.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {

class BodySkin {
 public:
  /// `avatar` must have a skin; it and `fields` (the world's part fields) must outlive
  /// this. `allowance_m` is how far out of its parts' surfaces a vertex may stand: the
  /// garments' least T0, below which the collision never leaves cloth, so that the body does
  /// not show through cloth the collision keeps out.
  BodySkin(const scene::Avatar& avatar, const std::vector<PartField>& fields, double allowance_m);

  /// The skin with the joints at `jointWorld`, fitted to the parts as above.
  void pose(std::span<const RigidTransform> jointWorld, std::vector<Vec3>& out);

 private:
  struct Nearest {
    double distance_m = std::numeric_limits<double>::infinity();
    Vec3 away = Vec3::Zero();  ///< world: out of the nearest part, per metre of distance
  };
  /// The nearest of vertex v's parts to world point p, read from their fields.
  [[nodiscard]] Nearest nearestPart(std::size_t v, const Vec3& p, std::span<const RigidTransform> jointWorld) const;

  /// Per vertex, fields [first_[v], first_[v + 1]) of fieldOf_ are its parts; none: not fitted.
  std::vector<std::uint32_t> first_;
  std::vector<std::uint32_t> fieldOf_;
  std::vector<RigidTransform> toLocal_;  ///< per field, world -> the part's frame, this pose
  const scene::Avatar& avatar_;
  const std::vector<PartField>& fields_;
  double allowance_m_;
};

}  // namespace drape::sim
