#include "drape/formats/json_text.hpp"

#include <algorithm>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::formats {
namespace {

using nlohmann::json;

// 1-based line and column of byte offset `at` in `text`.
SourcePos positionOf(std::string_view text, std::size_t at, const std::string& name) {
  return advancePosition(text, 0, {name, 1, 1}, at);
}

// nlohmann's message without its "[json.exception.parse_error.101] parse error at ...: " prefix.
std::string messageOf(const json::parse_error& e) {
  std::string what = e.what();
  if (const auto colon = what.find(": "); colon != std::string::npos) what = what.substr(colon + 2);
  return what;
}

// Rejects nesting deeper than kMaxJsonDepth before nlohmann sees the text: brackets inside
// strings do not count.
void checkDepth(std::string_view text, const std::string& name) {
  int depth = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '"') {
      i = endOfJsonString(text, i) - 1;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxJsonDepth)
        throw Error::at(positionOf(text, i, name), fmt::format("nesting deeper than {} levels", kMaxJsonDepth));
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

// Where nlohmann gave up: it reports a number too large for a double (out_of_range 406)
// without the position a parse_error carries, so a second, SAX-only pass records where
// the token that stopped it began.
class FailureLocator : public nlohmann::json_sax<json> {
 public:
  std::size_t start = 0;
  std::string token;

  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string& lastToken, const nlohmann::detail::exception&) override {
    start = position >= lastToken.size() ? position - lastToken.size() : 0;
    token = lastToken;
    return false;
  }
};

// JSON leaves the meaning of a key written twice in one object open, and nlohmann keeps the
// last silently: in a rig, a glTF asset or a joint map that is a slip, one of the two values
// lost. One pass over the text (already parsed, so valid JSON), with the keys of every open
// object; a key is compared as written, or decoded where it holds an escape.
void checkRepeatedKeys(std::string_view text, const std::string& name) {
  struct Open {
    bool object = false;
    std::unordered_map<std::string, SourcePos> keys;
  };
  std::vector<Open> open;  // by depth; reused, so that sibling objects do not allocate anew
  std::size_t depth = 0;
  SourcePos here{name, 1, 1};
  std::size_t counted = 0;  // `here` is the place of text[counted]
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '{' || c == '[') {
      if (open.size() <= depth) open.emplace_back();
      open[depth].object = c == '{';
      open[depth].keys.clear();
      ++depth;
    } else if (c == '}' || c == ']') {
      depth -= depth > 0;
    } else if (c == '"') {
      const std::size_t end = endOfJsonString(text, i);
      const std::size_t next = text.find_first_not_of(" \t\r\n", end);
      if (depth > 0 && open[depth - 1].object && next != std::string_view::npos && text[next] == ':') {
        const std::string_view token = text.substr(i, end - i);
        std::string key(token.substr(1, token.size() - 2));
        if (key.find('\\') != std::string::npos) {
          const json decoded = json::parse(token, nullptr, false);
          if (decoded.is_string()) key = decoded.get<std::string>();
        }
        here = advancePosition(text, counted, here, i);
        counted = i;
        const auto [first, fresh] = open[depth - 1].keys.emplace(std::move(key), here);
        if (!fresh)
          throw Error::at(here, fmt::format("key '{}' is written twice in one object (first at line {}, column {}); "
                                            "which one counts is left open",
                                            first->first, first->second.line, first->second.column));
      }
      i = end - 1;
    }
  }
}

}  // namespace

std::size_t endOfJsonString(std::string_view text, std::size_t open) {
  std::size_t i = open + 1;
  while (i < text.size() && text[i] != '"') i += text[i] == '\\' ? 2 : 1;
  return std::min(i + 1, text.size());
}

SourcePos advancePosition(std::string_view text, std::size_t from, SourcePos start, std::size_t at) {
  for (std::size_t i = from; i < std::min(at, text.size()); ++i) {
    if (text[i] == '\n') {
      ++start.line;
      start.column = 1;
    } else {
      ++start.column;
    }
  }
  return start;
}

nlohmann::json parseJsonText(std::string_view text, const std::string& name) {
  checkDepth(text, name);
  try {
    json doc = json::parse(text.begin(), text.end());
    checkRepeatedKeys(text, name);
    return doc;
  } catch (const json::parse_error& e) {
    throw Error::at(positionOf(text, e.byte > 0 ? e.byte - 1 : 0, name), messageOf(e));
  } catch (const json::exception&) {  // out_of_range: a number too large for a double
    FailureLocator locator;
    (void)json::sax_parse(text.begin(), text.end(), &locator);
    throw Error::at(positionOf(text, locator.start, name), fmt::format("expected a finite number, found '{}'", locator.token.substr(0, 40)));
  }
}

}  // namespace drape::formats
