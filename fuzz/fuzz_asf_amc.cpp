// libFuzzer target: ASF skeleton and AMC motion. The input is split at its first NUL byte:
// the ASF before it, the AMC after it (no NUL: the whole input is tried as both).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/asf_amc.hpp"
#include "drape/motion/clip_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t split = all.find('\0');
  const std::string_view asfText = split == std::string_view::npos ? all : all.substr(0, split);
  const std::string_view amcText = split == std::string_view::npos ? all : all.substr(split + 1);
  try {
    const drape::formats::AsfSkeleton asf = drape::formats::parseAsf(asfText, "fuzz.asf");
    const drape::formats::AmcMotion amc = drape::formats::parseAmc(amcText, "fuzz.amc", asf);
    (void)drape::motion::clipFromAsfAmc(asf, amc);
  } catch (const drape::Error&) {
  }
  return 0;
}
