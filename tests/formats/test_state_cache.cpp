// State caches (formats/state_cache.hpp): what drape run writes beside each garment's PC2
// cache, read back as written; every malformed file refused with where and what.

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "drape/core/error.hpp"
#include "drape/formats/state_cache.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::formats {
namespace {

std::string stateTempPath(const std::string& name) {
  return (testing::processTempDir("state_cache") / name).string();
}

std::string messageOf(std::string_view bytes) {
  try {
    (void)parseStateCache(bytes, "t.states");
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

std::string header(std::uint32_t version, std::uint32_t vertices) {
  std::string h = "DRAPESTS";
  for (std::uint32_t v : {version, vertices})
    for (int b = 0; b < 4; ++b) h += static_cast<char>((v >> (8 * b)) & 0xff);
  return h;
}

TEST(StateCache, RoundTripsEveryKnownByteAndTheFrameCount) {
  const std::string path = stateTempPath("round.states");
  std::vector<std::vector<std::uint8_t>> frames;
  for (int f = 0; f < 7; ++f) {
    std::vector<std::uint8_t> s;
    for (int v = 0; v < 16; ++v) s.push_back(static_cast<std::uint8_t>((v + f) & kKnownStateBits));
    frames.push_back(s);
  }
  {
    StateCacheWriter w(path, 16);
    for (const auto& f : frames) w.writeFrame(f);
    EXPECT_EQ(w.frameCount(), 7u);
  }
  const StateCache c = readStateCache(path);
  EXPECT_EQ(c.vertexCount, 16u);
  EXPECT_EQ(c.frames, frames);
  EXPECT_EQ(std::filesystem::file_size(path), 16u + 7u * 16u);
}

TEST(StateCache, AnEmptyTakeHasNoFrames) {
  const std::string path = stateTempPath("empty.states");
  { StateCacheWriter w(path, 3); }
  const StateCache c = readStateCache(path);
  EXPECT_EQ(c.vertexCount, 3u);
  EXPECT_TRUE(c.frames.empty());
}

TEST(StateCache, MalformedBytesSayWhereAndWhat) {
  EXPECT_EQ(messageOf("DRAPE"), "t.states: not a state cache: 5 bytes, shorter than the 16-byte header");
  EXPECT_EQ(messageOf(std::string("POINTCACHE2\0\0\0\0\0", 16)),
            "t.states: not a state cache: expected 'DRAPESTS' at byte 0");
  EXPECT_EQ(messageOf(header(2, 4)), "t.states: state cache version 2 at byte 8; this drape reads version 1");
  EXPECT_EQ(messageOf(header(1, 0)), "t.states: the vertex count at byte 12 is 0");
  EXPECT_EQ(messageOf(header(1, 4) + std::string(6, '\0')),
            "t.states: the last frame is cut short: 6 bytes after the header are not whole frames of 4 vertices");
  EXPECT_EQ(messageOf(header(1, 2) + std::string("\x01\x02\x0f\x10", 4)),
            "t.states: byte 19 (frame 1, vertex 1) is 0x10: bits no state uses (known: 0x0f)");
  // A vertex count near 2^32 with a short body: no huge allocation, a plain error.
  EXPECT_NE(messageOf(header(1, 0xffffffffu) + "ab").find("cut short"), std::string::npos);
}

TEST(StateCache, MalformedFilesOnDisk) {
  const std::string dir = std::string(DRAPE_TEST_DATA_DIR) + "/bad/cache/";
  for (const auto& [file, expected] : std::vector<std::pair<std::string, std::string>>{
           {"states_cut_short.states", ": the last frame is cut short: 8 bytes after the header"},
           {"states_unknown_bits.states", ": byte 23 (frame 1, vertex 2) is 0x21: bits no state uses"}}) {
    try {
      (void)readStateCache(dir + file);
      ADD_FAILURE() << file << " was read";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW((void)readStateCache(dir + "no_such.states"), Error);
}

TEST(StateCache, TheWriterRefusesAFrameOfAnotherSizeAndWritesAfterClose) {
  const std::string path = stateTempPath("sizes.states");
  StateCacheWriter w(path, 4);
  const std::vector<std::uint8_t> three(3, 0), four(4, 0);
  EXPECT_THROW(w.writeFrame(three), Error);
  w.writeFrame(four);
  w.close();
  EXPECT_THROW(w.writeFrame(four), Error);
  EXPECT_THROW(StateCacheWriter(stateTempPath("none.states"), 0), Error);
  EXPECT_THROW(StateCacheWriter("/nonexistent/dir/x.states", 4), Error);
}

}  // namespace
}  // namespace drape::formats
