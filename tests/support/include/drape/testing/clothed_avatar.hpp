#pragma once
// Shared by the test modules: a character file that holds its clothes as well as its body,
// as games and character tools ship them. CesiumMan (data/avatars/CesiumMan.glb) written
// as a .gltf whose body node is called "Body" and which has a second skinned node, "Cape"
// (mesh "CapeMesh"), moved by the same skin: his skin pushed out along its normals by
// `offset_m` (in the mesh's own space, before skinning). Test modules that include this
// link nlohmann_json.

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace drape::testing {

struct ClothedAvatarOptions {
  double offset_m = 0.01;
  /// Give the cape a skin of its own (a copy of the body's), as some exporters write one
  /// skin per mesh: drape reads the file's first skin only.
  bool capeSkinOfItsOwn = false;
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

  // The cape's positions: each skin vertex moved along its normal (tightly packed floats).
  const nlohmann::json body = doc["meshes"][0]["primitives"][0];
  auto floats = [&](int accessor) {
    const nlohmann::json& a = doc["accessors"][accessor];
    const nlohmann::json& view = doc["bufferViews"][a["bufferView"].get<int>()];
    const std::size_t at = view.value("byteOffset", std::size_t{0}) + a.value("byteOffset", std::size_t{0});
    const std::size_t stride = view.value("byteStride", std::size_t{12});
    std::vector<float> out;
    for (std::size_t v = 0; v < a["count"].get<std::size_t>(); ++v)
      for (std::size_t c = 0; c < 3; ++c) {
        float x = 0;
        std::memcpy(&x, bin.data() + at + v * stride + c * 4, 4);
        out.push_back(x);
      }
    return out;
  };
  const std::vector<float> p = floats(body["attributes"]["POSITION"].get<int>());
  const std::vector<float> n = floats(body["attributes"]["NORMAL"].get<int>());
  while (bin.size() % 4 != 0) bin.push_back('\0');
  const std::size_t capeAt = bin.size();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const float x = p[i] + static_cast<float>(options.offset_m) * n[i];
    bin.append(reinterpret_cast<const char*>(&x), 4);
  }
  doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", capeAt}, {"byteLength", 4 * p.size()}});
  doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                              {"componentType", 5126},
                              {"count", p.size() / 3},
                              {"type", "VEC3"}});
  nlohmann::json cape = body;
  cape.erase("material");
  cape["attributes"].erase("NORMAL");
  cape["attributes"].erase("TEXCOORD_0");
  cape["attributes"]["POSITION"] = doc["accessors"].size() - 1;
  doc["meshes"].push_back({{"name", "CapeMesh"}, {"primitives", {cape}}});

  // Node 1 places the body; the cape goes beside it under the same parent.
  int skin = 0;
  if (options.capeSkinOfItsOwn) {
    doc["skins"].push_back(doc["skins"][0]);
    skin = static_cast<int>(doc["skins"].size()) - 1;
  }
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
