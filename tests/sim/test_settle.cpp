// Settling before frame 0 (CharacterWorld::settle). The bundled walking dress is modelled
// tighter than its offset surfaces: its jacket starts inside the chest, and until the
// easing had carried it out frames 0 and 1 showed the body through it. Settled at the rest
// pose, frame 0 has no vertex inside the body and no pair left to ease; the walking skirt,
// which starts clear of its parts, is not touched.

#include <gtest/gtest.h>

#include <cmath>

#include "drape/motion/animation.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/character_world.hpp"
#include "drape/sim/scene_setup.hpp"
#include "drape/testing/examples.hpp"

namespace drape::sim {
namespace {

struct Example {
  scene::Scene scene;
  std::unique_ptr<scene::Avatar> avatar;
  motion::AvatarAnimation animation;
};

Example loadExample(const std::string& name) {
  Example e;
  e.scene = scene::loadScene(std::string(DRAPE_SOURCE_DIR) + "/examples/" + name + "/scene.wrl");
  e.avatar = sceneAvatar(e.scene);
  motion::MotionOptions mo;
  mo.clip.rate = e.scene.simulation.frameRate;
  mo.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  e.animation = motion::loadAnimation(*e.avatar, testing::kSkirtWalk, mo);
  return e;
}

std::unique_ptr<CharacterWorld> worldOf(const Example& e) {
  return std::make_unique<CharacterWorld>(*e.avatar, &e.animation, garmentSpecs(e.scene, e.avatar.get()),
                                          toWorldSettings(e.scene.simulation));
}

/// Over the free vertices of garment 0 and every part it collides with at time t: how many
/// (vertex, part) pairs have the vertex inside the part, and the deepest, m.
struct Inside {
  std::size_t pairs = 0;
  double deepest_m = 0.0;
};

Inside insideTheBody(const CharacterWorld& world, double t_s) {
  Inside r;
  const cloth::ClothState& s = world.solver(0).state();
  std::vector<std::uint8_t> fixed(s.size(), 0);
  for (const cloth::PinGroup& g : world.solver(0).pins())
    for (std::uint32_t v : g.vertices) fixed[v] = 1;
  for (const cloth::CollisionPart& part : world.collider(0)->parts()) {
    const RigidTransform pose = part.motion->poseAt(t_s);
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (fixed[i]) continue;
      const double d = part.field->distanceAt(pose.rotation.conjugate() * (s.position(i) - pose.translation));
      if (d < 0.0) {
        ++r.pairs;
        r.deepest_m = std::max(r.deepest_m, -d);
      }
    }
  }
  return r;
}

std::size_t easedPairs(const cloth::FieldCollider& collider) {
  std::size_t n = 0;
  for (std::size_t pairs : collider.easedPairsPerPart()) n += pairs;
  return n;
}

TEST(Settle, TheDressStartsOutOfTheBodyAtFrameZero) {
  const Example e = loadExample("walking_dress");
  const std::unique_ptr<CharacterWorld> world = worldOf(e);
  const Inside modelled = insideTheBody(*world, 0.0);
  const std::size_t eased = easedPairs(*world->collider(0));
  const std::optional<double> ends = world->collider(0)->easingEnds_s();
  std::printf("as modelled: %zu (vertex, part) pairs inside the body, %.1f mm deep at most; %zu pairs eased, the "
              "last due at %.3f s\n",
              modelled.pairs, 1e3 * modelled.deepest_m, eased, ends.value_or(-1.0));
  ASSERT_GT(modelled.pairs, 0u) << "the dress no longer starts inside the body: the test tests nothing";
  ASSERT_GT(eased, 0u);
  ASSERT_TRUE(ends.has_value());

  SettleReport report;
  ASSERT_TRUE(world->settle(1.0, report)) << world->instability();
  const double rate = e.scene.simulation.frameRate;
  // Whole frames covering the easing, ending at time 0.
  EXPECT_EQ(report.frames, static_cast<long>(std::ceil(*ends * rate - 1e-9)));
  EXPECT_DOUBLE_EQ(report.seconds, static_cast<double>(report.frames) / rate);
  EXPECT_EQ(report.pairsEased, eased);
  EXPECT_EQ(report.pairsLeft, 0u);
  EXPECT_EQ(easedPairs(*world->collider(0)), 0u);
  EXPECT_EQ(report.pairsTimedOut, world->collider(0)->fieldCounters().embeddedTimedOut);
  EXPECT_LT(report.pairsTimedOut, eased / 2) << "most pairs reach T2 on their own";

  const Inside settled = insideTheBody(*world, 0.0);
  std::printf("settled %ld frames: %zu pairs inside the body, %.2f mm deep at most; %zu timed out\n", report.frames,
              settled.pairs, 1e3 * settled.deepest_m, report.pairsTimedOut);
  EXPECT_EQ(settled.pairs, 0u) << settled.deepest_m << " m deep";
  // The body held its rest pose: the stage clocks started again, and the walk goes on.
  EXPECT_EQ(world->solver(0).stageTimes().forces_s, 0.0);
  for (long f = 1; f <= 3; ++f) ASSERT_TRUE(world->stepFrame(f)) << world->instability();
}

TEST(Settle, ACapShorterThanTheEasingLeavesPairsToEaseInTheRun) {
  const Example e = loadExample("walking_dress");
  const std::unique_ptr<CharacterWorld> world = worldOf(e);
  SettleReport report;
  ASSERT_TRUE(world->settle(0.05, report)) << world->instability();
  EXPECT_EQ(report.frames, 2);  // 0.05 s at 30 Hz, in whole frames
  EXPECT_GT(report.pairsLeft, 0u);
  EXPECT_EQ(report.pairsLeft, easedPairs(*world->collider(0)));
  EXPECT_LT(report.pairsLeft, report.pairsEased);
  ASSERT_TRUE(world->stepFrame(1)) << world->instability();
}

TEST(Settle, AGarmentClearOfItsPartsIsNotTouched) {
  const Example e = loadExample("walking_skirt");
  const std::unique_ptr<CharacterWorld> settled = worldOf(e);
  const std::unique_ptr<CharacterWorld> plain = worldOf(e);
  ASSERT_EQ(easedPairs(*settled->collider(0)), 0u);
  SettleReport report;
  ASSERT_TRUE(settled->settle(1.0, report));
  EXPECT_EQ(report.frames, 0);
  EXPECT_EQ(report.pairsEased, 0u);
  for (long f = 1; f <= 5; ++f) {
    ASSERT_TRUE(settled->stepFrame(f));
    ASSERT_TRUE(plain->stepFrame(f));
  }
  EXPECT_EQ(settled->solver(0).state().x, plain->solver(0).state().x);
  EXPECT_EQ(settled->solver(0).state().y, plain->solver(0).state().y);
  EXPECT_EQ(settled->solver(0).state().z, plain->solver(0).state().z);
}

TEST(Settle, NoSettlingWhenNoneIsAllowed) {
  const Example e = loadExample("walking_dress");
  const std::unique_ptr<CharacterWorld> world = worldOf(e);
  const std::size_t eased = easedPairs(*world->collider(0));
  SettleReport report;
  ASSERT_TRUE(world->settle(0.0, report));
  EXPECT_EQ(report.frames, 0);
  EXPECT_EQ(report.pairsEased, eased);
  EXPECT_EQ(easedPairs(*world->collider(0)), eased);
}

}  // namespace
}  // namespace drape::sim
