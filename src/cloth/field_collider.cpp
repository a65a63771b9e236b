#include "drape/cloth/field_collider.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

// Outward impulse per collision interval below T1, as a fraction of the depth below T1
// per interval: strong enough to lift a point out within a few substeps, weak enough to
// stay well inside the explicit step's stability limit (a rate of 1 would be a projection).
constexpr double kPenaltyRate = 0.25;
/// How fast a point that started below T1 is eased out (releaseEmbedded), m/s.
constexpr double kEmbeddedSpeed_m_s = 0.1;

int toIndex(PointState s) { return static_cast<int>(s); }

Vec3i roundVoxel(const Vec3& c) {
  return Vec3i(static_cast<int>(std::lround(c.x())), static_cast<int>(std::lround(c.y())),
               static_cast<int>(std::lround(c.z())));
}

Aabb transformedBox(const Aabb& box, const RigidTransform& pose) {
  Aabb out;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 p((corner & 1) ? box.max.x() : box.min.x(), (corner & 2) ? box.max.y() : box.min.y(),
                 (corner & 4) ? box.max.z() : box.min.z());
    out.extend(pose.apply(p));
  }
  return out;
}

}  // namespace

bool walkable(const field::DistanceField& f, const Vec3i& p) {
  return f.dims().contains(p.x(), p.y(), p.z()) && !f.isBorder(f.index(p.x(), p.y(), p.z()));
}

Vec3i entryVoxel(const field::DistanceField& f, const Vec3i& inside, const Vec3i& outside) {
  Vec3i entry = inside;
  walkVoxels(inside, outside, [&](const Vec3i& p) {
    if (!walkable(f, p)) return false;
    entry = p;
    return true;
  });
  return entry;
}

void OffsetSurfaces::validate(const std::string& prefix) const {
  if (!(t0_m >= 0 && t0_m < t1_m && t1_m < t2_m && t2_m < t3_m) || !std::isfinite(t3_m)) {
    throw Error(fmt::format("{}offsets must satisfy 0 <= T0 < T1 < T2 < T3 (m), got {:g} {:g} {:g} {:g}", prefix, t0_m,
                            t1_m, t2_m, t3_m));
  }
}

FieldCollider::FieldCollider(std::string garmentName, std::vector<CollisionPart> parts, const OffsetSurfaces& offsets,
                             double staticFriction, double dynamicFriction, int every)
    : garment_(std::move(garmentName)),
      parts_(std::move(parts)),
      offsets_(offsets),
      staticFriction_(staticFriction),
      dynamicFriction_(dynamicFriction),
      every_(std::max(1, every)) {
  offsets_.validate("garment '" + garment_ + "': ");
  for (const CollisionPart& p : parts_) {
    if (!p.field || !p.motion) throw Error(fmt::format("garment '{}': body part '{}' has no distance field or motion", garment_, p.name), ExitCode::Internal);
    if (p.field->shell_m() + 1e-12 < offsets_.t3_m) {
      throw Error(fmt::format("garment '{}': body part '{}': its distance field keeps Voronoi normals within {:.4f} m, "
                              "less than the outer offset T3 = {:.4f} m",
                              garment_, p.name, p.field->shell_m(), offsets_.t3_m));
    }
  }
}

void FieldCollider::initialise(const ClothState& state, double t_s) {
  const std::size_t n = state.size();
  states_.assign(parts_.size(), std::vector<PointState>(n, PointState::OutsideVol));
  lastLocal_.assign(parts_.size(), std::vector<Vec3>(n, Vec3::Zero()));
  penalty_.assign(n, 0);
  embedded_.assign(parts_.size(), std::vector<std::uint8_t>(n, 0));
  field_.embeddedAtStart = 0;
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    const field::DistanceField& f = *parts_[k].field;
    const RigidTransform inverse = parts_[k].motion->poseAt(t_s).inverse();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 local = inverse.apply(state.position(i));
      lastLocal_[k][i] = local;
      if (!walkable(f, roundVoxel(f.toVoxel(local)))) continue;
      const double d = f.distanceAt(local);
      states_[k][i] = d < offsets_.t2_m ? PointState::OnSurf : PointState::InsideVol;
      if (d < offsets_.t1_m) {
        states_[k][i] = PointState::InsideVol;
        embedded_[k][i] = 1;
        ++field_.embeddedAtStart;
      }
    }
  }
  lastTime_s_ = t_s;
}

FieldCollider::PartFrame FieldCollider::framePart(const CollisionPart& part, double t0_s, double t1_s) const {
  PartFrame frame;
  frame.pose0 = part.motion->poseAt(t0_s);
  frame.pose1 = part.motion->poseAt(t1_s);
  frame.inverse1 = frame.pose1.inverse();
  frame.worldBox1 = transformedBox(part.field->bounds(), frame.pose1);
  return frame;
}

