#include "drape/render/run_replay.hpp"

#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
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

/// What each frame's overlay shows of the simulation's stages, from DIR/stats.json when the
/// run wrote one: `frame_ms_per_stage` (each stage's milliseconds per frame) or, in a run
/// made before drape wrote those, `ms_per_stage`'s means over the run, named as means.
/// Stages that took no time that frame are left out (strain limiting, in a run that needed
/// none; frame 0, the initial state). Anything else in the file is not the player's
/// business; a malformed file, or columns that do not hold a value per frame, is reported.
std::vector<std::vector<StageTime>> readStageTimes(const std::filesystem::path& directory, std::int64_t frames) {
  const std::filesystem::path path = directory / "stats.json";
  const std::optional<std::string> text = readFileText(path);
  if (!text) return {};
  const nlohmann::json j = formats::parseJsonText(*text, path.string());
  if (!j.is_object()) return {};
  if (j.contains("frame_ms_per_stage") && j["frame_ms_per_stage"].is_object()) {
    std::vector<std::vector<StageTime>> stages(static_cast<std::size_t>(frames));
    for (const auto& [stage, column] : j["frame_ms_per_stage"].items()) {
      if (!column.is_array() || static_cast<std::int64_t>(column.size()) != frames)
        throw Error(fmt::format("{}: frame_ms_per_stage.{} should be an array of a number per frame ({}), got {}",
                                path.string(), stage, frames,
                                column.is_array() ? fmt::format("{} values", column.size()) : column.type_name()));
      for (std::size_t f = 0; f < stages.size(); ++f) {
        if (!column[f].is_number())
          throw Error(fmt::format("{}: frame_ms_per_stage.{}[{}] should be a number, got {}", path.string(), stage, f,
                                  column[f].type_name()));
        if (const double ms = column[f].get<double>(); ms != 0.0) stages[f].push_back({stage, ms});
      }
    }
    return stages;
  }
  std::vector<StageTime> means;
  if (!j.contains("ms_per_stage") || !j["ms_per_stage"].is_object()) return {};
  for (const auto& [stage, value] : j["ms_per_stage"].items())
    if (value.is_number() && value.get<double>() != 0.0) means.push_back({"mean " + stage, value.get<double>()});
  return {std::move(means)};
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
    info.character = m.character;
    info.colour = m.colour;
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
  stages_ = readStageTimes(dir, frames_);
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
  if (stages_.size() == 1) out.stages = stages_[0];  // the run's means
  else if (!stages_.empty()) out.stages = stages_[static_cast<std::size_t>(index)];
  else out.stages.clear();
  return true;
}

}  // namespace drape::render
