#include "drape/motion/jointmap.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/motion/standing.hpp"
#include "drape/formats/json_text.hpp"
#include "drape/scene/humanoid.hpp"

namespace drape::motion {
namespace {

// Where a joint entry was written: its key, its value, and each string inside the value.
struct EntryPositions {
  TextPos key;
  TextPos value;
  std::vector<TextPos> strings;
};

// The place of text[at], counting from `from` (whose place is `start`).
TextPos advance(std::string_view text, std::size_t from, TextPos start, std::size_t at) {
  const SourcePos p = formats::advancePosition(text, from, {{}, start.line, start.column}, at);
  return {p.line, p.column};
}

// nlohmann's DOM keeps no positions, so the key of each entry of the top-level "joints"
// object, and the strings of its value, are located in one pass over the text (already
// parsed, so valid JSON: strings hold no raw newline). A search per key was quadratic:
// 6,500 keys in 64 KB took seconds.
std::map<std::string, EntryPositions> jointEntryPositions(std::string_view text) {
  std::map<std::string, EntryPositions> positions;
  TextPos here{1, 1};        // of the string being read
  std::size_t lineStart = 0;  // index of its line's first character
  int depth = 0;
  bool inJoints = false;                // inside the top-level "joints" object
  std::string topKey;                   // the last key of the top-level object
  EntryPositions* current = nullptr;    // the entry whose value is being read
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++here.line;
      lineStart = i + 1;
    } else if (c == '{' || c == '[') {
      if (++depth == 2) inJoints = c == '{' && topKey == "joints";
    } else if (c == '}' || c == ']') {
      if (depth == 2) inJoints = false;
      --depth;
    } else if (c == '"') {
      here.column = static_cast<int>(i - lineStart) + 1;
      const std::size_t end = formats::endOfJsonString(text, i);
      const std::size_t next = text.find_first_not_of(" \t\r\n", end);
      const bool isKey = next != std::string_view::npos && text[next] == ':';
      const std::string_view token = text.substr(i, end - i);
      i = end - 1;
      if (!isKey) {
        if (inJoints && current != nullptr && depth <= 3) current->strings.push_back(here);
        continue;
      }
      if (depth != 1 && !(depth == 2 && inJoints)) continue;
      // The key as nlohmann decoded it (escapes resolved); no exception on the off chance
      // the token is not one string: that key just has no place.
      const nlohmann::json key = nlohmann::json::parse(token, nullptr, false);
      if (!key.is_string()) continue;
      if (depth == 1) {
        topKey = key.get<std::string>();
        continue;
      }
      const std::size_t value = std::min(text.find_first_not_of(" \t\r\n", next + 1), text.size());
      const TextPos valuePos = advance(text, end - token.size(), here, value);
      // A key written twice was refused by parseJsonText.
      current = &positions.emplace(key.get<std::string>(), EntryPositions{here, valuePos, {}}).first->second;
    }
  }
  return positions;
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
  for (const SkeletonJoint& j : skeleton.joints) map.entries.push_back({j.name, j.name, {}, {}});
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
  const std::map<std::string, EntryPositions> positions = jointEntryPositions(json);
  for (const auto& [motionJoint, avatarJoint] : doc["joints"].items()) {
    const auto found = positions.find(motionJoint);
    const EntryPositions where = found == positions.end() ? EntryPositions{} : found->second;
    // The k-th avatar joint's own place where the scan found it, else the value's.
    const auto valueAt = [&](std::size_t k) { return k < where.strings.size() ? where.strings[k] : where.value; };
    // A list: a chain of avatar joints (parent first) that together make the motion's one
    // bone, as rigs with twist joints split a thigh in two; all of them take its rotation.
    const bool chain = avatarJoint.is_array() && !avatarJoint.empty() &&
                       std::all_of(avatarJoint.begin(), avatarJoint.end(), [](const auto& j) { return j.is_string(); });
    if (!avatarJoint.is_string() && !chain)
      throw Error::at({name, where.value.line, where.value.column},
                      fmt::format("the avatar joint for '{}' must be a string or a list of strings", motionJoint));
    if (chain) {
      for (std::size_t k = 0; k < avatarJoint.size(); ++k)
        map.entries.push_back({motionJoint, avatarJoint[k].get<std::string>(), where.key, valueAt(k)});
    } else {
      map.entries.push_back({motionJoint, avatarJoint.get<std::string>(), where.key, valueAt(0)});
    }
  }
  std::stable_sort(map.entries.begin(), map.entries.end(),
                   [](const JointMapEntry& a, const JointMapEntry& b) { return a.at.line < b.at.line; });
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
      if (b.motionJoint == a.avatarJoint) composed.entries.push_back({a.motionJoint, b.avatarJoint, a.at, a.avatarAt});
  return composed;
}

