#include "drape/formats/asf_amc.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

using detail::finiteNumber;
using detail::quoted;

constexpr std::size_t kMaxBones = 10'000;

// A line split into words with their columns: both formats are line-oriented.
struct Line {
  int number = 0;
  std::vector<detail::LineWord> words;
};

// The lines that hold words, '#' comments dropped (anywhere in a line, as the formats allow).
std::vector<Line> splitLines(std::string_view text) {
  std::vector<Line> lines;
  int number = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    ++number;
    std::string_view raw = text.substr(start, end - start);
    if (const auto hash = raw.find('#'); hash != std::string_view::npos) raw = raw.substr(0, hash);
    Line line{number, detail::lineWords(raw)};
    if (!line.words.empty()) lines.push_back(std::move(line));
    if (end == text.size()) break;
    start = end + 1;
  }
  return lines;
}

struct AsfReader {
  std::string file;
  [[nodiscard]] SourcePos at(const Line& l, std::size_t word) const {
    return {file, l.number, word < l.words.size() ? l.words[word].column : 0};
  }
  [[nodiscard]] double number(const Line& l, std::size_t word) const {
    if (word >= l.words.size()) throw Error::at({file, l.number, 0}, fmt::format("expected a number after '{}'", l.words[0].text));
    const std::optional<double> v = finiteNumber(l.words[word].text);
    if (!v) throw Error::at(at(l, word), fmt::format("expected a number, found {}", quoted(l.words[word].text)));
    return *v;
  }
  [[nodiscard]] Vec3 vec3(const Line& l, std::size_t first) const {
    return {number(l, first), number(l, first + 1), number(l, first + 2)};
  }
};

