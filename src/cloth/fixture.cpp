#include "drape/cloth/fixture.hpp"

namespace drape::cloth {

PinGroup PinGroup::atRest(std::vector<std::uint32_t> vertices, const std::vector<double>& restX,
                          const std::vector<double>& restY, const std::vector<double>& restZ,
                          std::shared_ptr<const FixtureMotion> motion) {
  PinGroup g;
  const RigidTransform toLocal = motion ? motion->poseAt(0.0).inverse() : RigidTransform::identity();
  for (std::uint32_t v : vertices) {
    const Vec3 local = toLocal.apply(Vec3(restX[v], restY[v], restZ[v]));
    g.localX.push_back(local.x());
    g.localY.push_back(local.y());
    g.localZ.push_back(local.z());
  }
  g.vertices = std::move(vertices);
  g.motion = std::move(motion);
  return g;
}

}  // namespace drape::cloth
