#include "shown_bodies.hpp"

#include "drape/motion/skinning.hpp"

namespace drape::cli {

ShownBodies::ShownBodies(const RunSetup& setup, std::vector<render::MeshInfo>& meshes,
                         const std::vector<const std::vector<sim::PartField>*>& fields,
                         const std::vector<double>& allowance_m)
    : setup_(setup) {
  const bool several = setup.characters.size() > 1;
  for (std::size_t c = 0; c < setup.characters.size(); ++c) {
    const CharacterSetup& character = setup.characters[c];
    const scene::Avatar& avatar = *character.avatar;
    const std::string who = several ? character.name : "";
    Body& body = bodies_.emplace_back();
    body.character = &character;
    body.firstSegment = meshes.size();
    for (const scene::Segment& seg : avatar.segments)
      meshes.push_back({seg.name, render::MeshRole::Segment, seg.mesh.vertexCount(), seg.mesh.triangles, who});
    if (avatar.skin && fields[c]) {
      body.skinMesh = meshes.size();
      meshes.push_back({"body", render::MeshRole::Skin, avatar.skin->mesh.vertexCount(), avatar.skin->mesh.triangles, who});
      body.skin = std::make_unique<sim::BodySkin>(avatar, *fields[c], allowance_m[c]);
    }
    if (avatar.drawnSkin) {
      body.drawnMesh = meshes.size();
      meshes.push_back({"drawn", render::MeshRole::Drawn, avatar.drawnSkin->mesh.vertexCount(),
                        avatar.drawnSkin->mesh.triangles, who});
    }
  }
}

void ShownBodies::pose(const std::vector<std::vector<RigidTransform>>& joints,
                       const std::vector<std::vector<Vec3>>& garments, std::vector<std::vector<Vec3>>& out) {
  for (std::size_t c = 0; c < bodies_.size(); ++c) {
    Body& body = bodies_[c];
    const scene::Avatar& avatar = *body.character->avatar;
    for (std::size_t s = 0; s < avatar.segments.size(); ++s) {
      const scene::Segment& seg = avatar.segments[s];
      std::vector<Vec3>& p = out[body.firstSegment + s];
      p.clear();
      const RigidTransform& pose = joints[c][static_cast<std::size_t>(seg.joint)];
      for (const Vec3& v : seg.mesh.positions) p.push_back(pose.apply(v));
    }
    if (body.drawnMesh) motion::poseSkin(avatar, *avatar.drawnSkin, joints[c], out[*body.drawnMesh]);
    if (!body.skin) continue;
    surfaces_.clear();
    for (const std::size_t g : body.character->garments)
      surfaces_.push_back({garments[g], setup_.garments[g].mesh.triangles});
    body.skin->pose(joints[c], surfaces_, out[*body.skinMesh]);
  }
}

}  // namespace drape::cli
