#include "drape/motion/jointmap.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/formats/json_text.hpp"

namespace drape::motion {
namespace {

// Index just past the string token that starts at text[open] (a '"'), escapes skipped.
std::size_t endOfString(std::string_view text, std::size_t open) {
  std::size_t i = open + 1;
  while (i < text.size() && text[i] != '"') i += text[i] == '\\' ? 2 : 1;
  return std::min(i + 1, text.size());
}

// nlohmann's DOM keeps no positions, so the line of each key of the top-level "joints"
// object is found in one pass over the text (already parsed, so valid JSON: strings hold
// no raw newline). A search per key was quadratic: 6,500 keys in 64 KB took seconds.
// A key written twice keeps its first line.
std::map<std::string, int> jointKeyLines(std::string_view text) {
  std::map<std::string, int> lines;
  int line = 1;
  int depth = 0;
  bool inJoints = false;  // inside the top-level "joints" object
  std::string topKey;     // the last key of the top-level object
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
    } else if (c == '{' || c == '[') {
      if (++depth == 2) inJoints = c == '{' && topKey == "joints";
    } else if (c == '}' || c == ']') {
      if (depth == 2) inJoints = false;
      --depth;
    } else if (c == '"') {
      const std::size_t end = endOfString(text, i);
      const std::size_t next = text.find_first_not_of(" \t\r\n", end);
      const bool isKey = next != std::string_view::npos && text[next] == ':';
      const std::string_view token = text.substr(i, end - i);
      i = end - 1;
      if (isKey && (depth == 1 || (depth == 2 && inJoints))) {
        // The key as nlohmann decoded it (escapes resolved); no exception on the off chance
        // the token is not one string: that key just has no line.
        const nlohmann::json key = nlohmann::json::parse(token, nullptr, false);
        if (!key.is_string()) continue;
        if (depth == 1) topKey = key.get<std::string>();
        else lines.emplace(key.get<std::string>(), line);
      }
    }
  }
  return lines;
}

}  // namespace

const std::string* JointMap::avatarJointFor(std::string_view motionJoint) const {
  for (const JointMapEntry& e : entries)
    if (e.motionJoint == motionJoint) return &e.avatarJoint;
  return nullptr;
}

JointMap JointMap::identity(const Skeleton& skeleton) {
  JointMap map;
  map.name = "same names";
  for (const SkeletonJoint& j : skeleton.joints) map.entries.push_back({j.name, j.name, 0});
  return map;
}

JointMap parseJointMap(std::string_view json, const std::string& name) {
  const nlohmann::json doc = formats::parseJsonText(json, name);
  if (!doc.is_object() || !doc.contains("joints") || !doc["joints"].is_object())
    throw Error(fmt::format("{}: expected a JSON object with a \"joints\" object of motion joint -> avatar joint", name));
  JointMap map;
  map.source = name;
  map.name = doc.contains("name") && doc["name"].is_string() ? doc["name"].get<std::string>()
                                                             : std::filesystem::path(name).stem().string();
  const std::map<std::string, int> lines = jointKeyLines(json);
  for (const auto& [motionJoint, avatarJoint] : doc["joints"].items()) {
    const auto found = lines.find(motionJoint);
    const int line = found == lines.end() ? 0 : found->second;
    // A list: a chain of avatar joints (parent first) that together make the motion's one
    // bone, as rigs with twist joints split a thigh in two; all of them take its rotation.
    const bool chain = avatarJoint.is_array() && !avatarJoint.empty() &&
                       std::all_of(avatarJoint.begin(), avatarJoint.end(), [](const auto& j) { return j.is_string(); });
    if (!avatarJoint.is_string() && !chain)
      throw Error::at({name, line, 0},
                      fmt::format("the avatar joint for '{}' must be a string or a list of strings", motionJoint));
    if (chain) {
      for (const auto& joint : avatarJoint) map.entries.push_back({motionJoint, joint.get<std::string>(), line});
    } else {
      map.entries.push_back({motionJoint, avatarJoint.get<std::string>(), line});
    }
  }
  std::stable_sort(map.entries.begin(), map.entries.end(),
                   [](const JointMapEntry& a, const JointMapEntry& b) { return a.line < b.line; });
  return map;
}

JointMap readJointMap(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: no such file", path));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return parseJointMap(buffer.str(), path);
}

std::vector<JointMap> readJointMapDirectory(const std::string& directory) {
  std::vector<JointMap> maps;
  std::error_code ec;
  if (!std::filesystem::is_directory(directory, ec)) return maps;
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::directory_iterator(directory, ec))
    if (entry.path().extension() == ".json") paths.push_back(entry.path().string());
  std::sort(paths.begin(), paths.end());
  for (const std::string& p : paths) maps.push_back(readJointMap(p));
  return maps;
}

std::size_t matchedJointCount(const JointMap& map, const Skeleton& skeleton, const scene::Avatar& avatar) {
  return static_cast<std::size_t>(std::count_if(map.entries.begin(), map.entries.end(), [&](const JointMapEntry& e) {
    return skeleton.find(e.motionJoint) >= 0 && avatar.findJoint(e.avatarJoint) >= 0;
  }));
}

JointMap composeJointMaps(const JointMap& first, const JointMap& second) {
  JointMap composed;
  composed.name = first.name + " + " + second.name;
  composed.source = first.source;
  for (const JointMapEntry& a : first.entries)
    for (const JointMapEntry& b : second.entries)
      if (b.motionJoint == a.avatarJoint) composed.entries.push_back({a.motionJoint, b.avatarJoint, a.line});
  return composed;
}

JointMap chooseJointMap(const std::vector<JointMap>& candidates, const Skeleton& skeleton, const scene::Avatar& avatar) {
  JointMap best = JointMap::identity(skeleton);
  std::size_t bestCount = matchedJointCount(best, skeleton, avatar);
  const auto consider = [&](const JointMap& m) {
    const std::size_t count = matchedJointCount(m, skeleton, avatar);
    if (count > bestCount) {
      best = m;
      bestCount = count;
    }
  };
  for (const JointMap& m : candidates) consider(m);
  // Then pairs: a naming style's map onto drape's names followed by a rig's map from drape's
  // names onto its own (the Daz style onto MakeHuman's default rig). A pair wins only where
  // it pairs strictly more joints than every single map.
  for (const JointMap& a : candidates)
    for (const JointMap& b : candidates)
      if (&a != &b) consider(composeJointMaps(a, b));
  return best;
}

void checkJointMap(const JointMap& map, const Skeleton& skeleton, const scene::Avatar& avatar) {
  for (const JointMapEntry& e : map.entries) {
    if (skeleton.find(e.motionJoint) < 0)
      throw Error::at({map.source, e.line, 0}, fmt::format("unknown motion joint '{}' (not in the motion's skeleton)", e.motionJoint));
    if (avatar.findJoint(e.avatarJoint) < 0)
      throw Error::at({map.source, e.line, 0}, fmt::format("unknown avatar joint '{}' (not in avatar '{}')", e.avatarJoint, avatar.name));
  }
}

}  // namespace drape::motion
