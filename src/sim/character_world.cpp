#include "drape/sim/character_world.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <unordered_map>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "drape/core/error.hpp"
#include "drape/core/log.hpp"
#include "drape/mesh/surface_distance.hpp"
#include "drape/mesh/topology.hpp"
#include "drape/motion/interpolate.hpp"
#include "drape/sim/garment_layers.hpp"

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

void AvatarPoses::useAnimation(const motion::AvatarAnimation* animation) {
  animation_ = animation;
  for (int c = 0; c < 2; ++c) {
    cacheTime_[c] = std::numeric_limits<double>::quiet_NaN();
    std::fill(cached_[c].begin(), cached_[c].end(), std::uint8_t{0});
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
                               std::vector<GarmentSpec> garments, const WorldSettings& settings,
                               std::shared_ptr<const std::vector<PartField>> fields, std::vector<Guest> guests)
    : avatar_(avatar), animation_(animation), settings_(settings) {
  settings_.step.validate();
  if (animation && animation->jointCount() != avatar.joints.size()) {
    throw Error(fmt::format("{}: the motion drives {} joints, the avatar has {}", avatar.name,
                            animation->jointCount(), avatar.joints.size()), ExitCode::Internal);
  }
  poses_ = std::make_unique<AvatarPoses>(avatar, animation, settings.leadIn_s);
  const std::vector<std::vector<std::size_t>> below = garmentsBelow(garments);  // refused before any work
  layers_ = layersOf(below);
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
  buildFields(garments, std::move(fields));
  if (animation && !settings_.keepApart.parts.empty()) keepBodyApart(*animation, garments);

  for (std::size_t g = 0; g < garments.size(); ++g) {
    GarmentSpec& spec = garments[g];
    const std::shared_ptr<const cloth::ClothModel>& model = models[g];
    std::vector<int> parts;
    for (const std::string& name : spec.collidesWith) {
      const auto it = std::find_if(fields_->begin(), fields_->end(), [&](const PartField& p) { return p.segment == name; });
      parts.push_back(static_cast<int>(it - fields_->begin()));
    }
    // The garment's own poses of the parts: garments step in parallel, and a pose cache
    // serves one thread.
    GarmentRun run;
    run.poses = std::make_unique<AvatarPoses>(avatar, keptApartMotion_ ? keptApartMotion_.get() : animation,
                                              settings.leadIn_s);
    for (const PartField& f : *fields_) run.motions.push_back(std::make_shared<SegmentMotion>(*run.poses, f.joint));
    std::vector<cloth::PinGroup> pins = bindMask(spec, parts, run.motions);
    if (!spec.pinned.empty()) {
      const auto& m = *model;
      pins.push_back(cloth::PinGroup::atRest(spec.pinned, m.restX(), m.restY(), m.restZ()));
    }
    std::vector<cloth::CollisionPart> collisionParts;
    for (int p : parts) {
      const bool faces = std::find(spec.faceSamplesWith.begin(), spec.faceSamplesWith.end(), (*fields_)[p].segment) !=
                         spec.faceSamplesWith.end();
      collisionParts.push_back({(*fields_)[p].segment, &(*fields_)[p].field, run.motions[static_cast<std::size_t>(p)], faces});
    }
    // The other characters' parts, after the avatar's own (whose indices the masks, face
    // samples and pinches use), each moved by the garment's own cache of that character's
    // poses. A part too far to reach costs a box test per collision test
    // (FieldCollider::outOfReach).
    for (const Guest& guest : guests) {
      run.guestPoses.push_back(std::make_unique<AvatarPoses>(*guest.avatar, guest.animation, settings.leadIn_s));
      for (const PartField& f : *guest.fields) {
        if (f.field.shell_m() + 1e-12 < spec.offsets.t3_m) {
          spdlog::warn("garment '{}': {}'s part {} keeps normals within {:.4f} m, less than its T3 {:.4f} m: it does not "
                       "collide with it",
                       spec.name, guest.name, f.segment, f.field.shell_m(), spec.offsets.t3_m);
          continue;
        }
        collisionParts.push_back({guest.name + "/" + f.segment, &f.field,
                                  std::make_shared<SegmentMotion>(*run.guestPoses.back(), f.joint), false});
      }
    }
    run.collider = std::make_unique<cloth::FieldCollider>(spec.name, std::move(collisionParts), spec.offsets,
                                                          spec.material.staticFriction, spec.material.dynamicFriction,
                                                          spec.collisionEvery);
    std::vector<std::uint32_t> fixed;  // the fixtures move these after the collider: it leaves them out
    for (const cloth::PinGroup& g : pins) fixed.insert(fixed.end(), g.vertices.begin(), g.vertices.end());
    run.collider->setFixedVertices(fixed, model->vertexCount());
    run.solver = std::make_unique<cloth::ClothSolver>(model, settings_.step, std::move(pins));
    run.solver->setStitches(spec.stitches, spec.name);
    run.collider->initialise(run.solver->state(), 0.0);
    run.fixed = std::move(fixed);
    garments_.push_back(std::move(run));
  }
  // Every solver made: the layers apart first (its own, the garments it is worn over), then
  // the body: where the two disagree, the body wins.
  for (std::size_t g = 0; g < garments.size(); ++g) {
    GarmentRun& run = garments_[g];
    run.layers = makeLayerCollider(
        garments, g, below[g], run.fixed, [&](std::size_t i) -> cloth::ClothSolver& { return *garments_[i].solver; },
        1.0 / settings_.step.frameRate_hz, &avatar);
    if (run.layers) run.solver->addCollider(*run.layers);
    run.solver->addCollider(*run.collider);
  }
  for (std::size_t g = 0; g < garments.size(); ++g) garments_[g].spec = std::move(garments[g]);
}

CharacterWorld::~CharacterWorld() = default;

namespace {

/// The segments any garment collides with, in the order the garments first name them, and
/// the largest T3 (the fields' shell). Throws on a segment the avatar does not have.
std::vector<std::string> collidableSegments(const scene::Avatar& avatar, const std::vector<GarmentSpec>& garments,
                                            const WorldSettings& settings, double& shell_m) {
  std::vector<std::string> names;
  shell_m = 0;
  for (const GarmentSpec& g : garments) {
    const cloth::OffsetSurfaces offsets = g.offsetsGiven ? g.offsets : cloth::OffsetSurfaces::fromVoxelSize(settings.voxel_m);
    shell_m = std::max(shell_m, offsets.t3_m);
    for (const std::string& name : g.collidesWith) {
      if (avatar.findSegment(name) < 0) {
        throw Error(fmt::format("garment '{}': collidesWith names '{}', which avatar '{}' does not have (it has: {})",
                                g.name, name, avatar.name, fmt::join(avatar.segmentNames(), ", ")));
      }
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
    for (const std::string& name : g.faceSamplesWith)
      if (std::find(g.collidesWith.begin(), g.collidesWith.end(), name) == g.collidesWith.end())
        throw Error(fmt::format("garment '{}': face samples with '{}', which it does not collide with (it collides "
                                "with: {})",
                                g.name, name, fmt::join(g.collidesWith, ", ")));
  }
  return names;
}

}  // namespace

std::vector<PartField> buildPartFields(const scene::Avatar& avatar, const std::vector<GarmentSpec>& garments,
                                       const WorldSettings& settings) {
  // One field per body segment any garment collides with, built once and shared.
  double shell_m = 0;
  const std::vector<std::string> names = collidableSegments(avatar, garments, settings, shell_m);
  field::FieldSettings fs;
  fs.voxelSize_m = settings.voxel_m;
  fs.shell_m = shell_m;
  fs.method = settings.fieldMethod;
  std::vector<PartField> fields;
  for (const std::string& name : names) {
    const scene::Segment& segment = avatar.segments[static_cast<std::size_t>(avatar.findSegment(name))];
    spdlog::debug("distance field for '{}' ({} triangles)", name, segment.mesh.triangleCount());
    fields.push_back({name, segment.joint, field::DistanceField::build(segment.mesh, fs)});
  }
  return fields;
}

double leastT0(const std::vector<GarmentSpec>& garments, const WorldSettings& settings) {
  double t0 = std::numeric_limits<double>::infinity();
  for (const GarmentSpec& g : garments)
    t0 = std::min(t0, (g.offsetsGiven ? g.offsets : cloth::OffsetSurfaces::fromVoxelSize(settings.voxel_m)).t0_m);
  return std::isfinite(t0) ? t0 : 0.0;
}

KeepApartSettings keepApartSettings(const std::vector<GarmentSpec>& garments, const WorldSettings& settings) {
  KeepApartSettings keep = settings.keepApart;
  if (keep.margin_m <= 0)
    for (const GarmentSpec& g : garments)
      keep.margin_m = std::max(
          keep.margin_m, 2.0 * (g.offsetsGiven ? g.offsets : cloth::OffsetSurfaces::fromVoxelSize(settings.voxel_m)).t2_m);
  return keep;
}

void CharacterWorld::buildFields(const std::vector<GarmentSpec>& garments,
                                 std::shared_ptr<const std::vector<PartField>> given) {
  const auto start = std::chrono::steady_clock::now();
  if (given) {
    // Built before for the same avatar and garments (a cloth-server's, once for all its
    // takes): the same parts, in the same order, or the garments' colliders would be wrong.
    double shell_m = 0;
    const std::vector<std::string> names = collidableSegments(avatar_, garments, settings_, shell_m);
    bool same = names.size() == given->size();
    for (std::size_t k = 0; same && k < names.size(); ++k) same = names[k] == (*given)[k].segment;
    if (!same) throw Error("the part fields given to the world are not the ones its garments collide with", ExitCode::Internal);
    fields_ = std::move(given);
  } else {
    fields_ = std::make_shared<const std::vector<PartField>>(buildPartFields(avatar_, garments, settings_));
  }
  for (const PartField& f : *fields_) partMotions_.push_back(std::make_shared<SegmentMotion>(*poses_, f.joint));
  fieldBuild_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void CharacterWorld::keepBodyApart(const motion::AvatarAnimation& animation, const std::vector<GarmentSpec>& garments) {
  const KeepApartSettings keep = keepApartSettings(garments, settings_);
  keptApartMotion_ = std::make_unique<motion::AvatarAnimation>(animation);
  keepApart_ = sim::keepBodyApart(avatar_, *keptApartMotion_, *fields_, keep);
  poses_->useAnimation(keptApartMotion_.get());
}

namespace {

/// The constraint mask's own edges: for each mask entry, the entries it shares a garment
/// edge with.
std::vector<std::vector<std::size_t>> maskNeighbours(const mesh::TriMesh& mesh, const std::vector<std::uint32_t>& bound) {
  std::unordered_map<std::uint32_t, std::size_t> entry;
  for (std::size_t i = 0; i < bound.size(); ++i) entry.emplace(bound[i], i);
  std::vector<std::vector<std::size_t>> next(bound.size());
  for (const mesh::Triangle& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = entry.find(t[static_cast<std::size_t>(k)]);
      const auto b = entry.find(t[static_cast<std::size_t>((k + 1) % 3)]);
      if (a == entry.end() || b == entry.end()) continue;
      next[a->second].push_back(b->second);
      next[b->second].push_back(a->second);
    }
  }
  for (std::vector<std::size_t>& n : next) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return next;
}

/// Each mask vertex's home part: the part most vertices of its connected piece of the mask
/// are nearest to (distance: n x np, row-major).
std::vector<std::size_t> homeParts(const std::vector<double>& distance, std::size_t np,
                                   const std::vector<std::vector<std::size_t>>& neighbours) {
  const std::size_t n = neighbours.size();
  std::vector<std::size_t> piece(n, n), home(n, 0);
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (piece[seed] != n) continue;
    std::vector<std::size_t> members{seed};
    piece[seed] = seed;
    for (std::size_t m = 0; m < members.size(); ++m)
      for (const std::size_t j : neighbours[members[m]])
        if (piece[j] == n) {
          piece[j] = seed;
          members.push_back(j);
        }
    std::vector<int> votes(np, 0);
    for (const std::size_t i : members) {
      const auto row = distance.begin() + static_cast<std::ptrdiff_t>(i * np);
      ++votes[static_cast<std::size_t>(std::min_element(row, row + static_cast<std::ptrdiff_t>(np)) - row)];
    }
    const auto part = static_cast<std::size_t>(std::max_element(votes.begin(), votes.end()) - votes.begin());
    for (const std::size_t i : members) home[i] = part;
  }
  return home;
}

/// Blend weights of the mask vertices over the parts (n x np, rows sum to 1). A vertex
/// follows its home part and the parts joined to it by one joint of the skeleton
/// (`adjacent`, np x np), each of those within kBlendWidth_m of as near to it as the nearest
/// of them, the nearer the more. The weights are then smoothed along the mask's edges, so
/// that they vary from vertex to vertex as gently as the cloth can follow, and shares below
/// kLeast are dropped.
std::vector<double> maskBlendWeights(const std::vector<double>& distance, std::size_t np,
                                     const std::vector<std::vector<std::size_t>>& neighbours,
                                     const std::vector<std::uint8_t>& adjacent) {
  constexpr double kBlendWidth_m = 0.01;
  constexpr int kSmoothingPasses = 3;
  constexpr double kLeast = 0.02;
  const std::size_t n = neighbours.size();
  const std::vector<std::size_t> home = homeParts(distance, np, neighbours);
  std::vector<double> w(n * np, 0.0);
  const auto normalise = [&](std::size_t i) {
    double sum = 0.0;
    for (std::size_t k = 0; k < np; ++k) sum += w[i * np + k];
    for (std::size_t k = 0; k < np; ++k) w[i * np + k] /= sum;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const auto allowed = [&](std::size_t k) { return k == home[i] || adjacent[home[i] * np + k]; };
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < np; ++k)
      if (allowed(k)) nearest = std::min(nearest, distance[i * np + k]);
    for (std::size_t k = 0; k < np; ++k)
      if (allowed(k)) w[i * np + k] = std::max(0.0, 1.0 - (distance[i * np + k] - nearest) / kBlendWidth_m);
    if (!std::isfinite(nearest)) w[i * np + home[i]] = 1.0;  // beyond every allowed part's grid
    normalise(i);
  }
  std::vector<double> next(w.size());
  for (int pass = 0; pass < kSmoothingPasses; ++pass) {
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < np; ++k) {
        double sum = w[i * np + k];
        for (const std::size_t j : neighbours[i]) sum += w[j * np + k];
        next[i * np + k] = sum / static_cast<double>(1 + neighbours[i].size());
      }
    w.swap(next);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const double largest = *std::max_element(w.begin() + static_cast<std::ptrdiff_t>(i * np),
                                             w.begin() + static_cast<std::ptrdiff_t>((i + 1) * np));
    for (std::size_t k = 0; k < np; ++k)
      if (w[i * np + k] < kLeast && w[i * np + k] < largest) w[i * np + k] = 0.0;
    normalise(i);
  }
  return w;
}

}  // namespace

