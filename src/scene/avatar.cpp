#include "drape/scene/avatar.hpp"

namespace drape::scene {

void placeAvatar(Avatar& avatar, const RigidTransform& placement, double scale) {
  for (Joint& j : avatar.joints) {
    j.restCenter = placement.apply(scale * j.restCenter);
    j.restOrientation = (placement.rotation * j.restOrientation).normalized();
  }
  // Segment vertices are in their joint's frame, which the joint's orientation turns.
  for (Segment& s : avatar.segments) s.mesh.scale(scale);
  for (std::optional<SkinnedMesh>* skin : {&avatar.skin, &avatar.drawnSkin}) {
    if (!*skin) continue;
    (*skin)->mesh.scale(scale);
    (*skin)->mesh.transform(placement);
  }
}

}  // namespace drape::scene
