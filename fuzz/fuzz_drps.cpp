// libFuzzer target: the studio's frames (docs/STUDIO.md) as a cloth-server or a player reads
// them off a NATS stream, where anything may arrive. Seeds: tests/data/studio/*.drps.

#include <cstddef>
#include <cstdint>
#include <span>

#include "drape/core/error.hpp"
#include "drape/studio/messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)drape::studio::decode(std::span<const std::uint8_t>(data, size));
  } catch (const drape::Error&) {
  }
  return 0;
}
