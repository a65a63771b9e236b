#include "drape/sim/character_world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/motion/interpolate.hpp"

namespace drape::sim {
namespace {

double smoothstep(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

/// A body part's pose in the world at time t: its joint's world transform.
class SegmentMotion final : public cloth::FixtureMotion {
 public:
  SegmentMotion(const AvatarPoses& poses, int joint) : poses_(poses), joint_(joint) {}
  [[nodiscard]] RigidTransform poseAt(double t_s) const override { return poses_.jointAt(t_s, joint_); }

 private:
  const AvatarPoses& poses_;
  int joint_;
};

}  // namespace

AvatarPoses::AvatarPoses(const scene::Avatar& avatar, const motion::AvatarAnimation* animation, double leadIn_s)
    : avatar_(avatar), animation_(animation), leadIn_s_(animation ? std::max(0.0, leadIn_s) : 0.0) {
  for (int c = 0; c < 2; ++c) {
    cacheTime_[c] = std::numeric_limits<double>::quiet_NaN();
    cache_[c].resize(avatar.joints.size());
    cached_[c].assign(avatar.joints.size(), 0);
  }
}

double AvatarPoses::end_s() const { return leadIn_s_ + (animation_ ? animation_->duration() : 0.0); }

AvatarPoses::When AvatarPoses::when(double t_s) const {
  When w;
  if (!animation_) return w;
  if (t_s < leadIn_s_) {
    // Lead-in: from the rest pose to the first frame, eased so the cloth is not jerked.
    w.leadIn = true;
    w.u = smoothstep(t_s / leadIn_s_);
    return w;
  }
  const double frames = (t_s - leadIn_s_) * animation_->rate();
  const double last = static_cast<double>(animation_->frameCount() - 1);
  const double clamped = std::clamp(frames, 0.0, last);
  w.f = static_cast<std::size_t>(std::min(std::floor(clamped), std::max(0.0, last - 1)));
  w.s = clamped - static_cast<double>(w.f);
  return w;
}

RigidTransform AvatarPoses::joint(const When& w, std::size_t j) const {
  if (!animation_) return avatar_.joints[j].restWorld();
  if (w.leadIn) return motion::interpolate(avatar_.joints[j].restWorld(), animation_->frame(0)[j], w.u);
  return animation_->evaluateJoint(w.f, w.s, j);
}

void AvatarPoses::evaluate(double t_s, std::span<RigidTransform> out) const {
  const When w = when(t_s);
  for (std::size_t j = 0; j < avatar_.joints.size(); ++j) out[j] = joint(w, j);
}

const RigidTransform& AvatarPoses::jointAt(double t_s, int jointIndex) const {
  const auto j = static_cast<std::size_t>(jointIndex);
  int c = cacheTime_[0] == t_s ? 0 : cacheTime_[1] == t_s ? 1 : -1;
  if (c < 0) {  // a new time: the older slot takes it
    c = next_;
    next_ = 1 - next_;
    cacheTime_[c] = t_s;
    cacheWhen_[c] = when(t_s);
    std::fill(cached_[c].begin(), cached_[c].end(), std::uint8_t{0});
  }
  if (!cached_[c][j]) {
    cache_[c][j] = joint(cacheWhen_[c], j);
    cached_[c][j] = 1;
  }
  return cache_[c][j];
}

CharacterWorld::CharacterWorld(const scene::Avatar& avatar, const motion::AvatarAnimation* animation,
                               std::vector<GarmentSpec> garments, const WorldSettings& settings)
    : avatar_(avatar), settings_(settings) {
  settings_.step.validate();
  if (animation && animation->jointCount() != avatar.joints.size()) {
    throw Error(fmt::format("{}: the motion drives {} joints, the avatar has {}", avatar.name,
                            animation->jointCount(), avatar.joints.size()), ExitCode::Internal);
  }
  poses_ = std::make_unique<AvatarPoses>(avatar, animation, settings.leadIn_s);
  for (GarmentSpec& g : garments)
    if (!g.offsetsGiven) g.offsets = cloth::OffsetSurfaces::fromVoxelSize(settings.voxel_m);
  // The garments' models first: a material or a step they cannot take is refused before the
  // distance fields are built (seconds, on a large avatar).
  std::vector<std::shared_ptr<const cloth::ClothModel>> models;
  for (GarmentSpec& spec : garments) {
    spec.material.validate("garment '" + spec.name + "': ");
    models.push_back(cloth::ClothModel::build(spec.mesh, mesh::Topology::build(spec.mesh), spec.material,
                                              settings_.step.massScaling()));
    cloth::checkBendingStep(*models.back(), settings_.step);
  }
  buildFields(garments);

  for (std::size_t g = 0; g < garments.size(); ++g) {
    GarmentSpec& spec = garments[g];
    const std::shared_ptr<const cloth::ClothModel>& model = models[g];
    std::vector<int> parts;
    for (const std::string& name : spec.collidesWith) {
      const auto it = std::find_if(fields_.begin(), fields_.end(), [&](const PartField& p) { return p.segment == name; });
      parts.push_back(static_cast<int>(it - fields_.begin()));
    }
    std::vector<cloth::PinGroup> pins = bindMask(spec, parts);
    if (!spec.pinned.empty()) {
      const auto& m = *model;
      pins.push_back(cloth::PinGroup::atRest(spec.pinned, m.restX(), m.restY(), m.restZ()));
    }
    GarmentRun run;
    std::vector<cloth::CollisionPart> collisionParts;
    for (int p : parts) {
      const bool faces = std::find(spec.faceSamplesWith.begin(), spec.faceSamplesWith.end(), fields_[p].segment) !=
                         spec.faceSamplesWith.end();
      collisionParts.push_back({fields_[p].segment, &fields_[p].field, partMotions_[p], faces});
    }
    run.collider = std::make_unique<cloth::FieldCollider>(spec.name, std::move(collisionParts), spec.offsets,
                                                          spec.material.staticFriction, spec.material.dynamicFriction,
                                                          spec.collisionEvery);
    std::vector<std::uint32_t> fixed;  // the fixtures move these after the collider: it leaves them out
    for (const cloth::PinGroup& g : pins) fixed.insert(fixed.end(), g.vertices.begin(), g.vertices.end());
    run.collider->setFixedVertices(fixed, model->vertexCount());
    run.solver = std::make_unique<cloth::ClothSolver>(model, settings_.step, std::move(pins));
    run.collider->initialise(run.solver->state(), 0.0);
    run.solver->addCollider(*run.collider);
    run.spec = std::move(spec);
    garments_.push_back(std::move(run));
  }
}

CharacterWorld::~CharacterWorld() = default;

void CharacterWorld::buildFields(const std::vector<GarmentSpec>& garments) {
  // One field per body segment any garment collides with, built once and shared.
  std::vector<std::string> names;
  double shell_m = 0;
  for (const GarmentSpec& g : garments) {
    shell_m = std::max(shell_m, g.offsets.t3_m);
    for (const std::string& name : g.collidesWith) {
      if (avatar_.findSegment(name) < 0) {
        std::vector<std::string> known;
        for (const auto& s : avatar_.segments) known.push_back(s.name);
        throw Error(fmt::format("garment '{}': collidesWith names '{}', which avatar '{}' does not have (it has: {})",
                                g.name, name, avatar_.name, fmt::join(known, ", ")));
      }
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
    for (const std::string& name : g.faceSamplesWith)
      if (std::find(g.collidesWith.begin(), g.collidesWith.end(), name) == g.collidesWith.end())
        throw Error(fmt::format("garment '{}': face samples with '{}', which it does not collide with (it collides "
                                "with: {})",
                                g.name, name, fmt::join(g.collidesWith, ", ")));
  }
  field::FieldSettings fs;
  fs.voxelSize_m = settings_.voxel_m;
  fs.shell_m = shell_m;
  fs.method = settings_.fieldMethod;
  const auto start = std::chrono::steady_clock::now();
  for (const std::string& name : names) {
    const scene::Segment& segment = avatar_.segments[static_cast<std::size_t>(avatar_.findSegment(name))];
    spdlog::debug("distance field for '{}' ({} triangles)", name, segment.mesh.triangleCount());
    fields_.push_back({name, segment.joint, field::DistanceField::build(segment.mesh, fs)});
    partMotions_.push_back(std::make_shared<SegmentMotion>(*poses_, segment.joint));
  }
  fieldBuild_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

namespace {

/// Connected pieces of the constraint mask: mask vertices joined by a garment edge whose two
/// ends are both in the mask. Returns each mask entry's piece index.
std::vector<std::size_t> maskPieces(const mesh::TriMesh& mesh, const std::vector<std::uint32_t>& bound) {
  std::vector<std::size_t> parent(bound.size());
  std::iota(parent.begin(), parent.end(), std::size_t{0});
  const auto find = [&](std::size_t a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  };
  std::unordered_map<std::uint32_t, std::size_t> entry;
  for (std::size_t i = 0; i < bound.size(); ++i) entry.emplace(bound[i], i);
  for (const mesh::Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = entry.find(t[static_cast<std::size_t>(k)]);
      const auto b = entry.find(t[static_cast<std::size_t>((k + 1) % 3)]);
      if (a != entry.end() && b != entry.end()) parent[find(a->second)] = find(b->second);
    }
  }
  std::vector<std::size_t> piece(bound.size());
  for (std::size_t i = 0; i < bound.size(); ++i) piece[i] = find(i);
  return piece;
}

}  // namespace

std::vector<cloth::PinGroup> CharacterWorld::bindMask(const GarmentSpec& spec, const std::vector<int>& parts) const {
  // Each mask vertex must lie within the threshold of a collidable part (measured with the
  // distance fields) and from then on moves rigidly with a part (section 4.1). The paper
  // binds each vertex to its nearest part; where an automatic segmentation puts a few waist
  // vertices nearer a thigh than the pelvis, or a shoulder seam's ends nearer the clavicles
  // than the chest, that tears the cloth between them as the parts move apart. So each
  // connected piece of the mask (a waistband, a shoulder yoke, a cuff) moves as one, with
  // the part most of its vertices are nearest to.
  const std::size_t n = spec.bound.size();
  const std::size_t np = parts.size();
  std::vector<double> distance(n * np, std::numeric_limits<double>::infinity());
  std::vector<Vec3> local(n * np, Vec3::Zero());
  std::vector<int> nearest(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 p = spec.mesh.positions[spec.bound[i]];
    for (std::size_t k = 0; k < np; ++k) {
      const PartField& pf = fields_[static_cast<std::size_t>(parts[k])];
      const Vec3 l = partMotions_[static_cast<std::size_t>(parts[k])]->poseAt(0.0).inverse().apply(p);
      local[i * np + k] = l;
      if (!pf.field.containsPoint(l)) continue;
      distance[i * np + k] = pf.field.distanceAt(l);
      if (nearest[i] < 0 || distance[i * np + k] < distance[i * np + static_cast<std::size_t>(nearest[i])])
        nearest[i] = static_cast<int>(k);
    }
  }
  const std::vector<std::size_t> piece = maskPieces(spec.mesh, spec.bound);
  std::unordered_map<std::size_t, std::vector<int>> votes;  // piece -> votes per part
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<int>& v = votes.try_emplace(piece[i], std::vector<int>(np, 0)).first->second;
    if (nearest[i] >= 0 && distance[i * np + static_cast<std::size_t>(nearest[i])] <= spec.bindThreshold_m)
      ++v[static_cast<std::size_t>(nearest[i])];
  }
  std::unordered_map<std::size_t, std::size_t> majority;  // piece -> part
  for (const auto& [p, v] : votes)
    majority[p] = static_cast<std::size_t>(std::max_element(v.begin(), v.end()) - v.begin());

  std::vector<cloth::PinGroup> groups(np);
  std::size_t unbound = 0;
  std::string firstUnbound;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t v = spec.bound[i];
    const int k = nearest[i];
    if (k < 0 || distance[i * np + static_cast<std::size_t>(k)] > spec.bindThreshold_m) {
      const Vec3& p = spec.mesh.positions[v];
      if (unbound++ == 0) {
        firstUnbound = k < 0 ? fmt::format("vertex {} at ({:.3f}, {:.3f}, {:.3f}) m is near no collidable part", v,
                                           p.x(), p.y(), p.z())
                             : fmt::format("vertex {} at ({:.3f}, {:.3f}, {:.3f}) m is {:.3f} m from '{}'", v, p.x(),
                                           p.y(), p.z(), distance[i * np + static_cast<std::size_t>(k)],
                                           fields_[static_cast<std::size_t>(parts[static_cast<std::size_t>(k)])].segment);
      }
      continue;
    }
    const std::size_t m = majority[piece[i]];
    cloth::PinGroup& g = groups[m];
    const Vec3& l = local[i * np + m];
    g.vertices.push_back(v);
    g.localX.push_back(l.x());
    g.localY.push_back(l.y());
    g.localZ.push_back(l.z());
  }
  if (unbound > 0) {
    throw Error(fmt::format("garment '{}': {} of {} constraint-mask vertices cannot be bound within bindThreshold "
                            "{:.3f} m of a collidable part ({}); {}",
                            spec.name, unbound, n, spec.bindThreshold_m, fmt::join(spec.collidesWith, ", "),
                            firstUnbound));
  }
  std::vector<cloth::PinGroup> out;
  for (std::size_t k = 0; k < groups.size(); ++k) {
    if (groups[k].vertices.empty()) continue;
    spdlog::debug("garment '{}': {} mask vertices bound to '{}'", spec.name, groups[k].vertices.size(),
                  fields_[static_cast<std::size_t>(parts[k])].segment);
    groups[k].motion = partMotions_[static_cast<std::size_t>(parts[k])];
    out.push_back(std::move(groups[k]));
  }
  return out;
}

bool CharacterWorld::stepFrame(long frame) {
  for (GarmentRun& g : garments_) {
    if (!g.solver->stepFrame(frame)) {
      instability_ = g.solver->instability().describe(g.spec.name, settings_.step.maxSpeed_m_s);
      // Where the vertex was held: most garments that blow up on a body do it in a pinch,
      // between parts whose offset surfaces overlap (docs/PHYSICS.md, examples/walking_dress).
      instability_ += cloth::pinchNear(g.solver->model(), *g.collider, g.solver->instability().vertex,
                                       settings_.step.substepsPerFrame);
      return false;
    }
  }
  return true;
}

}  // namespace drape::sim
