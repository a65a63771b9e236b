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

RunFunction setupConvert(CLI::App& app) {
  static std::string input, output;
  static double rate = 30.0;
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
  return [] {
    const std::string ext = std::filesystem::path(output).extension().string();
    const bool skinned = formats::isAssimpAvatarPath(output);
    if (ext != ".wrl" && !skinned)
      throw Error(fmt::format("--to {}: drape converts avatars to H-Anim VRML97 (.wrl), Collada (.dae) or FBX (.fbx)", output));
    const scene::Avatar avatar = scene::loadAvatarFile(input);
    if (skinned) {
      const std::vector<formats::SkinnedJointMotion> animations =
          formats::isAvatarMotionPath(input) ? formats::readAvatarMotions(input, rate) : std::vector<formats::SkinnedJointMotion>{};
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
