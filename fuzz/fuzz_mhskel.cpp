// libFuzzer target: MakeHuman rig JSON (.mhskel skeletons and .mhw weights).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/mhskel.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)drape::formats::parseMhskel(text, "fuzz.mhskel");
  } catch (const drape::Error&) {
  }
  try {
    (void)drape::formats::parseMhw(text, "fuzz.mhw");
  } catch (const drape::Error&) {
  }
  return 0;
}