void FieldCollider::collide(const ClothModel& /*model*/, double t0_s, double t1_s, ClothState& io) {
  ++counters_.calls;
  if (states_.empty() || states_.front().size() != io.size()) initialise(io, t0_s);
  if ((calls_++ % every_) != 0) return;  // reduced-frequency collision tests
  const double interval_s = t1_s - lastTime_s_;
  if (!(interval_s > 0)) return;

  std::fill(penalty_.begin(), penalty_.end(), 0);
  for (std::size_t k = 0; k < parts_.size(); ++k) {
    const PartFrame frame = framePart(parts_[k], lastTime_s_, t1_s);
    for (std::size_t i = 0; i < io.size(); ++i) collidePoint(k, frame, i, interval_s, io);
  }

  // Penetration after the response, against the nearest part.
  const std::size_t n = io.size();
  field_.vertexSubsteps += n;
  for (std::size_t i = 0; i < n; ++i) {
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < parts_.size(); ++k) {
      if (states_[k][i] == PointState::OutsideVol || embedded_[k][i]) continue;
      const Vec3 local = lastLocal_[k][i];
      nearest = std::min(nearest, parts_[k].field->distanceAt(local));
    }
    if (nearest < offsets_.t1_m) {
      ++field_.vertexSubstepsBelowT1;
      penalty_[i] = 1;
    }
    if (nearest < offsets_.t0_m) ++field_.vertexSubstepsBelowT0;
    if (nearest < 0) {
      ++field_.vertexSubstepsInsideBody;
      field_.maxPenetration_m = std::max(field_.maxPenetration_m, -nearest);
    }
  }
  counters_.maxPenetration_m = field_.maxPenetration_m;
  lastTime_s_ = t1_s;
}

void FieldCollider::collidePoint(std::size_t k, const PartFrame& frame, std::size_t i, double dt_s, ClothState& io) {
  const field::DistanceField& f = *parts_[k].field;
  PointState& state = states_[k][i];
  Vec3& last = lastLocal_[k][i];
  const PointState from = state;
  ++field_.tests;
  ++counters_.pointsTested;

  const Vec3 world1 = io.position(i);
  if (embedded_[k][i]) {
    releaseEmbedded(k, frame, i, dt_s, io);
    ++field_.transitions[toIndex(from)][toIndex(state)];
    return;
  }
  // OutsideVol -> OutsideVol: culled by the part's box, no trace.
  if (state == PointState::OutsideVol && !frame.worldBox1.contains(world1)) {
    ++field_.transitions[0][0];
    return;
  }
  const Vec3 local1 = frame.inverse1.apply(world1);
  // A point outside the volume has no cached local position: where it was at the start of
  // the interval follows from its velocity (x1 = x0 + v dt after the integrator).
  const Vec3 local0 = state == PointState::OutsideVol
                          ? frame.pose0.inverse().apply(world1 - io.velocity(i) * dt_s)
                          : last;
  const Vec3 c0 = f.toVoxel(local0), c1 = f.toVoxel(local1);
  const Vec3i v0 = roundVoxel(c0), v1 = roundVoxel(c1);
  const bool in1 = walkable(f, v1);
  if (state == PointState::OutsideVol && !in1) {
    ++field_.transitions[0][0];
    last = local1;
    return;
  }

  // Where the walk starts: the start voxel, or, entering from outside, the entry voxel
  // found by walking backwards from the end until the walk leaves the volume.
  const Vec3i start = state == PointState::OutsideVol ? entryVoxel(f, v1, v0) : v0;
  // Forward walk: stop where it leaves the volume (it cannot re-enter a box) or, unless the
  // point already slides on the surface, at the first voxel below T2.
  const double t2Voxels = offsets_.t2_m / f.voxelSize();
  bool hit = false;
  Vec3i hitVoxel = start;
  const int walked = walkVoxels(start, v1, [&](const Vec3i& p) {
    if (!walkable(f, p)) return false;
    if (state != PointState::OnSurf && f.distanceVoxels(f.index(p.x(), p.y(), p.z())) < t2Voxels) {
      hit = true;
      hitVoxel = p;
      return false;
    }
    return true;
  });
  ++field_.traces;
  field_.traceVoxels += static_cast<std::uint64_t>(walked - 1);

  if (!in1 && !hit) {  // left the volume
    state = PointState::OutsideVol;
    last = local1;
    ++field_.transitions[toIndex(from)][toIndex(state)];
    return;
  }

  Vec3 local = local1;
  bool moved = false;
  double d = f.distanceAt(local);
  if (state != PointState::OnSurf && (hit || d < offsets_.t2_m)) {
    // Collision: stop where the path meets T2. The contact point is the path point nearest
    // the first voxel below T2, moved along the offset-surface normal onto T2.
    if (hit) {
      const Vec3 seg = c1 - c0;
      const double len2 = seg.squaredNorm();
      const double s = len2 > 0 ? std::clamp((hitVoxel.cast<double>() - c0).dot(seg) / len2, 0.0, 1.0) : 1.0;
      local = f.toLocal(c0 + s * seg);
      d = f.distanceAt(local);
    }
    local += (offsets_.t2_m - d) * f.normalAt(local);
    moved = true;
    state = PointState::OnSurf;
    ++field_.collisions;
    ++counters_.contacts;
  } else if (state == PointState::OnSurf) {
    if (d > offsets_.t3_m) {
      state = PointState::InsideVol;  // carried away by forces
    } else if (d < offsets_.t0_m) {
      local += (offsets_.t2_m - d) * f.normalAt(local);  // last resort
      moved = true;
      ++field_.projections;
      ++counters_.contacts;
    } else if (d < offsets_.t2_m) {
      // Sliding: the point stays on T2 while the part moves into it; the envelope down to
      // T1 absorbs what one substep's normal cannot (the penalty below).
      local += (offsets_.t2_m - d) * f.normalAt(local);
      moved = true;
    }
  } else {
    state = PointState::InsideVol;
  }

  if (state == PointState::OnSurf) {
    const Vec3 n = frame.pose1.applyVector(f.normalAt(local));
    const Vec3 world = frame.pose1.apply(local);
    const Vec3 partVelocity = (world - frame.pose0.apply(local)) / dt_s;
    Vec3 v = io.velocity(i);
    const double depth = offsets_.t2_m - f.distanceAt(local);
    if (depth > -1e-12) {
      // In contact: remove the inward normal velocity relative to the part, with Coulomb
      // friction on the tangential part (stick below the static coefficient).
      const Vec3 rel = v - partVelocity;
      const double vn = rel.dot(n);
      if (vn < 0) {
        Vec3 vt = rel - vn * n;
        const double speed = vt.norm();
        if (speed <= staticFriction_ * -vn) {
          vt.setZero();
        } else {
          vt *= 1.0 - dynamicFriction_ * -vn / speed;
        }
        v = partVelocity + vt;
      }
    }
    const double belowT1 = offsets_.t1_m - f.distanceAt(local);
    if (belowT1 > 0) {
      // Penalty: separate from the part at least at the rate that removes kPenaltyRate of
      // the depth per substep. A floor on the relative normal velocity, not an added impulse,
      // so that two parts meeting in a corner, or many substeps below T1, cannot pump energy.
      const double wanted = kPenaltyRate * belowT1 / dt_s;
      const double vn = (v - partVelocity).dot(n);
      if (vn < wanted) v += n * (wanted - vn);
    }
    io.setVelocity(i, v);
    if (moved) io.setPosition(i, world);
  }
  last = local;
  ++field_.transitions[toIndex(from)][toIndex(state)];
}

