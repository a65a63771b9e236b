// `drape convert AVATAR --to avatar.wrl|.dae|.fbx`: writes any avatar drape loads (.glb,
// .gltf, .dae, .fbx, MakeHuman .mhskel) as a segmented H-Anim 1.1 VRML97 humanoid, or its
// skinned mesh and skeleton, with the animations the file carries, as Collada or (ASCII)
// FBX through Assimp.

#include <filesystem>

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

// The command line (CLI11 binds options to variables that outlive setupConvert).
std::string input, output, motionPath, jointMap;
double rate = 30.0, motionScale = 0.0;

// --motion: the motion as `drape run --motion` plays it on this avatar (retargeted,
// grounded), the lead-in left out, as one animation named after the motion file.
formats::SkinnedJointMotion retargeted(const scene::Avatar& avatar) {
  motion::MotionOptions options;
  options.clip.rate = rate;
  if (motionScale > 0) options.clip.metresPerUnit = motionScale;
  options.jointMapPath = jointMap;
  options.jointMapDirectory = std::string(DRAPE_SHARE_DIR) + "/jointmaps";
  motion::ClipLoadReport report;
  motion::JointMap map;
  const motion::AvatarAnimation animation = motion::loadAnimation(avatar, motionPath, options, &report, &map);
  spdlog::info("{}: {} frames at {:g} Hz in {}; joint map '{}'", motionPath, report.sourceFrames, report.sourceRate,
               report.units.name, map.name);
  return animation.toJointMotion(avatar, std::filesystem::path(motionPath).stem().string());
}

RunFunction setupConvert(CLI::App& app) {
  app.add_option("avatar", input,
                 "The avatar to convert: .glb, .gltf, .dae, .fbx or MakeHuman .mhskel (mesh and weights beside it)")
      ->required();
  app.add_option("--to", output,
                 "Output file: a segmented H-Anim 1.1 VRML97 humanoid (.wrl), or the skinned mesh and skeleton as "
                 "Collada (.dae, metres) or ASCII FBX (.fbx, centimetres)")
      ->required();
  app.add_option("--rate", rate,
                 "With --to .dae or .fbx: frames per second at which the avatar file's animations are sampled into "
                 "keys (every animation it carries is written)")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 1000.0));
  CLI::Option* motionOption =
      app.add_option("--motion", motionPath,
                     "With --to .dae or .fbx: motion the avatar is written with instead of its file's own animations "
                     "(.bvh, .amc, retargeted as drape run does; or an avatar file's animation), sampled at --rate");
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
    const scene::Avatar avatar = scene::loadAvatarFile(input);
    if (!motionPath.empty() && !skinned)
      throw Error(fmt::format("--motion: {} is an H-Anim VRML97 humanoid, which drape writes without motion; write "
                              ".dae or .fbx to carry it",
                              output));
    if (skinned) {
      const std::vector<formats::SkinnedJointMotion> animations =
          !motionPath.empty()                  ? std::vector<formats::SkinnedJointMotion>{retargeted(avatar)}
          : formats::isAvatarMotionPath(input) ? formats::readAvatarMotions(input, rate)
                                               : std::vector<formats::SkinnedJointMotion>{};
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
    writeHanim(output, toHanim(avatar));
    spdlog::info("{}: {} joints, {} segments written to {}", input, avatar.joints.size(), avatar.segments.size(), output);
    return 0;
  };
}

const bool registered =
    registerCommand({"convert", "Convert an avatar to a segmented H-Anim VRML97 humanoid, Collada or FBX", "", 40, &setupConvert});

}  // namespace
}  // namespace drape::cli
