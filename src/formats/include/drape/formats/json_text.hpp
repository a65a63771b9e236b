#pragma once
// JSON text as drape's JSON readers (MakeHuman rigs, glTF, joint maps, run manifests) take it:
// nlohmann_json underneath, with every failure turned into "name:line:column: what".

#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"

namespace drape::formats {

/// Deepest nesting of arrays and objects accepted. nlohmann parses without recursion but
/// copies and dumps recursively, so a hostile file of 30,000 '[' would overflow the stack.
inline constexpr int kMaxJsonDepth = 512;

/// Parses `text` (read from `name`, used in messages). Throws drape::Error
/// "name:line:column: what" for a syntax error, a number too large for a double (1e999),
/// nesting deeper than kMaxJsonDepth, or a key written twice in one object (there at its
/// second place, naming the first).
[[nodiscard]] nlohmann::json parseJsonText(std::string_view text, const std::string& name);

/// One past the closing quote of the JSON string that opens at text[open] (in valid JSON:
/// a backslash escapes the next character); text.size() if it does not close.
[[nodiscard]] std::size_t endOfJsonString(std::string_view text, std::size_t open);

/// The 1-based line and column of text[at], counting on from text[from], whose place is
/// `start` (for readers that locate what nlohmann's DOM does not keep).
[[nodiscard]] SourcePos advancePosition(std::string_view text, std::size_t from, SourcePos start, std::size_t at);

}  // namespace drape::formats
