#pragma once
// Small helpers about file names, shared by the readers and the commands that pick a reader
// by extension.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace drape {

/// The extension of `path` with its dot, in lower case (".glb" for "Walk.GLB"; "" for none).
[[nodiscard]] inline std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace drape
