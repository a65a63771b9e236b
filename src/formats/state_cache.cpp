#include "drape/formats/state_cache.hpp"

#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

constexpr char kStateSignature[8] = {'D', 'R', 'A', 'P', 'E', 'S', 'T', 'S'};
constexpr std::size_t kHeaderBytes = 16;
constexpr std::uint32_t kStateVersion = 1;

void putUint32(unsigned char* out, std::uint32_t v) {
  for (int b = 0; b < 4; ++b) out[b] = static_cast<unsigned char>(v >> (8 * b));
}

std::uint32_t getUint32(std::string_view bytes, std::size_t at) {
  std::uint32_t v = 0;
  for (int b = 0; b < 4; ++b) v |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + b])) << (8 * b);
  return v;
}

}  // namespace

StateCacheWriter::StateCacheWriter(const std::string& path, std::size_t vertexCount)
    : path_(path), vertices_(vertexCount) {
  if (vertexCount == 0 || vertexCount > std::numeric_limits<std::uint32_t>::max())
    throw Error(fmt::format("{}: a state cache needs 1 to 2^32 - 1 vertices, not {}", path, vertexCount),
                ExitCode::Internal);
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw Error(fmt::format("{}: cannot be written", path));
  unsigned char header[kHeaderBytes];
  std::memcpy(header, kStateSignature, sizeof kStateSignature);
  putUint32(header + 8, kStateVersion);
  putUint32(header + 12, static_cast<std::uint32_t>(vertexCount));
  if (std::fwrite(header, 1, sizeof header, file_) != sizeof header) throw Error(fmt::format("{}: write failed", path));
}

StateCacheWriter::~StateCacheWriter() {
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() reports failures when called directly
  }
}

void StateCacheWriter::writeFrame(std::span<const std::uint8_t> states) {
  if (!file_) throw Error(fmt::format("{}: write after close", path_), ExitCode::Internal);
  if (states.size() != vertices_)
    throw Error(fmt::format("{}: frame has {} vertices, the cache {}", path_, states.size(), vertices_),
                ExitCode::Internal);
  if (std::fwrite(states.data(), 1, states.size(), file_) != states.size())
    throw Error(fmt::format("{}: write failed", path_));
  ++frames_;
}

void StateCacheWriter::close() {
  if (!file_) return;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!closed) throw Error(fmt::format("{}: write failed", path_));
}

StateCache parseStateCache(std::string_view bytes, const std::string& name) {
  if (bytes.size() < kHeaderBytes)
    throw Error(fmt::format("{}: not a state cache: {} bytes, shorter than the {}-byte header", name, bytes.size(),
                            kHeaderBytes));
  if (std::memcmp(bytes.data(), kStateSignature, sizeof kStateSignature) != 0)
    throw Error(fmt::format("{}: not a state cache: expected 'DRAPESTS' at byte 0", name));
  const std::uint32_t version = getUint32(bytes, 8);
  if (version != kStateVersion)
    throw Error(fmt::format("{}: state cache version {} at byte 8; this drape reads version {}", name, version,
                            kStateVersion));
  StateCache cache;
  cache.vertexCount = getUint32(bytes, 12);
  if (cache.vertexCount == 0) throw Error(fmt::format("{}: the vertex count at byte 12 is 0", name));
  const std::size_t body = bytes.size() - kHeaderBytes;
  if (body % cache.vertexCount != 0)
    throw Error(fmt::format("{}: the last frame is cut short: {} bytes after the header are not whole frames of {} "
                            "vertices",
                            name, body, cache.vertexCount));
  const std::size_t frames = body / cache.vertexCount;
  cache.frames.reserve(frames);
  for (std::size_t f = 0; f < frames; ++f) {
    const std::size_t at = kHeaderBytes + f * cache.vertexCount;
    const auto* first = reinterpret_cast<const std::uint8_t*>(bytes.data() + at);
    for (std::size_t v = 0; v < cache.vertexCount; ++v)
      if ((first[v] & ~kKnownStateBits) != 0)
        throw Error(fmt::format("{}: byte {} (frame {}, vertex {}) is 0x{:02x}: bits no state uses (known: 0x{:02x})",
                                name, at + v, f, v, first[v], kKnownStateBits));
    cache.frames.emplace_back(first, first + cache.vertexCount);
  }
  return cache;
}

StateCache readStateCache(const std::string& path) {
  // No size limit: a cache is as long as its take, and the parser checks it is whole frames.
  return parseStateCache(detail::readWholeFile(path, std::numeric_limits<std::size_t>::max()), path);
}

}  // namespace drape::formats
