// libFuzzer target: a run directory's manifest.json, which `drape play`, `render` and
// `export` read from any directory they are given.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/run_manifest.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)drape::formats::parseRunManifest(std::string_view(reinterpret_cast<const char*>(data), size), "manifest.json");
  } catch (const drape::Error&) {
  }
  return 0;
}
