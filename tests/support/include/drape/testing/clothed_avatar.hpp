#pragma once
// Shared by the test modules: a character file that holds its clothes as well as its body,
// as games and character tools ship them. CesiumMan (data/avatars/CesiumMan.glb) written
// as a .gltf whose body node is called "Body" and which has a second skinned node, "Cape"
// (mesh "CapeMesh"), moved by the same skin: his skin pushed out along its normals by
// `offset_m` (in the mesh's own space, before skinning). Test modules that include this
// link nlohmann_json.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace drape::testing {

/// Which skin moves the cape.
enum class CapeSkin {
  Body,      ///< the body's
  Copy,      ///< a skin of its own listing the same joints (exporters that write one skin per mesh)
  Reversed,  ///< a skin of its own listing the same joints in reverse order, its JOINTS_0 renumbered to match
  Apart,     ///< a skin of one joint of its own, a node outside the body's skeleton (a second character)
};

struct ClothedAvatarOptions {
  double offset_m = 0.01;
  CapeSkin capeSkin = CapeSkin::Body;
};

/// Writes DIR/clothed.gltf and DIR/clothed.bin; returns the .gltf's path.
inline std::string clothedCesiumMan(const std::filesystem::path& dir, const ClothedAvatarOptions& options = {}) {
  std::ifstream in(std::string(DRAPE_DATA_DIR) + "/avatars/CesiumMan.glb", std::ios::binary);
  const std::string glb((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (glb.size() < 28) throw std::runtime_error("CesiumMan.glb: too short");
  std::uint32_t jsonLength = 0, binLength = 0;
  std::memcpy(&jsonLength, glb.data() + 12, 4);
  std::memcpy(&binLength, glb.data() + 20 + jsonLength, 4);
  nlohmann::json doc = nlohmann::json::parse(glb.substr(20, jsonLength));
  std::string bin = glb.substr(28 + jsonLength, binLength);

  const nlohmann::json body = doc["meshes"][0]["primitives"][0];
  // An accessor's components as numbers (floats, or unsigned bytes or shorts), `n` per element.
  auto numbers = [&](int accessor, std::size_t n) {
    const nlohmann::json& a = doc["accessors"][accessor];
    const nlohmann::json& view = doc["bufferViews"][a["bufferView"].get<int>()];
    const int type = a["componentType"].get<int>();
    const std::size_t size = type == 5126 ? 4 : type == 5123 ? 2 : 1;
    const std::size_t at = view.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
    const std::size_t stride = view.value("byteStride", n * size);
    std::vector<double> out;
    for (std::size_t e = 0; e < a["count"].get<std::size_t>(); ++e)
      for (std::size_t c = 0; c < n; ++c) {
        const char* q = bin.data() + at + e * stride + c * size;
        float f = 0;
        std::uint16_t u = 0;
        if (size == 4) std::memcpy(&f, q, 4);
        if (size == 2) std::memcpy(&u, q, 2);
        out.push_back(size == 4 ? f : size == 2 ? u : static_cast<unsigned char>(*q));
      }
    return out;
  };
  // Appends `values` as a new accessor of `type` (floats, or unsigned shorts for 5123).
  auto appendAccessor = [&](const std::vector<double>& values, int componentType, const char* type, std::size_t count) {
    while (bin.size() % 4 != 0) bin.push_back('\0');
    const std::size_t at = bin.size();
    for (double v : values) {
      if (componentType == 5126) {
        const auto f = static_cast<float>(v);
        bin.append(reinterpret_cast<const char*>(&f), 4);
      } else {
        const auto u = static_cast<std::uint16_t>(v);
        bin.append(reinterpret_cast<const char*>(&u), 2);
      }
    }
    doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", bin.size() - at}});
    doc["accessors"].push_back(
        {{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", componentType}, {"count", count}, {"type", type}});
    return static_cast<int>(doc["accessors"].size()) - 1;
  };
  // The cape's positions: each skin vertex moved along its normal.
  const std::vector<double> p = numbers(body["attributes"]["POSITION"].get<int>(), 3);
  const std::vector<double> n = numbers(body["attributes"]["NORMAL"].get<int>(), 3);
  std::vector<double> capePositions(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)  // in floats, as the file stores them
    capePositions[i] = static_cast<float>(p[i]) + static_cast<float>(options.offset_m) * static_cast<float>(n[i]);
  const int capeAccessor = appendAccessor(capePositions, 5126, "VEC3", p.size() / 3);
  nlohmann::json cape = body;
  cape.erase("material");
  cape["attributes"].erase("NORMAL");
  cape["attributes"].erase("TEXCOORD_0");
  cape["attributes"]["POSITION"] = capeAccessor;
  doc["meshes"].push_back({{"name", "CapeMesh"}, {"primitives", {cape}}});

  // The cape's skin.
  int skin = 0;
  const std::size_t vertices = p.size() / 3;
  if (options.capeSkin == CapeSkin::Copy) {
    doc["skins"].push_back(doc["skins"][0]);
    skin = 1;
  } else if (options.capeSkin == CapeSkin::Reversed) {
    nlohmann::json reversed = doc["skins"][0];
    const std::size_t n = reversed["joints"].size();
    std::reverse(reversed["joints"].begin(), reversed["joints"].end());
    const std::vector<double> bind = numbers(reversed["inverseBindMatrices"].get<int>(), 16);
    std::vector<double> bindReversed;
    for (std::size_t j = n; j-- > 0;) bindReversed.insert(bindReversed.end(), bind.begin() + 16 * j, bind.begin() + 16 * (j + 1));
    reversed["inverseBindMatrices"] = appendAccessor(bindReversed, 5126, "MAT4", n);
    std::vector<double> joints = numbers(body["attributes"]["JOINTS_0"].get<int>(), 4);
    for (double& j : joints) j = static_cast<double>(n - 1) - j;
    doc["skins"].push_back(reversed);
    skin = 1;
    cape["attributes"]["JOINTS_0"] = appendAccessor(joints, 5123, "VEC4", vertices);
  } else if (options.capeSkin == CapeSkin::Apart) {
    doc["nodes"].push_back({{"name", "Prop"}});
    doc["nodes"][0]["children"].push_back(doc["nodes"].size() - 1);
    doc["skins"].push_back({{"joints", {doc["nodes"].size() - 1}}});
    skin = 1;
    cape["attributes"]["JOINTS_0"] = appendAccessor(std::vector<double>(4 * vertices, 0.0), 5123, "VEC4", vertices);
  }
  doc["meshes"].back()["primitives"][0] = cape;

  // Node 1 places the body; the cape goes beside it under the same parent.
  doc["nodes"][1]["name"] = "Body";
  doc["nodes"].push_back({{"name", "Cape"}, {"mesh", doc["meshes"].size() - 1}, {"skin", skin}});
  const std::size_t capeNode = doc["nodes"].size() - 1;
  for (nlohmann::json& node : doc["nodes"])
    if (node.contains("children"))
      for (const nlohmann::json& c : node["children"])
        if (c.get<int>() == 1) {
          node["children"].push_back(capeNode);
          break;
        }
  doc["buffers"] = nlohmann::json::array({{{"uri", "clothed.bin"}, {"byteLength", bin.size()}}});
  // The images were in the GLB's buffer; the test reads no texture.
  doc.erase("images");
  doc.erase("textures");
  doc.erase("materials");
  doc.erase("samplers");
  doc["meshes"][0]["primitives"][0].erase("material");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "clothed.bin", std::ios::binary) << bin;
  std::ofstream(dir / "clothed.gltf") << doc.dump(1);
  return (dir / "clothed.gltf").string();
}

}  // namespace drape::testing
