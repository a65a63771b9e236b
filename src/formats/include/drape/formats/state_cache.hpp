#pragma once
// Per-vertex state caches of a run (DIR/garment.states), beside the PC2 position cache of the
// same mesh: one byte per vertex per frame, the bits the renderer colours by
// (render::vertex_state: the collision state in the low two bits, pinned 0x04, bound 0x08).
// PC2 holds float triples only, and nothing standard holds a byte per point per sample, so
// the format is drape's own and as small as it can be: a 16-byte header ("DRAPESTS", uint32
// version 1, uint32 vertex count, little-endian), then the frames, vertex-count bytes each.
// The frame count is the file's length; a take cut short by an instability is still whole.

#include <cstdint>
#include <cstdio>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace drape::formats {

/// The bits a state byte may have (render::vertex_state's); others are refused on reading.
inline constexpr std::uint8_t kKnownStateBits = 0x0f;

/// Streams frames to a state cache.
class StateCacheWriter {
 public:
  StateCacheWriter(const std::string& path, std::size_t vertexCount);
  ~StateCacheWriter();
  StateCacheWriter(const StateCacheWriter&) = delete;
  StateCacheWriter& operator=(const StateCacheWriter&) = delete;

  void writeFrame(std::span<const std::uint8_t> states);
  /// Flushes and closes; further writes are errors. Called by the destructor too.
  void close();
  [[nodiscard]] std::size_t frameCount() const { return frames_; }

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
  std::size_t vertices_;
  std::size_t frames_ = 0;
};

struct StateCache {
  std::size_t vertexCount = 0;
  std::vector<std::vector<std::uint8_t>> frames;
};

/// Parses the bytes of a state cache read from `name` (used in messages). Throws
/// drape::Error "name: ..." on a bad header, a last frame cut short, or a byte with bits no
/// state uses (with its frame, vertex and byte offset: the format is binary, it has no lines).
[[nodiscard]] StateCache parseStateCache(std::string_view bytes, const std::string& name);
/// Reads and parses a whole state cache.
[[nodiscard]] StateCache readStateCache(const std::string& path);

}  // namespace drape::formats