AcclaimDof parseDof(const AsfReader& r, const Line& l, std::size_t word) {
  std::string w(l.words[word].text);
  std::transform(w.begin(), w.end(), w.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (w == "rx") return AcclaimDof::RX;
  if (w == "ry") return AcclaimDof::RY;
  if (w == "rz") return AcclaimDof::RZ;
  if (w == "tx") return AcclaimDof::TX;
  if (w == "ty") return AcclaimDof::TY;
  if (w == "tz") return AcclaimDof::TZ;
  if (w == "l") return AcclaimDof::L;
  throw Error::at(r.at(l, word), fmt::format("unknown degree of freedom {} (expected rx ry rz tx ty tz l)", quoted(l.words[word].text)));
}

std::string axisOrder(const AsfReader& r, const Line& l, std::size_t word) {
  if (word >= l.words.size()) return "XYZ";
  std::string order(l.words[word].text);
  std::transform(order.begin(), order.end(), order.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  std::string sorted = order;
  std::sort(sorted.begin(), sorted.end());
  if (sorted != "XYZ") throw Error::at(r.at(l, word), fmt::format("expected an axis order such as XYZ, found {}", quoted(l.words[word].text)));
  return order;
}

// ":bonedata" blocks: begin ... end.
std::size_t readBone(const AsfReader& r, const std::vector<Line>& lines, std::size_t i, AsfSkeleton& out) {
  AsfBone bone;
  bone.line = lines[i].number;
  bool named = false;
  for (++i; i < lines.size(); ++i) {
    const Line& l = lines[i];
    const std::string_view key = l.words[0].text;
    if (key == "end") break;
    if (key == "name") {
      if (l.words.size() < 2) throw Error::at(r.at(l, 0), "expected a bone name after 'name'");
      bone.name = std::string(l.words[1].text);
      named = true;
    } else if (key == "direction") {
      bone.direction = r.vec3(l, 1);
      if (bone.direction.norm() > 1e-12) bone.direction.normalize();
    } else if (key == "length") {
      bone.length = r.number(l, 1);
      if (bone.length < 0.0) throw Error::at(r.at(l, 1), "a bone length must not be negative");
    } else if (key == "axis") {
      bone.axis = r.vec3(l, 1);
      bone.axisOrder = axisOrder(r, l, 4);
    } else if (key == "dof") {
      for (std::size_t w = 1; w < l.words.size(); ++w) bone.dofs.push_back(parseDof(r, l, w));
    } else if (key.front() == ':' || key == "begin") {
      throw Error::at(r.at(l, 0), fmt::format("expected 'end' to close the bone that begins on line {}", bone.line));
    }
    // id, limits and their continuation lines, bodymass, cofmass: not needed
  }
  if (i == lines.size()) throw Error::at({r.file, bone.line, 0}, "bone has no 'end'");
  if (!named) throw Error::at({r.file, bone.line, 0}, "bone has no 'name'");
  if (out.find(bone.name) >= 0) throw Error::at({r.file, bone.line, 0}, fmt::format("bone '{}' is defined twice", bone.name));
  if (out.bones.size() >= kMaxBones) throw Error::at({r.file, bone.line, 0}, "too many bones");
  out.bones.push_back(std::move(bone));
  return i;
}

// ":hierarchy": "parent child child..." lines; bones are then reordered parents first.
std::size_t readHierarchy(const AsfReader& r, const std::vector<Line>& lines, std::size_t i, AsfSkeleton& out) {
  std::vector<int> parent(out.bones.size(), -2);  // -2: not yet placed
  std::size_t j = i + 1;
  if (j < lines.size() && lines[j].words[0].text == "begin") ++j;
  for (; j < lines.size() && lines[j].words[0].text != "end" && lines[j].words[0].text.front() != ':'; ++j) {
    const Line& l = lines[j];
    int p = -1;
    if (l.words[0].text != "root") {
      p = out.find(l.words[0].text);
      if (p < 0) throw Error::at(r.at(l, 0), fmt::format("unknown bone {} in the hierarchy", quoted(l.words[0].text)));
    }
    for (std::size_t w = 1; w < l.words.size(); ++w) {
      const int c = out.find(l.words[w].text);
      if (c < 0) throw Error::at(r.at(l, w), fmt::format("unknown bone {} in the hierarchy", quoted(l.words[w].text)));
      if (parent[static_cast<std::size_t>(c)] != -2)
        throw Error::at(r.at(l, w), fmt::format("bone {} has two parents", quoted(l.words[w].text)));
      parent[static_cast<std::size_t>(c)] = p;
    }
  }
  // Parents first: repeatedly place bones whose parent is placed (also rejects cycles).
  std::vector<int> newIndex(out.bones.size(), -1);
  std::vector<AsfBone> ordered;
  for (bool progress = true; progress;) {
    progress = false;
    for (std::size_t b = 0; b < out.bones.size(); ++b) {
      if (newIndex[b] >= 0) continue;
      const int p = parent[b];
      if (p == -2) throw Error::at({r.file, out.bones[b].line, 0}, fmt::format("bone '{}' is not in the hierarchy", out.bones[b].name));
      if (p >= 0 && newIndex[static_cast<std::size_t>(p)] < 0) continue;
      AsfBone bone = out.bones[b];
      bone.parent = p < 0 ? -1 : newIndex[static_cast<std::size_t>(p)];
      newIndex[b] = static_cast<int>(ordered.size());
      ordered.push_back(std::move(bone));
      progress = true;
    }
  }
  if (ordered.size() != out.bones.size()) throw Error::at(r.at(lines[i], 0), "the hierarchy has a cycle");
  out.bones = std::move(ordered);
  return (j < lines.size() && lines[j].words[0].text == "end") ? j : j - 1;
}

}  // namespace

int AsfSkeleton::find(std::string_view bone) const {
  for (std::size_t i = 0; i < bones.size(); ++i)
    if (bones[i].name == bone) return static_cast<int>(i);
  return -1;
}

AsfSkeleton parseAsf(std::string_view text, const std::string& name) {
  const AsfReader r{name};
  const std::vector<Line> lines = splitLines(text);
  AsfSkeleton out;
  out.source = name;
  out.rootOrder = {AcclaimDof::TX, AcclaimDof::TY, AcclaimDof::TZ, AcclaimDof::RX, AcclaimDof::RY, AcclaimDof::RZ};
  std::string section;
  bool sawBones = false, sawHierarchy = false;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const Line& l = lines[i];
    const std::string_view key = l.words[0].text;
    if (key.front() == ':') {
      section = std::string(key);
      if (section == ":name" && l.words.size() > 1) out.name = std::string(l.words[1].text);
      if (section == ":hierarchy") {
        if (!sawBones) throw Error::at(r.at(l, 0), "':hierarchy' before ':bonedata'");
        i = readHierarchy(r, lines, i, out);
        sawHierarchy = true;
        section.clear();
      }
      if (section == ":bonedata") sawBones = true;
      continue;
    }
    if (section == ":units") {
      if (key == "length") out.lengthScale = r.number(l, 1);
      if (key == "angle") {
        if (l.words.size() < 2 || (l.words[1].text != "deg" && l.words[1].text != "rad"))
          throw Error::at(r.at(l, 1), "expected 'angle deg' or 'angle rad'");
        out.degrees = l.words[1].text == "deg";
      }
    } else if (section == ":root") {
      if (key == "order") {
        out.rootOrder.clear();
        for (std::size_t w = 1; w < l.words.size(); ++w) out.rootOrder.push_back(parseDof(r, l, w));
      } else if (key == "axis") {
        out.rootAxisOrder = axisOrder(r, l, 1);
      } else if (key == "position") {
        out.rootPosition = r.vec3(l, 1);
      } else if (key == "orientation") {
        out.rootOrientation = r.vec3(l, 1);
      }
    } else if (section == ":bonedata") {
      if (key != "begin") throw Error::at(r.at(l, 0), fmt::format("expected 'begin', found {}", quoted(key)));
      i = readBone(r, lines, i, out);
    }
  }
  if (!sawBones || out.bones.empty()) throw Error(fmt::format("{}: no ':bonedata' section with bones", name));
  if (!sawHierarchy) throw Error(fmt::format("{}: no ':hierarchy' section", name));
  return out;
}

