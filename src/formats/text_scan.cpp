#include "text_scan.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace drape::formats::detail {

std::string readWholeFile(const std::string& path, std::size_t maxBytes) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(fmt::format("{}: no such file", path));
  if (std::filesystem::is_directory(path, ec)) throw Error(fmt::format("{}: is a directory, expected a file", path));
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > maxBytes) throw Error(fmt::format("{}: is larger than {} bytes", path, maxBytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: cannot be read", path));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

namespace {
bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
bool isBrace(char c) { return c == '{' || c == '}'; }
}  // namespace

void WordScanner::advance() {
  if (text_[pos_] == '\n') {
    ++line_;
    column_ = 1;
  } else {
    ++column_;
  }
  ++pos_;
}

void WordScanner::skipSpace() {
  while (pos_ < text_.size() && isSpace(text_[pos_])) advance();
}

bool WordScanner::atEnd() {
  skipSpace();
  return pos_ >= text_.size();
}

WordScanner::Word WordScanner::next() {
  skipSpace();
  Word w{{}, line_, column_};
  const std::size_t start = pos_;
  if (pos_ < text_.size() && isBrace(text_[pos_])) {
    advance();
  } else {
    while (pos_ < text_.size() && !isSpace(text_[pos_]) && !isBrace(text_[pos_])) advance();
  }
  w.text = text_.substr(start, pos_ - start);
  return w;
}

WordScanner::Word WordScanner::peek() {
  const std::size_t p = pos_;
  const int l = line_, c = column_;
  Word w = next();
  pos_ = p;
  line_ = l;
  column_ = c;
  return w;
}

WordScanner::Word WordScanner::restOfLine() {
  while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) advance();
  Word w{{}, line_, column_};
  const std::size_t start = pos_;
  while (pos_ < text_.size() && text_[pos_] != '\n') advance();
  std::string_view t = text_.substr(start, pos_ - start);
  while (!t.empty() && isSpace(t.back())) t.remove_suffix(1);
  w.text = t;
  return w;
}

std::vector<LineWord> lineWords(std::string_view line, std::size_t most, char comment) {
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
  std::vector<LineWord> words;
  std::size_t i = 0;
  while (words.size() < most) {
    while (i < line.size() && space(line[i])) ++i;
    if (i == line.size() || (comment != '\0' && line[i] == comment)) break;
    const std::size_t start = i;
    while (i < line.size() && !space(line[i])) ++i;
    words.push_back({line.substr(start, i - start), static_cast<int>(start) + 1});
  }
  return words;
}

std::string quoted(std::string_view word) {
  if (word.empty()) return "end of file";
  std::string s(word.substr(0, 40));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  return "'" + s + (word.size() > 40 ? "...'" : "'");
}

std::optional<double> finiteNumber(std::string_view word) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (word.empty() || ec != std::errc() || end != word.data() + word.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

double parseNumber(const WordScanner& s, const WordScanner::Word& w) {
  const std::optional<double> value = finiteNumber(w.text);
  if (!value) throw Error::at(s.pos(w), fmt::format("expected a number, found {}", quoted(w.text)));
  return *value;
}

std::size_t parseCount(const WordScanner& s, const WordScanner::Word& w, std::size_t max, const char* what) {
  std::size_t value = 0;
  const auto [end, ec] = std::from_chars(w.text.data(), w.text.data() + w.text.size(), value);
  if (w.text.empty() || end != w.text.data() + w.text.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
    throw Error::at(s.pos(w), fmt::format("expected {} (a whole number), found {}", what, quoted(w.text)));
  if (ec == std::errc::result_out_of_range || value > max)
    throw Error::at(s.pos(w), fmt::format("{} {} exceeds the limit of {}", what, w.text, max));
  return value;
}

}  // namespace drape::formats::detail
