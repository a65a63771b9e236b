#include "drape/formats/bvh.hpp"

#include <algorithm>
#include <optional>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

using detail::quoted;
using detail::WordScanner;
using Word = WordScanner::Word;

constexpr std::size_t kMaxBvhJoints = 10'000;
constexpr std::size_t kMaxDepth = 256;

void expectWord(WordScanner& s, std::string_view wanted) {
  const Word w = s.next();
  if (w.text != wanted) throw Error::at(s.pos(w), fmt::format("expected '{}', found {}", wanted, quoted(w.text)));
}

Vec3 readOffset(WordScanner& s) {
  expectWord(s, "OFFSET");
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = detail::parseNumber(s, s.next());
  return v;
}

BvhChannel parseChannel(const WordScanner& s, const Word& w) {
  static constexpr std::pair<std::string_view, BvhChannel> kNames[] = {
      {"Xposition", BvhChannel::Xposition}, {"Yposition", BvhChannel::Yposition},
      {"Zposition", BvhChannel::Zposition}, {"Xrotation", BvhChannel::Xrotation},
      {"Yrotation", BvhChannel::Yrotation}, {"Zrotation", BvhChannel::Zrotation}};
  for (const auto& [name, channel] : kNames)
    if (w.text == name) return channel;
  throw Error::at(s.pos(w), fmt::format("unknown channel {} (expected Xposition..Zrotation)", quoted(w.text)));
}

// Reads "CHANNELS n name..." for one joint.
void readChannels(WordScanner& s, BvhJoint& joint, std::size_t& channelTotal) {
  expectWord(s, "CHANNELS");
  const Word countWord = s.next();
  const std::size_t n = detail::parseCount(s, countWord, 6, "channel count");
  for (std::size_t i = 0; i < n; ++i) joint.channels.push_back(parseChannel(s, s.next()));
  joint.firstChannel = channelTotal;
  channelTotal += n;
}

// HIERARCHY ... up to MOTION: an explicit stack instead of recursion, so deep nesting in a
// hostile file is an error message rather than a stack overflow.
void readHierarchy(WordScanner& s, BvhFile& out) {
  expectWord(s, "HIERARCHY");
  const Word root = s.next();
  if (root.text != "ROOT") throw Error::at(s.pos(root), fmt::format("expected 'ROOT', found {}", quoted(root.text)));
  std::vector<int> open;  // joints whose '}' is pending; -2 marks an End Site block
  auto beginJoint = [&](const Word& keyword) {
    if (out.joints.size() >= kMaxBvhJoints) throw Error::at(s.pos(keyword), fmt::format("more than {} joints", kMaxBvhJoints));
    if (open.size() >= kMaxDepth) throw Error::at(s.pos(keyword), fmt::format("joints nested deeper than {}", kMaxDepth));
    const Word name = s.next();
    if (name.text.empty() || name.text == "{") throw Error::at(s.pos(name), "expected a joint name");
    BvhJoint joint;
    joint.name = std::string(name.text);
    joint.parent = open.empty() ? -1 : open.back();
    joint.line = keyword.line;
    expectWord(s, "{");
    joint.offset = readOffset(s);
    readChannels(s, joint, out.channelCount);
    out.joints.push_back(std::move(joint));
    open.push_back(static_cast<int>(out.joints.size() - 1));
  };
  beginJoint(root);
  while (!open.empty()) {
    const Word w = s.next();
    if (w.text == "JOINT") {
      beginJoint(w);
    } else if (w.text == "End") {
      expectWord(s, "Site");
      expectWord(s, "{");
      const Vec3 site = readOffset(s);
      expectWord(s, "}");
      BvhJoint& parent = out.joints[static_cast<std::size_t>(open.back())];
      if (!parent.endSite) parent.endSite = site;  // a second End Site adds nothing drape uses
    } else if (w.text == "}") {
      open.pop_back();
    } else {
      throw Error::at(s.pos(w), fmt::format("expected 'JOINT', 'End Site' or '}}', found {}", quoted(w.text)));
    }
  }
  // Joint names must be unique: maps and avatars refer to joints by name.
  for (std::size_t i = 0; i < out.joints.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (out.joints[i].name == out.joints[j].name)
        throw Error::at({out.source, out.joints[i].line, 0}, fmt::format("joint '{}' is defined twice", out.joints[i].name));
}

// "Frames: N" and "Frame Time: T", then the header checks, before any value is stored.
void readMotionHeader(WordScanner& s, BvhFile& out) {
  expectWord(s, "MOTION");
  Word w = s.next();
  std::size_t frames = 0;
  Word framesWord;
  if (w.text == "Frames:") {
    framesWord = s.next();
  } else if (w.text.size() > 7 && w.text.substr(0, 7) == "Frames:") {
    framesWord = w;
    framesWord.text.remove_prefix(7);
  } else {
    throw Error::at(s.pos(w), fmt::format("expected 'Frames:', found {}", quoted(w.text)));
  }
  frames = detail::parseCount(s, framesWord, kMaxBvhFrames, "Frames:");
  expectWord(s, "Frame");
  w = s.next();
  Word timeWord;
  if (w.text == "Time:") {
    timeWord = s.next();
  } else if (w.text.size() > 5 && w.text.substr(0, 5) == "Time:") {
    timeWord = w;
    timeWord.text.remove_prefix(5);
  } else {
    throw Error::at(s.pos(w), fmt::format("expected 'Time:', found {}", quoted(w.text)));
  }
  const double frameTime = detail::parseNumber(s, timeWord);
  if (!(frameTime > 0.0)) throw Error::at(s.pos(timeWord), fmt::format("Frame Time must be > 0 s, found {}", timeWord.text));
  if (frameTime < 1e-6 || frameTime > 3600.0)
    throw Error::at(s.pos(timeWord), fmt::format("Frame Time {} s is outside 1e-6..3600 s", timeWord.text));
  if (out.channelCount == 0) throw Error::at(s.pos(framesWord), "the skeleton has no channels, so frames cannot hold motion");
  out.frameCount = frames;
  out.frameTime = frameTime;
}

// One frame per line, exactly channelCount values each. Storage is reserved for no more
// values than the rest of the file can hold (each takes at least two bytes, "0 "), so a
// header that promises more frames than the file has costs nothing before the error.
void readFrames(WordScanner& s, std::string_view text, BvhFile& out) {
  const std::size_t needed = out.frameCount * out.channelCount;
  const std::size_t bytesLeft = text.size() - std::min(text.size(), s.offset());
  out.values.reserve(std::min(needed, bytesLeft / 2 + 1));
  std::size_t frame = 0;
  while (!s.atEnd()) {
    const Word first = s.peek();
    if (frame == out.frameCount)
      throw Error::at(s.pos(first), fmt::format("more values than the {} frames declared", out.frameCount));
    if (frame == 0) out.firstFrameLine = first.line;
    const int line = first.line;
    std::size_t count = 0;
    while (!s.atEnd() && s.peek().line == line) {
      const Word w = s.next();
      if (count < out.channelCount) out.values.push_back(detail::parseNumber(s, w));
      ++count;
    }
    if (count != out.channelCount)
      throw Error::at({out.source, line, 0}, fmt::format("frame {} has {} values, expected {} (one per channel)",
                                                         frame + 1, count, out.channelCount));
    ++frame;
  }
  if (frame < out.frameCount)
    throw Error::at(s.here(), fmt::format("the file ends after {} of the {} frames declared", frame, out.frameCount));
}

}  // namespace

