// libFuzzer target: MakeHuman clothes fitting text (.mhclo). Any drape::Error is a correct
// answer; a crash is a bug.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/mhclo.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)drape::formats::parseMhclo(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.mhclo");
  } catch (const drape::Error&) {
  }
  return 0;
}
