// Face samples on the bundled walking dress (examples/walking_dress): its pencil skirt is
// stretched over the swinging thighs in triangles larger than a thigh's curvature allows at
// T2, and with the vertices alone colliding the thighs bulge through between vertices that
// all stay outside them. The scene lets the triangles' centroids collide with the legs too
// (faceSamplesWith); here the same walk runs with and without, and the centroids inside a leg
// are counted at the end of every frame.

#include <gtest/gtest.h>

#include <cmath>

#include "drape/motion/animation.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/character_world.hpp"
#include "drape/sim/scene_setup.hpp"
#include "drape/testing/long_scenario.hpp"
#include "drape/testing/examples.hpp"

namespace drape::sim {
namespace {

struct FaceFigures {
  long frames = 0;
  std::size_t centroidsInside = 0;  ///< (triangle, frame) pairs with the centroid inside a face-sample part
  std::size_t vertexSubstepsInside = 0;
  std::uint64_t faceContacts = 0;
  std::vector<std::string> faceParts;
};

FaceFigures walk(long frames, bool faceSamples) {
  const scene::Scene sc = scene::loadScene(testing::kDressScene);
  const std::unique_ptr<scene::Avatar> avatar = sceneAvatar(sc);
  motion::MotionOptions mo;
  mo.clip.rate = sc.simulation.frameRate;
  mo.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation animation = motion::loadAnimation(*avatar, testing::kSkirtWalk, mo);
  std::vector<GarmentSpec> specs = garmentSpecs(sc, avatar.get());
  FaceFigures r;
  r.faceParts = specs.at(0).faceSamplesWith;  // the scene's, counted either way
  if (!faceSamples) specs[0].faceSamplesWith.clear();
  CharacterWorld world(*avatar, &animation, specs, toWorldSettings(sc.simulation));
  const cloth::FieldCollider& collider = *world.collider(0);
  const auto& triangles = world.solver(0).model().triangles();
  for (long f = 1; f <= frames; ++f) {
    if (!world.stepFrame(f)) {
      ADD_FAILURE() << world.instability();
      break;
    }
    r.frames = f;
    const cloth::ClothState& s = world.solver(0).state();
    const double t = world.frameTime(f);
    for (const cloth::CollisionPart& part : collider.parts()) {
      if (std::find(r.faceParts.begin(), r.faceParts.end(), part.name) == r.faceParts.end()) continue;
      const RigidTransform pose = part.motion->poseAt(t);
      for (const mesh::Triangle& tri : triangles) {
        const Vec3 centroid = (s.position(tri[0]) + s.position(tri[1]) + s.position(tri[2])) / 3.0;
        const Vec3 local = pose.rotation.conjugate() * (centroid - pose.translation);
        r.centroidsInside += part.field->distanceAt(local) < 0;
      }
    }
  }
  r.vertexSubstepsInside = collider.fieldCounters().vertexSubstepsInsideBody;
  r.faceContacts = collider.fieldCounters().faceContacts;
  return r;
}

TEST(WalkingDressFaces, TheThighsNoLongerBulgeThroughTheSkirt) {
  DRAPE_LONG_SCENARIO();
  // The lead-in (30 frames) brings the arms down; the walk's first steps follow.
  constexpr long kFrames = 45;
  const FaceFigures vertices = walk(kFrames, false);
  const FaceFigures faces = walk(kFrames, true);
  ASSERT_EQ(vertices.frames, kFrames);
  ASSERT_EQ(faces.frames, kFrames);
  EXPECT_EQ(faces.faceParts, (std::vector<std::string>{"LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"}));
  EXPECT_EQ(vertices.faceContacts, 0u);
  EXPECT_GT(faces.faceContacts, 0u);
  std::printf("centroids inside a leg over %ld frames: %zu with vertices alone, %zu with face samples\n", kFrames,
              vertices.centroidsInside, faces.centroidsInside);
  EXPECT_GT(vertices.centroidsInside, 0u) << "the legs never bulged through: the test tests nothing";
  EXPECT_LE(faces.centroidsInside * 5, vertices.centroidsInside);
  // And the vertices stay out as well as before.
  EXPECT_LE(faces.vertexSubstepsInside, vertices.vertexSubstepsInside + vertices.vertexSubstepsInside / 4 + 10);
}

}  // namespace
}  // namespace drape::sim
