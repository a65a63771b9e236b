// libFuzzer target: BVH text through the reader and the clip conversion (units guess,
// T-pose test, resampling). Any drape::Error is a correct answer; a crash is a bug.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/motion/clip_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const drape::formats::BvhFile bvh =
        drape::formats::parseBvh(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.bvh");
    (void)drape::motion::clipFromBvh(bvh);
  } catch (const drape::Error&) {
  }
  return 0;
}
