// libFuzzer target: joint name maps (JSON, `--joint-map FILE`), parsed and then checked
// against a small skeleton and avatar, as a run does with a user's map.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/motion/jointmap.hpp"

namespace {

drape::motion::Skeleton smallSkeleton() {
  drape::motion::Skeleton skeleton;
  skeleton.joints.push_back({});
  skeleton.joints.back().name = "hip";
  return skeleton;
}

drape::scene::Avatar smallAvatar() {
  drape::scene::Avatar avatar;
  avatar.name = "fuzz";
  avatar.joints.push_back({"Hips", -1, drape::Vec3::Zero(), drape::Quat::Identity()});
  return avatar;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const drape::motion::Skeleton skeleton = smallSkeleton();
  static const drape::scene::Avatar avatar = smallAvatar();
  try {
    const drape::motion::JointMap map =
        drape::motion::parseJointMap(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    (void)drape::motion::matchedJointCount(map, skeleton, avatar);
    drape::motion::checkJointMap(map, skeleton, avatar);
  } catch (const drape::Error&) {
  }
  return 0;
}
