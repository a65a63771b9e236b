// MakeHuman clothes fitting files: the vertex lines in both forms, the scale lines, the end
// of the list, and file:line:column errors for what is malformed.
#include <gtest/gtest.h>

#include "drape/core/error.hpp"
#include "drape/formats/mhclo.hpp"
#include "drape/testing/errors.hpp"

namespace drape::formats {
namespace {

constexpr const char* kSmall =
    "# comment\n"
    "basemesh hm08\n"
    "name tiny\n"
    "obj_file tiny.obj\n"
    "x_scale 0 1 2.0\n"
    "y_scale 0 2 4.0\n"
    "verts 0\n"
    "0 1 2 0.5 0.25 0.25 0.1 -0.2 0.3\n"
    "7\n"
    "delete_verts\n"
    "5 - 9\n";

TEST(Mhclo, ParsesBothVertexFormsAndTheScales) {
  const Mhclo m = parseMhclo(kSmall, "tiny.mhclo");
  EXPECT_EQ(m.name, "tiny");
  EXPECT_EQ(m.objFile, "tiny.obj");
  EXPECT_EQ(m.baseMesh, "hm08");
  ASSERT_EQ(m.vertices.size(), 2u) << "delete_verts ends the list";
  EXPECT_EQ(m.vertices[0].base, (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_DOUBLE_EQ(m.vertices[0].weight[1], 0.25);
  EXPECT_DOUBLE_EQ(m.vertices[0].offset.y(), -0.2);
  EXPECT_EQ(m.vertices[1].base, (std::array<std::uint32_t, 3>{7, 7, 7}));
  EXPECT_DOUBLE_EQ(m.vertices[1].weight[0], 1.0);
  EXPECT_TRUE(m.hasScale[0] && m.hasScale[1] && !m.hasScale[2]);
  EXPECT_EQ(m.scale[1].b, 2u);
  EXPECT_DOUBLE_EQ(m.scale[1].reference, 4.0);
  EXPECT_EQ(m.largestBaseIndex, 7u);
}

void expectError(const std::string& text, const std::string& where, const std::string& what) {
  try {
    (void)parseMhclo(text, "bad.mhclo");
    FAIL() << "expected an error for: " << text;
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.rfind(where, 0), 0u) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  }
}

TEST(Mhclo, MalformedLinesNameLineAndColumn) {
  expectError("verts 0\n0 1 2 0.5 0.25 x 0 0 0\n", "bad.mhclo:2:16:", "expected a number, found 'x'");
  expectError("verts 0\n0 1 2 0.5\n", "bad.mhclo:2:1:", "expected 1 or 9 values");
  expectError("verts 0\n-3\n", "bad.mhclo:2:1:", "expected a base-mesh vertex index");
  expectError("verts 0\n3x\n", "bad.mhclo:2:1:", "expected a base-mesh vertex index");
  expectError("x_scale 1 2\nverts 0\n1\n", "bad.mhclo:1:1:", "expected 'x_scale A B DISTANCE'");
  expectError("x_scale 1 2 0\nverts 0\n1\n", "bad.mhclo:1:13:", "reference distance > 0");
  expectError("name nothing\n", "bad.mhclo:", "no 'verts' list");
}

// Weights, offsets and scale distances must be finite: nan, inf and 1e999 (beyond double).
TEST(Mhclo, MalformedCorpus) {
  drape::testing::expectCorpus(std::string(DRAPE_TEST_DATA_DIR) + "/bad/mesh", {
      {"mhclo_infinite_offset.mhclo", "3:25: expected a number, found 'inf'"},
      {"mhclo_nan_weight.mhclo", "3:7: expected a number, found 'nan'"},
      {"mhclo_overflow_scale.mhclo", "1:13: expected a number, found '1e999'"},
  }, [](const std::string& path) { (void)readMhclo(path); });
}

TEST(Mhclo, TheBundledDressHasOneLinePerMeshVertex) {
  const Mhclo m = readMhclo(std::string(DRAPE_DATA_DIR) + "/garments/makehuman_female_elegantsuit01_dress.mhclo");
  EXPECT_EQ(m.vertices.size(), 2205u);
  EXPECT_EQ(m.baseMesh, "hm08");
  EXPECT_LT(m.largestBaseIndex, 19158u);
  for (const MhcloVertex& v : m.vertices) EXPECT_NEAR(v.weight[0] + v.weight[1] + v.weight[2], 1.0, 0.02);
}

}  // namespace
}  // namespace drape::formats
