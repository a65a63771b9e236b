// libFuzzer target: BVH text through the reader and the clip conversion (units guess,
// standing up a body lying along another axis, T-pose test, resampling); a clip whose
// skeleton is humanoid by its shape then retargeted onto the bundled MakeHuman body through
// the joint map found by shape; and the text as a live source sends it (anim-server --live):
// the header up to its "Frame Time:" line, then a frame a line. Any drape::Error is a
// correct answer; a crash is a bug.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "drape/core/error.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/motion/animation.hpp"
#include "drape/motion/clip_io.hpp"
#include "drape/motion/jointmap.hpp"
#include "drape/scene/avatar_gltf.hpp"

namespace {

void readAsStream(std::string_view text) {
  std::size_t at = drape::formats::bvhHeaderLength(text).value_or(text.size());
  const drape::formats::BvhFile head = drape::formats::parseBvhHeader(text.substr(0, at), "stream");
  int line = static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
  const auto nextLine = [&](std::string_view& out) {
    if (at >= text.size()) return false;
    const std::size_t end = std::min(text.find('\n', at), text.size());
    out = text.substr(at, end - at);
    at = end + 1;
    ++line;
    return true;
  };
  std::string_view l;
  std::vector<double> values(head.channelCount);
  while (nextLine(l)) {
    try {
      drape::formats::parseBvhFrameLine(l, "stream", line, values);
    } catch (const drape::Error&) {
    }
  }
}

/// The body a capture drives, loaded once (the MakeHuman rig the examples walk).
const drape::scene::Avatar& body() {
  static const drape::scene::Avatar avatar =
      drape::scene::loadAvatarFile(DRAPE_SOURCE_DIR "/data/avatars/makehuman_rig_cmu_mb.mhskel");
  return avatar;
}

void retargetByShape(const drape::motion::Clip& clip) {
  const std::optional<drape::motion::JointMap> map = drape::motion::shapeJointMap(clip.skeleton, body());
  if (map) (void)drape::motion::AvatarAnimation::build(body(), clip, *map);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const drape::formats::BvhFile bvh = drape::formats::parseBvh(text, "fuzz.bvh");
    retargetByShape(drape::motion::clipFromBvh(bvh));
  } catch (const drape::Error&) {
  }
  try {
    readAsStream(text);
  } catch (const drape::Error&) {
  }
  return 0;
}
