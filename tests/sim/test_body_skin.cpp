// The skinned body as players draw it (sim/body_skin): on the MakeHuman body walking the
// bundled walk, skinning alone puts the hip creases centimetres out of the rigid parts the
// cloth collides with; fitted, no vertex skinned to collidable parts stands out of them by
// more than the allowance, measured here by brute force against the parts' triangles; the
// vertices it may not touch are left exactly as skinned.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "drape/motion/animation.hpp"
#include "drape/motion/skinning.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/sim/body_skin.hpp"
#include "drape/sim/character_world.hpp"

namespace drape::sim {
namespace {

constexpr double kAllowance = 0.005;  // the walking skirt's T0
constexpr const char* kParts[] = {"Hips", "LowerBack", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"};

struct Walk {
  scene::Avatar avatar;
  motion::AvatarAnimation animation;
  std::vector<PartField> fields;
};

/// The walking skirt's body, its six collidable parts' fields and its walk.
const Walk& skirtWalk() {
  static const Walk walk = [] {
    scene::Avatar avatar =
        scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
    motion::MotionOptions mo;
    mo.clip.rate = 30.0;
    mo.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
    motion::AvatarAnimation animation =
        motion::loadAnimation(avatar, std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/walk.bvh", mo);
    field::FieldSettings fs;
    fs.voxelSize_m = 0.005;
    fs.shell_m = 0.03;
    std::vector<PartField> fields;
    for (const char* name : kParts) {
      const scene::Segment& s = avatar.segments[static_cast<std::size_t>(avatar.findSegment(name))];
      fields.push_back({name, s.joint, field::DistanceField::build(s.mesh, fs)});
    }
    return Walk{std::move(avatar), std::move(animation), std::move(fields)};
  }();
  return walk;
}

/// Closest point to p on triangle abc (Ericson, Real-Time Collision Detection, 5.1.5).
Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// How far world point p stands out of part f posed at `pose`: 0 inside it (the voxelized
/// inside, the field's sign), else the distance to its nearest triangle, by brute force.
double outside(const Walk& w, const PartField& f, const RigidTransform& pose, const Vec3& p) {
  const Vec3 local = pose.inverse().apply(p);
  if (f.field.containsPoint(local) && f.field.distanceAt(local) < 0.0) return 0.0;
  const mesh::TriMesh& m = w.avatar.segments[static_cast<std::size_t>(w.avatar.findSegment(f.segment))].mesh;
  double best = std::numeric_limits<double>::infinity();
  for (const mesh::Triangle& t : m.triangles)
    best = std::min(best, (closestOnTriangle(local, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]) - local)
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