JointMap reverseJointMap(const JointMap& map) {
  JointMap reversed;
  reversed.name = map.name + " (reversed)";
  reversed.source = map.source;
  std::set<std::string_view> drivers, driven;
  for (const JointMapEntry& e : map.entries) {
    if (drivers.count(e.avatarJoint) != 0 || driven.count(e.motionJoint) != 0) continue;
    drivers.insert(e.avatarJoint);
    driven.insert(e.motionJoint);
    reversed.entries.push_back({e.avatarJoint, e.motionJoint, e.avatarAt, e.at});
  }
  return reversed;
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
  // The maps as written first, so that a reversed one wins only where it pairs more: the
  // choices for drape's own names and every style's stay what they were.
  std::vector<JointMap> maps = candidates;
  for (const JointMap& m : candidates) maps.push_back(reverseJointMap(m));
  for (const JointMap& m : maps) consider(m);
  // Then pairs: a naming style's map onto drape's names followed by a rig's map from drape's
  // names onto its own (the Daz style onto MakeHuman's default rig), or by a style's map
  // reversed (the MotionBuilder style onto an H-Anim humanoid, its index finger too). A
  // pair wins only where it pairs strictly more joints than every single map.
  for (const JointMap& a : maps)
    for (const JointMap& b : maps)
      if (&a != &b) consider(composeJointMaps(a, b));
  return best;
}

void checkJointMap(const JointMap& map, const Skeleton& skeleton, const scene::Avatar& avatar) {
  for (const JointMapEntry& e : map.entries) {
    if (skeleton.find(e.motionJoint) < 0)
      throw Error::at({map.source, e.at.line, e.at.column}, fmt::format("unknown motion joint '{}' (not in the motion's skeleton)", e.motionJoint));
    if (avatar.findJoint(e.avatarJoint) < 0)
      throw Error::at({map.source, e.avatarAt.line, e.avatarAt.column}, fmt::format("unknown avatar joint '{}' (not in avatar '{}')", e.avatarJoint, avatar.name));
  }
}

namespace {

/// Pairs two skeletons' shapes into a map's entries.
struct ShapePairing {
  const Skeleton& skeleton;
  const scene::Avatar& avatar;
  const std::vector<scene::JointAt>& motionAt;
  JointMap map;

