#pragma once
// The avatar's skinned mesh in a pose: linear blend skinning with the joints' world rigid
// transforms. What players and exporters draw the body with; the collision sees only the
// rigid segments (scene/avatar.hpp), so this runs once per output frame, not per substep.

#include <span>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/scene/avatar.hpp"

namespace drape::motion {

/// World positions of `avatar.skin` with every joint j at `jointWorld[j]` (joint frame ->
/// world, as AvatarAnimation::evaluate writes): p = sum_k w_k (J_k R_k^-1) p_rest, with R_k
/// joint k's rest transform. `out` is resized to the skin's vertex count. The rest pose
/// gives the rest positions back (to rounding). Throws drape::Error when the avatar has no
/// skin or the span does not hold one transform per joint.
void poseSkin(const scene::Avatar& avatar, std::span<const RigidTransform> jointWorld, std::vector<Vec3>& out);

/// The same for another skinned mesh over the avatar's joints (its drawn meshes,
/// Avatar::drawnSkin).
void poseSkin(const scene::Avatar& avatar, const scene::SkinnedMesh& skin, std::span<const RigidTransform> jointWorld,
              std::vector<Vec3>& out);

}  // namespace drape::motion
