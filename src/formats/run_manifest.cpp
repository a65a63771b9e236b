#include "drape/formats/run_manifest.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/formats/json_text.hpp"

namespace drape::formats {
namespace {

constexpr int kManifestVersion = 1;

// The value under `key`; "missing key" when `j` is not an object or lacks it.
const nlohmann::json& requiredKey(const nlohmann::json& j, const char* key, const std::string& file) {
  if (!j.is_object() || !j.contains(key)) throw Error(fmt::format("{}: missing key '{}'", file, key));
  return j.at(key);
}

[[noreturn]] void wrongType(const char* key, const std::string& file) {
  throw Error(fmt::format("{}: key '{}' has the wrong type", file, key));
}

std::string requiredString(const nlohmann::json& j, const char* key, const std::string& file) {
  const nlohmann::json& v = requiredKey(j, key, file);
  if (!v.is_string()) wrongType(key, file);
  return v.get<std::string>();
}

// Whole numbers only: nlohmann would convert 2.5 or 1e300 to an integer unchecked (the
// latter undefined behaviour).
long long wholeNumber(const nlohmann::json& v, const char* key, const std::string& file) {
  if (!v.is_number_integer()) wrongType(key, file);
  if (v.is_number_unsigned() && v.get<std::uint64_t>() > std::uint64_t(std::numeric_limits<long long>::max())) wrongType(key, file);
  return v.get<long long>();
}

long long requiredWhole(const nlohmann::json& j, const char* key, const std::string& file) {
  return wholeNumber(requiredKey(j, key, file), key, file);
}

double requiredNumber(const nlohmann::json& j, const char* key, const std::string& file) {
  const nlohmann::json& v = requiredKey(j, key, file);
  if (!v.is_number()) wrongType(key, file);
  return v.get<double>();
}

/// Three numbers from 0 to 1.
Vec3 colourOf(const nlohmann::json& v, const std::string& file) {
  if (!v.is_array() || v.size() != 3) wrongType("colour", file);
  Vec3 c;
  for (int k = 0; k < 3; ++k) {
    if (!v[static_cast<std::size_t>(k)].is_number()) wrongType("colour", file);
    c[k] = v[static_cast<std::size_t>(k)].get<double>();
    if (!(c[k] >= 0.0 && c[k] <= 1.0)) throw Error(fmt::format("{}: key 'colour' must hold numbers from 0 to 1", file));
  }
  return c;
}

}  // namespace

void writeRunManifest(const std::string& directory, const RunManifest& manifest) {
  nlohmann::json j;
  j["format"] = "drape-run";
  j["version"] = kManifestVersion;
  j["frame_rate"] = manifest.frameRate;
  j["frames"] = manifest.frames;
  j["start_frame"] = manifest.startFrame;
  j["meshes"] = nlohmann::json::array();
  for (const RunMesh& m : manifest.meshes) {
    nlohmann::json mesh = {{"name", m.name}, {"role", m.role}, {"topology", m.topology}, {"cache", m.cache}};
    if (!m.states.empty()) mesh["states"] = m.states;
    if (!m.character.empty()) mesh["character"] = m.character;
    if (m.colour) mesh["colour"] = {m.colour->x(), m.colour->y(), m.colour->z()};
    j["meshes"].push_back(std::move(mesh));
  }
  const std::string path = (std::filesystem::path(directory) / "manifest.json").string();
  std::ofstream out(path);
  out << j.dump(2) << '\n';
  if (!out) throw Error(fmt::format("{}: cannot be written", path));
}

RunManifest parseRunManifest(std::string_view text, const std::string& name) {
  const nlohmann::json j = parseJsonText(text, name);
  const auto format = j.is_object() ? j.find("format") : j.end();
  if (format == j.end() || !format->is_string() || format->get<std::string>() != "drape-run")
    throw Error(fmt::format("{}: not a drape run manifest", name));
  const long long version = requiredWhole(j, "version", name);
  if (version != kManifestVersion) throw Error(fmt::format("{}: manifest version {} (this drape reads {})", name, version, kManifestVersion));
  RunManifest m;
  m.frameRate = requiredNumber(j, "frame_rate", name);
  const long long frames = requiredWhole(j, "frames", name);
  const long long startFrame = j.contains("start_frame") ? wholeNumber(j["start_frame"], "start_frame", name) : 0;
  if (!(m.frameRate > 0) || frames < 0) throw Error(fmt::format("{}: frame_rate must be > 0 and frames >= 0", name));
  m.frames = static_cast<long>(frames);
  m.startFrame = static_cast<long>(startFrame);
  const nlohmann::json& meshes = requiredKey(j, "meshes", name);
  if (!meshes.is_array()) wrongType("meshes", name);
  for (const nlohmann::json& mesh : meshes) {
    RunMesh r;
    r.name = requiredString(mesh, "name", name);
    r.role = requiredString(mesh, "role", name);
    r.topology = requiredString(mesh, "topology", name);
    r.cache = requiredString(mesh, "cache", name);
    if (mesh.contains("states")) r.states = requiredString(mesh, "states", name);
    if (mesh.contains("character")) r.character = requiredString(mesh, "character", name);
    if (mesh.contains("colour")) r.colour = colourOf(mesh["colour"], name);
    m.meshes.push_back(std::move(r));
  }
  return m;
}

RunManifest readRunManifest(const std::string& directory) {
  const std::string path = (std::filesystem::path(directory) / "manifest.json").string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(fmt::format("{}: not a drape run directory (no manifest.json)", directory));
  std::ostringstream text;
  text << in.rdbuf();
  return parseRunManifest(text.str(), path);
}

}  // namespace drape::formats
