// libFuzzer target: state caches (binary) as players and renderers read them back from a
// run directory.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/state_cache.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)drape::formats::parseStateCache(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.states");
  } catch (const drape::Error&) {
  }
  return 0;
}
