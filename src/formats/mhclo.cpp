#include "drape/formats/mhclo.hpp"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

using detail::LineWord;

class LineReader {
 public:
  LineReader(const std::string& name, int line, const std::vector<LineWord>& words)
      : name_(name), line_(line), words_(words) {}

  [[nodiscard]] Error error(std::size_t k, const std::string& what) const {
    const int column = k < words_.size() ? words_[k].column : (words_.empty() ? 1 : words_.back().column);
    return Error::at({name_, line_, column}, what);
  }
  [[nodiscard]] std::uint32_t index(std::size_t k) const {
    std::uint32_t v = 0;
    const std::string_view t = words_.at(k).text;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec != std::errc() || end != t.data() + t.size())
      throw error(k, fmt::format("expected a base-mesh vertex index (a whole number), found '{}'", t));
    return v;
  }
  [[nodiscard]] double number(std::size_t k) const {
    const std::string_view t = words_.at(k).text;
    const std::optional<double> v = detail::finiteNumber(t);
    if (!v) throw error(k, fmt::format("expected a number, found '{}'", t));
    return *v;
  }

 private:
  const std::string& name_;
  int line_;
  const std::vector<LineWord>& words_;
};

MhcloVertex parseVertex(const LineReader& r, std::size_t count) {
  MhcloVertex v;
  if (count == 1) {
    v.base = {r.index(0), r.index(0), r.index(0)};
    return v;
  }
  if (count != 9) throw r.error(0, fmt::format("expected 1 or 9 values on a vertex line (A B C wa wb wc ox oy oz), found {}", count));
  for (std::size_t k = 0; k < 3; ++k) {
    v.base[k] = r.index(k);
    v.weight[k] = r.number(3 + k);
  }
  v.offset = Vec3(r.number(6), r.number(7), r.number(8));
  return v;
}

}  // namespace

Mhclo parseMhclo(std::string_view text, const std::string& name) {
  Mhclo m;
  m.source = name;
  bool inVertices = false;
  int lineNo = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++lineNo;
    const std::vector<LineWord> words = detail::lineWords(line);
    if (words.empty() || words[0].text.front() == '#') {
      if (end == text.size()) break;
      continue;
    }
    const LineReader r(name, lineNo, words);
    const std::string_view key = words[0].text;
    const bool numeric = (key.front() >= '0' && key.front() <= '9') || key.front() == '-' || key.front() == '+';
    if (inVertices && numeric) {
      m.vertices.push_back(parseVertex(r, words.size()));
      for (std::uint32_t b : m.vertices.back().base) m.largestBaseIndex = std::max(m.largestBaseIndex, b);
    } else if (key == "verts") {
      inVertices = true;
    } else if (key == "x_scale" || key == "y_scale" || key == "z_scale") {
      if (words.size() != 4) throw r.error(0, fmt::format("expected '{} A B DISTANCE'", key));
      const std::size_t axis = static_cast<std::size_t>(key[0] - 'x');
      m.scale[axis] = {r.index(1), r.index(2), r.number(3)};
      if (!(m.scale[axis].reference > 0.0)) throw r.error(3, "expected a reference distance > 0");
      m.hasScale[axis] = true;
    } else {
      inVertices = false;  // delete_verts and anything after the list
      if (key == "name" && words.size() > 1) m.name = std::string(words[1].text);
      if (key == "obj_file" && words.size() > 1) m.objFile = std::string(words[1].text);
      if (key == "basemesh" && words.size() > 1) m.baseMesh = std::string(words[1].text);
    }
    if (end == text.size()) break;
  }
  if (m.vertices.empty()) throw Error(fmt::format("{}: no 'verts' list (not a MakeHuman clothes file?)", name));
  return m;
}

Mhclo readMhclo(const std::string& path) { return parseMhclo(detail::readWholeFile(path), path); }

}  // namespace drape::formats