std::vector<cloth::PinGroup> CharacterWorld::bindMask(const GarmentSpec& spec, const std::vector<int>& parts,
                                                      const std::vector<std::shared_ptr<const cloth::FixtureMotion>>& motions) const {
  // Each mask vertex must lie within the threshold of a collidable part (measured with the
  // distance fields) and from then on moves rigidly with the body (section 4.1). The paper
  // binds each vertex to its nearest part. Where a mask spans a joint, that tears the cloth
  // between neighbours bound to parts that move apart (a few waist vertices nearer a thigh
  // than the pelvis, a shoulder seam's ends nearer the clavicles than the chest). Binding a
  // whole piece of the mask to one part instead lets the other parts move through the bound
  // cloth: the clavicles through a jacket's yoke bound to the chest as the arms come down.
  // So each piece has a home part (the one most of its vertices are nearest to) and each of
  // its vertices follows a blend of the home part and the parts one joint away from it that
  // it lies on (linear blend skinning), with weights that vary smoothly along the mask.
  const std::size_t n = spec.bound.size();
  const std::size_t np = parts.size();
  std::vector<double> distance(n * np, std::numeric_limits<double>::infinity());
  std::vector<Vec3> local(n * np, Vec3::Zero());
  std::vector<int> nearest(n, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 p = spec.mesh.positions[spec.bound[i]];
    for (std::size_t k = 0; k < np; ++k) {
      const PartField& pf = (*fields_)[static_cast<std::size_t>(parts[k])];
      const Vec3 l = partMotions_[static_cast<std::size_t>(parts[k])]->poseAt(0.0).inverse().apply(p);
      local[i * np + k] = l;
      if (!pf.field.containsPoint(l)) continue;
      distance[i * np + k] = pf.field.distanceAt(l);
      if (nearest[i] < 0 || distance[i * np + k] < distance[i * np + static_cast<std::size_t>(nearest[i])])
        nearest[i] = static_cast<int>(k);
    }
  }
  measureBeyondTheFields(parts, local, distance, nearest);
  std::size_t unbound = 0;
  std::string firstUnbound;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t v = spec.bound[i];
    const int k = nearest[i];
    if (k >= 0 && distance[i * np + static_cast<std::size_t>(k)] <= spec.bindThreshold_m) continue;
    const Vec3& p = spec.mesh.positions[v];
    if (unbound++ == 0) {
      firstUnbound = k < 0 ? fmt::format("vertex {} at ({:.3f}, {:.3f}, {:.3f}) m is near no collidable part", v,
                                         p.x(), p.y(), p.z())
                           : fmt::format("vertex {} at ({:.3f}, {:.3f}, {:.3f}) m is {:.3f} m from '{}'", v, p.x(),
                                         p.y(), p.z(), distance[i * np + static_cast<std::size_t>(k)],
                                         (*fields_)[static_cast<std::size_t>(parts[static_cast<std::size_t>(k)])].segment);
    }
  }
  if (unbound > 0) {
    throw Error(fmt::format("garment '{}': {} of {} constraint-mask vertices cannot be bound within bindThreshold "
                            "{:.3f} m of a collidable part ({}); {}",
                            spec.name, unbound, n, spec.bindThreshold_m, fmt::join(spec.collidesWith, ", "),
                            firstUnbound));
  }

  liftOutOfTheParts(spec, parts, local);

  std::vector<std::uint8_t> adjacent(np * np, 0);  // parts whose joints are parent and child
  for (std::size_t a = 0; a < np; ++a)
    for (std::size_t b = 0; b < np; ++b) {
      const int ja = (*fields_)[static_cast<std::size_t>(parts[a])].joint;
      const int jb = (*fields_)[static_cast<std::size_t>(parts[b])].joint;
      adjacent[a * np + b] = ja >= 0 && jb >= 0 && ja != jb &&
                             (avatar_.joints[static_cast<std::size_t>(ja)].parent == jb ||
                              avatar_.joints[static_cast<std::size_t>(jb)].parent == ja);
    }
  const std::vector<double> weight = maskBlendWeights(distance, np, maskNeighbours(spec.mesh, spec.bound), adjacent);
  std::vector<cloth::PinGroup> groups(np);
  std::size_t blended = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t shares = 0;
    for (std::size_t k = 0; k < np; ++k) {
      if (weight[i * np + k] == 0.0) continue;
      ++shares;
      cloth::PinGroup& g = groups[k];
      const Vec3& l = local[i * np + k];
      g.vertices.push_back(spec.bound[i]);
      g.localX.push_back(l.x());
      g.localY.push_back(l.y());
      g.localZ.push_back(l.z());
      g.weight.push_back(weight[i * np + k]);
    }
    blended += shares > 1;
  }
  std::vector<cloth::PinGroup> out;
  for (std::size_t k = 0; k < groups.size(); ++k) {
    if (groups[k].vertices.empty()) continue;
    spdlog::debug("garment '{}': {} mask vertices follow '{}'", spec.name, groups[k].vertices.size(),
                  (*fields_)[static_cast<std::size_t>(parts[k])].segment);
    groups[k].motion = motions[static_cast<std::size_t>(parts[k])];
    out.push_back(std::move(groups[k]));
  }
  if (blended > 0)
    spdlog::info("garment '{}': {} of {} constraint-mask vertices follow a blend of parts across a joint", spec.name,
                 blended, n);
  return out;
}

