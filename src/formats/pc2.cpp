#include "drape/formats/pc2.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "text_scan.hpp"

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

constexpr char kPc2Signature[12] = {'P', 'O', 'I', 'N', 'T', 'C', 'A', 'C', 'H', 'E', '2', '\0'};

}  // namespace

Pc2Writer::Pc2Writer(const std::string& path, std::size_t pointCount, double startFrame, double sampleRate)
    : path_(path), points_(pointCount), buffer_(pointCount * 3) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw Error(fmt::format("{}: cannot be written", path));
  Pc2Header h{};
  std::memcpy(h.signature, kPc2Signature, sizeof kPc2Signature);
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

namespace {

// The header's promise checked against the bytes there are, dimension by dimension: the
// product of two 31-bit counts and 12 bytes overflows 64 bits.
void checkPayloadSize(const Pc2Header& h, std::size_t payload, std::size_t total, const std::string& name) {
  const std::uint64_t pointBytes = std::uint64_t(h.numPoints) * 12u;
  const bool fits = h.numSamples == 0 || (pointBytes <= payload && std::uint64_t(h.numSamples) <= payload / pointBytes);
  if (!fits) {
    // long double: the promise may exceed 64 bits, and its 64-bit mantissa holds it exactly.
    const long double promised = static_cast<long double>(sizeof h) + static_cast<long double>(pointBytes) * h.numSamples;
    throw Error(fmt::format("{}: truncated: the header promises {} samples of {} points ({:.0f} bytes), the file has {}",
                            name, h.numSamples, h.numPoints, promised, total));
  }
}

// The timing must be finite and the rate positive: NaN or infinity from a file would reach
// the time codes of players and exporters unnoticed.
void checkHeaderNumbers(const Pc2Header& h, const std::string& name) {
  if (!std::isfinite(h.startFrame)) throw Error(fmt::format("{}: the start frame {} is not a finite number", name, h.startFrame));
  if (!std::isfinite(h.sampleRate) || !(h.sampleRate > 0.0f))
    throw Error(fmt::format("{}: the sample rate {} is not a finite number > 0", name, h.sampleRate));
}

}  // namespace

Pc2Cache parsePc2(std::string_view bytes, const std::string& name) {
  Pc2Header h{};
  if (bytes.size() >= sizeof h) std::memcpy(&h, bytes.data(), sizeof h);
  if (bytes.size() < sizeof h || std::memcmp(h.signature, kPc2Signature, sizeof kPc2Signature) != 0 || h.version != 1 ||
      h.numPoints < 0 || h.numSamples < 0) {
    throw Error(fmt::format("{}: not a PC2 point cache (expected the POINTCACHE2 header, version 1)", name));
  }
  // Samples of no points would cost a vector each and say nothing: 2^31 of them is 48 GB.
  if (h.numPoints == 0 && h.numSamples > 0)
    throw Error(fmt::format("{}: the header promises {} samples of 0 points, expected at least 1 point", name, h.numSamples));
  checkPayloadSize(h, bytes.size() - sizeof h, bytes.size(), name);
  checkHeaderNumbers(h, name);
  Pc2Cache cache;
  cache.pointCount = static_cast<std::size_t>(h.numPoints);
  cache.startFrame = h.startFrame;
  cache.sampleRate = h.sampleRate;
  cache.frames.resize(static_cast<std::size_t>(h.numSamples));
  const char* at = bytes.data() + sizeof h;
  for (std::size_t s = 0; s < cache.frames.size(); ++s) {
    std::vector<Vec3>& frame = cache.frames[s];
    frame.resize(cache.pointCount);
    for (std::size_t i = 0; i < cache.pointCount; ++i, at += 12) {
      float xyz[3];
      std::memcpy(xyz, at, sizeof xyz);
      if (!std::isfinite(xyz[0]) || !std::isfinite(xyz[1]) || !std::isfinite(xyz[2])) {
        throw Error(fmt::format("{}: sample {} point {} has a non-finite coordinate (byte {})", name, s, i,
                                at - bytes.data()));
      }
      frame[i] = Vec3(xyz[0], xyz[1], xyz[2]);
    }
  }
  return cache;
}

Pc2Cache readPc2(const std::string& path) {
  // No size limit: a cache is as long as its take, and parsePc2 checks the header against it.
  return parsePc2(detail::readWholeFile(path, std::numeric_limits<std::size_t>::max()), path);
}

}  // namespace drape::formats
