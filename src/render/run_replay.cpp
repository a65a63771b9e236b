#include "drape/render/run_replay.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/formats/json_text.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"
#include "drape/formats/state_cache.hpp"

namespace drape::render {
namespace {

// A state cache holds exactly the bits the renderer draws by.
static_assert((vertex_state::kCollisionMask | vertex_state::kPinned | vertex_state::kBound) ==
              formats::kKnownStateBits);

/// DIR/stats.json's "ms_per_stage" object ({"forces": 1.2, ...}), when the run wrote one,
/// without the stages that never ran (strain limiting, in a run that needed none). Anything
/// else in the file is not the player's business; a malformed file is reported.
std::vector<StageTime> readStageTimes(const std::filesystem::path& directory) {
  const std::filesystem::path path = directory / "stats.json";
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const nlohmann::json j = formats::parseJsonText(text, path.string());
  std::vector<StageTime> stages;
  if (!j.is_object() || !j.contains("ms_per_stage") || !j["ms_per_stage"].is_object()) return stages;
  for (const auto& [stage, value] : j["ms_per_stage"].items()) {
    if (value.is_number() && value.get<double>() != 0.0) stages.push_back({stage, value.get<double>()});
  }
  return stages;
}

}  // namespace

RunReplay::RunReplay(const std::string& directory) : directory_(directory) {
  const formats::RunManifest manifest = formats::readRunManifest(directory);
  const std::filesystem::path dir(directory);
  if (manifest.frames <= 0) throw Error(fmt::format("{}: the run has no frames", (dir / "manifest.json").string()));
  if (!(manifest.frameRate > 0.0) || !std::isfinite(manifest.frameRate)) {
    throw Error(fmt::format("{}: frame_rate must be positive", (dir / "manifest.json").string()));
  }
  frameRate_ = manifest.frameRate;
  frames_ = manifest.frames;
  startFrame_ = manifest.startFrame;
  for (const formats::RunMesh& m : manifest.meshes) {
    const std::string objPath = (dir / m.topology).string();
    const std::string pc2Path = (dir / m.cache).string();
    mesh::TriMesh topology = formats::readObj(objPath);
    formats::Pc2Cache cache = formats::readPc2(pc2Path);
    if (cache.pointCount != topology.vertexCount()) {
      throw Error(fmt::format("{}: {} points per sample, but {} has {} vertices", pc2Path, cache.pointCount, objPath,
                              topology.vertexCount()));
    }
    if (static_cast<std::int64_t>(cache.frames.size()) < frames_) {
      throw Error(fmt::format("{}: {} samples, the manifest says {} frames", pc2Path, cache.frames.size(), frames_));
    }
    cache.frames.resize(static_cast<std::size_t>(frames_));
    for (const std::vector<Vec3>& f : cache.frames) {
      for (const Vec3& p : f) {
        if (!p.allFinite()) throw Error(fmt::format("{}: a position is not finite", pc2Path));
        bounds_.extend(p);
      }
    }
    MeshInfo info;
    info.name = m.name;
    try {
      info.role = parseMeshRole(m.role);
    } catch (const Error& e) {
      throw Error(fmt::format("{}: {}", (dir / "manifest.json").string(), e.what()));
    }
    std::vector<std::vector<std::uint8_t>> states;
    if (!m.states.empty()) {
      const std::string statesPath = (dir / m.states).string();
      formats::StateCache read = formats::readStateCache(statesPath);
      if (read.vertexCount != topology.vertexCount())
        throw Error(fmt::format("{}: {} vertices per frame, but {} has {}", statesPath, read.vertexCount, objPath,
                                topology.vertexCount()));
      if (static_cast<std::int64_t>(read.frames.size()) < frames_)
        throw Error(fmt::format("{}: {} frames, the manifest says {}", statesPath, read.frames.size(), frames_));
      read.frames.resize(static_cast<std::size_t>(frames_));
      states = std::move(read.frames);
    }
    info.vertexCount = topology.vertexCount();
    info.triangles = std::move(topology.triangles);
    meshes_.push_back(std::move(info));
    caches_.push_back(std::move(cache.frames));
    states_.push_back(std::move(states));
  }
  if (meshes_.empty()) throw Error(fmt::format("{}: the run lists no meshes", (dir / "manifest.json").string()));
  stages_ = readStageTimes(dir);
}

Aabb RunReplay::frameBounds(std::int64_t f) const {
  Aabb box;
  for (std::size_t m = 0; m < caches_.size(); ++m)
    for (const Vec3& p : positions(m, f)) box.extend(p);
  return box;
}

bool RunReplay::read(std::int64_t index, Frame& out) {
  if (index < 0 || index >= frames_) return false;
  out.index = index;
  out.time = TimeCode{startFrame_ + index, frameRate_};
  out.positions.resize(meshes_.size());
  for (std::size_t m = 0; m < meshes_.size(); ++m) out.positions[m] = caches_[m][static_cast<std::size_t>(index)];
  out.states.assign(meshes_.size(), {});
  for (std::size_t m = 0; m < meshes_.size(); ++m)
    if (!states_[m].empty()) out.states[m] = states_[m][static_cast<std::size_t>(index)];
  out.stages = stages_;
  return true;
}

}  // namespace drape::render
