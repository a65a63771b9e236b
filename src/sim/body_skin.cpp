#include "drape/sim/body_skin.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/motion/skinning.hpp"

namespace drape::sim {
namespace {

/// Influences lighter than this do not decide whether a vertex is fitted: skinning tools
/// leave small weights on joints far along the chain.
constexpr float kLeastWeight = 0.05f;
/// Steps of the fit per vertex (BodySkin::pose).
constexpr int kSteps = 8;

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
  }
}

void BodySkin::pose(std::span<const RigidTransform> jointWorld, std::vector<Vec3>& out) {
  motion::poseSkin(avatar_, jointWorld, out);
  toLocal_.resize(fields_.size());
  for (std::size_t f = 0; f < fields_.size(); ++f)
    toLocal_[f] = jointWorld[static_cast<std::size_t>(fields_[f].joint)].inverse();
  for (std::size_t v = 0; v + 1 < first_.size(); ++v) {
    if (first_[v] == first_[v + 1]) continue;
    // Steps towards the nearest part by the excess; where the field bends (a crease between
    // two parts, the nearest part changing) one step falls short, so repeat.
    for (int step = 0; step < kSteps; ++step) {
      const Nearest n = nearestPart(v, out[v], jointWorld);
      if (!(n.distance_m > allowance_m_) || !std::isfinite(n.distance_m)) break;
      out[v] -= (n.distance_m - allowance_m_) * n.away;
    }
  }
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
    // A Newton step on the trilinear distance: the gradient, over its squared length, so
    // that one step meets the allowance where the field is linear. Where the gradient
    // vanishes (the blend's flat middle), the offset-surface normal.
    const field::FieldJet jet = part.field.jetAtVoxel(part.field.toVoxel(local));
    const Vec3 g = jet.gradient / part.field.voxelSize();
    const Vec3 step = g.squaredNorm() > 0.25 ? Vec3(g / g.squaredNorm()) : jet.sample.normal;
    n.distance_m = at.distance_m;
    n.away = jointWorld[static_cast<std::size_t>(part.joint)].rotation * step;
  }
  return n;
}

}  // namespace drape::sim
