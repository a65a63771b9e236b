#pragma once
// Where a motion puts one collidable part of the body inside another.
//
// A segmented avatar driven by motion capture made on another body (other proportions,
// other shoulders) can swing a forearm through the small of the back, or press the thighs
// into each other. Cloth between two such parts has no place: each part's offset surfaces
// push it towards the other, the pinch holds it, and the rest of the garment pulls it
// apart until its triangles tear or the step goes unstable (examples/walking_dress on
// cmu_walk_delfem2). No collision response can mend motion that puts the body inside
// itself, so `drape run` looks for it before simulating and says where and when.
//
// Per ordered pair of parts (A, B), the depth at time t is the deepest of A's surface
// vertices below B's surface, read from B's distance field (the one the collision uses;
// exact to within the field's accuracy, about half a voxel). Parts whose joints are the
// same, parent and child, grandparent and grandchild (a hip's short joint between pelvis and
// thigh) or siblings meet at a joint and overlap there by construction; they are left out. Of the others, what counts is the depth beyond the pair's own at the
// avatar's rest pose (segmented bodies overlap a little where their caps meet).

#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/scene/avatar.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {

/// One pair of parts the motion puts inside each other.
struct BodyOverlap {
  std::string part;       ///< the part whose surface goes inside
  std::string into;       ///< the part it goes into
  double depth_m = 0;     ///< deepest, beyond the pair's depth at rest
  long deepestFrame = 0;  ///< where it is deepest
  long firstFrame = 0, lastFrame = 0;  ///< the first and last frame deeper than the threshold
  long frames = 0;        ///< frames deeper than the threshold
  /// Per frame 0..frames of the search, the depth beyond rest (m; 0 where not inside).
  std::vector<float> depthPerFrame;
};

/// The deepest any vertex of `surface` (m, in its part's frame, which is at `pose` in the
/// world) lies inside `into` (at `intoPose`): minus the least distance read from its field,
/// 0 when no vertex is inside. Vertices outside the field's grid are not inside.
[[nodiscard]] double overlapDepth(const mesh::TriMesh& surface, const RigidTransform& pose, const PartField& into,
                                  const RigidTransform& intoPose);

/// Whether two joints meet: the same, parent and child, grandparent and grandchild, or
/// siblings.
[[nodiscard]] bool jointsMeet(const scene::Avatar& avatar, int a, int b);

/// The pairs of `fields`' parts (not meeting at a joint) that the avatar's motion puts
/// inside each other by more than `threshold_m` beyond their depth at rest, checked at the
/// end of frames 0..frames (`frameRate_hz`), deepest first.
[[nodiscard]] std::vector<BodyOverlap> findBodyOverlaps(const scene::Avatar& avatar, const AvatarPoses& poses,
                                                        const std::vector<PartField>& fields, long frames,
                                                        double frameRate_hz, double threshold_m);

/// "LeftForeArm goes up to 23 mm into LowerBack (frames 3 to 115, 96 frames, deepest in
/// frame 40)".
[[nodiscard]] std::string describe(const BodyOverlap& overlap);

}  // namespace drape::sim
