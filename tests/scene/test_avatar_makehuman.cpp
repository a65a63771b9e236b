// The MakeHuman body as a segmented avatar: cmu_mb joints where SOURCES.md measured them,
// closed segments covering every body triangle, weights folded as MakeHuman does.

#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "drape/core/error.hpp"
#include "drape/scene/avatar_makehuman.hpp"
#include "drape/scene/avatar_segment.hpp"

namespace drape::scene {
namespace {

const Avatar& makeHuman() {
  static const Avatar avatar = [] {
    MakeHumanAvatarOptions options;
    options.directory = std::string(DRAPE_DATA_DIR) + "/avatars";
    return buildMakeHumanAvatar(options);
  }();
  return avatar;
}

TEST(MakeHumanAvatar, JointsWhereTheRigPutsThem) {
  const Avatar& a = makeHuman();
  ASSERT_EQ(a.joints.size(), 31u);
  EXPECT_EQ(a.joints[0].name, "Hips");
  EXPECT_EQ(a.joints[0].parent, -1);
  for (std::size_t j = 1; j < a.joints.size(); ++j) EXPECT_LT(a.joints[j].parent, static_cast<int>(j));
  // SOURCES.md, checked positions (dm there, m here).
  EXPECT_NEAR((a.joints[static_cast<std::size_t>(a.findJoint("Hips"))].restCenter - Vec3(0, 0.0727, 0.0144)).norm(), 0.0, 1e-3);
  EXPECT_NEAR((a.joints[static_cast<std::size_t>(a.findJoint("LeftUpLeg"))].restCenter - Vec3(0.1104, 0.0486, 0.0123)).norm(), 0.0, 1e-3);
  EXPECT_NEAR((a.joints[static_cast<std::size_t>(a.findJoint("LeftLeg"))].restCenter - Vec3(0.1581, -0.3695, 0.0320)).norm(), 0.0, 1e-3);
  EXPECT_NEAR((a.joints[static_cast<std::size_t>(a.findJoint("LeftArm"))].restCenter - Vec3(0.1677, 0.5246, 0.0146)).norm(), 0.0, 1e-3);
  EXPECT_NEAR((a.joints[static_cast<std::size_t>(a.findJoint("Head"))].restCenter - Vec3(0, 0.6975, 0.0161)).norm(), 0.0, 1e-3);
}

TEST(MakeHumanAvatar, ClosedSegmentsCoverTheBody) {
  const Avatar& a = makeHuman();
  ASSERT_TRUE(a.skin.has_value());
  EXPECT_EQ(a.skin->mesh.positions.size(), 13380u);
  EXPECT_GE(a.segments.size(), 19u);
  std::size_t covered = 0;
  Avatar copy = a;
  const std::vector<int> segmentOf = segmentSkinnedAvatar(copy);
  for (int s : segmentOf) covered += s >= 0 ? 1 : 0;
  EXPECT_EQ(covered, a.skin->mesh.triangles.size());
  for (const Segment& s : a.segments) {
    EXPECT_EQ(countBoundaryEdges(s.mesh), 0u) << s.name;
    EXPECT_EQ(s.name, a.joints[static_cast<std::size_t>(s.joint)].name);
  }
  // SOURCES.md: after folding, LeftLeg's vertices lie between knee and ankle (y -0.728..-0.376 m).
  const Segment& shin = a.segments[static_cast<std::size_t>(a.findSegment("LeftLeg"))];
  const Vec3 knee = a.joints[static_cast<std::size_t>(shin.joint)].restCenter;
  for (std::size_t v = 0; v < shin.mesh.positions.size(); ++v) {
    const double y = shin.mesh.positions[v].y() + knee.y();
    EXPECT_GT(y, -0.76);
    EXPECT_LT(y, -0.35);
  }
}

/// Highest point of `segment` with its joint turned by `turn` about the joint's centre (the
/// rest of the avatar at rest), in world.
double highestTurned(const Avatar& a, const Segment& segment, const Quat& turn) {
  const RigidTransform rest = a.joints[static_cast<std::size_t>(segment.joint)].restWorld();
  const RigidTransform posed{(turn * rest.rotation).normalized(), rest.translation};
  double top = -1e9;
  for (const Vec3& p : segment.mesh.positions) top = std::max(top, posed.apply(p).y());
  return top;
}

TEST(MakeHumanAvatar, ArmsCutAtTheShouldersNoLongerRiseThroughThemAsTheyLower) {
  const Avatar& a = makeHuman();
  Avatar cut = a;
  std::size_t moved = 0;
  const std::vector<int> segmentOf = segmentSkinnedAvatar(cut, {"LeftArm", "RightArm"}, &moved);
  Avatar uncut = a;
  const std::vector<int> before = segmentSkinnedAvatar(uncut);
  ASSERT_EQ(segmentOf.size(), before.size());

  // Only arm triangles changed part, each to its shoulder, and every part is still closed.
  std::size_t changed = 0;
  for (std::size_t t = 0; t < before.size(); ++t) {
    const std::string from = uncut.segments[static_cast<std::size_t>(before[t])].name;
    const std::string to = cut.segments[static_cast<std::size_t>(segmentOf[t])].name;
    if (from == to) continue;
    ++changed;
    EXPECT_TRUE((from == "LeftArm" && to == "LeftShoulder") || (from == "RightArm" && to == "RightShoulder"))
        << from << " -> " << to;
  }
  EXPECT_EQ(changed, moved);
  EXPECT_GT(moved, 40u) << "the deltoids' tops, over the shoulder joints";
  EXPECT_EQ(cut.segments.size(), uncut.segments.size());
  for (const Segment& s : cut.segments) EXPECT_EQ(countBoundaryEdges(s.mesh), 0u) << s.name;

  // The rest pose holds the arms 45 degrees out; the walk lowers them to the sides. Turned
  // down by 40 degrees about the joint, the uncut upper arm's end behind the joint swings
  // up over the top of the shoulder: the peak the jacket used to show. Cut, it stays below.
  for (const char* side : {"Left", "Right"}) {
    const std::string arm = std::string(side) + "Arm", shoulder = std::string(side) + "Shoulder";
    const double sign = side[0] == 'L' ? 1.0 : -1.0;  // the left arm lowers turning about -z
    const Quat lower(Eigen::AngleAxisd(-sign * 40.0 * M_PI / 180.0, Vec3::UnitZ()));
    const auto top = [&](const Avatar& avatar, const std::string& part, const Quat& q) {
      return highestTurned(avatar, avatar.segments[static_cast<std::size_t>(avatar.findSegment(part))], q);
    };
    const double shoulderTop = top(uncut, shoulder, Quat::Identity());
    const double uncutArm = top(uncut, arm, lower), cutArm = top(cut, arm, lower);
    // Measured: the uncut arm 10.9 mm over the shoulder's top, the cut one 36 mm under it.
    EXPECT_GT(uncutArm, shoulderTop + 0.008) << side;
    EXPECT_LT(cutArm, top(cut, shoulder, Quat::Identity()) - 0.02) << side;
  }
}

TEST(MakeHumanAvatar, CuttingAtJointsNamesWhatItCannotCut) {
  Avatar a = makeHuman();
  const auto errorOf = [&](const std::vector<std::string>& joints) {
    try {
      segmentSkinnedAvatar(a, joints);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(errorOf({"LeftArm", "Wing"}).find("cutAtJoints names 'Wing', which is not a joint of avatar"), std::string::npos);
  EXPECT_NE(errorOf({"Hips"}).find("names 'Hips', the root joint"), std::string::npos);
  EXPECT_NE(errorOf({"LeftHandFinger1"}).find("'LeftHandFinger1', a joint without children"), std::string::npos);
  Avatar rigid = makeHuman();
  rigid.skin.reset();
  try {
    segmentSkinnedAvatar(rigid, {"LeftArm"});
    ADD_FAILURE() << "an avatar of rigid parts has no skin to cut";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("came as rigid parts, without a skinned mesh"), std::string::npos) << e.what();
  }
}

// MakeHuman's own rigs: the weights name the default rig's bones, so the default rig keeps
// them as they are and the game-engine rig folds them through its references. Either way
// every limb is a segment of its own (a rig whose weights all fell to the root would be one
// rigid block that the motion only carries along).
TEST(MakeHumanAvatar, TheDefaultAndGameEngineRigsAreSegmentedLimbByLimb) {
  for (const auto& [file, thigh, shin, forearm] :
       {std::tuple{"makehuman_rig_default.mhskel", "upperleg01.L", "lowerleg01.L", "lowerarm01.L"},
        std::tuple{"makehuman_rig_game_engine.mhskel", "thigh_l", "calf_l", "lowerarm_l"}}) {
    MakeHumanAvatarOptions options;
    options.directory = std::string(DRAPE_DATA_DIR) + "/avatars";
    options.skeletonFile = file;
    const Avatar a = buildMakeHumanAvatar(options);
    EXPECT_GE(a.segments.size(), 40u) << file;
    for (const char* part : {thigh, shin, forearm}) {
      const int s = a.findSegment(part);
      ASSERT_GE(s, 0) << file << ": no segment " << part;
      EXPECT_GT(a.segments[static_cast<std::size_t>(s)].mesh.triangleCount(), 200u) << file << ": " << part;
    }
  }
}

TEST(Segmentation, CapsAnOpenTube) {
  // A square tube open at both ends: two caps, no boundary left, outward winding kept.
  mesh::TriMesh tube;
  for (int ring = 0; ring < 2; ++ring)
    for (int k = 0; k < 4; ++k) tube.positions.emplace_back(std::cos(k * M_PI / 2), std::sin(k * M_PI / 2), ring);
  for (std::uint32_t k = 0; k < 4; ++k) {
    const std::uint32_t a = k, b = (k + 1) % 4, c = 4 + k, d = 4 + (k + 1) % 4;
    tube.triangles.push_back({a, b, d});
    tube.triangles.push_back({a, d, c});
  }
  EXPECT_EQ(countBoundaryEdges(tube), 8u);
  EXPECT_EQ(capOpenings(tube), 2u);
  EXPECT_EQ(countBoundaryEdges(tube), 0u);
  // Closed and consistently wound: the signed volume is the prism's (2 x 1 = 2) in magnitude.
  double volume = 0.0;
  for (std::size_t t = 0; t < tube.triangles.size(); ++t) {
    const auto& tri = tube.triangles[t];
    volume += tube.positions[tri[0]].dot(tube.positions[tri[1]].cross(tube.positions[tri[2]])) / 6.0;
  }
  EXPECT_NEAR(std::abs(volume), 2.0, 1e-12);
}

}  // namespace
}  // namespace drape::scene
