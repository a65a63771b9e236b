// `drape convert AVATAR --to avatar.wrl|.dae|.fbx`: writes any avatar drape loads (.glb,
// .gltf, .dae, .fbx, MakeHuman .mhskel, an H-Anim .wrl) as a segmented H-Anim 1.1 VRML97
// humanoid with one motion, or a skinned avatar's mesh and skeleton with the animations the
// file carries, as Collada or (ASCII) FBX through Assimp; or with a motion file's walk
// retargeted onto it instead.

#include <filesystem>
#include <span>

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include "command.hpp"
#include "drape/core/error.hpp"
#include "drape/formats/assimp_avatar.hpp"
#include "drape/formats/avatar_motion.hpp"
#include "drape/formats/hanim_writer.hpp"
#include "drape/motion/animation.hpp"
#include "drape/scene/avatar_gltf.hpp"

namespace drape::cli {
namespace {

// Segments are stored in their joint's frame; H-Anim 1.1's default pose puts every point
// in humanoid coordinates.
formats::HanimHumanoidData toHanim(const scene::Avatar& a) {
  formats::HanimHumanoidData h;
  h.name = a.name.empty() ? "avatar" : a.name;
  h.info = {"authorName=drape convert", "source=" + std::filesystem::path(a.source).filename().string(),
            "units=metres (1 unit = 1 m), Y up"};
  for (const scene::Joint& j : a.joints) h.joints.push_back({j.name, j.parent, j.restCenter, {}});
  for (const scene::Segment& s : a.segments) {
    if (s.joint < 0 || static_cast<std::size_t>(s.joint) >= a.joints.size()) continue;
    const RigidTransform rest = a.joints[static_cast<std::size_t>(s.joint)].restWorld();
    formats::HanimSegmentData seg;
    seg.name = s.name;
    seg.triangles = s.mesh.triangles;
    for (const Vec3& p : s.mesh.positions) seg.points.push_back(rest.apply(p));
    h.joints[static_cast<std::size_t>(s.joint)].segments.push_back(std::move(seg));
  }
  return h;
}

// The motion as H-Anim Joint fields: a joint's segment points are in humanoid coordinates
// at rest, so in frame f joint j must move them by D_j = W_j(f) W_j,rest^-1 (W its world
// transform); under its parent's D_p, the Joint's own transform is L_j = D_p^-1 D_j, which
// a Joint writes as a rotation R about its centre c and a translation t:
// L_j(x) = R x + (t + c - R c).
formats::HanimMotion hanimMotion(const scene::Avatar& a, const motion::AvatarAnimation& animation,
                                 const std::string& name) {
  formats::HanimMotion m;
  m.name = name;
  m.frameRate = animation.rate();
  std::vector<RigidTransform> restInverse;
  for (const scene::Joint& j : a.joints) restInverse.push_back(j.restWorld().inverse());
  std::vector<RigidTransform> moved(a.joints.size());
  for (std::size_t f = 0; f < animation.frameCount(); ++f) {
    const std::span<const RigidTransform> world = animation.frame(f);
    std::vector<RigidTransform>& fields = m.frames.emplace_back(a.joints.size());
    for (std::size_t j = 0; j < a.joints.size(); ++j) {
      moved[j] = world[j] * restInverse[j];
      const int p = a.joints[j].parent;
      const RigidTransform local =
          p >= 0 && static_cast<std::size_t>(p) < j ? moved[static_cast<std::size_t>(p)].inverse() * moved[j] : moved[j];
      const Vec3& c = a.joints[j].restCenter;
      fields[j] = {local.rotation, local.translation - c + local.rotation * c};
    }
  }
  return m;
}

// The command line (CLI11 binds options to variables that outlive setupConvert).
std::string input, output, motionPath, jointMap, animationName;
std::vector<std::string> avatarMeshes;  ///< --avatar-meshes: the skinned meshes to convert
double rate = 30.0, motionScale = 0.0;

// --motion: the motion as `drape run --motion` plays it on this avatar (retargeted,
// grounded), the lead-in left out.
motion::AvatarAnimation retargeted(const scene::Avatar& avatar) {
  motion::MotionOptions options;
  options.clip.rate = rate;
  if (motionScale > 0) options.clip.metresPerUnit = motionScale;
  options.jointMapPath = jointMap;
  options.jointMapDirectory = std::string(DRAPE_SHARE_DIR) + "/jointmaps";
  options.animation = animationName;
  motion::ClipLoadReport report;
  motion::JointMap map;
  motion::AvatarAnimation animation = motion::loadAnimation(avatar, motionPath, options, &report, &map);
  spdlog::info("{}: {} frames at {:g} Hz in {}; joint map '{}'", motionPath, report.sourceFrames, report.sourceRate,
               report.units.name, map.name);
  return animation;
}

// The animations the avatar file carries, sampled at --rate: the one --animation names, or
// every one (none for a file that carries none, or cannot: MakeHuman).
std::vector<formats::SkinnedJointMotion> ownAnimations() {
  if (!formats::isAvatarMotionPath(input)) {
    if (!animationName.empty())
      throw Error(fmt::format("--animation {}: {} carries no animations (.glb, .gltf, .vrm, .dae, .fbx and H-Anim .wrl files can)",
                              animationName, input));
    return {};
  }
  if (!animationName.empty()) return {formats::readAvatarMotion(input, rate, animationName)};
  return formats::readAvatarMotions(input, rate);
}

// The one animation a .wrl humanoid is written with: --animation's, else the file's first.
// A skinned avatar's file named its animations as it was read, so only the first is sampled.
std::vector<formats::SkinnedJointMotion> firstOwnAnimation(const scene::Avatar& avatar) {
  if (animationName.empty() && avatar.skin && formats::isAvatarMotionPath(input)) {
    if (avatar.animations.empty()) return {};
    return {formats::readAvatarMotion(input, rate)};
  }
  return ownAnimations();
}

// --to .wrl: the humanoid with one motion (the --motion file's, or the avatar file's own
// animation), as its Joints' interpolators.
void writeHanimWithMotion(const scene::Avatar& avatar) {
  formats::HanimHumanoidData h = toHanim(avatar);
  if (!motionPath.empty()) {
    h.motion = hanimMotion(avatar, retargeted(avatar), std::filesystem::path(motionPath).stem().string());
  } else if (const std::vector<formats::SkinnedJointMotion> own = firstOwnAnimation(avatar); !own.empty()) {
    h.motion = hanimMotion(avatar, motion::AvatarAnimation::fromJointMotion(avatar, own.front(), input),
                           own.front().animation);
    if (own.front().animationNames.size() > 1)
      spdlog::info("{}: a VRML97 humanoid carries one motion: '{}' of the file's {} ({}; --animation chooses)", output,
                   own.front().animation, own.front().animationNames.size(),
                   fmt::join(own.front().animationNames, ", "));
  }
  writeHanim(output, h);
  spdlog::info("{}: {} joints, {} segments written to {}", input, avatar.joints.size(), avatar.segments.size(), output);
  if (h.motion)
    spdlog::info("{}: motion '{}', {} frames at {:g} Hz, written with it (interpolators routed into the joints)",
                 output, h.motion->name, h.motion->frames.size(), h.motion->frameRate);
}

RunFunction setupConvert(CLI::App& app) {
  app.add_option("avatar", input,
                 "The avatar to convert: .glb, .gltf, .vrm, .dae, .fbx, MakeHuman .mhskel (mesh and weights beside it), or "
                 "an H-Anim VRML97 humanoid (.wrl; segmented, so to .wrl only)")
      ->required();
  app.add_option("--avatar-meshes", avatarMeshes,
                 "Of an avatar file whose skin moves several meshes (drape inspect FILE lists them), those to convert, "
                 "by node or mesh name or shell pattern (the body without the clothes the file holds too)")
      ->delimiter(',');
  app.add_option("--to", output,
                 "Output file: a segmented H-Anim 1.1 VRML97 humanoid (.wrl) with one motion as its joints' "
                 "interpolators, or the skinned mesh and skeleton as Collada (.dae, metres) or ASCII FBX (.fbx, "
                 "centimetres) with every animation")
      ->required();
  app.add_option("--rate", rate,
                 "Frames per second at which the motion is sampled into keys (with --to .dae or .fbx every animation "
                 "the avatar file carries is written; a .wrl humanoid carries one, the first unless --animation)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0));
  CLI::Option* motionOption =
      app.add_option("--motion", motionPath,
                     "Motion the avatar is written with instead of its file's own animations (.bvh, .amc, retargeted "
                     "as drape run does; or an avatar file's animation, .wrl humanoids' included), sampled at --rate");
  app.add_option("--animation", animationName,
                 "Which animation, by name or by index from 0 (drape inspect FILE lists them): of the --motion file "
                 "when it is an avatar file, else of the avatar file (only that one is written)");
  app.add_option("--joint-map", jointMap, "With --motion: the joint map (JSON) from the motion's joints to the avatar's")
      ->needs(motionOption);
  app.add_option("--motion-scale", motionScale, "With --motion: metres per motion-file unit (default: guessed)")
      ->needs(motionOption)
      ->check(CLI::PositiveNumber);
  return [] {
    const std::string ext = std::filesystem::path(output).extension().string();
    const bool skinned = formats::isAssimpAvatarPath(output);
    if (ext != ".wrl" && !skinned)
      throw Error(fmt::format("--to {}: drape converts avatars to H-Anim VRML97 (.wrl), Collada (.dae) or FBX (.fbx)", output));
    const scene::Avatar avatar = scene::loadAvatarFile(input, avatarMeshes);
    if (skinned && !avatar.skin)
      throw Error(fmt::format("--to {}: {} is a segmented avatar (rigid parts, no skin and weights), which Collada and "
                              "FBX skinned models cannot carry; convert it --to .wrl",
                              output, input));
    if (skinned) {
      const std::vector<formats::SkinnedJointMotion> animations =
          !motionPath.empty()
              ? std::vector<formats::SkinnedJointMotion>{retargeted(avatar).toJointMotion(
                    avatar, std::filesystem::path(motionPath).stem().string())}
              : ownAnimations();
      formats::writeAssimpSkinnedModel(output, scene::skinnedModelOf(avatar), animations);
      spdlog::info("{}: {} joints, {} skinned vertices written to {}", input, avatar.joints.size(),
                   avatar.skin->mesh.vertexCount(), output);
      std::vector<std::string> names;
      for (const formats::SkinnedJointMotion& m : animations) names.push_back(fmt::format("'{}', {} frames", m.animation, m.frameCount()));
      if (!animations.empty())
        spdlog::info("{}: {} animation{} sampled at {:g} Hz written with it ({})", output, animations.size(),
                     animations.size() > 1 ? "s" : "", rate, fmt::join(names, "; "));
      return 0;
    }
    writeHanimWithMotion(avatar);
    return 0;
  };
}

const bool registered_cmd_convert =
    registerCommand({"convert", "Convert an avatar to a segmented H-Anim VRML97 humanoid, Collada or FBX", "", 40, &setupConvert});

}  // namespace
}  // namespace drape::cli
