// The skinned body as players draw it (sim/body_skin): on the MakeHuman body walking the
// bundled walk, skinning alone puts the hip creases centimetres out of the rigid parts the
// cloth collides with; fitted, no vertex skinned to collidable parts stands out of them by
// more than the allowance, measured here by brute force against the parts' triangles; the
// vertices it may not touch are left exactly as skinned.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "drape/mesh/closest_point.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/skinning.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/sim/body_skin.hpp"
#include "drape/sim/character_world.hpp"
#include "walk_fixture.hpp"

namespace drape::sim {
namespace {

constexpr double kAllowance = 0.005;  // the walking skirt's T0
constexpr const char* kParts[] = {"Hips", "LowerBack", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"};

using fixture::Walk;

/// The walking skirt's body, its six collidable parts' fields and its walk.
const Walk& skirtWalk() {
  static const Walk walk = fixture::loadWalk(std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh",
                                             {std::begin(kParts), std::end(kParts)}, 0.03);
  return walk;
}

/// How far world point p stands out of part f posed at `pose`: 0 inside it (the voxelized
/// inside, the field's sign), else the distance to its nearest triangle, by brute force.
double outside(const Walk& w, const PartField& f, const RigidTransform& pose, const Vec3& p) {
  const Vec3 local = pose.inverse().apply(p);
  if (f.field.containsPoint(local) && f.field.distanceAt(local) < 0.0) return 0.0;
  const mesh::TriMesh& m = w.avatar.segments[static_cast<std::size_t>(w.avatar.findSegment(f.segment))].mesh;
  double best = std::numeric_limits<double>::infinity();
  for (const mesh::Triangle& t : m.triangles)
    best = std::min(best, (mesh::closestOnTriangle(local, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]) - local)
                              .squaredNorm());
  return std::sqrt(best);
}

/// The fields of the vertex's parts, or none when one of its influences is not collidable
/// (decided here from the weights, independently of BodySkin).
std::vector<const PartField*> partsOf(const Walk& w, std::size_t v) {
  std::vector<const PartField*> parts;
  const scene::SkinnedMesh& skin = *w.avatar.skin;
  for (std::size_t k = 0; k < 4; ++k) {
    if (skin.weights[v][k] < 0.05f) continue;
    const int joint = skin.joints[v][k];
    const auto it = std::find_if(w.fields.begin(), w.fields.end(), [&](const PartField& f) { return f.joint == joint; });
    if (it == w.fields.end()) return {};
    parts.push_back(&*it);
  }
  return parts;
}

TEST(BodySkin, NoVertexStandsOutOfTheCollidablePartsBeyondTheAllowance) {
  const Walk& w = skirtWalk();
  BodySkin skin(w.avatar, w.fields, kAllowance);
  std::vector<RigidTransform> pose(w.avatar.joints.size());
  std::vector<Vec3> skinned, fitted;
  double worstSkinned = 0.0, worstFitted = 0.0;
  double worstRead = 0.0;  // over the vertices, the nearest part's distance as its field reads it
  std::size_t checked = 0, untouchedMoved = 0;
  for (std::size_t f = 10; f < w.animation.frameCount(); f += 25) {
    w.animation.evaluate(f, 0.0, pose);
    motion::poseSkin(w.avatar, pose, skinned);
    skin.pose(pose, fitted);
    ASSERT_EQ(fitted.size(), skinned.size());
    for (std::size_t v = 0; v < skinned.size(); ++v) {
      const std::vector<const PartField*> parts = partsOf(w, v);
      if (parts.empty()) {
        untouchedMoved += fitted[v] != skinned[v];
        continue;
      }
      // Where the cloth is: a vertex this far out was skinned off its parts altogether.
      double before = std::numeric_limits<double>::infinity(), after = before;
      for (const PartField* p : parts) {
        const RigidTransform& at = pose[static_cast<std::size_t>(p->joint)];
        before = std::min(before, outside(w, *p, at, skinned[v]));
        after = std::min(after, outside(w, *p, at, fitted[v]));
      }
      if (before > 0.02 + kAllowance) continue;
      worstSkinned = std::max(worstSkinned, before);
      double read = std::numeric_limits<double>::infinity();
      for (const PartField* p : parts) {
        const Vec3 local = pose[static_cast<std::size_t>(p->joint)].inverse().apply(fitted[v]);
        if (p->field.containsPoint(local)) read = std::min(read, p->field.distanceAt(local));
      }
      if (std::isfinite(read)) worstRead = std::max(worstRead, read);
      worstFitted = std::max(worstFitted, after);
      ++checked;
    }
  }
  EXPECT_EQ(untouchedMoved, 0u);
  EXPECT_GT(checked, 1000u);
  EXPECT_GT(worstSkinned, kAllowance + 0.008) << "skinning alone leaves the parts: the test would not see the fit";
  // As the collision reads the parts (their fields), the fit reaches the allowance; the
  // trilinear fields read up to about half a voxel near at creases of the cut parts, which
  // the cloth's collision sees alike.
  EXPECT_LT(worstRead, kAllowance + 0.0002);
  EXPECT_LT(worstFitted, kAllowance + 0.005) << "skinned alone: " << worstSkinned;
  std::printf("hip creases: skinned up to %.1f mm out of the parts, fitted %.1f mm exactly and %.1f mm as the fields "
              "read (allowance %.1f mm), %zu checks\n",
              1e3 * worstSkinned, 1e3 * worstFitted, 1e3 * worstRead, 1e3 * kAllowance, checked);
}

}  // namespace
}  // namespace drape::sim
