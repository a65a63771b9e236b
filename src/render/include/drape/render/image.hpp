#pragma once
// RGB images read back from the renderer, PNG files and contact sheets.

#include <cstdint>
#include <string>
#include <vector>

namespace drape::render {

/// 8-bit RGB, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  ///< width * height * 3 bytes

  [[nodiscard]] const std::uint8_t* pixel(int x, int y) const {
    return rgb.data() +
           (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3;
  }
  [[nodiscard]] std::uint8_t* pixel(int x, int y) {
    return rgb.data() +
           (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x)) * 3;
  }
};

/// Writes a PNG; throws drape::Error naming the path when it cannot be written.
void writePng(const std::string& path, const Image& image);
/// Reads a PNG as RGB; throws drape::Error naming the path on a missing or bad file.
[[nodiscard]] Image readPng(const std::string& path);

}  // namespace drape::render
