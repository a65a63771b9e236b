#pragma once
// PC2 point caches (the format 3ds Max and Blender read): a 32-byte header
// ("POINTCACHE2\0", version 1, point count, start frame, sample rate, sample count)
// followed by float32 x y z for every point of every sample.

#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/core/math.hpp"

namespace drape::formats {

/// Streams frames to a PC2 file; the sample count in the header is fixed on close.
class Pc2Writer {
 public:
  Pc2Writer(const std::string& path, std::size_t pointCount, double startFrame = 0.0,
            double sampleRate = 1.0);
  ~Pc2Writer();
  Pc2Writer(const Pc2Writer&) = delete;
  Pc2Writer& operator=(const Pc2Writer&) = delete;

  void writeFrame(std::span<const Vec3> positions);
  /// Writes the final header; further writes are errors. Called by the destructor too.
  void close();
  [[nodiscard]] std::size_t frameCount() const { return frames_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::size_t points_;
  std::size_t frames_ = 0;
  std::vector<float> buffer_;
};

struct Pc2Cache {
  std::size_t pointCount = 0;
  double startFrame = 0.0;
  double sampleRate = 1.0;
  std::vector<std::vector<Vec3>> frames;
};

/// Parses the bytes of a PC2 file read from `name` (used in messages). Throws drape::Error
/// "name: ..." on a bad header, a truncated file, or a non-finite time or coordinate (with
/// its sample, point and byte offset: the format is binary, it has no lines).
[[nodiscard]] Pc2Cache parsePc2(std::string_view bytes, const std::string& name);
/// Reads and parses a whole PC2 file.
[[nodiscard]] Pc2Cache readPc2(const std::string& path);

}  // namespace drape::formats
