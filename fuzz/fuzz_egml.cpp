// libFuzzer target for EGML event graphs: the VRML97 reader's whole path (pre-scan, Coin in
// the child process, the hand-over) and then the graph's own checks, from text as drape run
// --events, the anim-server and drape inject take it. Every input must end in a graph or a
// drape::Error; the motions a graph names are not loaded (a path is only text here).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/events/graph.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)drape::events::parseGraph(text, "fuzz.egml", DRAPE_SOURCE_DIR "/examples/event_graph");
  } catch (const drape::Error&) {
    // A clear message: the expected outcome for malformed input.
  }
  return 0;
}
