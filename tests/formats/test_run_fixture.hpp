#pragma once
// A small run directory written the way `drape run` writes one (manifest, OBJ topologies,
// PC2 caches), for the player, renderer and exporter tests: a closed cylinder "torso"
// segment that turns and sways rigidly, and a square "flag" garment beside it that waves
// (its left edge pinned, so that edge stays put), with a state cache for the overlays.
// Units m, Y up.

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/formats/state_cache.hpp"
#include "drape/mesh/trimesh.hpp"
#include "drape/testing/temp_dir.hpp"

namespace drape::testrun {

inline constexpr double kRate = 24.0;
inline constexpr int kFlagColumns = 16;  // vertices along x
inline constexpr int kFlagRows = 12;     // vertices along y
inline constexpr double kFlagLeft = 0.30, kFlagWidth = 0.60, kFlagBottom = 0.55, kFlagHeight = 0.45;

/// A fresh directory under the system's temporary directory.
inline std::string freshDir(const std::string& name) {
  const std::filesystem::path dir = testing::processTempDir(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// A closed cylinder (radius r, from y0 to y1, axis Y through the origin), outward winding.
inline mesh::TriMesh cylinder(double r, double y0, double y1, int sides = 24) {
  mesh::TriMesh m;
  m.name = "torso";
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < sides; ++i) {
      const double a = 2.0 * std::numbers::pi * i / sides;
      m.positions.emplace_back(r * std::cos(a), ring == 0 ? y0 : y1, -r * std::sin(a));
    }
  const auto bottom = static_cast<std::uint32_t>(m.positions.size());
  m.positions.emplace_back(0.0, y0, 0.0);
  m.positions.emplace_back(0.0, y1, 0.0);
  const std::uint32_t top = bottom + 1;
  const auto n = static_cast<std::uint32_t>(sides);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    m.triangles.push_back({i, j, n + j});
    m.triangles.push_back({i, n + j, n + i});
    m.triangles.push_back({bottom, j, i});
    m.triangles.push_back({top, n + i, n + j});
  }
  return m;
}

/// The segment's rigid motion at frame f: a turn about Y and a sway along X.
inline RigidTransform torsoMotion(long f) {
  const double t = static_cast<double>(f) / kRate;
  RigidTransform x;
  x.rotation = Quat(Eigen::AngleAxisd(0.4 * std::sin(2.0 * t), Vec3::UnitY()));
  x.translation = Vec3(0.03 * std::sin(3.0 * t), 0.0, 0.0);
  return x;
}

inline std::vector<mesh::Triangle> flagTriangles() {
  std::vector<mesh::Triangle> tris;
  for (int j = 0; j + 1 < kFlagRows; ++j)
    for (int i = 0; i + 1 < kFlagColumns; ++i) {
      const auto a = static_cast<std::uint32_t>(j * kFlagColumns + i);
      tris.push_back({a, a + 1, a + kFlagColumns + 1});
      tris.push_back({a, a + kFlagColumns + 1, a + kFlagColumns});
    }
  return tris;
}

/// The flag at frame f: a travelling wave in z whose amplitude grows from the pinned left edge.
inline std::vector<Vec3> flagPositions(long f) {
  const double t = static_cast<double>(f) / kRate;
  std::vector<Vec3> p;
  for (int j = 0; j < kFlagRows; ++j)
    for (int i = 0; i < kFlagColumns; ++i) {
      const double u = static_cast<double>(i) / (kFlagColumns - 1);
      const double x = kFlagLeft + u * kFlagWidth;
      const double y = kFlagBottom + static_cast<double>(j) / (kFlagRows - 1) * kFlagHeight;
      p.emplace_back(x, y, 0.12 * u * std::sin(9.0 * u - 6.0 * t));
    }
  return p;
}

/// The flag's vertex states at frame f (render::vertex_state bits): its pinned left edge
/// (0x04), the right half on a collision surface (2) from frame 1 on, the rest outside (0).
inline std::vector<std::uint8_t> flagStates(long f) {
  std::vector<std::uint8_t> s;
  for (int j = 0; j < kFlagRows; ++j)
    for (int i = 0; i < kFlagColumns; ++i)
      s.push_back(i == 0 ? std::uint8_t{0x04} : (f > 0 && 2 * i >= kFlagColumns) ? std::uint8_t{2} : std::uint8_t{0});
  return s;
}

/// Writes the run into `dir` with `frames` frames; returns dir.
inline std::string writeTestRun(const std::string& dir, long frames = 24) {
  const mesh::TriMesh torso = cylinder(0.15, 0.35, 1.05);
  const std::vector<mesh::Triangle> flag = flagTriangles();
  formats::writeObj(dir + "/torso.obj", torso.positions, torso.triangles);
  formats::writeObj(dir + "/flag.obj", flagPositions(0), flag);
  {
    formats::Pc2Writer torsoCache(dir + "/torso.pc2", torso.vertexCount(), 0.0, 1.0);
    formats::Pc2Writer flagCache(dir + "/flag.pc2", static_cast<std::size_t>(kFlagColumns * kFlagRows), 0.0, 1.0);
    formats::StateCacheWriter stateCache(dir + "/flag.states", static_cast<std::size_t>(kFlagColumns * kFlagRows));
    for (long f = 0; f < frames; ++f) {
      std::vector<Vec3> moved = torso.positions;
      for (Vec3& p : moved) p = torsoMotion(f).apply(p);
      torsoCache.writeFrame(moved);
      flagCache.writeFrame(flagPositions(f));
      stateCache.writeFrame(flagStates(f));
    }
  }
  formats::RunManifest manifest;
  manifest.frameRate = kRate;
  manifest.frames = frames;
  manifest.startFrame = 0;
  manifest.meshes = {{"torso", "segment", "torso.obj", "torso.pc2", "", "", std::nullopt},
                     {"flag", "garment", "flag.obj", "flag.pc2", "flag.states", "", std::nullopt}};
  formats::writeRunManifest(dir, manifest);
  return dir;
}

}  // namespace drape::testrun