// A point that started below T1 of the part (a garment modelled tight on a smooth body lies
// inside a rigid segment's offset surfaces, or its capped volume, near the joints) is eased
// out along the normal at most kEmbeddedSpeed, losing its inward velocity relative to the
// part, instead of being thrown onto T2 in one substep; once on T2 it collides like any other.
void FieldCollider::releaseEmbedded(std::size_t k, const PartFrame& frame, std::size_t i, double dt_s,
                                    ClothState& io) {
  const field::DistanceField& f = *parts_[k].field;
  Vec3 local = frame.inverse1.apply(io.position(i));
  lastLocal_[k][i] = local;
  if (!walkable(f, roundVoxel(f.toVoxel(local)))) {
    embedded_[k][i] = 0;
    states_[k][i] = PointState::OutsideVol;
    return;
  }
  const double d = f.distanceAt(local);
  if (d >= offsets_.t2_m) {
    embedded_[k][i] = 0;
    states_[k][i] = d > offsets_.t3_m ? PointState::InsideVol : PointState::OnSurf;
    return;
  }
  const Vec3 normal = f.normalAt(local);
  const double rest = offsets_.t2_m - d;
  const double step = std::min(rest, kEmbeddedSpeed_m_s * dt_s);
  local += step * normal;
  lastLocal_[k][i] = local;
  if (step == rest) {  // on T2 now (to the field's accuracy): slide from here
    embedded_[k][i] = 0;
    states_[k][i] = PointState::OnSurf;
  }
  const Vec3 n = frame.pose1.applyVector(normal);
  const Vec3 world = frame.pose1.apply(local);
  const Vec3 partVelocity = (world - frame.pose0.apply(local)) / dt_s;
  const Vec3 v = io.velocity(i);
  const double vn = (v - partVelocity).dot(n);
  if (vn < 0) io.setVelocity(i, v - vn * n);
  io.setPosition(i, world);
}

std::array<std::size_t, 3> FieldCollider::pointsPerState() const {
  std::array<std::size_t, 3> counts{};
  for (const auto& part : states_)
    for (PointState s : part) ++counts[toIndex(s)];
  return counts;
}

void FieldCollider::vertexDisplayStates(std::vector<std::uint8_t>& out) const {
  const std::size_t n = states_.empty() ? 0 : states_.front().size();
  out.assign(n, 0);
  for (const auto& part : states_)
    for (std::size_t i = 0; i < n; ++i) out[i] = std::max<std::uint8_t>(out[i], static_cast<std::uint8_t>(part[i]));
  for (std::size_t i = 0; i < n && i < penalty_.size(); ++i)
    if (penalty_[i]) out[i] = 3;
}

}  // namespace drape::cloth
