// The skinned body as players draw it (sim/body_skin): on the MakeHuman body walking the
// bundled walk, skinning alone puts the hip creases centimetres out of the rigid parts the
// cloth collides with; fitted, no vertex skinned to collidable parts stands out of them by
// more than the allowance, measured here by brute force against the parts' triangles; the
// vertices it may not touch are left exactly as skinned.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <tbb/global_control.h>

#include "drape/field/shapes.hpp"
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

TEST(BodySkin, TheSameOnOneThreadAsOnSeveral) {
  // The fit and the tuck's reads run in parallel; the result may not depend on it. Cloth:
  // the fitted skin itself from the waist to the knees, 1 mm out along its normals (inside
  // the tuck's 2 mm margin), thousands of points for the tuck to look at.
  const Walk& w = skirtWalk();
  std::vector<RigidTransform> pose(w.avatar.joints.size());
  w.animation.evaluate(60, 0.0, pose);
  BodySkin fitter(w.avatar, w.fields, kAllowance);
  std::vector<Vec3> fitted;
  fitter.pose(pose, fitted);
  const std::vector<mesh::Triangle>& triangles = w.avatar.skin->mesh.triangles;
  std::vector<Vec3> normals;
  mesh::vertexNormals(fitted, triangles, normals);
  mesh::TriMesh cloth;
  for (std::size_t v = 0; v < fitted.size(); ++v) cloth.positions.push_back(fitted[v] + 0.001 * normals[v]);
  const double waist = pose[0].translation.y() + 0.1, knees = waist - 0.55;
  for (const mesh::Triangle& t : triangles)
    if (std::all_of(t.begin(), t.end(), [&](std::uint32_t v) { return fitted[v].y() < waist && fitted[v].y() > knees; }))
      cloth.triangles.push_back(t);
  ASSERT_GT(cloth.triangles.size(), 3000u);
  const GarmentSurface garment{cloth.positions, cloth.triangles};
  const auto tucked = [&] {
    BodySkin skin(w.avatar, w.fields, kAllowance);
    std::vector<Vec3> out;
    skin.pose(pose, std::span(&garment, 1), out);
    return out;
  };
  std::vector<Vec3> serial;
  {
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    serial = tucked();
  }
  for (int run = 0; run < 3; ++run) {  // a race shows in some runs only
    const std::vector<Vec3> parallel = tucked();
    ASSERT_EQ(parallel.size(), serial.size());
    for (std::size_t v = 0; v < serial.size(); ++v) ASSERT_EQ(parallel[v], serial[v]) << "vertex " << v << ", run " << run;
  }
  std::size_t pushed = 0;
  for (std::size_t v = 0; v < serial.size(); ++v) pushed += serial[v] != fitted[v];
  EXPECT_GT(pushed, 500u) << "the tuck must have work to do for the comparison to mean anything";
}

// The tuck on concentric spheres, where every distance is known: a part of radius 5 cm, a
// skin of radius 7 cm around it (standing out of the part by 2 cm, within the allowance
// given, so the fit leaves it: the skin over a crease), and cloth caps of other radii.
struct Spheres {
  static constexpr double kPart = 0.05, kSkin = 0.07;
  scene::Avatar avatar;
  std::vector<PartField> fields;

  /// `skinnedToThePart`: the skin's weights on the part's joint, or on a joint without a field.
  explicit Spheres(bool skinnedToThePart) {
    avatar.name = avatar.source = "spheres";
    avatar.joints = {scene::Joint{"part", -1}, scene::Joint{"other", 0}};
    scene::SkinnedMesh skin;
    skin.mesh = field::makeSphere(kSkin, Vec3::Zero(), 32, 16);  // 1.4 cm triangles, as MakeHuman's
    const std::uint16_t joint = skinnedToThePart ? 0 : 1;
    skin.joints.assign(skin.mesh.vertexCount(), {joint, 0, 0, 0});
    skin.weights.assign(skin.mesh.vertexCount(), {1.0f, 0.0f, 0.0f, 0.0f});
    avatar.skin = std::move(skin);
    field::FieldSettings fs;
    fs.voxelSize_m = 0.005;
    fs.shell_m = 0.03;
    fields.push_back({"part", 0, field::DistanceField::build(field::makeSphere(kPart, Vec3::Zero(), 64, 32), fs)});
  }

