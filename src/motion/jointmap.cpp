#include "drape/motion/jointmap.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"

namespace drape::motion {
namespace {

// 1-based line and column of byte offset `at` in `text`.
SourcePos positionOf(std::string_view text, std::size_t at, const std::string& name) {
  SourcePos pos{name, 1, 1};
  for (std::size_t i = 0; i < std::min(at, text.size()); ++i) {
    if (text[i] == '\n') {
      ++pos.line;
      pos.column = 1;
    } else {
      ++pos.column;
    }
  }
  return pos;
}

// nlohmann's DOM keeps no positions, so an entry's line is found by searching for its
// quoted key after the "joints" key (names are unique keys of one object).
int lineOfKey(std::string_view text, const std::string& key) {
  const std::size_t joints = text.find("\"joints\"");
  const std::size_t at = text.find("\"" + key + "\"", joints == std::string_view::npos ? 0 : joints);
  if (at == std::string_view::npos) return 0;
  return static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n')) + 1;
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
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(json.begin(), json.end());
  } catch (const nlohmann::json::parse_error& e) {
    std::string what = e.what();
    if (const auto colon = what.find(": "); colon != std::string::npos) what = what.substr(colon + 2);
    throw Error::at(positionOf(json, e.byte > 0 ? e.byte - 1 : 0, name), what);
  } catch (const nlohmann::json::exception& e) {  // out_of_range: a number too large for a double
    throw Error(fmt::format("{}: bad JSON ({})", name, e.what()));
  }
  if (!doc.is_object() || !doc.contains("joints") || !doc["joints"].is_object())
    throw Error(fmt::format("{}: expected a JSON object with a \"joints\" object of motion joint -> avatar joint", name));
  JointMap map;
  map.source = name;
  map.name = doc.contains("name") && doc["name"].is_string() ? doc["name"].get<std::string>()
                                                             : std::filesystem::path(name).stem().string();
  std::string text(json);
  for (const auto& [motionJoint, avatarJoint] : doc["joints"].items()) {
    const int line = lineOfKey(text, motionJoint);
    if (!avatarJoint.is_string())
      throw Error::at({name, line, 0}, fmt::format("the avatar joint for '{}' must be a string", motionJoint));
    map.entries.push_back({motionJoint, avatarJoint.get<std::string>(), line});
  }
  std::sort(map.entries.begin(), map.entries.end(), [](const JointMapEntry& a, const JointMapEntry& b) { return a.line < b.line; });
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

JointMap chooseJointMap(const std::vector<JointMap>& candidates, const Skeleton& skeleton, const scene::Avatar& avatar) {
  JointMap best = JointMap::identity(skeleton);
  std::size_t bestCount = matchedJointCount(best, skeleton, avatar);
  for (const JointMap& m : candidates) {
    const std::size_t count = matchedJointCount(m, skeleton, avatar);
    if (count > bestCount) {
      best = m;
      bestCount = count;
    }
  }
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
