#include "drape/formats/run_manifest.hpp"

#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"

namespace drape::formats {
namespace {

constexpr int kVersion = 1;

template <typename T>
T required(const nlohmann::json& j, const char* key, const std::string& file) {
  if (!j.contains(key)) throw Error(fmt::format("{}: missing key '{}'", file, key));
  try {
    return j.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw Error(fmt::format("{}: key '{}' has the wrong type", file, key));
  }
}

}  // namespace

void writeRunManifest(const std::string& directory, const RunManifest& manifest) {
  nlohmann::json j;
  j["format"] = "drape-run";
  j["version"] = kVersion;
  j["frame_rate"] = manifest.frameRate;
  j["frames"] = manifest.frames;
  j["start_frame"] = manifest.startFrame;
  j["meshes"] = nlohmann::json::array();
  for (const RunMesh& m : manifest.meshes) {
    j["meshes"].push_back({{"name", m.name}, {"role", m.role}, {"topology", m.topology}, {"cache", m.cache}});
  }
  const std::string path = (std::filesystem::path(directory) / "manifest.json").string();
  std::ofstream out(path);
  out << j.dump(2) << '\n';
  if (!out) throw Error(fmt::format("{}: cannot be written", path));
}

RunManifest readRunManifest(const std::string& directory) {
  const std::string path = (std::filesystem::path(directory) / "manifest.json").string();
  std::ifstream in(path);
  if (!in) throw Error(fmt::format("{}: not a drape run directory (no manifest.json)", directory));
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& e) {
    throw Error(fmt::format("{}: not valid JSON (byte {})", path, e.byte));
  }
  if (!j.is_object() || j.value("format", "") != "drape-run") throw Error(fmt::format("{}: not a drape run manifest", path));
  const int version = required<int>(j, "version", path);
  if (version != kVersion) throw Error(fmt::format("{}: manifest version {} (this drape reads {})", path, version, kVersion));
  RunManifest m;
  m.frameRate = required<double>(j, "frame_rate", path);
  m.frames = required<long>(j, "frames", path);
  m.startFrame = j.value("start_frame", 0L);
  if (!(m.frameRate > 0) || m.frames < 0) throw Error(fmt::format("{}: frame_rate must be > 0 and frames >= 0", path));
  for (const auto& mesh : required<nlohmann::json>(j, "meshes", path)) {
    RunMesh r;
    r.name = required<std::string>(mesh, "name", path);
    r.role = required<std::string>(mesh, "role", path);
    r.topology = required<std::string>(mesh, "topology", path);
    r.cache = required<std::string>(mesh, "cache", path);
    m.meshes.push_back(std::move(r));
  }
  return m;
}

}  // namespace drape::formats
