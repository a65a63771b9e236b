// `drape inspect FILE.bvh|.amc|.asf|.glb|.gltf|.vrm|.dae|.fbx|.mhskel`: skeleton, frame count, rate,
// duration and the units guess of motion files; joints and segments of avatars; the humanoid
// each skeleton's shape shows.

#include <algorithm>
#include <cctype>
#include <filesystem>

#include <fmt/ostream.h>
#include <fmt/ranges.h>

#include "command.hpp"
#include "inspect_humanoid.hpp"
#include "inspect_mesh.hpp"
#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/asf_amc.hpp"
#include "drape/formats/bvh.hpp"
#include "drape/formats/avatar_motion.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/motion/clip_io.hpp"
#include "drape/scene/avatar_gltf.hpp"
#include "drape/scene/humanoid.hpp"

namespace drape::cli {
namespace {

/// A joint tree (parents first) in depth-first order, each joint with its depth: indented
/// so, every joint's children follow it, which a listing in the stored (breadth-first)
/// order does not show.
std::vector<std::pair<std::size_t, int>> depthFirst(const std::vector<int>& parents) {
  std::vector<std::vector<std::size_t>> children(parents.size());
  std::vector<std::size_t> stack;
  for (std::size_t j = 0; j < parents.size(); ++j)
    if (parents[j] >= 0) children[static_cast<std::size_t>(parents[j])].push_back(j);
  for (std::size_t j = parents.size(); j-- > 0;)
    if (parents[j] < 0) stack.push_back(j);  // the first root on top
  std::vector<std::pair<std::size_t, int>> order;
  std::vector<int> depth(parents.size(), 0);
  while (!stack.empty()) {
    const std::size_t j = stack.back();
    stack.pop_back();
    if (parents[j] >= 0) depth[j] = depth[static_cast<std::size_t>(parents[j])] + 1;
    order.emplace_back(j, depth[j]);
    for (auto c = children[j].rbegin(); c != children[j].rend(); ++c) stack.push_back(*c);  // the first child on top
  }
  return order;
}

void printSkeleton(std::ostream& out, const motion::Skeleton& s) {
  fmt::print(out, "  skeleton   {} joints\n", s.size());
  std::vector<int> parents;
  for (const auto& j : s.joints) parents.push_back(j.parent);
  for (const auto& [j, depth] : depthFirst(parents))
    fmt::print(out, "    {}{}\n", std::string(static_cast<std::size_t>(depth) * 2, ' '), s.joints[j].name);
}

void printClip(std::ostream& out, const std::string& path, const char* kind, const motion::Clip& clip,
               const motion::ClipLoadReport& r) {
  fmt::print(out, "{}: {} motion\n", path, kind);
  printSkeleton(out, clip.skeleton);
  const double sourceDuration = r.sourceFrames > 1 ? static_cast<double>(r.sourceFrames - 1) / r.sourceRate : 0.0;
  fmt::print(out, "  frames     {} at {:.4g} Hz in the file ({:.3f} s)\n", r.sourceFrames, r.sourceRate, sourceDuration);
  fmt::print(out, "  standing   {}\n", r.standingAxis == "+y" ? std::string("along +y") : r.stoodUp());
  fmt::print(out, "  T-pose     {}\n", r.referenceTPoseSkipped ? r.referenceTPose() : "no reference frame");
  const std::string unfolding = r.restUnfoldSkipped();
  fmt::print(out, "  unfolding  {}\n", unfolding.empty() ? "none from the rest pose" : unfolding);
  fmt::print(out, "  played     {} frames at {:.4g} Hz ({:.3f} s), starting {}\n", clip.frameCount(), clip.rate, clip.duration(),
             clip.start.smpte());
  fmt::print(out, "  units      {} guessed from a rest extent of {:.4g} units ({:.3f} m each)\n", r.units.name,
             r.units.extentInUnits, r.units.metresPerUnit);
  std::vector<std::string> names;
  std::vector<scene::JointAt> joints;
  const std::vector<Vec3> rest = clip.skeleton.restPositions();
  for (std::size_t j = 0; j < clip.skeleton.size(); ++j) {
    names.push_back(clip.skeleton.joints[j].name);
    joints.push_back({clip.skeleton.joints[j].parent, rest[j]});
  }
  printHumanoid(out, names, joints);
  if (clip.frameCount() > 0) {
    const Vec3 a = clip.rootTranslations.front(), b = clip.rootTranslations.back();
    fmt::print(out, "  root path  [{:.3f} {:.3f} {:.3f}] -> [{:.3f} {:.3f} {:.3f}] m\n", a.x(), a.y(), a.z(), b.x(), b.y(), b.z());
  }
}

void inspectBvh(const std::string& path, std::ostream& out) {
  motion::ClipLoadReport report;
  const motion::Clip clip = motion::loadClip(path, {}, &report);
  printClip(out, path, "BVH", clip, report);
}

void inspectAcclaim(const std::string& path, std::ostream& out) {
  const std::string ext = lowerExtension(path);
  if (ext == ".asf") {
    const formats::AsfSkeleton asf = formats::readAsf(path);
    fmt::print(out, "{}: Acclaim ASF skeleton '{}'\n  bones      {}\n", path, asf.name, asf.bones.size());
    for (const formats::AsfBone& b : asf.bones)
      fmt::print(out, "    {:<12} parent {:<12} length {:.4g}, {} dof\n", b.name,
                 b.parent < 0 ? "root" : asf.bones[static_cast<std::size_t>(b.parent)].name, b.length, b.dofs.size());
    return;
  }
  motion::ClipLoadReport report;
  const motion::Clip clip = motion::loadClip(path, {}, &report);
  printClip(out, path, "Acclaim AMC", clip, report);
}

/// An avatar file's own animations: what `drape run` plays on this avatar by itself, and
/// `--motion FILE` on another.
void inspectAvatarMotion(const std::string& path, std::ostream& out) {
  std::vector<formats::SkinnedJointMotion> motions;
  try {
    motions = formats::readAvatarMotions(path, 30.0);
  } catch (const Error& e) {
    fmt::print(out, "  motion     none: {}\n", e.what());
    return;
  }
  if (motions.empty()) {
    fmt::print(out, "  motion     none (the file has no animation)\n");
    return;
  }
  const bool several = motions.size() > 1;
  fmt::print(out,
             "  motion     {} animation{}; drape run plays {} on this avatar by itself (--motion none: at rest), and "
             "--motion {} on another, retargeted\n",
             motions.size(), several ? "s" : "", several ? "the first (--animation NAME|INDEX chooses)" : "it", path);
  for (std::size_t i = 0; i < motions.size(); ++i) {
    const formats::SkinnedJointMotion& m = motions[i];
    fmt::print(out, "    {} '{}': {:.3f} s ({:.3f} to {:.3f} s of key times), {} frames at 30 Hz\n", i, m.animation,
               m.end_s - m.start_s, m.start_s, m.end_s, m.frameCount());
  }
}

void inspectAvatar(const std::string& path, std::ostream& out) {
  scene::Avatar a;
  try {
    a = scene::loadAvatarFile(path);
  } catch (const Error& e) {
    // A glTF, Collada or FBX file without a skin may be a garment: say what it holds as one.
    if (lowerExtension(path) == ".mhskel") throw;
    try {
      inspectMeshFile(path, out);
    } catch (const Error&) {
      throw e;
    }
    fmt::print(out, "  as an avatar: {}\n", e.what());
    return;
  }
  fmt::print(out, "{}: skinned avatar '{}'\n", path, a.name);
  fmt::print(out, "  joints     {}\n", a.joints.size());
  std::vector<int> parents;
  for (const scene::Joint& j : a.joints) parents.push_back(j.parent);
  for (const auto& [j, depth] : depthFirst(parents)) {
    const Vec3 c = a.joints[j].restCenter;
    fmt::print(out, "    {}{} at [{:.3f} {:.3f} {:.3f}] m\n", std::string(static_cast<std::size_t>(depth) * 2, ' '),
               a.joints[j].name, c.x(), c.y(), c.z());
  }
  if (a.fileMeshes.size() > 1)
    fmt::print(out,
               "  meshes     {} skinned: {} (make-scene --avatar-meshes chooses those that make the body, "
               "--avatar-drawn-meshes those drawn with it)\n",
               a.fileMeshes.size(), fmt::join(a.fileMeshes, ", "));
  if (a.skin) {
    const Aabb box = a.skin->mesh.bounds();
    fmt::print(out, "  skin       {} vertices, {} triangles, height {:.3f} m\n", a.skin->mesh.vertexCount(),
               a.skin->mesh.triangleCount(), box.size().y());
  }
  fmt::print(out, "  segments   {} (closed, by dominant skin weight)\n", a.segments.size());
  for (const scene::Segment& s : a.segments)
    fmt::print(out, "    {:<18} {:>6} triangles\n", s.name, s.mesh.triangleCount());
  std::vector<std::string> names;
  for (const scene::Joint& j : a.joints) names.push_back(j.name);
  printHumanoid(out, names, scene::jointsAt(a));
  if (formats::isAvatarMotionPath(path)) inspectAvatarMotion(path, out);
}

const bool bvh = registerInspector({".bvh"}, "BVH motion: skeleton, frames, rate, duration, units guess", &inspectBvh);
const bool acclaim = registerInspector({".amc", ".asf"}, "Acclaim (CMU) ASF skeletons and AMC motion", &inspectAcclaim);
const bool avatars = registerInspector({".glb", ".gltf", ".vrm", ".dae", ".fbx", ".mhskel"}, "skinned avatars: joints, skin, segments (a file without a skin: its meshes, as a garment)", &inspectAvatar);

}  // namespace
}  // namespace drape::cli