void CharacterWorld::measureBeyondTheFields(const std::vector<int>& parts, const std::vector<Vec3>& local,
                                            std::vector<double>& distance, std::vector<int>& nearest) const {
  // A field reaches T3 (and a little more) around its part, while bindThreshold is the
  // scene's own: a mask vertex beyond every part's field is measured on the parts' surfaces
  // themselves, exactly. Only those: a vertex some field holds binds as it always has.
  const std::size_t np = parts.size();
  std::vector<std::optional<mesh::SurfaceDistance>> surfaces(np);
  for (std::size_t i = 0; i < nearest.size(); ++i) {
    if (nearest[i] >= 0) continue;
    for (std::size_t k = 0; k < np; ++k) {
      if (!surfaces[k]) {
        const std::string& name = (*fields_)[static_cast<std::size_t>(parts[k])].segment;
        const mesh::TriMesh& m = avatar_.segments[static_cast<std::size_t>(avatar_.findSegment(name))].mesh;
        surfaces[k].emplace(m.positions, m.triangles);
      }
      distance[i * np + k] = std::abs(surfaces[k]->at(local[i * np + k]).distance_m);
      if (nearest[i] < 0 || distance[i * np + k] < distance[i * np + static_cast<std::size_t>(nearest[i])])
        nearest[i] = static_cast<int>(k);
    }
  }
}

