#include "drape/motion/skinning.hpp"

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::motion {

void poseSkin(const scene::Avatar& avatar, std::span<const RigidTransform> jointWorld, std::vector<Vec3>& out) {
  if (!avatar.skin) throw Error(fmt::format("{}: the avatar has no skinned mesh to pose", avatar.source));
  poseSkin(avatar, *avatar.skin, jointWorld, out);
}

void poseSkin(const scene::Avatar& avatar, const scene::SkinnedMesh& skin, std::span<const RigidTransform> jointWorld,
              std::vector<Vec3>& out) {
  if (jointWorld.size() != avatar.joints.size())
    throw Error(fmt::format("{}: {} joint transforms for an avatar of {} joints", avatar.source, jointWorld.size(),
                            avatar.joints.size()));
  // Rest world -> posed world per joint, as a matrix and an offset: one product per weight.
  std::vector<Mat3> linear(avatar.joints.size());
  std::vector<Vec3> offset(avatar.joints.size());
  for (std::size_t j = 0; j < avatar.joints.size(); ++j) {
    const RigidTransform m = jointWorld[j] * avatar.joints[j].restWorld().inverse();
    linear[j] = m.rotation.toRotationMatrix();
    offset[j] = m.translation;
  }
  const std::size_t n = skin.mesh.positions.size();
  out.resize(n);
  for (std::size_t v = 0; v < n; ++v) {
    const Vec3& p = skin.mesh.positions[v];
    Vec3 sum = Vec3::Zero();
    for (std::size_t k = 0; k < 4; ++k) {
      const double w = skin.weights[v][k];
      if (w == 0.0) continue;
      const std::size_t j = skin.joints[v][k];
      sum += w * (linear[j] * p + offset[j]);
    }
    out[v] = sum;
  }
}

}  // namespace drape::motion