  /// The skin, fitted (allowance 3 cm: it stays) and tucked under a cap of cloth of radius
  /// r over the top (y above 2 cm).
  [[nodiscard]] std::vector<Vec3> tuckedUnder(double r, mesh::TriMesh& cap) const {
    const mesh::TriMesh ball = field::makeSphere(r, Vec3::Zero(), 64, 32);  // finer than the skin
    cap.positions = ball.positions;
    cap.triangles.clear();
    for (const mesh::Triangle& t : ball.triangles)
      if (ball.positions[t[0]].y() > 0.02 && ball.positions[t[1]].y() > 0.02 && ball.positions[t[2]].y() > 0.02)
        cap.triangles.push_back(t);
    BodySkin skin(avatar, fields, 0.03);
    const std::vector<RigidTransform> pose(2, RigidTransform::identity());
    const GarmentSurface garment{cap.positions, cap.triangles};
    std::vector<Vec3> out;
    skin.pose(pose, std::span(&garment, 1), out);
    return out;
  }
};

TEST(BodySkin, IsTuckedUnderClothThatIsOutsideThePartsButInsideTheSkin) {
  const Spheres spheres(true);
  mesh::TriMesh cap;
  const std::vector<Vec3> tucked = spheres.tuckedUnder(0.065, cap);  // 5 mm into the skin, 15 mm out of the part
  const std::vector<Vec3>& rest = spheres.avatar.skin->mesh.positions;
  const std::vector<Vec3> normals = spheres.avatar.skin->mesh.vertexNormals();
  std::size_t under = 0, away = 0;
  for (std::size_t v = 0; v < rest.size(); ++v) {
    const double height = rest[v].y() / Spheres::kSkin;
    // Well under the cap (its edge is at 0.02 / 0.065 = 0.31), and off the pole, where the
    // sphere's 32 thin triangles meet (no skin is made so).
    if (height > 0.4 && height < 0.9) {
      // Pushed in along its normal to 2 mm under the cloth; a little deeper where cloth
      // points near a triangle's corner push it (by up to 1.2 times the depth they need).
      const Vec3 moved = rest[v] - tucked[v];
      EXPECT_LT(tucked[v].norm(), 0.065 - BodySkin::kTuckMargin_m + 1e-4) << v << " at height " << height;
      EXPECT_GT(tucked[v].norm(), 0.065 - BodySkin::kTuckMargin_m - 4e-3) << v << " at height " << height;
      EXPECT_LT((moved.normalized() - normals[v]).norm(), 1e-9) << "along its normal";
      ++under;
    } else if (height < 0.0) {  // far from the cap
      EXPECT_EQ(tucked[v], rest[v]) << v;
      ++away;
    }
  }
  EXPECT_GT(under, 80u);
  EXPECT_GT(away, 200u);
}

TEST(BodySkin, IsNotTuckedUnderClothInsideThePartsOrSkinnedElsewhere) {
  mesh::TriMesh cap;
  // Cloth the collision let into the part: the body shows through it, as it is.
  const Spheres spheres(true);
  EXPECT_EQ(spheres.tuckedUnder(0.045, cap), spheres.avatar.skin->mesh.positions);
  // Skin skinned to a joint the cloth does not collide with (a hand on a skirt).
  const Spheres elsewhere(false);
  EXPECT_EQ(elsewhere.tuckedUnder(0.065, cap), elsewhere.avatar.skin->mesh.positions);
  // Cloth out of the skin by more than the margin.
  EXPECT_EQ(spheres.tuckedUnder(0.075, cap), spheres.avatar.skin->mesh.positions);
}

}  // namespace
}  // namespace drape::sim