  void pair(int motionJoint, int avatarJoint) {
    map.entries.push_back({skeleton.joints[static_cast<std::size_t>(motionJoint)].name,
                           avatar.joints[static_cast<std::size_t>(avatarJoint)].name,
                           {},
                           {}});
  }
  /// A bone: the motion's last joint of it, whose child ends the bone and whose world
  /// rotation therefore points it (a Daz thigh's lThigh after lButtock, a twist joint after
  /// its bone's first), drives the avatar's whole chain.
  void bone(const scene::JointChain& motion, const scene::JointChain& avatarChain) {
    if (motion.empty()) return;
    for (int a : avatarChain) pair(motion.back(), a);
  }
  /// A run of joints between two fixed ones (the spine between the pelvis and the chest,
  /// `motion` and `avatarRun` ending at the chest, `motionBase` and `avatarBase` below
  /// them): joint for joint where the two runs are as long, else each avatar joint driven by
  /// the motion's joint (the base among them) nearest its fraction of the run's height, and
  /// the top by the top. The runs' joints seldom stand where each other's do (a Daz spine
  /// has two joints where MakeHuman's default rig has five), so the pairing is by height.
  void run(const scene::JointChain& motion, int motionBase, const scene::JointChain& avatarRun, int avatarBase) {
    if (motion.empty() || avatarRun.empty()) return;
    if (motion.size() == avatarRun.size()) {
      for (std::size_t i = 0; i < motion.size(); ++i) pair(motion[i], avatarRun[i]);
      return;
    }
    const auto fractions = [](const scene::JointChain& chain, int base, const auto& yOf) {
      const double y0 = yOf(base), height = yOf(chain.back()) - y0;
      std::vector<double> f;
      for (int j : chain) f.push_back(height > 0 ? (yOf(j) - y0) / height : 1.0);
      return f;
    };
    const auto motionY = [&](int j) { return motionAt[static_cast<std::size_t>(j)].rest.y(); };
    const auto avatarY = [&](int j) { return avatar.joints[static_cast<std::size_t>(j)].restCenter.y(); };
    const std::vector<double> fm = fractions(motion, motionBase, motionY);
    const std::vector<double> fa = fractions(avatarRun, avatarBase, avatarY);
    for (std::size_t a = 0; a < avatarRun.size(); ++a) {
      int driver = motionBase;
      double miss = std::abs(fa[a]);  // the base's own fraction is 0
      for (std::size_t m = 0; m < motion.size(); ++m)
        if (std::abs(fm[m] - fa[a]) < miss) {
          miss = std::abs(fm[m] - fa[a]);
          driver = motion[m];
        }
      if (a + 1 == avatarRun.size()) driver = motion.back();
      pair(driver, avatarRun[a]);
    }
  }
  void limb(const scene::HumanoidLimb& motion, const scene::HumanoidLimb& avatarLimb) {
    if (!motion.base.empty() && !avatarLimb.base.empty()) bone(motion.base, avatarLimb.base);
    bone(motion.upper, avatarLimb.upper);
    bone(motion.lower, avatarLimb.lower);
    bone(motion.end, avatarLimb.end);
    if (!motion.tip.empty() && !avatarLimb.tip.empty()) bone(motion.tip, avatarLimb.tip);
  }
};

}  // namespace

std::optional<JointMap> shapeJointMap(const Skeleton& skeleton, const scene::Avatar& avatar, std::string* whyNot) {
  const std::vector<scene::JointAt> motionAt = jointsAt(skeleton);
  std::string why;
  const std::optional<scene::Humanoid> m = scene::findHumanoid(motionAt, &why);
  if (!m) {
    if (whyNot) *whyNot = "the motion's skeleton: " + why;
    return std::nullopt;
  }
  const std::vector<scene::JointAt> avatarAt = scene::jointsAt(avatar);
  const std::optional<scene::Humanoid> a = scene::findHumanoid(avatarAt, &why);
  if (!a) {
    if (const std::optional<scene::Upright> u = scene::uprightAlongAnotherAxis(avatarAt))
      why = fmt::format("it stands along {}, not along +y as drape's scenes do; {}", u->axis, u->standUpAdvice());
    if (whyNot) *whyNot = "the avatar's skeleton: " + why;
    return std::nullopt;
  }
  ShapePairing p{skeleton, avatar, motionAt, {}};
  p.map.name = "by shape";
  if (!m->abovePelvis.empty() && !a->abovePelvis.empty()) p.pair(m->abovePelvis.front(), a->abovePelvis.front());
  p.pair(m->pelvis, a->pelvis);
  if (!m->hips.empty() && !a->hips.empty()) p.bone(m->hips, a->hips);
  p.run(m->spine, m->pelvis, a->spine, a->pelvis);
  p.run(m->neck, m->chest(), a->neck, a->chest());
  for (std::size_t s = 0; s < 2; ++s) p.limb(m->legs[s], a->legs[s]);
  for (std::size_t s = 0; s < 2; ++s) p.limb(m->arms[s], a->arms[s]);
  return std::move(p.map);
}

bool drivesTheTrunk(const JointMap& map, const Skeleton& skeleton, const scene::Avatar& avatar) {
  std::set<std::string_view> driven;
  for (const JointMapEntry& e : map.entries)
    if (skeleton.find(e.motionJoint) >= 0) driven.insert(e.avatarJoint);
  for (const scene::Joint& j : avatar.joints)
    if (j.parent < 0 && driven.count(j.name) != 0) return true;
  const std::optional<scene::Humanoid> h = scene::findHumanoid(scene::jointsAt(avatar));
  return h && driven.count(avatar.joints[static_cast<std::size_t>(h->pelvis)].name) != 0;
}

}  // namespace drape::motion
