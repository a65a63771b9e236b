#include "drape/sim/body_overlap.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace drape::sim {

double overlapDepth(const mesh::TriMesh& surface, const RigidTransform& pose, const PartField& into,
                    const RigidTransform& intoPose) {
  const field::DistanceField& f = into.field;
  // surface frame -> into's frame, once.
  const RigidTransform toInto = intoPose.inverse() * pose;
  double deepest = 0;
  for (const Vec3& v : surface.positions) {
    const Vec3 p = toInto.apply(v);
    if (!f.containsPoint(p)) continue;
    deepest = std::max(deepest, -f.distanceAt(p));
  }
  return deepest;
}

bool jointsMeet(const scene::Avatar& avatar, int a, int b) {
  const auto parent = [&](int j) { return j < 0 ? -1 : avatar.joints[static_cast<std::size_t>(j)].parent; };
  const int pa = parent(a), pb = parent(b);
  return a == b || pa == b || pb == a || (pa >= 0 && pa == pb) || parent(pa) == b || parent(pb) == a;
}

std::vector<BodyOverlap> findBodyOverlaps(const scene::Avatar& avatar, const AvatarPoses& poses,
                                          const std::vector<PartField>& fields, long frames, double frameRate_hz,
                                          double threshold_m) {
  const std::size_t n = fields.size();
  const auto surfaceOf = [&](std::size_t k) -> const mesh::TriMesh& {
    return avatar.segments[static_cast<std::size_t>(avatar.findSegment(fields[k].segment))].mesh;
  };
  // The pairs that may overlap, and their depth at rest (the avatar's own joint frames).
  struct Pair {
    std::size_t a, b;
    double rest_m;
    BodyOverlap found;
  };
  std::vector<Pair> pairs;
  for (std::size_t a = 0; a < n; ++a)
    for (std::size_t b = 0; b < n; ++b) {
      if (a == b || jointsMeet(avatar, fields[a].joint, fields[b].joint)) continue;
      const RigidTransform restA = avatar.joints[static_cast<std::size_t>(fields[a].joint)].restWorld();
      const RigidTransform restB = avatar.joints[static_cast<std::size_t>(fields[b].joint)].restWorld();
      Pair p{a, b, overlapDepth(surfaceOf(a), restA, fields[b], restB), {}};
      p.found.part = fields[a].segment;
      p.found.into = fields[b].segment;
      p.found.depthPerFrame.assign(static_cast<std::size_t>(frames + 1), 0.0f);
      pairs.push_back(std::move(p));
    }
  std::vector<RigidTransform> pose(n);
  std::vector<Aabb> box(n);
  for (long frame = 0; frame <= frames; ++frame) {
    const double t = static_cast<double>(frame) / frameRate_hz;
    for (std::size_t k = 0; k < n; ++k) {
      pose[k] = poses.jointAt(t, fields[k].joint);
      box[k] = moved(fields[k].field.bodyBounds(), pose[k]);
    }
    for (Pair& p : pairs) {
      if (!box[p.a].overlaps(box[p.b])) continue;
      const double beyond = overlapDepth(surfaceOf(p.a), pose[p.a], fields[p.b], pose[p.b]) - p.rest_m;
      if (beyond <= 0) continue;
      BodyOverlap& o = p.found;
      o.depthPerFrame[static_cast<std::size_t>(frame)] = static_cast<float>(beyond);
      if (beyond <= threshold_m) continue;
      if (o.frames == 0) o.firstFrame = frame;
      o.lastFrame = frame;
      ++o.frames;
      if (beyond > o.depth_m) {
        o.depth_m = beyond;
        o.deepestFrame = frame;
      }
    }
  }
  std::vector<BodyOverlap> out;
  for (Pair& p : pairs)
    if (p.found.frames > 0) out.push_back(std::move(p.found));
  std::sort(out.begin(), out.end(), [](const BodyOverlap& x, const BodyOverlap& y) { return x.depth_m > y.depth_m; });
  return out;
}

std::string describe(const BodyOverlap& o) {
  const std::string span = o.frames == 1 ? fmt::format("frame {}", o.firstFrame)
                                         : fmt::format("frames {} to {}, {} frames, deepest in frame {}", o.firstFrame,
                                                       o.lastFrame, o.frames, o.deepestFrame);
  return fmt::format("{} goes up to {:.0f} mm into {} ({})", o.part, 1e3 * o.depth_m, o.into, span);
}

}  // namespace drape::sim
