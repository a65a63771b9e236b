#include "drape/formats/pc2.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::formats {
namespace {

#pragma pack(push, 1)
struct Pc2Header {
  char signature[12];
  std::int32_t version;
  std::int32_t numPoints;
  float startFrame;
  float sampleRate;
  std::int32_t numSamples;
};
#pragma pack(pop)
static_assert(sizeof(Pc2Header) == 32);

constexpr char kSignature[12] = {'P', 'O', 'I', 'N', 'T', 'C', 'A', 'C', 'H', 'E', '2', '\0'};

}  // namespace

Pc2Writer::Pc2Writer(const std::string& path, std::size_t pointCount, double startFrame, double sampleRate)
    : path_(path), points_(pointCount), buffer_(pointCount * 3) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw Error(fmt::format("{}: cannot be written", path));
  Pc2Header h{};
  std::memcpy(h.signature, kSignature, sizeof kSignature);
  h.version = 1;
  h.numPoints = static_cast<std::int32_t>(pointCount);
  h.startFrame = static_cast<float>(startFrame);
  h.sampleRate = static_cast<float>(sampleRate);
  h.numSamples = 0;
  if (std::fwrite(&h, sizeof h, 1, file_) != 1) throw Error(fmt::format("{}: write failed", path));
}

Pc2Writer::~Pc2Writer() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() reports failures when called directly
  }
}

void Pc2Writer::writeFrame(std::span<const Vec3> positions) {
  if (!file_) throw Error(fmt::format("{}: write after close", path_), ExitCode::Internal);
  if (positions.size() != points_) {
    throw Error(fmt::format("{}: frame has {} points, the cache {}", path_, positions.size(), points_), ExitCode::Internal);
  }
  for (std::size_t i = 0; i < points_; ++i) {
    buffer_[3 * i] = static_cast<float>(positions[i].x());
    buffer_[3 * i + 1] = static_cast<float>(positions[i].y());
    buffer_[3 * i + 2] = static_cast<float>(positions[i].z());
  }
  if (std::fwrite(buffer_.data(), sizeof(float), buffer_.size(), file_) != buffer_.size()) {
    throw Error(fmt::format("{}: write failed", path_));
  }
  ++frames_;
}

void Pc2Writer::close() {
  if (!file_) return;
  const auto samples = static_cast<std::int32_t>(frames_);
  const bool ok = std::fseek(file_, offsetof(Pc2Header, numSamples), SEEK_SET) == 0 &&
                  std::fwrite(&samples, sizeof samples, 1, file_) == 1;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) throw Error(fmt::format("{}: write failed", path_));
}

Pc2Cache readPc2(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw Error(fmt::format("{}: no such file", path));
  Pc2Header h{};
  const bool headerOk = std::fread(&h, sizeof h, 1, f) == 1;
  if (!headerOk || std::memcmp(h.signature, kSignature, sizeof kSignature) != 0 || h.version != 1 ||
      h.numPoints < 0 || h.numSamples < 0) {
    std::fclose(f);
    throw Error(fmt::format("{}: not a PC2 point cache (expected the POINTCACHE2 header, version 1)", path));
  }
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  const std::uint64_t expected = sizeof h + std::uint64_t(h.numPoints) * 12u * std::uint64_t(h.numSamples);
  if (ec || size < expected) {
    std::fclose(f);
    throw Error(fmt::format("{}: truncated: the header promises {} samples of {} points ({} bytes), the file has {}",
                            path, h.numSamples, h.numPoints, expected, size));
  }
  Pc2Cache cache;
  cache.pointCount = static_cast<std::size_t>(h.numPoints);
  cache.startFrame = h.startFrame;
  cache.sampleRate = h.sampleRate;
  std::vector<float> buffer(cache.pointCount * 3);
  cache.frames.resize(static_cast<std::size_t>(h.numSamples));
  for (auto& frame : cache.frames) {
    if (std::fread(buffer.data(), sizeof(float), buffer.size(), f) != buffer.size()) {
      std::fclose(f);
      throw Error(fmt::format("{}: truncated sample data", path));
    }
    frame.resize(cache.pointCount);
    for (std::size_t i = 0; i < cache.pointCount; ++i) frame[i] = Vec3(buffer[3 * i], buffer[3 * i + 1], buffer[3 * i + 2]);
  }
  std::fclose(f);
  return cache;
}

}  // namespace drape::formats
