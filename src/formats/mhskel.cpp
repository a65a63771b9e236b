#include "drape/formats/mhskel.hpp"

#include <algorithm>
#include <deque>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/formats/json_text.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

using nlohmann::json;

constexpr std::size_t kMaxVertexIndex = 100'000'000;

std::string stringOr(const json& j, const char* key, const std::string& fallback) {
  const auto it = j.find(key);
  return it != j.end() && it->is_string() ? it->get<std::string>() : fallback;
}

std::vector<std::string> stringList(const json& j, const char* key, const std::string& name, const std::string& bone) {
  std::vector<std::string> out;
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return out;
  if (!it->is_array()) throw Error(fmt::format("{}: bone '{}': \"{}\" must be a list of bone names", name, bone, key));
  for (const json& s : *it) {
    if (!s.is_string()) throw Error(fmt::format("{}: bone '{}': \"{}\" must be a list of bone names", name, bone, key));
    out.push_back(s.get<std::string>());
  }
  return out;
}

std::uint32_t vertexIndex(const json& v, const std::string& name, const std::string& what) {
  if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > static_cast<long long>(kMaxVertexIndex))
    throw Error(fmt::format("{}: {}: expected a vertex index (a whole number >= 0), found {}", name, what, v.dump()));
  return static_cast<std::uint32_t>(v.get<long long>());
}

}  // namespace

int MhSkeleton::find(std::string_view bone) const {
  for (std::size_t i = 0; i < bones.size(); ++i)
    if (bones[i].name == bone) return static_cast<int>(i);
  return -1;
}

MhSkeleton parseMhskel(std::string_view text, const std::string& name) {
  const json doc = parseJsonText(text, name);
  if (!doc.is_object() || !doc.contains("bones") || !doc["bones"].is_object() || !doc.contains("joints") ||
      !doc["joints"].is_object())
    throw Error(fmt::format("{}: expected a MakeHuman skeleton (a JSON object with \"bones\" and \"joints\")", name));
  MhSkeleton out;
  out.source = name;
  out.name = stringOr(doc, "name", "");
  for (const auto& [jointName, list] : doc["joints"].items()) {
    if (!list.is_array() || list.empty())
      throw Error(fmt::format("{}: joint '{}' must list at least one vertex index", name, jointName));
    std::vector<std::uint32_t>& v = out.joints[jointName];
    for (const json& i : list) v.push_back(vertexIndex(i, name, "joint '" + jointName + "'"));
  }
  std::vector<MhBone> unordered;
  for (const auto& [boneName, b] : doc["bones"].items()) {
    if (!b.is_object()) throw Error(fmt::format("{}: bone '{}' must be an object", name, boneName));
    MhBone bone;
    bone.name = boneName;
    const auto parent = b.find("parent");
    if (parent != b.end() && !parent->is_null()) {
      if (!parent->is_string()) throw Error(fmt::format("{}: bone '{}': \"parent\" must be a bone name or null", name, boneName));
      bone.parent = parent->get<std::string>();
    }
    bone.head = stringOr(b, "head", "");
    bone.tail = stringOr(b, "tail", "");
    for (const std::string* j : {&bone.head, &bone.tail})
      if (!out.joints.count(*j)) throw Error(fmt::format("{}: bone '{}' names joint '{}', which \"joints\" does not define", name, boneName, *j));
    bone.reference = stringList(b, "reference", name, boneName);
    bone.weightsReference = stringList(b, "weights_reference", name, boneName);
    unordered.push_back(std::move(bone));
  }
  // Breadth-first from the root, as MakeHuman orders bones.
  std::deque<std::string> queue;
  for (const MhBone& b : unordered) {
    if (!b.parent.empty()) continue;
    if (!queue.empty()) throw Error(fmt::format("{}: two root bones ('{}' and '{}')", name, queue.front(), b.name));
    queue.push_back(b.name);
  }
  if (queue.empty()) throw Error(fmt::format("{}: no root bone (a bone whose parent is null)", name));
  while (!queue.empty()) {
    const std::string current = queue.front();
    queue.pop_front();
    for (const MhBone& b : unordered)
      if (b.name == current) out.bones.push_back(b);
    for (const MhBone& b : unordered)
      if (b.parent == current) queue.push_back(b.name);
  }
  if (out.bones.size() != unordered.size()) {
    for (const MhBone& b : unordered)
      if (out.find(b.name) < 0)
        throw Error(fmt::format("{}: bone '{}' is not reachable from the root (unknown parent '{}' or a cycle)", name, b.name, b.parent));
  }
  return out;
}

MhSkeleton readMhskel(const std::string& path) { return parseMhskel(detail::readWholeFile(path, 64u << 20), path); }

MhWeights parseMhw(std::string_view text, const std::string& name) {
  const json doc = parseJsonText(text, name);
  if (!doc.is_object() || !doc.contains("weights") || !doc["weights"].is_object())
    throw Error(fmt::format("{}: expected MakeHuman weights (a JSON object with \"weights\")", name));
  MhWeights out;
  out.source = name;
  for (const auto& [bone, pairs] : doc["weights"].items()) {
    if (!pairs.is_array()) throw Error(fmt::format("{}: weights of bone '{}' must be a list of [vertex, weight]", name, bone));
    auto& list = out.weights[bone];
    for (const json& p : pairs) {
      if (!p.is_array() || p.size() != 2 || !p[1].is_number())
        throw Error(fmt::format("{}: weights of bone '{}': expected [vertex, weight], found {}", name, bone, p.dump().substr(0, 60)));
      const double w = p[1].get<double>();
      if (!(w >= 0.0) || w > 1e6) throw Error(fmt::format("{}: bone '{}': weight {} is not a finite number >= 0", name, bone, w));
      list.emplace_back(vertexIndex(p[0], name, "weights of bone '" + bone + "'"), static_cast<float>(w));
    }
  }
  return out;
}

MhWeights readMhw(const std::string& path) { return parseMhw(detail::readWholeFile(path, 256u << 20), path); }

std::map<std::string, std::string> readMakeHumanWeightFold(const std::string& path, bool neckFix) {
  const std::string text = detail::readWholeFile(path, 64u << 20);
  const json doc = parseJsonText(text, path);
  const char* key = neckFix ? "default_bone_weights_to_bvh_neck_fix" : "default_bone_weights_to_bvh";
  if (!doc.is_object() || !doc.contains(key) || !doc[key].is_object())
    throw Error(fmt::format("{}: expected an object \"{}\" of default bone -> BVH joint", path, key));
  std::map<std::string, std::string> fold;
  for (const auto& [bone, joint] : doc[key].items()) {
    if (!joint.is_string()) throw Error(fmt::format("{}: \"{}\": '{}' must map to a joint name", path, key, bone));
    fold[bone] = joint.get<std::string>();
  }
  // The neck-fix table lists only the neck bones it changes; the rest come from the default.
  if (neckFix) {
    for (const auto& [bone, joint] : readMakeHumanWeightFold(path, false)) fold.emplace(bone, joint);
  }
  return fold;
}

}  // namespace drape::formats
