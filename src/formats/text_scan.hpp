#pragma once
// Private helpers of the hand-written readers (BVH, ASF/AMC, MakeHuman rigs and clothes, PC2,
// the OBJ vertex check): whole-file reading with a size limit, a line/column tracking word
// scanner, and number checks.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drape/core/error.hpp"

namespace drape::formats::detail {

/// Reads a whole file; throws drape::Error "path: no such file" / "is a directory" /
/// "is larger than N bytes".
[[nodiscard]] std::string readWholeFile(const std::string& path, std::size_t maxBytes = std::size_t{1} << 30);

/// Splits text into whitespace-separated words, tracking 1-based line and column.
/// `{` and `}` are words of their own even when glued to a neighbour.
class WordScanner {
 public:
  WordScanner(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

  struct Word {
    std::string_view text;
    int line = 0;
    int column = 0;
  };

  /// The next word, or an empty word at end of input (line/column of the end).
  Word next();
  /// Peeks the next word without consuming it.
  Word peek();
  /// The rest of the current line after the last word read (trimmed), consumed.
  Word restOfLine();
  [[nodiscard]] bool atEnd();
  [[nodiscard]] SourcePos pos(const Word& w) const { return {file_, w.line, w.column}; }
  [[nodiscard]] SourcePos here() const { return {file_, line_, column_}; }
  [[nodiscard]] const std::string& file() const { return file_; }
  [[nodiscard]] std::size_t offset() const { return pos_; }
  [[nodiscard]] int line() const { return line_; }

 private:
  void skipSpace();
  void advance();

  std::string_view text_;
  std::string file_;
  std::size_t pos_ = 0;
  int line_ = 1;
  int column_ = 1;
};

/// A word of one line and its 1-based column.
struct LineWord {
  std::string_view text;
  int column = 0;
};

/// The words of one line (separated by spaces, tabs and carriage returns), at most `most`;
/// a word that starts with `comment` (when given) ends the line. For the line-oriented
/// readers (ASF/AMC, mhclo, the OBJ vertex check).
[[nodiscard]] std::vector<LineWord> lineWords(std::string_view line, std::size_t most = SIZE_MAX, char comment = '\0');

/// A whole word as a finite double (a leading '+' allowed); nothing for anything else:
/// "nan", "inf", 1e999, trailing characters, an empty word.
[[nodiscard]] std::optional<double> finiteNumber(std::string_view word);
/// Parses a whole word as a finite double; throws "expected a number, found 'x'" at w.
[[nodiscard]] double parseNumber(const WordScanner& s, const WordScanner::Word& w);
/// Parses a whole word as a non-negative integer no larger than `max`.
[[nodiscard]] std::size_t parseCount(const WordScanner& s, const WordScanner::Word& w, std::size_t max,
                                     const char* what);
/// Quotes a word for messages, shortened to 40 characters; "end of file" if empty.
[[nodiscard]] std::string quoted(std::string_view word);

}  // namespace drape::formats::detail