void CharacterWorld::liftOutOfTheParts(const GarmentSpec& spec, const std::vector<int>& parts,
                                       std::vector<Vec3>& local) const {
  // A bound vertex never collides (the collider leaves the fixtures' vertices out), so one
  // the garment puts inside a part (a collar cut for another body's neck) would stay there,
  // with the skin showing through the cloth around it for the whole run. The mask is moved
  // out of the body, onto the parts' surfaces, as one piece:
  // alternately each vertex is pushed out of the parts by a Newton step on their fields at
  // rest (as BodySkin fits the skin) and each of the mask's own edges is given back its
  // length (position-based projection), ending on the parts. Pushed one by one, two
  // neighbours deep in a thin part went out through its opposite sides, and the edge
  // between them stretched by 144 %.
  constexpr int kRounds = 64;
  constexpr double kTolerance_m = 1e-4;
  // Not out to T0, where free vertices stay: a waistband modelled on the skin then stood
  // off it, and the skin showed through the skirt below it on the Daz-style walk.
  constexpr double target = 0.0;
  const std::size_t np = parts.size(), n = spec.bound.size();
  std::vector<RigidTransform> pose(np), toLocal(np);
  for (std::size_t k = 0; k < np; ++k) {
    pose[k] = partMotions_[static_cast<std::size_t>(parts[k])]->poseAt(0.0);
    toLocal[k] = pose[k].inverse();
  }
  std::vector<Vec3> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = spec.mesh.positions[spec.bound[i]];
  const std::vector<Vec3> modelled = p;

  // How far q lies inside part k (0 if not); l: q in the part's frame.
  const auto below = [&](const Vec3& q, std::size_t k, Vec3& l) {
    const field::DistanceField& f = (*fields_)[static_cast<std::size_t>(parts[k])].field;
    l = toLocal[k].apply(q);
    const field::PointLocation at = f.locate(l);
    return at.inVolume && at.distance_m < target - kTolerance_m ? target - at.distance_m : 0.0;
  };
  // Pushes p[i] out of every part it is inside, by a Newton step on each one's field (as
  // the skin's fit does).
  const auto pushOut = [&](std::size_t i) {
    for (std::size_t k = 0; k < np; ++k) {
      Vec3 l;
      const double depth = below(p[i], k, l);
      if (depth <= 0) continue;
      const field::DistanceField& f = (*fields_)[static_cast<std::size_t>(parts[k])].field;
      p[i] += pose[k].rotation * (f.newtonDirection(l) * depth);
    }
  };
  const auto deepestBelow = [&](const Vec3& q, std::size_t* part) {
    double deepest = 0;
    for (std::size_t k = 0; k < np; ++k) {
      Vec3 l;
      const double depth = below(q, k, l);
      if (depth > deepest && part) *part = k;
      deepest = std::max(deepest, depth);
    }
    return deepest;
  };
  std::size_t modelledBelow = 0, deepestPart = 0;
  double deepest = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t part = 0;
    const double depth = deepestBelow(p[i], &part);
    modelledBelow += depth > 0;
    if (depth > deepest) deepest = depth, deepestPart = part;
  }
  if (modelledBelow == 0) return;
  struct Edge {
    std::size_t a, b;
    double rest_m;
  };
  std::vector<Edge> edges;  // the mask's own, each once
  const std::vector<std::vector<std::size_t>> next = maskNeighbours(spec.mesh, spec.bound);
  for (std::size_t i = 0; i < n; ++i)
    for (const std::size_t j : next[i])
      if (j > i) edges.push_back({i, j, (modelled[j] - modelled[i]).norm()});
  for (int round = 0; round < kRounds; ++round) {
    for (std::size_t i = 0; i < n; ++i) pushOut(i);
    if (round + 1 == kRounds) break;
    for (const Edge& e : edges) {
      const Vec3 d = p[e.b] - p[e.a];
      const double length = d.norm();
      if (length <= 0) continue;
      const Vec3 half = 0.5 * (length - e.rest_m) / length * d;
      p[e.a] += half;
      p[e.b] -= half;
    }
  }
  std::size_t still = 0;
  double furthest = 0, strain = 0;
  for (std::size_t i = 0; i < n; ++i) {
    still += deepestBelow(p[i], nullptr) > 0;
    furthest = std::max(furthest, (p[i] - modelled[i]).norm());
    if (p[i] != modelled[i])
      for (std::size_t k = 0; k < np; ++k) local[i * np + k] = toLocal[k].apply(p[i]);
  }
  for (const Edge& e : edges)
    if (e.rest_m > 0) strain = std::max(strain, std::abs((p[e.b] - p[e.a]).norm() / e.rest_m - 1.0));
  spdlog::info("garment '{}': {} of {} constraint-mask vertices lie inside a collidable part where the garment was "
               "modelled, the deepest {:.1f} mm inside '{}'; the mask is moved out onto the body before it is bound "
               "(by {:.1f} mm at most, its edges {:.0f} % longer or shorter at most{})",
               spec.name, modelledBelow, n, 1e3 * deepest,
               (*fields_)[static_cast<std::size_t>(parts[deepestPart])].segment, 1e3 * furthest, 100 * strain,
               still ? fmt::format("; {} still inside", still) : std::string());
}

