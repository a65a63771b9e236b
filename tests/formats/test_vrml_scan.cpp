// The pre-scan on its own: positions of errors, DEF/USE order, field checks, the tags it
// injects for drape's nodes.

#include <gtest/gtest.h>

#include "drape/core/error.hpp"
#include "drape/formats/vrml_scan.hpp"

namespace drape::formats::vrml {
namespace {

std::string errorOf(std::string_view text, const ScanOptions& options = {}) {
  try {
    (void)scan(text, "t.wrl", options);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(VrmlScan, AcceptsValidStructure) {
  const std::string text =
      "#VRML V2.0 utf8\n"
      "PROTO P [ field SFFloat a 1 exposedField MFNode kids [ Group { } ] eventIn SFTime go ] { Group { children IS "
      "kids } }\n"
      "DEF A Transform { translation -1 .5 +2e-3 children [ Shape { geometry Box { } }, USE A_ ] }\n";
  EXPECT_NE(errorOf(text).find("USE A_ before any DEF A_"), std::string::npos);
  const std::string ok =
      "#VRML V2.0 utf8\n# comment { [\nDEF A Transform { rotation 0 1 0 1.57 children [ Shape { geometry Sphere { } } "
      "] }\n"
      "Group { children [ USE A ] }\nDEF T TimeSensor { loop TRUE }\nDEF I PositionInterpolator { key [ 0 1 ] }\n"
      "ROUTE T.fraction_changed TO I.set_fraction\nWorldInfo { info [ \"a \\\"quoted\\\" }\" ] }\n";
  EXPECT_EQ(errorOf(ok), "(no error)");
}

TEST(VrmlScan, ReportsLineAndColumn) {
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nGroup {\n  children [ Shape { } ]\n  }\n}\n"),
            "t.wrl:5:1: expected a node type, found '}'");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nGroup { children [ Group ) ] }\n"),
            "t.wrl:2:26: expected '{' after the node type Group, found ')'");
  // A list holds one kind of value: a word among numbers is a number mistyped, not a node.
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nGroup { children [ 1 2 ) ] }\n"),
            "t.wrl:2:24: expected a number or ']' in the value of field 'children', found ')'");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nCoordinate { point [ 0 1 2,\n  0 nan 2 ] }\n"),
            "t.wrl:3:5: expected a number or ']' in the value of field 'point', found 'nan'");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nCoordinate { point [ 0 1 2, 0 1\n }\n"),
            "t.wrl:3:2: expected a number or ']' in the value of field 'point', found '}'");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nWorldInfo { title 'x' }\n"), "t.wrl:2:19: unexpected character '''");
  EXPECT_EQ(errorOf(std::string("#VRML V2.0 utf8\nGroup { \x01 }\n", 28)), "t.wrl:2:9: unexpected byte 0x01");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nGroup {"),
            "t.wrl:2:8: unexpected end of file in Group (the '{' at line 2 is not closed)");
  EXPECT_EQ(errorOf(""), "t.wrl:1:1: not a VRML97 file (it must begin with '#VRML V2.0 utf8')");
}

TEST(VrmlScan, UseInsideItsOwnDefIsRejectedEvenWhenClosed) {
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nDEF T Group { children [ DEF U Group { children USE T } ] }\n"),
            "t.wrl:2:53: USE T inside its own DEF T (a node cannot contain itself)");
  // After the DEF closes, USE is fine.
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nDEF T Group { }\nGroup { children USE T }\n"), "(no error)");
}

TEST(VrmlScan, ProtoBodiesHaveTheirOwnNames) {
  EXPECT_NE(errorOf("#VRML V2.0 utf8\nPROTO P [ ] { DEF Inner Group { } }\nGroup { children USE Inner }\n")
                .find("USE Inner before any DEF"),
            std::string::npos);
}

TEST(VrmlScan, ChecksFieldsOfKnownProtosAndInjectsTags) {
  ScanOptions options;
  options.knownProtos = {{"ClothMaterial", {"density", "thickness", "drapeNodeId"}, 0, false}};
  options.trackedTypes = {"ClothMaterial"};
  const std::string text =
      "#VRML V2.0 utf8\nDEF A ClothMaterial {\n  density 200\n}\nClothMaterial { thickness 0.001 }\n";
  const ScanResult r = scan(text, "t.wrl", options);
  ASSERT_EQ(r.sites.size(), 2u);
  EXPECT_EQ(r.sites[0].def, "A");
  EXPECT_EQ(r.sites[0].line, 2);
  EXPECT_EQ(r.sites[0].fieldLines.at("density"), 3);
  EXPECT_EQ(r.sites[1].fieldLines.at("thickness"), 5);
  EXPECT_EQ(r.text,
            "#VRML V2.0 utf8\nDEF A ClothMaterial { drapeNodeId 0 \n  density 200\n}\nClothMaterial { drapeNodeId 1  "
            "thickness 0.001 }\n");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nClothMaterial { densty 1 }\n", options),
            "t.wrl:2:17: unknown field 'densty' in ClothMaterial (its fields: density, thickness)");
  // A file that declares the type itself is checked against its own declaration, untagged.
  const ScanResult own = scan(
      "#VRML V2.0 utf8\nPROTO ClothMaterial [ field SFFloat weight 1 ] { Group { } }\nClothMaterial { weight 2 }\n",
      "t.wrl", options);
  EXPECT_EQ(own.sites.size(), 1u);
  EXPECT_EQ(own.text.find("drapeNodeId"), std::string::npos);
}

// Found while fuzzing by hand: Coin expands a PROTO that contains itself until its stack
// overflows (signal 11 in the reader's child).
TEST(VrmlScan, RecursivePrototypesAreRejected) {
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nPROTO P [ ] { Group { children P { } } }\nP { }\n"),
            "t.wrl:2:7: PROTO P contains an instance of itself (directly or through other PROTOs)");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nPROTO A [ ] { Group { } }\nPROTO B [ ] { A { } }\nPROTO A [ ] { B { } }\n"),
            "t.wrl:4:7: PROTO A contains an instance of itself (directly or through other PROTOs)");
  EXPECT_EQ(errorOf("#VRML V2.0 utf8\nPROTO A [ ] { Group { } }\nPROTO B [ ] { A { } }\nB { }\n"), "(no error)");
}

TEST(VrmlScan, LimitsNesting) {
  std::string deep = "#VRML V2.0 utf8\n";
  for (int i = 0; i < 100; ++i) deep += "Group { children [ ";
  ScanOptions options;
  options.maxDepth = 50;
  EXPECT_NE(errorOf(deep, options).find("nesting deeper than 50 levels"), std::string::npos);
}

}  // namespace
}  // namespace drape::formats::vrml