AsfSkeleton readAsf(const std::string& path) { return parseAsf(detail::readWholeFile(path), path); }

AmcMotion parseAmc(std::string_view text, const std::string& name, const AsfSkeleton& skeleton) {
  const AsfReader r{name};
  const std::vector<Line> lines = splitLines(text);
  AmcMotion out;
  out.source = name;
  out.valuesPerFrame = skeleton.rootOrder.size();
  for (const AsfBone& b : skeleton.bones) {
    out.boneFirstValue.push_back(out.valuesPerFrame);
    out.valuesPerFrame += b.dofs.size();
  }
  // Frames are counted first so the values are allocated once, and only for frames the
  // file really holds.
  std::size_t frames = 0;
  for (const Line& l : lines)
    if (l.words.size() == 1 && std::isdigit(static_cast<unsigned char>(l.words[0].text.front()))) ++frames;
  if (frames > kMaxAmcFrames) throw Error(fmt::format("{}: more than {} frames", name, kMaxAmcFrames));
  out.values.reserve(frames * out.valuesPerFrame);
  std::vector<bool> seen;
  long previousNumber = 0;
  for (const Line& l : lines) {
    const std::string_view key = l.words[0].text;
    if (key.front() == ':') continue;  // :FULLY-SPECIFIED, :DEGREES
    if (l.words.size() == 1 && std::isdigit(static_cast<unsigned char>(key.front()))) {
      long number = 0;
      const auto [end, ec] = std::from_chars(key.data(), key.data() + key.size(), number);
      if (ec != std::errc() || end != key.data() + key.size())
        throw Error::at(r.at(l, 0), fmt::format("expected a frame number, found {}", quoted(key)));
      // number - 1, not previousNumber + 1: the word starts with a digit, so number >= 0 and
      // cannot underflow, while a previous frame numbered LONG_MAX would overflow.
      if (out.frameCount > 0 && number - 1 != previousNumber)
        throw Error::at(r.at(l, 0), fmt::format("frame {} follows frame {}", number, previousNumber));
      previousNumber = number;
      ++out.frameCount;
      out.values.resize(out.frameCount * out.valuesPerFrame, 0.0);
      seen.assign(skeleton.bones.size() + 1, false);
      continue;
    }
    if (out.frameCount == 0) throw Error::at(r.at(l, 0), fmt::format("expected a frame number, found {}", quoted(key)));
    std::size_t first = 0, count = 0, slot = 0;
    if (key == "root") {
      count = skeleton.rootOrder.size();
    } else {
      const int b = skeleton.find(key);
      if (b < 0) throw Error::at(r.at(l, 0), fmt::format("unknown bone {} (not in the ASF skeleton)", quoted(key)));
      first = out.boneFirstValue[static_cast<std::size_t>(b)];
      count = skeleton.bones[static_cast<std::size_t>(b)].dofs.size();
      slot = static_cast<std::size_t>(b) + 1;
    }
    if (seen[slot]) throw Error::at(r.at(l, 0), fmt::format("bone {} appears twice in frame {}", quoted(key), previousNumber));
    seen[slot] = true;
    if (l.words.size() - 1 != count)
      throw Error::at(r.at(l, 0), fmt::format("bone {} has {} values, expected {} (its degrees of freedom)", quoted(key),
                                              l.words.size() - 1, count));
    double* values = out.values.data() + (out.frameCount - 1) * out.valuesPerFrame + first;
    for (std::size_t w = 1; w < l.words.size(); ++w) values[w - 1] = r.number(l, w);
  }
  if (out.frameCount == 0) throw Error(fmt::format("{}: no frames", name));
  return out;
}

AmcMotion readAmc(const std::string& path, const AsfSkeleton& skeleton) {
  return parseAmc(detail::readWholeFile(path), path, skeleton);
}

}  // namespace drape::formats