bool CharacterWorld::settle(double max_s, SettleReport& report) {
  report = {};
  std::optional<double> ends;
  for (const GarmentRun& g : garments_) {
    if (const std::optional<double> e = g.collider->easingEnds_s()) ends = std::max(ends.value_or(*e), *e);
    for (std::size_t pairs : g.collider->easedPairsPerPart()) report.pairsEased += pairs;
  }
  if (!ends || !(max_s > 0.0)) return true;
  // Whole frames that end at time 0, so frame 1 follows the last of them as it would the
  // initial state; the colliders start again from the earlier time (the garment has not
  // moved, and the rest pose holds for any time before 0), so each eased pair gets its
  // easing time from there.
  const double rate = settings_.step.frameRate_hz;
  const double span_s = std::min(*ends, max_s);
  const long frames = std::max(1L, static_cast<long>(std::ceil(span_s * rate - 1e-9)));
  for (GarmentRun& g : garments_) g.collider->initialise(g.solver->state(), -static_cast<double>(frames) / rate);
  const auto start = std::chrono::steady_clock::now();
  for (long frame = 1 - frames; frame <= 0; ++frame)
    if (!checkStable(stepGarments(frame), frame, "settling at the rest pose before frame 0: ")) return false;
  report.frames = frames;
  report.seconds = static_cast<double>(frames) / rate;
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (GarmentRun& g : garments_) {
    for (std::size_t pairs : g.collider->easedPairsPerPart()) report.pairsLeft += pairs;
    report.pairsTimedOut += g.collider->fieldCounters().embeddedTimedOut;
    g.solver->resetStageTimes();
    g.collider->resetTimes();
  }
  return true;
}

