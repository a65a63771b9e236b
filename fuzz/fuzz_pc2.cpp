// libFuzzer target: PC2 point caches (binary) as players, renderers and the glTF exporter
// read them back from a run directory.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/pc2.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)drape::formats::parsePc2(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.pc2");
  } catch (const drape::Error&) {
  }
  return 0;
}
