#pragma once
// BVH motion capture (Biovision hierarchy), read by hand: a joint tree with offsets and
// channel lists, then one line of channel values per frame. Syntax only: values stay in
// the file's units and degrees; motion/ turns them into a Skeleton and a Clip.
//
// The header is checked before any frame data is stored (at most kMaxBvhFrames frames, at
// least one channel, a frame time > 0, and a file long enough to hold frames x channels
// values), so a 58-byte file that declares 329490295 frames is an error, not 7.7 GB.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "drape/core/math.hpp"

namespace drape::formats {

inline constexpr std::size_t kMaxBvhFrames = 1'000'000;

enum class BvhChannel : std::uint8_t { Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation };

struct BvhJoint {
  std::string name;
  int parent = -1;                 ///< index into BvhFile::joints; parents come first
  Vec3 offset = Vec3::Zero();      ///< file units, from the parent joint, parent frame at rest
  std::vector<BvhChannel> channels;
  std::size_t firstChannel = 0;    ///< index of channels[0] within a frame's values
  std::optional<Vec3> endSite;     ///< file units, offset of the End Site, if the joint has one
  int line = 0;                    ///< line of the ROOT/JOINT keyword, for messages
};

struct BvhFile {
  std::string source;              ///< file name for messages
  std::vector<BvhJoint> joints;    ///< in file order (parents first)
  std::size_t channelCount = 0;    ///< values per frame
  std::size_t frameCount = 0;
  double frameTime = 0.0;          ///< s
  int firstFrameLine = 0;          ///< line of the first frame's values
  std::vector<double> values;      ///< frameCount x channelCount, file units and degrees

  [[nodiscard]] const double* frame(std::size_t f) const { return values.data() + f * channelCount; }
};

/// Parses BVH text. `name` is the file name used in "name:line:column: ..." errors.
/// Throws drape::Error on any syntax error, a bad header or missing or extra values.
[[nodiscard]] BvhFile parseBvh(std::string_view text, const std::string& name);

/// Reads and parses a BVH file (throws drape::Error "path: no such file" etc.).
[[nodiscard]] BvhFile readBvh(const std::string& path);

/// A BVH that arrives as it is written (a live capture's stream, a pipe): the header first,
/// the text up to and including its "Frame Time:" line, read as parseBvh reads it, with no
/// frames (frameCount as declared, which such a stream need not keep; values empty).
[[nodiscard]] BvhFile parseBvhHeader(std::string_view text, const std::string& name);
/// True for the line that ends a BVH header ("Frame Time: T"): what a stream reader waits for.
[[nodiscard]] bool endsBvhHeader(std::string_view line);
/// Bytes of `text` up to and including its header's last line (and that line's newline):
/// where a BVH's frames begin. Nothing when no line ends a header.
[[nodiscard]] std::optional<std::size_t> bvhHeaderLength(std::string_view text);
/// One frame of such a stream, the line `lineNumber` of `name`: exactly out.size() finite
/// values (the channels). Throws drape::Error "name:line:column: expected ...".
void parseBvhFrameLine(std::string_view line, const std::string& name, int lineNumber, std::span<double> out);

/// "Xposition" etc.
[[nodiscard]] const char* bvhChannelName(BvhChannel channel);

}  // namespace drape::formats