bool CharacterWorld::stepFrame(long frame) { return checkStable(stepGarments(frame), frame, ""); }

bool CharacterWorld::checkStable(const std::vector<std::uint8_t>& stables, long frame, const std::string& when) {
  for (std::size_t i = 0; i < garments_.size(); ++i) {
    const GarmentRun& g = garments_[i];
    logFrameRecovery(*g.solver, g.spec.name, frame);
    if (!stables[i]) {
      instability_ = when + g.solver->instability().describe(g.spec.name, settings_.step.maxSpeed_m_s);
      // Where the vertex was held: most garments that blow up on a body do it in a pinch,
      // between parts whose offset surfaces overlap (docs/PHYSICS.md, examples/walking_dress).
      instability_ += cloth::pinchNear(g.solver->model(), *g.collider, g.solver->instability().vertex,
                                       g.solver->instability().substepsPerFrame);
      return false;
    }
  }
  return true;
}

std::vector<std::uint8_t> CharacterWorld::stepGarments(long frame) {
  return stepInParallel(
      garments_.size(), frame, [&](std::size_t g) -> cloth::ClothSolver& { return *garments_[g].solver; }, layers_);
}

void logFrameRecovery(const cloth::ClothSolver& solver, const std::string& garment, long frame) {
  const std::string refined = cloth::describeRefinedFrame(solver, garment);
  if (!refined.empty()) spdlog::info("{}", refined);
  const std::string rescue = cloth::describeStrainLimitRescue(solver, garment, frame);
  if (!rescue.empty()) spdlog::warn("{}", rescue);
}

std::vector<std::uint8_t> stepInParallel(std::size_t count, long frame,
                                         const std::function<cloth::ClothSolver&(std::size_t)>& solver,
                                         std::span<const int> layers) {
  // Garments of one layer do not touch each other: each steps on whichever thread is free,
  // with its own poses and colliders, and comes out the same on any number of threads. A
  // garment worn over others steps after them (a layer above), reading the frame they made.
  std::vector<std::uint8_t> stable(count, 0);
  if (count == 1) {  // one garment: on this thread, without a task
    stable[0] = solver(0).stepFrame(frame) ? 1 : 0;
    return stable;
  }
  const int top = layers.empty() ? 0 : *std::max_element(layers.begin(), layers.end());
  std::vector<std::size_t> these;
  for (int layer = 0; layer <= top; ++layer) {
    these.clear();
    for (std::size_t g = 0; g < count; ++g)
      if (layers.empty() || layers[g] == layer) these.push_back(g);
    tbb::parallel_for(std::size_t{0}, these.size(),
                      [&](std::size_t i) { stable[these[i]] = solver(these[i]).stepFrame(frame) ? 1 : 0; });
  }
  return stable;
}

}  // namespace drape::sim
