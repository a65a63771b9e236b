#include "drape/scene/avatar_segment.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/mesh/edge_key.hpp"
#include "drape/mesh/weld.hpp"

namespace drape::scene {
namespace {

std::unordered_map<std::uint64_t, int> edgeUseCounts(const mesh::TriMesh& mesh) {
  std::unordered_map<std::uint64_t, int> count;
  count.reserve(mesh.triangles.size() * 3);
  for (const mesh::Triangle& t : mesh.triangles)
    for (int c = 0; c < 3; ++c) ++count[mesh::edgeKey(t[c], t[(c + 1) % 3])];
  return count;
}

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t v) {
  while (parent[v] != v) v = parent[v] = parent[parent[v]];
  return v;
}

}  // namespace

std::vector<int> dominantJointPerTriangle(const SkinnedMesh& skin, std::size_t jointCount) {
  std::vector<int> label(skin.mesh.triangles.size(), 0);
  std::vector<double> sum(jointCount, 0.0);
  for (std::size_t t = 0; t < skin.mesh.triangles.size(); ++t) {
    for (std::uint32_t v : skin.mesh.triangles[t])
      for (int k = 0; k < 4; ++k)
        if (skin.joints[v][k] < jointCount) sum[skin.joints[v][k]] += skin.weights[v][k];
    int best = 0;
    for (std::size_t j = 1; j < jointCount; ++j)
      if (sum[j] > sum[static_cast<std::size_t>(best)]) best = static_cast<int>(j);
    label[t] = best;
    for (std::uint32_t v : skin.mesh.triangles[t])
      for (int k = 0; k < 4; ++k)
        if (skin.joints[v][k] < jointCount) sum[skin.joints[v][k]] = 0.0;
  }
  return label;
}

std::size_t countBoundaryEdges(const mesh::TriMesh& mesh) {
  std::size_t boundary = 0;
  for (const auto& [key, count] : edgeUseCounts(mesh))
    if (count == 1) ++boundary;
  return boundary;
}

std::size_t capOpenings(mesh::TriMesh& mesh) {
  const auto counts = edgeUseCounts(mesh);
  // Boundary half-edges as they appear in their one face (u -> v).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary;
  for (const mesh::Triangle& t : mesh.triangles)
    for (int c = 0; c < 3; ++c)
      if (counts.at(mesh::edgeKey(t[c], t[(c + 1) % 3])) == 1) boundary.emplace_back(t[c], t[(c + 1) % 3]);
  if (boundary.empty()) return 0;
  // Openings = connected components of the boundary edges.
  std::vector<std::uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (const auto& [u, v] : boundary) parent[findRoot(parent, u)] = findRoot(parent, v);
  std::unordered_map<std::uint32_t, std::uint32_t> centreOf;  // component root -> centre vertex
  std::unordered_map<std::uint32_t, std::pair<Vec3, int>> sums;
  for (const auto& [u, v] : boundary) {
    auto& s = sums[findRoot(parent, u)];
    if (s.second == 0) s.first = Vec3::Zero();
    s.first += mesh.positions[u];
    ++s.second;
  }
  for (auto& [root, s] : sums) {
    centreOf[root] = static_cast<std::uint32_t>(mesh.positions.size());
    mesh.positions.push_back(s.first / s.second);
  }
  for (const auto& [u, v] : boundary) mesh.triangles.push_back({v, u, centreOf[findRoot(parent, u)]});
  return sums.size();
}

namespace {

/// Each joint's bone direction at rest: towards the mean of its children's centres (zero
/// for a joint without children).
std::vector<Vec3> boneDirections(const Avatar& avatar) {
  std::vector<Vec3> sum(avatar.joints.size(), Vec3::Zero());
  for (const Joint& j : avatar.joints)
    if (j.parent >= 0) sum[static_cast<std::size_t>(j.parent)] += j.restCenter - avatar.joints[static_cast<std::size_t>(j.parent)].restCenter;
  for (Vec3& d : sum)
    if (d.norm() > 0) d.normalize();
  return sum;
}

/// The joints `names` names, checked: each one of the avatar's, with a parent to give the
/// cut triangles to and children to say which way its bone runs.
std::vector<int> jointsToCut(const Avatar& avatar, const std::vector<std::string>& names,
                             const std::vector<Vec3>& bones) {
  std::vector<int> joints;
  for (const std::string& name : names) {
    const int j = avatar.findJoint(name);
    if (j < 0) {
      std::vector<std::string> all;
      for (const Joint& joint : avatar.joints) all.push_back(joint.name);
      throw Error(fmt::format("{}: cutAtJoints names '{}', which is not a joint of avatar '{}' (it has: {})",
                              avatar.source, name, avatar.name, fmt::join(all, ", ")));
    }
    if (avatar.joints[static_cast<std::size_t>(j)].parent < 0)
      throw Error(fmt::format("{}: cutAtJoints names '{}', the root joint: there is no parent part to give what lies "
                              "behind it to",
                              avatar.source, name));
    if (bones[static_cast<std::size_t>(j)].norm() == 0)
      throw Error(fmt::format("{}: cutAtJoints names '{}', a joint without children: its bone has no direction to "
                              "cut across",
                              avatar.source, name));
    joints.push_back(j);
  }
  return joints;
}

}  // namespace

