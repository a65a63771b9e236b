// The skinned body `drape run` writes for players stays under the cloth: on the bundled
// walking skirt, over the whole walk, no point of the skirt lies inside the skin where the
// skin is skinned to the parts the skirt collides with. Without the tuck (sim/body_skin)
// the skin's triangles span the crease at the front of the flexed hip and stand up to
// 26 mm out through the skirt, which players showed as holes in it.
//
// Measured here independently of drape's code: random points of the skirt's triangles,
// against the nearest triangle of the skin, inside or out by its outward vertex normals.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <unordered_map>

#include "cli_runner.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/mesh/closest_point.hpp"
#include "drape/scene/avatar_gltf.hpp"

namespace drape {
namespace {

const std::string kSkirtDir = std::string(DRAPE_SOURCE_DIR) + "/examples/walking_skirt";
/// The skirt's collidesWith in examples/walking_skirt/scene.wrl.
const std::set<std::string> kCollidable = {"LowerBack", "Hips", "LeftUpLeg", "RightUpLeg", "LeftLeg", "RightLeg"};

/// Skin triangles whose three vertices are skinned to those parts for at least half their
/// weight: the rest (arms, hands) is not the skirt's to keep out.
std::vector<mesh::Triangle> collidableSkin(const scene::Avatar& avatar) {
  const scene::SkinnedMesh& skin = *avatar.skin;
  std::vector<std::uint8_t> collidable(skin.mesh.vertexCount(), 0);
  for (std::size_t v = 0; v < collidable.size(); ++v) {
    float w = 0;
    for (std::size_t k = 0; k < 4; ++k) w += kCollidable.count(avatar.joints[skin.joints[v][k]].name) ? skin.weights[v][k] : 0;
    collidable[v] = w >= 0.5f;
  }
  std::vector<mesh::Triangle> out;
  for (const mesh::Triangle& t : skin.mesh.triangles)
    if (collidable[t[0]] && collidable[t[1]] && collidable[t[2]]) out.push_back(t);
  return out;
}

/// The skin's triangles of one frame in cells of 8 cm by their first vertex: the nearest
/// triangle within 5 cm of a point has its first vertex in the point's cell or a neighbour
/// (no skin triangle is 3 cm across).
class SkinCells {
 public:
  /// `all`: the whole skin, for its normals; `triangles`: the ones looked at.
  SkinCells(const std::vector<Vec3>& skin, const std::vector<mesh::Triangle>& all,
            const std::vector<mesh::Triangle>& triangles)
      : skin_(skin), triangles_(triangles), normals_(skin.size(), Vec3::Zero()) {
    for (std::size_t t = 0; t < triangles.size(); ++t) cells_[key(cellOf(skin[triangles[t][0]]))].push_back(t);
    for (const mesh::Triangle& t : all) {
      const Vec3 n = (skin[t[1]] - skin[t[0]]).cross(skin[t[2]] - skin[t[0]]);
      for (const std::uint32_t v : t) normals_[v] += n;
    }
  }

  /// How far p lies inside the skin (0 when outside): against the nearest triangle within
  /// 5 cm.
  [[nodiscard]] double depthInside(const Vec3& p) const {
    double best = 0.05 * 0.05, depth = 0.0;
    const std::array<long, 3> c = cellOf(p);
    for (long dz = -1; dz <= 1; ++dz)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dx = -1; dx <= 1; ++dx) {
          const auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (const std::size_t i : it->second) {
            const mesh::Triangle& t = triangles_[i];
            const Vec3 &a = skin_[t[0]], &b = skin_[t[1]], &cc = skin_[t[2]];
            const Vec3 q = mesh::closestOnTriangle(p, a, b, cc);
            const double d2 = (q - p).squaredNorm();
            if (d2 >= best) continue;
            best = d2;
            // Inside or out by the vertex normals blended at q: a triangle's own normal
            // says nothing where q is its corner.
            const Vec3 w = mesh::barycentric(q, a, b, cc);
            const Vec3 n = w.x() * normals_[t[0]] + w.y() * normals_[t[1]] + w.z() * normals_[t[2]];
            depth = (p - q).dot(n) < 0 ? std::sqrt(d2) : 0.0;
          }
        }
    return depth;
  }

