// The paper's scenario end to end (section 5): the bundled walking skirt over every walk in
// data/mocap. The skirt must stay out of the body: no NaN, not one vertex-substep inside
// it, fewer than 0.1 % of vertex-substeps below the inner envelope T1.

#include <gtest/gtest.h>

#include <cmath>

#include "drape/motion/animation.hpp"
#include "drape/scene/scene.hpp"
#include "drape/sim/character_world.hpp"
#include "drape/sim/scene_setup.hpp"

namespace drape::sim {
namespace {

const std::string kScene = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt/scene.wrl";

struct ScenarioResult {
  long frames = 0;
  cloth::FieldCollisionCounters counters;
  bool stable = true;
  std::string instability;
  std::size_t bound = 0;
};

ScenarioResult runScenario(const std::string& motionPath) {
  const scene::Scene sc = scene::loadScene(kScene);
  const std::unique_ptr<scene::Avatar> avatar = sceneAvatar(sc);
  EXPECT_TRUE(avatar);
  motion::MotionOptions mo;
  mo.clip.rate = sc.simulation.frameRate;
  mo.jointMapDirectory = std::string(DRAPE_SOURCE_DIR) + "/share/drape/jointmaps";
  const motion::AvatarAnimation animation = motion::loadAnimation(*avatar, motionPath, mo);
  const WorldSettings ws = toWorldSettings(sc.simulation);
  CharacterWorld world(*avatar, &animation, garmentSpecs(sc, avatar.get()), ws);

  ScenarioResult r;
  r.frames = static_cast<long>(std::ceil((ws.leadIn_s + animation.duration()) * ws.step.frameRate_hz));
  for (long f = 1; f <= r.frames; ++f) {
    if (!world.stepFrame(f)) {
      r.stable = false;
      r.instability = world.instability();
      break;
    }
  }
  r.counters = world.collider(0)->fieldCounters();
  return r;
}

class WalkingSkirt : public ::testing::TestWithParam<std::string> {};

TEST_P(WalkingSkirt, StaysOutOfTheBody) {
  const ScenarioResult r = runScenario(std::string(DRAPE_DATA_DIR) + "/mocap/" + GetParam());
  ASSERT_TRUE(r.stable) << r.instability;
  EXPECT_GT(r.frames, 60);
  EXPECT_GT(r.counters.vertexSubsteps, 0u);
  EXPECT_GT(r.counters.collisions, 0u) << "the skirt never touched the legs: the scenario tests nothing";
  EXPECT_EQ(r.counters.vertexSubstepsInsideBody, 0u) << "deepest " << r.counters.maxPenetration_m << " m";
  const double belowT1 = double(r.counters.vertexSubstepsBelowT1) / double(r.counters.vertexSubsteps);
  EXPECT_LT(belowT1, 0.001);
}

INSTANTIATE_TEST_SUITE_P(Walks, WalkingSkirt,
                         ::testing::Values("cmu_12_03_walk.bvh", "cmu_walk_delfem2.bvh", "cmu_02_02_walk_dazstyle.bvh"),
                         [](const auto& info) {
                           std::string name = info.param.substr(0, info.param.find('.'));
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
}  // namespace drape::sim