std::vector<int> segmentSkinnedAvatar(Avatar& avatar, const std::vector<std::string>& cutAtJoints,
                                      std::size_t* cutTriangles) {
  if (cutTriangles != nullptr) *cutTriangles = 0;
  if (!cutAtJoints.empty() && !avatar.skin)
    throw Error(fmt::format("{}: cutAtJoints: avatar '{}' came as rigid parts, without a skinned mesh to cut them from "
                            "again",
                            avatar.source, avatar.name));
  avatar.segments.clear();
  std::vector<int> segmentOfTriangle;
  if (!avatar.skin) return segmentOfTriangle;
  const SkinnedMesh& skin = *avatar.skin;
  std::vector<int> label = dominantJointPerTriangle(skin, avatar.joints.size());
  if (!cutAtJoints.empty()) {
    const std::vector<Vec3> bones = boneDirections(avatar);
    std::vector<bool> cut(avatar.joints.size(), false);
    for (int j : jointsToCut(avatar, cutAtJoints, bones)) cut[static_cast<std::size_t>(j)] = true;
    for (std::size_t t = 0; t < label.size(); ++t) {
      const auto j = static_cast<std::size_t>(label[t]);
      if (!cut[j]) continue;
      const mesh::Triangle& tri = skin.mesh.triangles[t];
      const Vec3 centroid = (skin.mesh.positions[tri[0]] + skin.mesh.positions[tri[1]] + skin.mesh.positions[tri[2]]) / 3.0;
      if ((centroid - avatar.joints[j].restCenter).dot(bones[j]) >= 0) continue;
      label[t] = avatar.joints[j].parent;
      if (cutTriangles != nullptr) ++*cutTriangles;
    }
  }
  const std::vector<std::uint32_t> weld = mesh::weldByPosition(skin.mesh);
  segmentOfTriangle.assign(label.size(), -1);
  std::vector<std::uint32_t> local(skin.mesh.positions.size(), mesh::kNoVertex);
  for (std::size_t j = 0; j < avatar.joints.size(); ++j) {
    Segment segment;
    segment.name = avatar.joints[j].name;
    segment.joint = static_cast<int>(j);
    segment.mesh.name = avatar.joints[j].name;
    const RigidTransform toJoint = avatar.joints[j].restWorld().inverse();
    std::vector<std::uint32_t> used;
    for (std::size_t t = 0; t < label.size(); ++t) {
      if (label[t] != static_cast<int>(j)) continue;
      mesh::Triangle tri;
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t v = weld[skin.mesh.triangles[t][c]];
        if (local[v] == mesh::kNoVertex) {
          local[v] = static_cast<std::uint32_t>(segment.mesh.positions.size());
          segment.mesh.positions.push_back(toJoint.apply(skin.mesh.positions[v]));
          used.push_back(v);
        }
        tri[c] = local[v];
      }
      // Welding can collapse a sliver triangle to a repeated vertex: it has no area to keep.
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) {
        segmentOfTriangle[t] = static_cast<int>(avatar.segments.size());
        continue;
      }
      segment.mesh.triangles.push_back(tri);
      segmentOfTriangle[t] = static_cast<int>(avatar.segments.size());
    }
    for (std::uint32_t v : used) local[v] = mesh::kNoVertex;
    if (segment.mesh.triangles.empty()) {
      for (int& s : segmentOfTriangle)
        if (s == static_cast<int>(avatar.segments.size())) s = -1;
      continue;
    }
    capOpenings(segment.mesh);
    avatar.segments.push_back(std::move(segment));
  }
  return segmentOfTriangle;
}

}  // namespace drape::scene
