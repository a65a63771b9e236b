#include "drape/scene/avatar_makehuman.hpp"

#include <algorithm>
#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/formats/mhskel.hpp"
#include "drape/formats/obj.hpp"
#include "drape/scene/avatar_segment.hpp"

namespace drape::scene {
namespace {

std::string join(const std::string& dir, const std::string& file) { return (std::filesystem::path(dir) / file).string(); }

// A joint's position is the mean of its vertices (MakeHuman's rule).
Vec3 jointPosition(const formats::MhSkeleton& skel, const std::string& joint, const std::vector<Vec3>& vertices) {
  const auto& list = skel.joints.at(joint);
  Vec3 sum = Vec3::Zero();
  for (std::uint32_t v : list) {
    if (v >= vertices.size())
      throw Error(fmt::format("{}: joint '{}' uses vertex {}, but the base mesh has {} vertices", skel.source, joint, v,
                              vertices.size()));
    sum += vertices[v];
  }
  return sum / static_cast<double>(list.size());
}

// Default-rig bone -> avatar joint index. The cmu_mb fold table names BVH joints, which are
// cmu_mb bone names except the index fingers; other rigs keep the bones they share with the
// default rig and fold the others through their "reference" lists.
std::map<std::string, int> foldTable(const formats::MhSkeleton& skel, const Avatar& avatar,
                                     const std::map<std::string, std::string>& bvhFold) {
  std::map<std::string, int> fold;
  for (const auto& [bone, bvhJoint] : bvhFold) {
    std::string name = bvhJoint;
    if (avatar.findJoint(name) < 0 && name.find("HandIndex1") != std::string::npos)
      name.replace(name.find("HandIndex1"), 10, "HandFinger1");
    const int j = avatar.findJoint(name);
    if (j >= 0) fold[bone] = j;
  }
  if (fold.size() < bvhFold.size() / 2) {  // not cmu_mb: the rig's own bones, then their references
    fold.clear();
    // The weights name the default rig's bones: a rig that has them (the default rig
    // itself) takes its weights as they are.
    for (std::size_t b = 0; b < skel.bones.size(); ++b) fold.emplace(skel.bones[b].name, static_cast<int>(b));
    for (std::size_t b = 0; b < skel.bones.size(); ++b) {
      const auto& refs = skel.bones[b].weightsReference.empty() ? skel.bones[b].reference : skel.bones[b].weightsReference;
      for (const std::string& r : refs) fold.emplace(r, static_cast<int>(b));
    }
  }
  return fold;
}

// Per-vertex weights folded to the avatar's joints, normalised, top four kept.
SkinnedMesh foldWeights(const mesh::TriMesh& body, const formats::MhWeights& weights, const std::map<std::string, int>& fold,
                        std::size_t jointCount) {
  const std::size_t n = body.positions.size();
  std::vector<std::vector<std::pair<int, float>>> perVertex(n);
  for (const auto& [bone, list] : weights.weights) {
    const auto it = fold.find(bone);
    if (it == fold.end()) continue;  // unreferenced bones (face, tongue) carry no body weight
    for (const auto& [v, w] : list) {
      if (v >= n) continue;  // helper geometry beyond the kept vertices
      auto& entries = perVertex[v];
      auto e = std::find_if(entries.begin(), entries.end(), [&](const auto& p) { return p.first == it->second; });
      if (e == entries.end()) entries.emplace_back(it->second, w);
      else e->second += w;
    }
  }
  SkinnedMesh skin;
  skin.mesh = body;
  skin.joints.assign(n, {0, 0, 0, 0});
  skin.weights.assign(n, {0.f, 0.f, 0.f, 0.f});
  for (std::size_t v = 0; v < n; ++v) {
    auto& entries = perVertex[v];
    std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    if (entries.empty()) entries.emplace_back(0, 1.f);  // MakeHuman gives unweighted vertices to the root
    float total = 0.f;
    for (std::size_t k = 0; k < std::min<std::size_t>(4, entries.size()); ++k) total += entries[k].second;
    for (std::size_t k = 0; k < std::min<std::size_t>(4, entries.size()); ++k) {
      skin.joints[v][k] = static_cast<std::uint16_t>(std::min<std::size_t>(static_cast<std::size_t>(entries[k].first), jointCount - 1));
      skin.weights[v][k] = entries[k].second / total;
    }
  }
  return skin;
}

}  // namespace

Avatar buildMakeHumanAvatar(const MakeHumanAvatarOptions& options) {
  const std::string meshPath = join(options.directory, options.meshFile);
  const formats::MhSkeleton skel = formats::readMhskel(join(options.directory, options.skeletonFile));
  const formats::MhWeights weights = formats::readMhw(join(options.directory, options.weightsFile));
  const auto bvhFold = formats::readMakeHumanWeightFold(join(options.directory, options.weightFoldFile), options.neckFix);

  // All vertices in file order (rig indices count every `v` line), faces of `g body` only.
  formats::ObjReadOptions objOptions;
  objOptions.metresPerUnit = options.metresPerUnit;
  objOptions.groups = {options.meshGroup};
  objOptions.keepUnusedVertices = true;
  mesh::TriMesh body = formats::readObj(meshPath, objOptions);
  // Drop the helper and joint-cube vertices after the last body vertex (they follow it).
  std::uint32_t last = 0;
  for (const mesh::Triangle& t : body.triangles) last = std::max({last, t[0], t[1], t[2]});
  const std::vector<Vec3> allVertices = body.positions;
  body.positions.resize(last + 1);
  body.name = options.skeletonFile;

  Avatar avatar;
  avatar.name = skel.name.empty() ? "makehuman" : "makehuman_" + skel.name;
  avatar.source = join(options.directory, options.skeletonFile);
  for (const formats::MhBone& b : skel.bones) {
    Joint j;
    j.name = b.name;
    j.parent = b.parent.empty() ? -1 : avatar.findJoint(b.parent);
    j.restCenter = jointPosition(skel, b.head, allVertices);
    avatar.joints.push_back(j);
  }
  avatar.skin = foldWeights(body, weights, foldTable(skel, avatar, bvhFold), avatar.joints.size());
  segmentSkinnedAvatar(avatar);
  return avatar;
}

Avatar loadMakeHumanAvatar(const std::string& mhskelPath) {
  MakeHumanAvatarOptions options;
  const std::filesystem::path p(mhskelPath);
  options.directory = p.parent_path().string();
  options.skeletonFile = p.filename().string();
  return buildMakeHumanAvatar(options);
}

std::vector<Vec3> loadMakeHumanBaseVertices(const std::string& mhskelPath) {
  const MakeHumanAvatarOptions options;
  formats::ObjReadOptions objOptions;
  objOptions.metresPerUnit = options.metresPerUnit;
  objOptions.groups = {options.meshGroup};
  objOptions.keepUnusedVertices = true;
  return formats::readObj(join(std::filesystem::path(mhskelPath).parent_path().string(), options.meshFile), objOptions)
      .positions;
}

}  // namespace drape::scene