const char* bvhChannelName(BvhChannel channel) {
  switch (channel) {
    case BvhChannel::Xposition: return "Xposition";
    case BvhChannel::Yposition: return "Yposition";
    case BvhChannel::Zposition: return "Zposition";
    case BvhChannel::Xrotation: return "Xrotation";
    case BvhChannel::Yrotation: return "Yrotation";
    case BvhChannel::Zrotation: return "Zrotation";
  }
  return "?";
}

namespace {

// The hierarchy and the MOTION header, which a file and a stream both begin with.
BvhFile readHeader(WordScanner& s, const std::string& name) {
  BvhFile out;
  out.source = name;
  readHierarchy(s, out);
  readMotionHeader(s, out);
  return out;
}

}  // namespace

BvhFile parseBvh(std::string_view text, const std::string& name) {
  WordScanner s(text, name);
  BvhFile out = readHeader(s, name);
  readFrames(s, text, out);
  return out;
}

BvhFile parseBvhHeader(std::string_view text, const std::string& name) {
  WordScanner s(text, name);
  BvhFile out = readHeader(s, name);
  if (!s.atEnd()) {
    const Word w = s.next();
    throw Error::at(s.pos(w), fmt::format("expected the header to end after 'Frame Time:', found {}", quoted(w.text)));
  }
  return out;
}

bool endsBvhHeader(std::string_view line) {
  const std::vector<detail::LineWord> words = detail::lineWords(line, 3);
  if (words.empty() || words[0].text != "Frame") return false;
  return words.size() > 1 && words[1].text.substr(0, 5) == "Time:";
}

std::optional<std::size_t> bvhHeaderLength(std::string_view text) {
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const bool last = endsBvhHeader(text.substr(at, end - at));
    at = std::min(end + 1, text.size());
    if (last) return at;
  }
  return std::nullopt;
}

void parseBvhFrameLine(std::string_view line, const std::string& name, int lineNumber, std::span<double> out) {
  const std::vector<detail::LineWord> words = detail::lineWords(line, out.size() + 1);
  for (std::size_t i = 0; i < words.size() && i < out.size(); ++i) {
    const std::optional<double> v = detail::finiteNumber(words[i].text);
    if (!v)
      throw Error::at({name, lineNumber, words[i].column},
                      fmt::format("expected a number, found {}", quoted(words[i].text)));
    out[i] = *v;
  }
  if (words.size() != out.size()) {
    const int column = words.size() > out.size() ? words[out.size()].column : static_cast<int>(line.size()) + 1;
    throw Error::at({name, lineNumber, column},
                    fmt::format("expected {} values (one per channel), found {}", out.size(),
                                words.size() > out.size() ? "more" : std::to_string(words.size())));
  }
}

BvhFile readBvh(const std::string& path) { return parseBvh(detail::readWholeFile(path), path); }

}  // namespace drape::formats
