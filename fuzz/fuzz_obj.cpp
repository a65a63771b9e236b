// libFuzzer target: Wavefront OBJ text through drape's vertex-line check, tinyobjloader
// (not instrumented: coverage guides drape's side) and the mesh build, once keeping every
// vertex, once keeping only group "body" with unused vertices dropped (the renumbering), and
// once the groups two shell patterns match (an unmatched one lists the file's groups).

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "drape/core/error.hpp"
#include "drape/formats/obj.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    (void)drape::formats::parseObj(text, "fuzz.obj", {});
  } catch (const drape::Error&) {
  }
  drape::formats::ObjReadOptions bodyOnly;
  bodyOnly.metresPerUnit = 0.1;
  bodyOnly.groups = {"body"};
  bodyOnly.keepUnusedVertices = false;
  try {
    (void)drape::formats::parseObj(text, "fuzz.obj", bodyOnly);
  } catch (const drape::Error&) {
  }
  drape::formats::ObjReadOptions byPattern;
  byPattern.groups = {"b*", "[!b]?*"};
  try {
    (void)drape::formats::parseObj(text, "fuzz.obj", byPattern);
  } catch (const drape::Error&) {
  }
  return 0;
}