 private:
  static std::array<long, 3> cellOf(const Vec3& p) {
    return {std::lround(std::floor(p.x() / 0.08)), std::lround(std::floor(p.y() / 0.08)),
            std::lround(std::floor(p.z() / 0.08))};
  }
  static long key(const std::array<long, 3>& c) { return (c[0] * 4096 + c[1]) * 4096 + c[2]; }

  const std::vector<Vec3>& skin_;
  const std::vector<mesh::Triangle>& triangles_;
  std::vector<Vec3> normals_;  ///< per vertex, area-weighted
  std::unordered_map<long, std::vector<std::size_t>> cells_;
};

struct Deepest {
  double depth_m = 0.0;
  std::size_t frame = 0, points = 0;
};

/// The walking skirt on `motion`: how far points of the skirt lie inside the skin.
Deepest skirtInsideSkin(const std::string& motion, const std::string& name) {
  testing::ScratchDir dir("body-under-cloth-" + name);
  const std::string out = dir / "out";
  const testing::CliResult r =
      testing::runDrape("run '" + kSkirtDir + "/scene.wrl' --motion '" + motion + "' --out '" + out + "'", dir);
  EXPECT_EQ(r.code, 0) << r.err;
  const scene::Avatar avatar = scene::loadAvatarFile(std::string(DRAPE_DATA_DIR) + "/avatars/makehuman_rig_cmu_mb.mhskel");
  const std::vector<mesh::Triangle> skinTriangles = collidableSkin(avatar);
  const formats::Pc2Cache body = formats::readPc2(out + "/body.pc2");
  const formats::Pc2Cache skirt = formats::readPc2(out + "/garment.pc2");
  const mesh::TriMesh skirtMesh = formats::readObj(out + "/garment.obj");
  EXPECT_EQ(body.pointCount, avatar.skin->mesh.vertexCount());
  EXPECT_GT(skirt.frames.size(), 100u);

  std::mt19937 random(20261123);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Deepest deepest;
  for (std::size_t f = 0; f < skirt.frames.size(); f += 5) {
    const std::vector<Vec3>& cloth = skirt.frames[f];
    const SkinCells skin(body.frames[f], avatar.skin->mesh.triangles, skinTriangles);
    for (const mesh::Triangle& t : skirtMesh.triangles)
      for (int k = 0; k < 3; ++k) {
        double u = unit(random), v = unit(random);
        if (u + v > 1) u = 1 - u, v = 1 - v;
        const Vec3 p = cloth[t[0]] + u * (cloth[t[1]] - cloth[t[0]]) + v * (cloth[t[2]] - cloth[t[0]]);
        const double depth = skin.depthInside(p);
        if (depth > deepest.depth_m) deepest.depth_m = depth, deepest.frame = f;
        ++deepest.points;
      }
  }
  std::printf("%s: %zu points of the skirt, at most %.2f mm inside the skin (frame %zu)\n", name.c_str(),
              deepest.points, 1e3 * deepest.depth_m, deepest.frame);
  return deepest;
}

// The tuck keeps the cloth 2 mm out of the skin at its own points; between them both
// surfaces are flat triangles of different sizes.
TEST(BodyUnderCloth, TheSkinIsNowhereOutsideTheWalkingSkirt) {
  const std::string mocap = std::string(DRAPE_DATA_DIR) + "/mocap/";
  for (const auto& [motion, name] : {std::pair{kSkirtDir + "/walk.bvh", std::string("bundled")},
                                     std::pair{mocap + "cmu_walk_delfem2.bvh", std::string("delfem2")},
                                     std::pair{mocap + "cmu_02_02_walk_dazstyle.bvh", std::string("dazstyle")}}) {
    const Deepest d = skirtInsideSkin(motion, name);
    EXPECT_LT(d.depth_m, 0.002) << name << ", frame " << d.frame;
  }
}

}  // namespace
}  // namespace drape
