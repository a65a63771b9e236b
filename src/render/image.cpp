#include "drape/render/image.hpp"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::render {

void writePng(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3) {
    throw Error(fmt::format("{}: image to write is empty or inconsistent", path), ExitCode::Internal);
  }
  // Level 4 instead of stb's default 8: a 1280x720 frame encodes in about 3/4 of the time
  // (drape bench render); frames for a quick look favour speed over a few percent of size.
  stbi_write_png_compression_level = 4;
  if (stbi_write_png(path.c_str(), image.width, image.height, 3, image.rgb.data(), image.width * 3) == 0) {
    throw Error(fmt::format("{}: cannot be written", path));
  }
}

Image readPng(const std::string& path) {
  int width = 0, height = 0, channels = 0;
  unsigned char* data = stbi_load(path.c_str(), &width, &height, &channels, 3);
  if (data == nullptr) throw Error(fmt::format("{}: not a readable PNG ({})", path, stbi_failure_reason()));
  Image image;
  image.width = width;
  image.height = height;
  image.rgb.assign(data, data + static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  stbi_image_free(data);
  return image;
}

}  // namespace drape::render
