#pragma once
// Small helpers about files, shared by the readers and the commands: names (to pick a
// reader by extension) and whole-file reads.

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

namespace drape {

/// The extension of `path` with its dot, in lower case (".glb" for "Walk.GLB"; "" for none).
[[nodiscard]] inline std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

/// The bytes of the file at `path`; nothing when it cannot be opened.
[[nodiscard]] inline std::optional<std::string> readFileText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace drape
