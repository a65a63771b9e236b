#pragma once
// How a user names the parts of a file (a glTF node or mesh, an OBJ group, a skinned mesh
// of a character): by the name itself, or by a shell pattern (`Wolf3D_*`, `Eye?`,
// `Hair[12]`), as fnmatch(3) reads it. A name is always its own pattern, brackets and all.

#include <fnmatch.h>

#include <string>

namespace drape::formats {

/// Whether `pattern` has a character fnmatch(3) gives a meaning (`*`, `?`, `[`).
[[nodiscard]] inline bool isNamePattern(const std::string& pattern) {
  return pattern.find_first_of("*?[") != std::string::npos;
}

/// Whether `name` is `pattern`, or matches it as a shell pattern.
[[nodiscard]] inline bool nameMatches(const std::string& pattern, const std::string& name) {
  return pattern == name || (isNamePattern(pattern) && ::fnmatch(pattern.c_str(), name.c_str(), 0) == 0);
}

}  // namespace drape::formats
