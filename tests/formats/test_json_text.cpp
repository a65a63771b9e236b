// JSON text as drape's readers take it: errors with their line and column.

#include <gtest/gtest.h>

#include <string>

#include "drape/formats/json_text.hpp"

namespace drape::formats {
namespace {

std::string errorOf(const std::string& text) {
  try {
    (void)parseJsonText(text, "t.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(JsonText, AKeyWrittenTwiceInOneObjectIsAnErrorAtItsSecondPlace) {
  EXPECT_EQ(errorOf("{\"a\": 1,\n \"b\": 2,\n   \"a\": 3}"),
            "t.json:3:4: key 'a' is written twice in one object (first at line 1, column 2); which one counts is "
            "left open");
  // Nested, after strings holding braces, quotes and colons, and written with an escape.
  EXPECT_EQ(errorOf("{\"x\": \"{\\\"a\\\": }\", \"o\": [{\"k\": \"a:\"}, {\"k\": 1, \"\\u006b\": 2}]}"),
            "t.json:1:48: key 'k' is written twice in one object (first at line 1, column 40); which one counts is "
            "left open");
}

TEST(JsonText, TheSameKeyInOtherObjectsIsNoRepeat) {
  // Siblings, parent and child, objects in arrays, and a value equal to a key.
  const nlohmann::json doc = parseJsonText(
      "{\"a\": {\"a\": {\"a\": 1}}, \"b\": [{\"a\": 1, \"b\": 2}, {\"a\": 3, \"b\": \"a\"}], \"c\": {\"a\": 2}}", "t.json");
  EXPECT_EQ(doc["b"][1]["a"], 3);
  std::string many = "[";
  for (int i = 0; i < 20000; ++i) many += std::string(i ? "," : "") + "{\"name\": \"n\", \"index\": " + std::to_string(i) + "}";
  many += "]";
  EXPECT_EQ(parseJsonText(many, "many.json").size(), 20000u);
}

TEST(JsonText, SyntaxErrorsAndDepthKeepTheirPlaces) {
  EXPECT_EQ(errorOf("{\"a\": 1,\n}"), "t.json:2:1: syntax error while parsing object key - unexpected '}'; expected string literal");
  EXPECT_EQ(errorOf("[1e999]"), "t.json:1:2: expected a finite number, found '1e999'");
  // Brackets inside strings (after an escaped quote too) do not count towards the depth.
  const std::string deep = std::string(600, '[') + std::string(600, ']');
  EXPECT_EQ(errorOf(deep), "t.json:1:513: nesting deeper than 512 levels");
  const std::string quoted = "[\"\\\"" + std::string(600, '[') + "\"]";
  EXPECT_EQ(parseJsonText(quoted, "t.json").size(), 1u);
}

}  // namespace
}  // namespace drape::formats
