#include "drape/formats/gltf_avatar.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/json_text.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/formats/part_names.hpp"
#include "plain_data.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

constexpr std::size_t kMaxElements = 50'000'000;

// ---- the glTF document, parsed by hand from its JSON ---------------------------------
//
// Only what a skinned character needs. Field names follow the glTF 2.0 schema.

constexpr int kComponentByte = 5120, kComponentUnsignedByte = 5121, kComponentShort = 5122,
              kComponentUnsignedShort = 5123, kComponentUnsignedInt = 5125, kComponentFloat = 5126;
constexpr int kModeTriangles = 4;

struct GBufferView {
  int buffer = -1;
  std::size_t byteOffset = 0, byteLength = 0, byteStride = 0;
};
struct GAccessor {
  int bufferView = -1;
  std::size_t byteOffset = 0, count = 0;
  int componentType = 0, components = 0;
  bool normalized = false, sparse = false;
};
struct GNode {
  std::string name;
  std::vector<int> children;
  std::vector<double> matrix, translation, rotation, scale;
  int mesh = -1, skin = -1;
};
struct GSkin {
  std::vector<int> joints;
  int inverseBindMatrices = -1;
};
struct GPrimitive {
  std::map<std::string, int> attributes;
  int indices = -1, mode = kModeTriangles;
};
struct GChannel {
  int sampler = -1, node = -1;
  std::string path;  ///< "translation", "rotation", "scale" or "weights"
};
struct GSampler {
  int input = -1, output = -1;
  std::string interpolation = "LINEAR";
};
struct GAnimation {
  std::string name;
  std::vector<GChannel> channels;
  std::vector<GSampler> samplers;
};
struct GModel {
  std::vector<GAnimation> animations;
  std::vector<std::vector<unsigned char>> buffers;
  std::vector<GBufferView> bufferViews;
  std::vector<GAccessor> accessors;
  std::vector<GNode> nodes;
  std::vector<GSkin> skins;
  std::vector<std::vector<GPrimitive>> meshes;
  std::vector<std::string> meshNames;  ///< "" where a mesh has none
  /// The root nodes of the scene the file shows (its "scene", else its first); nullopt for
  /// a file without scenes, which shows every node.
  std::optional<std::vector<int>> sceneRoots;
};

bool insideFolder(const std::string& baseDir, const std::string& path) {
  if (baseDir.empty()) return false;
  std::error_code ec;
  const auto base = std::filesystem::weakly_canonical(baseDir, ec);
  if (ec) return false;
  const auto full = std::filesystem::weakly_canonical(path, ec);
  if (ec) return false;
  const auto rel = full.lexically_relative(base);
  return !rel.empty() && *rel.begin() != ".." && !rel.is_absolute();
}

std::vector<unsigned char> decodeBase64(std::string_view text, const std::string& name) {
  auto value = [](char c) -> int {
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+' || c == '-') return 62;
    if (c == '/' || c == '_') return 63;
    return -1;
  };
  std::vector<unsigned char> out;
  out.reserve(text.size() / 4 * 3);
  unsigned bits = 0;
  int count = 0;
  for (char c : text) {
    if (c == '=') break;
    const int v = value(c);
    if (v < 0) throw Error(fmt::format("{}: a data: URI holds a character that is not base64", name));
    bits = (bits << 6) | static_cast<unsigned>(v);
    if (++count == 4) {
      out.push_back(static_cast<unsigned char>(bits >> 16));
      out.push_back(static_cast<unsigned char>(bits >> 8));
      out.push_back(static_cast<unsigned char>(bits));
      bits = 0;
      count = 0;
    }
  }
  if (count == 2) out.push_back(static_cast<unsigned char>(bits >> 4));
  if (count == 3) {
    out.push_back(static_cast<unsigned char>(bits >> 10));
    out.push_back(static_cast<unsigned char>(bits >> 2));
  }
  return out;
}

// A buffer's bytes: a base64 data: URI, or a file inside the model's folder.
std::vector<unsigned char> loadUri(const std::string& uri, const std::string& name, const std::string& baseDir) {
  if (uri.rfind("data:", 0) == 0) {
    const std::size_t comma = uri.find(',');
    if (comma == std::string::npos || uri.substr(0, comma).find(";base64") == std::string::npos)
      throw Error(fmt::format("{}: only base64 data: URIs are supported", name));
    return decodeBase64(std::string_view(uri).substr(comma + 1), name);
  }
  const std::size_t colon = uri.find(':');
  const std::string path = (std::filesystem::path(baseDir) / uri).string();
  if ((colon != std::string::npos && colon < uri.find('/')) || std::filesystem::path(uri).is_absolute() ||
      !insideFolder(baseDir, path))
    throw Error(fmt::format("{}: refers to '{}', outside the model's folder (only data: URIs and files beside the model are read)",
                            name, uri));
  const std::string bytes = detail::readWholeFile(path, std::size_t{1} << 30);
  return {bytes.begin(), bytes.end()};
}

using nlohmann::json;

int intOr(const json& j, const char* key, int fallback) {
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  if (!it->is_number_integer()) throw Error(fmt::format("\"{}\" must be a whole number", key));
  const auto v = it->get<long long>();
  if (v < -1 || v > 1'000'000'000) throw Error(fmt::format("\"{}\" is out of range", key));
  return static_cast<int>(v);
}

std::size_t sizeOr(const json& j, const char* key, std::size_t fallback) {
  const auto it = j.find(key);
  if (it == j.end()) return fallback;
  if (!it->is_number_unsigned()) throw Error(fmt::format("\"{}\" must be a whole number >= 0", key));
  const auto v = it->get<unsigned long long>();
  if (v > (1ull << 40)) throw Error(fmt::format("\"{}\" is out of range", key));
  return static_cast<std::size_t>(v);
}

std::vector<double> numbers(const json& j, const char* key, std::size_t expected) {
  std::vector<double> out;
  const auto it = j.find(key);
  if (it == j.end()) return out;
  if (!it->is_array() || it->size() != expected) throw Error(fmt::format("\"{}\" must hold {} numbers", key, expected));
  for (const json& v : *it) {
    if (!v.is_number()) throw Error(fmt::format("\"{}\" must hold {} numbers", key, expected));
    out.push_back(v.get<double>());
  }
  return out;
}

std::vector<int> indices(const json& j, const char* key) {
  std::vector<int> out;
  const auto it = j.find(key);
  if (it == j.end()) return out;
  if (!it->is_array()) throw Error(fmt::format("\"{}\" must be a list of indices", key));
  for (const json& v : *it) {
    if (!v.is_number_unsigned() || v.get<unsigned long long>() > 1'000'000'000) throw Error(fmt::format("\"{}\" must be a list of indices", key));
    out.push_back(static_cast<int>(v.get<unsigned long long>()));
  }
  return out;
}

const json& arrayOf(const json& doc, const char* key) {
  static const json empty = json::array();
  const auto it = doc.find(key);
  if (it == doc.end()) return empty;
  if (!it->is_array()) throw Error(fmt::format("\"{}\" must be a list", key));
  return *it;
}

int componentsOf(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

// Splits a GLB container into its JSON and BIN chunks (bounds checked).
void splitGlb(std::string_view bytes, const std::string& name, std::string_view& jsonText, std::vector<unsigned char>& bin) {
  auto u32 = [&](std::size_t at) {
    std::uint32_t v;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  if (bytes.size() < 20) throw Error(fmt::format("{}: a GLB file needs at least 20 bytes", name));
  if (u32(4) != 2) throw Error(fmt::format("{}: GLB version {} (drape reads glTF 2.0)", name, u32(4)));
  const std::size_t total = std::min<std::size_t>(u32(8), bytes.size());
  std::size_t at = 12;
  bool sawJson = false;
  while (at + 8 <= total) {
    const std::size_t length = u32(at);
    const std::uint32_t type = u32(at + 4);
    if (length > total - at - 8) throw Error(fmt::format("{}: a GLB chunk runs past the end of the file", name));
    const std::string_view chunk = bytes.substr(at + 8, length);
    if (type == 0x4E4F534Au && !sawJson) {
      jsonText = chunk;
      sawJson = true;
    } else if (type == 0x004E4942u && bin.empty()) {
      bin.assign(chunk.begin(), chunk.end());
    }
    at += 8 + length;
  }
  if (!sawJson) throw Error(fmt::format("{}: the GLB file has no JSON chunk", name));
}

// The extensions a file may require that change nothing drape reads: appearance (materials,
// textures, lights, metadata), and KHR_mesh_quantization, whose integer positions the
// accessor reader takes as it takes floats. Any other (Draco or meshopt compression, GPU
// instancing) changes where the geometry is, and a file that requires it is refused.
bool harmlessExtension(const std::string& ext) {
  for (const char* prefix : {"KHR_materials_", "KHR_texture_", "EXT_texture_", "KHR_lights_", "KHR_xmp"})
    if (ext.rfind(prefix, 0) == 0) return true;
  return ext == "KHR_mesh_quantization";
}

GModel parseDocument(std::string_view bytes, const std::string& name, const std::string& baseDir) {
  std::string_view jsonText = bytes;
  std::vector<unsigned char> bin;
  const bool glb = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
  if (glb) splitGlb(bytes, name, jsonText, bin);
  if (!glb && jsonText.substr(std::min(jsonText.find_first_not_of(" \t\r\n"), jsonText.size()), 1) != "{")
    throw Error(fmt::format("{}: not a glTF 2.0 file (neither the GLB header 'glTF' nor a JSON object)", name));
  // The shared reader gives syntax errors a line and column (within the JSON chunk for GLB)
  // and bounds the nesting before nlohmann's recursive parser sees it.
  const json doc = parseJsonText(jsonText, glb ? name + " (JSON chunk)" : name);
  if (!doc.is_object() || !doc.contains("asset") || !doc["asset"].is_object())
    throw Error(fmt::format("{}: not a glTF 2.0 file (no \"asset\" object)", name));
  const auto versionIt = doc["asset"].find("version");
  const std::string version = versionIt != doc["asset"].end() && versionIt->is_string() ? versionIt->get<std::string>() : "";
  if (version.rfind("2.", 0) != 0) throw Error(fmt::format("{}: glTF version '{}' (drape reads 2.x)", name, version));
  GModel m;
  try {
    for (const json& e : arrayOf(doc, "extensionsRequired")) {
      if (!e.is_string()) throw Error("\"extensionsRequired\" must be a list of names");
      if (!harmlessExtension(e.get<std::string>()))
        throw Error(fmt::format("needs the glTF extension {}, which drape does not read (export it without compression "
                                "or instancing)", e.get<std::string>()));
    }
    for (const json& b : arrayOf(doc, "buffers")) {
      const std::size_t length = sizeOr(b, "byteLength", 0);
      std::vector<unsigned char> data;
      if (b.contains("uri")) {
        if (!b["uri"].is_string()) throw Error("\"uri\" must be a string");
        data = loadUri(b["uri"].get<std::string>(), name, baseDir);
      } else if (glb && m.buffers.empty()) {
        data = bin;
      }
      if (data.size() < length) throw Error(fmt::format("buffer {} holds {} bytes, fewer than its byteLength {}", m.buffers.size(), data.size(), length));
      m.buffers.push_back(std::move(data));
    }
    for (const json& v : arrayOf(doc, "bufferViews"))
      m.bufferViews.push_back({intOr(v, "buffer", -1), sizeOr(v, "byteOffset", 0), sizeOr(v, "byteLength", 0), sizeOr(v, "byteStride", 0)});
    for (const json& a : arrayOf(doc, "accessors")) {
      GAccessor acc;
      acc.bufferView = intOr(a, "bufferView", -1);
      acc.byteOffset = sizeOr(a, "byteOffset", 0);
      acc.count = sizeOr(a, "count", 0);
      acc.componentType = intOr(a, "componentType", 0);
      acc.components = componentsOf(a.value("type", std::string()));
      acc.normalized = a.value("normalized", false);
      acc.sparse = a.contains("sparse");
      m.accessors.push_back(acc);
    }
    for (const json& n : arrayOf(doc, "nodes")) {
      GNode node;
      node.name = n.contains("name") && n["name"].is_string() ? n["name"].get<std::string>() : "";
      node.children = indices(n, "children");
      node.matrix = numbers(n, "matrix", 16);
      node.translation = numbers(n, "translation", 3);
      node.rotation = numbers(n, "rotation", 4);
      node.scale = numbers(n, "scale", 3);
      node.mesh = intOr(n, "mesh", -1);
      node.skin = intOr(n, "skin", -1);
      m.nodes.push_back(std::move(node));
    }
    for (const json& s : arrayOf(doc, "skins")) m.skins.push_back({indices(s, "joints"), intOr(s, "inverseBindMatrices", -1)});
    const json& scenes = arrayOf(doc, "scenes");
    if (!scenes.empty()) {
      const int shown = intOr(doc, "scene", 0);
      if (shown < 0 || static_cast<std::size_t>(shown) >= scenes.size())
        throw Error(fmt::format("\"scene\" {} names no scene (the file has {})", shown, scenes.size()));
      m.sceneRoots = indices(scenes[static_cast<std::size_t>(shown)], "nodes");
    }
    for (const json& a : arrayOf(doc, "animations")) {
      GAnimation anim;
      anim.name = a.contains("name") && a["name"].is_string() ? a["name"].get<std::string>() : "";
      for (const json& c : arrayOf(a, "channels")) {
        GChannel channel;
        channel.sampler = intOr(c, "sampler", -1);
        const auto target = c.find("target");
        if (target == c.end() || !target->is_object()) throw Error(fmt::format("animation {} has a channel without a \"target\" object", m.animations.size()));
        channel.node = intOr(*target, "node", -1);
        channel.path = target->value("path", std::string());
        anim.channels.push_back(std::move(channel));
      }
      for (const json& sm : arrayOf(a, "samplers"))
        anim.samplers.push_back({intOr(sm, "input", -1), intOr(sm, "output", -1), sm.value("interpolation", std::string("LINEAR"))});
      m.animations.push_back(std::move(anim));
    }
    for (const json& mesh : arrayOf(doc, "meshes")) {
      std::vector<GPrimitive> prims;
      for (const json& p : arrayOf(mesh, "primitives")) {
        GPrimitive prim;
        if (p.contains("attributes")) {
          if (!p["attributes"].is_object()) throw Error("\"attributes\" must be an object");
          for (const auto& [key, value] : p["attributes"].items()) {
            if (!value.is_number_unsigned()) throw Error(fmt::format("attribute {} must name an accessor", key));
            prim.attributes[key] = static_cast<int>(std::min<unsigned long long>(value.get<unsigned long long>(), 1'000'000'000));
          }
        }
        prim.indices = intOr(p, "indices", -1);
        prim.mode = intOr(p, "mode", kModeTriangles);
        prims.push_back(std::move(prim));
      }
      m.meshes.push_back(std::move(prims));
      m.meshNames.push_back(mesh.contains("name") && mesh["name"].is_string() ? mesh["name"].get<std::string>() : "");
    }
  } catch (const json::exception& e) {
    throw Error(fmt::format("{}: bad glTF JSON ({})", name, e.what()));
  } catch (const Error& e) {
    const std::string what = e.what();
    if (what.rfind(name + ":", 0) == 0) throw;
    throw Error(fmt::format("{}: {}", name, what));
  }
  return m;
}

// ---- accessors, bounds checked ------------------------------------------------------

struct GltfReader {
  const GModel& model;
  std::string name;

  [[noreturn]] void fail(const std::string& what) const { throw Error(fmt::format("{}: {}", name, what)); }

  // Reads accessor `index` as `components` numbers per element (as doubles).
  std::vector<double> read(int index, int components, const char* what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model.accessors.size()) fail(fmt::format("{}: accessor {} does not exist", what, index));
    const GAccessor& a = model.accessors[static_cast<std::size_t>(index)];
    if (a.sparse) fail(fmt::format("{}: sparse accessors are not supported", what));
    if (a.components != components) fail(fmt::format("{}: accessor {} has {} components, expected {}", what, index, a.components, components));
    if (a.count > kMaxElements) fail(fmt::format("{}: accessor {} has too many elements ({})", what, index, a.count));
    const int size = componentSize(a.componentType);
    if (size <= 0) fail(fmt::format("{}: accessor {} has an unknown component type {}", what, index, a.componentType));
    std::vector<double> out(a.count * static_cast<std::size_t>(components), 0.0);
    if (a.bufferView < 0) return out;  // all zeros, as the spec says
    if (static_cast<std::size_t>(a.bufferView) >= model.bufferViews.size()) fail(fmt::format("{}: buffer view {} does not exist", what, a.bufferView));
    const GBufferView& view = model.bufferViews[static_cast<std::size_t>(a.bufferView)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size()) fail(fmt::format("{}: buffer {} does not exist", what, view.buffer));
    const std::vector<unsigned char>& data = model.buffers[static_cast<std::size_t>(view.buffer)];
    const std::size_t element = static_cast<std::size_t>(size) * static_cast<std::size_t>(components);
    const std::size_t stride = view.byteStride ? view.byteStride : element;
    if (stride < element) fail(fmt::format("{}: byte stride {} is smaller than an element ({} bytes)", what, stride, element));
    const std::size_t start = view.byteOffset + a.byteOffset;
    if (a.count > 0) {
      const std::size_t end = start + stride * (a.count - 1) + element;
      if (view.byteOffset > data.size() || end > data.size() || end > view.byteOffset + view.byteLength || end < start)
        fail(fmt::format("{}: accessor {} reads past the end of its buffer", what, index));
    }
    for (std::size_t i = 0; i < a.count; ++i) {
      const unsigned char* p = data.data() + start + i * stride;
      for (int c = 0; c < components; ++c) out[i * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)] =
          component(p + c * size, a.componentType, a.normalized);
    }
    return out;
  }

  static int componentSize(int type) {
    switch (type) {
      case kComponentByte: case kComponentUnsignedByte: return 1;
      case kComponentShort: case kComponentUnsignedShort: return 2;
      case kComponentUnsignedInt: case kComponentFloat: return 4;
      default: return 0;
    }
  }

  static double component(const unsigned char* p, int type, bool normalized) {
    switch (type) {
      case kComponentFloat: { float f; std::memcpy(&f, p, 4); return f; }
      case kComponentUnsignedByte: return normalized ? *p / 255.0 : *p;
      case kComponentByte: { const auto v = static_cast<std::int8_t>(*p); return normalized ? std::max(v / 127.0, -1.0) : v; }
      case kComponentUnsignedShort: { std::uint16_t v; std::memcpy(&v, p, 2); return normalized ? v / 65535.0 : v; }
      case kComponentShort: { std::int16_t v; std::memcpy(&v, p, 2); return normalized ? std::max(v / 32767.0, -1.0) : v; }
      case kComponentUnsignedInt: { std::uint32_t v; std::memcpy(&v, p, 4); return v; }
      default: return 0.0;
    }
  }
};

Eigen::Matrix4d localMatrix(const GNode& node) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (node.matrix.size() == 16) {
    for (int i = 0; i < 16; ++i) m(i % 4, i / 4) = node.matrix[static_cast<std::size_t>(i)];  // column-major
    return m;
  }
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  if (node.translation.size() == 3) t.translate(Vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    const Quat q(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
    if (q.norm() > 1e-12) t.rotate(q.normalized());
  }
  if (node.scale.size() == 3) t.scale(Vec3(node.scale[0], node.scale[1], node.scale[2]));
  return t.matrix();
}

// Each node's parent (-1 for a root), checked: children exist, no node has two parents.
std::vector<int> nodeParents(const GModel& model, const GltfReader& r) {
  const std::size_t n = model.nodes.size();
  std::vector<int> parent(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    for (int c : model.nodes[i].children) {
      if (c < 0 || static_cast<std::size_t>(c) >= n) r.fail(fmt::format("node {} has a child {} that does not exist", i, c));
      if (parent[static_cast<std::size_t>(c)] >= 0 || static_cast<std::size_t>(c) == i) r.fail(fmt::format("node {} has two parents", c));
      parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
    }
  return parent;
}

// World matrices of every node from their local matrices.
std::vector<Eigen::Matrix4d> worldsOf(const std::vector<int>& parent, const std::vector<Eigen::Matrix4d>& local,
                                      const GltfReader& r) {
  const std::size_t n = parent.size();
  std::vector<Eigen::Matrix4d> world(n, Eigen::Matrix4d::Identity());
  std::vector<int> state(n, 0);  // 0 todo, 1 visiting, 2 done
  std::vector<std::size_t> chain;
  for (std::size_t i = 0; i < n; ++i) {
    chain.clear();  // iterative walk up to a finished ancestor (no deep recursion)
    for (std::size_t k = i;;) {
      if (state[k] == 2) break;
      if (state[k] == 1) r.fail(fmt::format("the node hierarchy has a cycle at node {}", k));
      state[k] = 1;
      chain.push_back(k);
      if (parent[k] < 0) break;
      k = static_cast<std::size_t>(parent[k]);
    }
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const int p = parent[*it];
      world[*it] = (p < 0 ? Eigen::Matrix4d::Identity() : world[static_cast<std::size_t>(p)]) * local[*it];
      state[*it] = 2;
    }
  }
  return world;
}

// World matrices of every node in the rest pose (the file's node transforms).
std::vector<Eigen::Matrix4d> nodeWorlds(const GModel& model, std::vector<int>& parent, const GltfReader& r) {
  parent = nodeParents(model, r);
  std::vector<Eigen::Matrix4d> local;
  for (const GNode& node : model.nodes) local.push_back(localMatrix(node));
  return worldsOf(parent, local, r);
}

// The skeleton: the joints of the first skin and of every skin that shares a joint with it
// (exporters from Unity and three.js write one skin per skinned mesh, each listing the
// joints its mesh uses, all of one skeleton), in parent-first order (by depth in the node
// tree), named and parented as SkinnedModel has them. A skin of joints apart from these
// (another character's) is not the avatar's.
struct SkinJoints {
  std::vector<int> node;          ///< k -> the joint's node
  std::vector<std::string> name;  ///< k -> its name
  std::vector<int> parent;        ///< k -> the nearest ancestor that is a joint, or -1
  /// Per skin of the file: index in its joint list -> k; empty for a skin not of the skeleton.
  std::vector<std::vector<int>> newIndex;
};

// Which skins share joints with the first, directly or through each other.
std::vector<bool> skinsOfTheSkeleton(const GModel& model, const GltfReader& r) {
  const std::size_t nodes = model.nodes.size(), skins = model.skins.size();
  for (std::size_t s = 0; s < skins; ++s) {
    if (model.skins[s].joints.empty()) r.fail(fmt::format("skin {} has no joints", s));
    if (model.skins[s].joints.size() > 65535) r.fail(fmt::format("skin {} has too many joints", s));
    for (const int node : model.skins[s].joints)
      if (node < 0 || static_cast<std::size_t>(node) >= nodes) r.fail(fmt::format("skin joint {} is not a node", node));
  }
  std::vector<bool> inSkeleton(skins, false), jointNode(nodes, false);
  inSkeleton[0] = true;
  for (const int node : model.skins[0].joints) jointNode[static_cast<std::size_t>(node)] = true;
  for (bool grew = true; grew;) {
    grew = false;
    for (std::size_t s = 1; s < skins; ++s) {
      if (inSkeleton[s]) continue;
      const std::vector<int>& joints = model.skins[s].joints;
      if (std::none_of(joints.begin(), joints.end(), [&](int n) { return jointNode[static_cast<std::size_t>(n)]; })) continue;
      inSkeleton[s] = grew = true;
      for (const int node : joints) jointNode[static_cast<std::size_t>(node)] = true;
    }
  }
  return inSkeleton;
}

SkinJoints skinJoints(const GModel& model, const std::vector<int>& nodeParent, const GltfReader& r) {
  if (model.skins.empty()) r.fail("has no skin (a skinned character is needed)");
  const std::vector<bool> inSkeleton = skinsOfTheSkeleton(model, r);
  // The skeleton's joint nodes: the first skin's in its order (an unnamed one is called by
  // its index there), then those the other skins add.
  std::vector<int> nodes, jointOfNode(model.nodes.size(), -1);
  for (std::size_t s = 0; s < model.skins.size(); ++s) {
    if (!inSkeleton[s]) continue;
    for (const int node : model.skins[s].joints) {
      int& j = jointOfNode[static_cast<std::size_t>(node)];
      if (j >= 0) {
        if (s == 0) r.fail(fmt::format("node {} is listed twice in the skin", node));
        continue;
      }
      j = static_cast<int>(nodes.size());
      nodes.push_back(node);
    }
  }
  if (nodes.size() > 65535) r.fail("its skins have too many joints");
  auto depth = [&](int node) {
    int d = 0;
    for (int k = nodeParent[static_cast<std::size_t>(node)]; k >= 0; k = nodeParent[static_cast<std::size_t>(k)]) ++d;
    return d;
  };
  const std::size_t jn = nodes.size();
  std::vector<std::size_t> order(jn);
  for (std::size_t j = 0; j < jn; ++j) order[j] = j;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return depth(nodes[a]) < depth(nodes[b]); });
  std::vector<int> kOf(jn);
  for (std::size_t k = 0; k < jn; ++k) kOf[order[k]] = static_cast<int>(k);
  SkinJoints out;
  for (std::size_t k = 0; k < jn; ++k) {
    const int node = nodes[order[k]];
    out.node.push_back(node);
    out.name.push_back(model.nodes[static_cast<std::size_t>(node)].name.empty()
                           ? fmt::format("joint{}", order[k])
                           : model.nodes[static_cast<std::size_t>(node)].name);
    int parent = -1;
    for (int a = nodeParent[static_cast<std::size_t>(node)]; a >= 0; a = nodeParent[static_cast<std::size_t>(a)])
      if (jointOfNode[static_cast<std::size_t>(a)] >= 0) {
        parent = kOf[static_cast<std::size_t>(jointOfNode[static_cast<std::size_t>(a)])];
        break;
      }
    out.parent.push_back(parent);
  }
  out.newIndex.resize(model.skins.size());
  for (std::size_t s = 0; s < model.skins.size(); ++s)
    if (inSkeleton[s])
      for (const int node : model.skins[s].joints)
        out.newIndex[s].push_back(kOf[static_cast<std::size_t>(jointOfNode[static_cast<std::size_t>(node)])]);
  return out;
}

std::vector<std::string> animationNames(const GModel& model) {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < model.animations.size(); ++i) names.push_back(detail::animationName(model.animations[i].name, i));
  return names;
}

// Skin `index`'s joint matrices at rest: each joint's world matrix times its inverse bind
// matrix (identity when the skin gives none, as the glTF spec says).
std::vector<Eigen::Matrix4d> skinMatrices(const GModel& model, std::size_t index, const std::vector<Eigen::Matrix4d>& world,
                                          const GltfReader& r) {
  if (index >= model.skins.size()) r.fail(fmt::format("skin {} does not exist", index));
  const GSkin& skin = model.skins[index];
  const std::size_t jn = skin.joints.size();
  std::vector<Eigen::Matrix4d> inverseBind(jn, Eigen::Matrix4d::Identity());
  if (skin.inverseBindMatrices >= 0) {
    const std::vector<double> m = r.read(skin.inverseBindMatrices, 16, "inverseBindMatrices");
    if (m.size() / 16 < jn) r.fail("inverseBindMatrices has fewer matrices than the skin has joints");
    for (std::size_t j = 0; j < jn; ++j)
      for (int i = 0; i < 16; ++i) inverseBind[j](i % 4, i / 4) = m[j * 16 + static_cast<std::size_t>(i)];
  }
  std::vector<Eigen::Matrix4d> out(jn);
  for (std::size_t j = 0; j < jn; ++j) {
    const int node = skin.joints[j];
    if (node < 0 || static_cast<std::size_t>(node) >= world.size()) r.fail(fmt::format("skin {} names joint node {}, which does not exist", index, node));
    out[j] = world[static_cast<std::size_t>(node)] * inverseBind[j];
  }
  return out;
}

// Which nodes the file's scene shows: those under its root nodes (every node when the file
// has no scenes). A node outside it (a collision proxy, another scene's) is not read.
std::vector<bool> shownNodes(const GModel& model, const std::vector<int>& nodeParent, const GltfReader& r) {
  const std::size_t n = model.nodes.size();
  if (!model.sceneRoots) return std::vector<bool>(n, true);
  std::vector<bool> root(n, false), shown(n, false);
  for (int k : *model.sceneRoots) {
    if (k < 0 || static_cast<std::size_t>(k) >= n) r.fail(fmt::format("the scene names node {}, which does not exist", k));
    root[static_cast<std::size_t>(k)] = true;
  }
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t top = i;  // the hierarchy has no cycles: nodeWorlds checked it
    while (nodeParent[top] >= 0 && !root[top]) top = static_cast<std::size_t>(nodeParent[top]);
    shown[i] = root[top];
  }
  return shown;
}

// What a mesh placed by node `ni` is called: its node's name, else its mesh's, else "node <ni>".
std::string partName(const GModel& model, std::size_t ni) {
  const GNode& node = model.nodes[ni];
  const std::string& meshName = model.meshNames[static_cast<std::size_t>(node.mesh)];
  return !node.name.empty() ? node.name : !meshName.empty() ? meshName : fmt::format("node {}", ni);
}

// The skin's rest model from the triangle meshes its first skin moves, those of `parts`
// only when some are named (by node or mesh name).
SkinnedModel extract(const GModel& model, const std::string& name, const std::vector<std::string>& parts = {}) {
  const GltfReader r{model, name};
  std::vector<int> nodeParent;
  const std::vector<Eigen::Matrix4d> world = nodeWorlds(model, nodeParent, r);
  const SkinJoints sj = skinJoints(model, nodeParent, r);
  const std::vector<bool> shown = shownNodes(model, nodeParent, r);

  SkinnedModel out;
  out.source = name;
  out.animations = animationNames(model);
  for (std::size_t k = 0; k < sj.node.size(); ++k) {
    SkinnedJoint joint;
    joint.name = sj.name[k];
    joint.parent = sj.parent[k];
    joint.restWorld = world[static_cast<std::size_t>(sj.node[k])];
    out.joints.push_back(joint);
  }

  std::vector<bool> matched(parts.size(), false);
  for (std::size_t ni = 0; ni < model.nodes.size(); ++ni) {
    const GNode& node = model.nodes[ni];
    // A node no scene shows (a collision proxy, another level of detail) is not the body's.
    if (node.skin < 0 || node.mesh < 0 || !shown[ni]) continue;
    if (static_cast<std::size_t>(node.mesh) >= model.meshes.size()) r.fail(fmt::format("node {} names mesh {}, which does not exist", ni, node.mesh));
    if (static_cast<std::size_t>(node.skin) >= model.skins.size()) r.fail(fmt::format("node {} names skin {}, which does not exist", ni, node.skin));
    const std::string part = partName(model, ni);
    const std::string& meshName = model.meshNames[static_cast<std::size_t>(node.mesh)];
    const std::vector<int>& newIndex = sj.newIndex[static_cast<std::size_t>(node.skin)];
    if (newIndex.empty()) {
      // Another skeleton's mesh (a second character): not the avatar's. Named (not only
      // matched by a pattern), it is an error.
      const auto named = [&](const std::string& p) { return !isNamePattern(p) && (p == part || p == meshName); };
      if (std::any_of(parts.begin(), parts.end(), named))
        r.fail(fmt::format("its mesh '{}' is moved by skin {}, whose joints are apart from the first skin's skeleton; "
                           "drape reads the character of the file's first skin",
                           part, node.skin));
      continue;
    }
    const std::size_t jn = newIndex.size();
    const std::vector<Eigen::Matrix4d> skinMatrix = skinMatrices(model, static_cast<std::size_t>(node.skin), world, r);
    out.meshes.push_back(part);
    if (!partWanted(parts, matched, part, meshName)) continue;
    const std::size_t trianglesBefore = out.triangles.size();
    for (const GPrimitive& prim : model.meshes[static_cast<std::size_t>(node.mesh)]) {
      if (prim.mode != kModeTriangles) continue;
      const auto pos = prim.attributes.find("POSITION");
      const auto jts = prim.attributes.find("JOINTS_0");
      const auto wts = prim.attributes.find("WEIGHTS_0");
      if (pos == prim.attributes.end() || jts == prim.attributes.end() || wts == prim.attributes.end()) continue;
      const std::vector<double> p = r.read(pos->second, 3, "POSITION");
      const std::vector<double> ji = r.read(jts->second, 4, "JOINTS_0");
      const std::vector<double> w = r.read(wts->second, 4, "WEIGHTS_0");
      const std::size_t count = p.size() / 3;
      if (ji.size() / 4 != count || w.size() / 4 != count) r.fail("JOINTS_0/WEIGHTS_0 and POSITION have different counts");
      const auto base = static_cast<std::uint32_t>(out.positions.size());
      if (out.positions.size() + count > kMaxElements) r.fail("too many vertices");
      for (std::size_t v = 0; v < count; ++v) {
        std::array<std::uint16_t, 4> joints{};
        std::array<float, 4> weights{};
        double total = 0.0;
        Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
        for (int k = 0; k < 4; ++k) {
          const double jk = ji[v * 4 + static_cast<std::size_t>(k)];
          const double wk = w[v * 4 + static_cast<std::size_t>(k)];
          if (!(jk >= 0.0) || jk >= static_cast<double>(jn)) r.fail(fmt::format("vertex {} names joint {}, but the skin has {}", v, jk, jn));
          if (!(wk >= 0.0) || !std::isfinite(wk)) r.fail(fmt::format("vertex {} has a bad weight {}", v, wk));
          joints[static_cast<std::size_t>(k)] = static_cast<std::uint16_t>(newIndex[static_cast<std::size_t>(jk)]);
          weights[static_cast<std::size_t>(k)] = static_cast<float>(wk);
          total += wk;
          m += wk * skinMatrix[static_cast<std::size_t>(jk)];
        }
        if (!(total > 1e-9)) r.fail(fmt::format("vertex {} has no skin weight", v));
        // Non-normalised weights (CesiumMan has them) are normalised, as viewers do.
        for (float& x : weights) x = static_cast<float>(x / total);
        m /= total;
        const Eigen::Vector4d h = m * Eigen::Vector4d(p[3 * v], p[3 * v + 1], p[3 * v + 2], 1.0);
        if (!h.allFinite()) r.fail(fmt::format("vertex {} is not finite after skinning", v));
        out.positions.emplace_back(h.x(), h.y(), h.z());
        out.vertexJoints.push_back(joints);
        out.vertexWeights.push_back(weights);
      }
      std::vector<double> idx;
      if (prim.indices >= 0) {
        idx = r.read(prim.indices, 1, "indices");
      } else {
        idx.resize(count);
        for (std::size_t i = 0; i < count; ++i) idx[i] = static_cast<double>(i);
      }
      for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        mesh::Triangle tri;
        for (int c = 0; c < 3; ++c) {
          const double i = idx[t + static_cast<std::size_t>(c)];
          if (!(i >= 0.0) || i >= static_cast<double>(count)) r.fail(fmt::format("index {} is out of range ({} vertices)", i, count));
          tri[static_cast<std::size_t>(c)] = base + static_cast<std::uint32_t>(i);
        }
        if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2]) out.triangles.push_back(tri);
      }
    }
    if (out.triangles.size() > trianglesBefore) out.meshesRead.push_back(part);
  }
  checkPartsMatched(parts, matched, out.meshes, name, "skinned meshes");
  if (out.triangles.empty())
    r.fail(parts.empty() ? "no skinned triangle mesh uses its first skin" : "the meshes asked for have no skinned triangles");
  return out;
}

// ---- static meshes (a garment, a mask) -------------------------------------------------

constexpr int kModeTriangleStrip = 5, kModeTriangleFan = 6;

// The triangles a primitive's index list draws in its mode (lists, strips, fans), with
// degenerate ones left out; `base` offsets the indices.
void appendTriangles(const std::vector<double>& idx, int mode, std::size_t count, std::uint32_t base,
                     std::vector<mesh::Triangle>& out, const GltfReader& r) {
  auto corner = [&](std::size_t k) {
    const double i = idx[k];
    if (!(i >= 0.0) || i >= static_cast<double>(count)) r.fail(fmt::format("index {} is out of range ({} vertices)", i, count));
    return base + static_cast<std::uint32_t>(i);
  };
  auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (a != b && b != c && a != c) out.push_back({a, b, c});
  };
  if (mode == kModeTriangles)
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) add(corner(t), corner(t + 1), corner(t + 2));
  else if (mode == kModeTriangleStrip)
    for (std::size_t t = 0; t + 2 < idx.size(); ++t)
      t % 2 == 0 ? add(corner(t), corner(t + 1), corner(t + 2)) : add(corner(t + 1), corner(t), corner(t + 2));
  else if (mode == kModeTriangleFan)
    for (std::size_t t = 1; t + 1 < idx.size(); ++t) add(corner(0), corner(t), corner(t + 1));
}

// One primitive's positions at rest: placed by its node, or skinned where the node has a
// skin and the primitive its joints and weights (the node's own transform then does not
// apply, as the glTF spec says).
std::vector<Vec3> restPositions(const GPrimitive& prim, const Eigen::Matrix4d& nodeWorld,
                                const std::vector<Eigen::Matrix4d>& skinning, const GltfReader& r) {
  const std::vector<double> p = r.read(prim.attributes.at("POSITION"), 3, "POSITION");
  const std::size_t count = p.size() / 3;
  const auto jts = prim.attributes.find("JOINTS_0");
  const auto wts = prim.attributes.find("WEIGHTS_0");
  const bool skinned = !skinning.empty() && jts != prim.attributes.end() && wts != prim.attributes.end();
  std::vector<double> ji, w;
  if (skinned) {
    ji = r.read(jts->second, 4, "JOINTS_0");
    w = r.read(wts->second, 4, "WEIGHTS_0");
    if (ji.size() / 4 != count || w.size() / 4 != count) r.fail("JOINTS_0/WEIGHTS_0 and POSITION have different counts");
  }
  std::vector<Vec3> out;
  out.reserve(count);
  for (std::size_t v = 0; v < count; ++v) {
    Eigen::Matrix4d m = nodeWorld;
    if (skinned) {
      Eigen::Matrix4d sum = Eigen::Matrix4d::Zero();
      double total = 0.0;
      for (std::size_t k = 0; k < 4; ++k) {
        const double jk = ji[v * 4 + k], wk = w[v * 4 + k];
        if (!(jk >= 0.0) || jk >= static_cast<double>(skinning.size())) r.fail(fmt::format("vertex {} names joint {}, but the skin has {}", v, jk, skinning.size()));
        if (!(wk >= 0.0) || !std::isfinite(wk)) r.fail(fmt::format("vertex {} has a bad weight {}", v, wk));
        sum += wk * skinning[static_cast<std::size_t>(jk)];
        total += wk;
      }
      if (total > 1e-9) m = sum / total;
    }
    const Eigen::Vector4d h = m * Eigen::Vector4d(p[3 * v], p[3 * v + 1], p[3 * v + 2], 1.0);
    if (!h.allFinite()) r.fail(fmt::format("vertex {} is not finite at rest", v));
    out.emplace_back(h.x(), h.y(), h.z());
  }
  return out;
}

MeshParts extractMesh(const GModel& model, const std::string& name, const std::vector<std::string>& parts, bool loose) {
  const GltfReader r{model, name};
  std::vector<int> nodeParent;
  const std::vector<Eigen::Matrix4d> world = nodeWorlds(model, nodeParent, r);
  const std::vector<bool> shown = shownNodes(model, nodeParent, r);
  MeshParts out;
  out.mesh.name = name;
  std::vector<bool> matched(parts.size(), false);
  for (std::size_t ni = 0; ni < model.nodes.size(); ++ni) {
    const GNode& node = model.nodes[ni];
    if (node.mesh < 0 || !shown[ni]) continue;
    if (static_cast<std::size_t>(node.mesh) >= model.meshes.size()) r.fail(fmt::format("node {} names mesh {}, which does not exist", ni, node.mesh));
    const std::string& meshName = model.meshNames[static_cast<std::size_t>(node.mesh)];
    const std::string part = partName(model, ni);
    out.all.push_back(part);
    if (!partWanted(parts, matched, part, meshName)) continue;
    const std::vector<Eigen::Matrix4d> skinning =
        node.skin >= 0 ? skinMatrices(model, static_cast<std::size_t>(node.skin), world, r) : std::vector<Eigen::Matrix4d>{};
    const std::size_t before = out.mesh.triangles.size(), beforeVertices = out.mesh.positions.size();
    for (const GPrimitive& prim : model.meshes[static_cast<std::size_t>(node.mesh)]) {
      const bool triangles = prim.mode == kModeTriangles || prim.mode == kModeTriangleStrip || prim.mode == kModeTriangleFan;
      // Points and lines (modes 0 to 3): loose vertices, which only a mask keeps.
      if (!(triangles || (loose && prim.mode >= 0 && prim.mode < kModeTriangles))) continue;
      if (prim.attributes.count("POSITION") == 0) continue;
      const std::vector<Vec3> positions = restPositions(prim, world[ni], skinning, r);
      if (out.mesh.positions.size() + positions.size() > kMaxElements) r.fail("too many vertices");
      const auto base = static_cast<std::uint32_t>(out.mesh.positions.size());
      out.mesh.positions.insert(out.mesh.positions.end(), positions.begin(), positions.end());
      std::vector<double> idx;
      if (prim.indices >= 0) {
        idx = r.read(prim.indices, 1, "indices");
      } else {
        idx.resize(positions.size());
        for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<double>(i);
      }
      if (triangles) appendTriangles(idx, prim.mode, positions.size(), base, out.mesh.triangles, r);
    }
    if (out.mesh.triangles.size() > before || (loose && out.mesh.positions.size() > beforeVertices)) out.read.push_back(part);
  }
  checkMeshParts(out, parts, matched, loose, name);
  return out;
}

// ---- animations ---------------------------------------------------------------------

constexpr double kMaxAnimationSeconds = 24.0 * 3600.0;

/// One channel's sampler, read and checked: key times and values (`components` per key,
/// three times as many for CUBICSPLINE: in-tangent, value, out-tangent).
struct Track {
  enum class Interpolation { Linear, Step, CubicSpline };
  int node = -1;
  std::string path;
  Interpolation interpolation = Interpolation::Linear;
  int components = 0;
  std::vector<double> times, values;

  /// The channel's value at time t (clamped to the key times), `components` numbers.
  void sample(double t, double* out) const {
    const std::size_t keys = times.size();
    const std::size_t stride = interpolation == Interpolation::CubicSpline ? 3 : 1;
    const auto value = [&](std::size_t k, std::size_t part, int c) {
      return values[(k * stride + part) * static_cast<std::size_t>(components) + static_cast<std::size_t>(c)];
    };
    const std::size_t mid = stride == 3 ? 1 : 0;
    if (keys == 1 || t <= times.front()) {
      for (int c = 0; c < components; ++c) out[c] = value(0, mid, c);
      return;
    }
    if (t >= times.back()) {
      for (int c = 0; c < components; ++c) out[c] = value(keys - 1, mid, c);
      return;
    }
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin()) - 1;
    const double span = times[k + 1] - times[k];
    const double u = span > 0 ? (t - times[k]) / span : 0.0;
    switch (interpolation) {
      case Interpolation::Step:
        for (int c = 0; c < components; ++c) out[c] = value(k, 0, c);
        return;
      case Interpolation::Linear:
        if (components == 4) {  // a rotation: SLERP, as the glTF spec asks
          const Quat a(value(k, 0, 3), value(k, 0, 0), value(k, 0, 1), value(k, 0, 2));
          const Quat b(value(k + 1, 0, 3), value(k + 1, 0, 0), value(k + 1, 0, 1), value(k + 1, 0, 2));
          const Quat q = a.normalized().slerp(u, b.normalized());
          out[0] = q.x(), out[1] = q.y(), out[2] = q.z(), out[3] = q.w();
          return;
        }
        for (int c = 0; c < components; ++c) out[c] = (1.0 - u) * value(k, 0, c) + u * value(k + 1, 0, c);
        return;
      case Interpolation::CubicSpline: {  // Hermite, tangents scaled by the key interval
        const double u2 = u * u, u3 = u2 * u;
        const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
        for (int c = 0; c < components; ++c)
          out[c] = h00 * value(k, 1, c) + h10 * span * value(k, 2, c) + h01 * value(k + 1, 1, c) +
                   h11 * span * value(k + 1, 0, c);
        return;
      }
    }
  }
};

/// The tracks of animation `index` that move nodes (weights channels left out), checked.
std::vector<Track> readTracks(const GModel& model, std::size_t index, const GltfReader& r) {
  const GAnimation& anim = model.animations[index];
  std::vector<Track> tracks;
  for (std::size_t ci = 0; ci < anim.channels.size(); ++ci) {
    const GChannel& ch = anim.channels[ci];
    const std::string where = fmt::format("animation {} channel {}", index, ci);
    if (ch.path == "weights") continue;  // morph targets: not part of the skeleton's motion
    if (ch.path != "translation" && ch.path != "rotation" && ch.path != "scale")
      r.fail(fmt::format("{}: target path '{}' (expected translation, rotation, scale or weights)", where, ch.path));
    if (ch.node < 0) continue;  // no node: the spec lets an extension say; nothing moves here
    if (static_cast<std::size_t>(ch.node) >= model.nodes.size())
      r.fail(fmt::format("{}: target node {} does not exist", where, ch.node));
    if (model.nodes[static_cast<std::size_t>(ch.node)].matrix.size() == 16)
      r.fail(fmt::format("{}: node {} has a matrix, and a node an animation targets must not", where, ch.node));
    if (ch.sampler < 0 || static_cast<std::size_t>(ch.sampler) >= anim.samplers.size())
      r.fail(fmt::format("{}: sampler {} does not exist", where, ch.sampler));
    const GSampler& sm = anim.samplers[static_cast<std::size_t>(ch.sampler)];
    Track t;
    t.node = ch.node;
    t.path = ch.path;
    t.components = ch.path == "rotation" ? 4 : 3;
    if (sm.interpolation == "LINEAR") t.interpolation = Track::Interpolation::Linear;
    else if (sm.interpolation == "STEP") t.interpolation = Track::Interpolation::Step;
    else if (sm.interpolation == "CUBICSPLINE") t.interpolation = Track::Interpolation::CubicSpline;
    else r.fail(fmt::format("{}: interpolation '{}' (expected LINEAR, STEP or CUBICSPLINE)", where, sm.interpolation));
    t.times = r.read(sm.input, 1, (where + " input").c_str());
    if (t.times.empty()) r.fail(fmt::format("{}: its sampler has no key times", where));
    for (std::size_t k = 0; k < t.times.size(); ++k) {
      if (!std::isfinite(t.times[k]) || t.times[k] < 0 || t.times[k] > kMaxAnimationSeconds)
        r.fail(fmt::format("{}: key time {} is {} (expected seconds from 0 to {:g})", where, k, t.times[k], kMaxAnimationSeconds));
      if (k > 0 && t.times[k] < t.times[k - 1])
        r.fail(fmt::format("{}: key times go back, from {} s to {} s at key {}", where, t.times[k - 1], t.times[k], k));
    }
    t.values = r.read(sm.output, t.components, (where + " output").c_str());
    const std::size_t perKey = t.interpolation == Track::Interpolation::CubicSpline ? 3 : 1;
    if (t.values.size() != t.times.size() * perKey * static_cast<std::size_t>(t.components))
      r.fail(fmt::format("{}: {} output values for {} key times (expected {})", where,
                         t.values.size() / static_cast<std::size_t>(t.components), t.times.size(), t.times.size() * perKey));
    for (double v : t.values)
      if (!std::isfinite(v)) r.fail(fmt::format("{}: an output value is not finite", where));
    tracks.push_back(std::move(t));
  }
  return tracks;
}

/// The skin's rest positions, or none for a file whose skin no mesh uses (an animation
/// without a character); the floor then comes from the joints.
std::vector<Vec3> skinPositions(const GModel& model, const std::string& name) {
  try {
    return extract(model, name).positions;
  } catch (const Error&) {
    return {};
  }
}

GltfJointMotion sampleJointMotion(const GModel& model, const std::string& name, double rate, const std::string& which) {
  const GltfReader r{model, name};
  const std::vector<std::string> names = animationNames(model);
  const std::size_t index = detail::chooseAnimation(names, which, name);
  std::vector<int> nodeParent;
  const std::vector<Eigen::Matrix4d> restWorld = nodeWorlds(model, nodeParent, r);
  const SkinJoints sj = skinJoints(model, nodeParent, r);
  const std::vector<Track> tracks = readTracks(model, index, r);
  if (tracks.empty()) r.fail(fmt::format("animation {} moves no node", index));

  GltfJointMotion out;
  out.animation = names[index];
  out.animationNames = names;
  out.rate = rate;
  out.start_s = std::numeric_limits<double>::infinity();
  out.end_s = 0.0;
  for (const Track& t : tracks) {
    out.start_s = std::min(out.start_s, t.times.front());
    out.end_s = std::max(out.end_s, t.times.back());
  }
  const std::size_t jn = sj.node.size();
  const std::size_t frameCount = detail::motionFrameCount(out.start_s, out.end_s, rate, jn, out.animation, name);
  out.joints = sj.name;
  out.parents = sj.parent;

  std::vector<Eigen::Matrix4d> restInverse(jn);
  for (std::size_t k = 0; k < jn; ++k) {
    const Eigen::Matrix4d& w = restWorld[static_cast<std::size_t>(sj.node[k])];
    out.restCenters.push_back(w.block<3, 1>(0, 3));
    restInverse[k] = w.inverse();
    if (!restInverse[k].allFinite()) r.fail(fmt::format("joint '{}' has a singular rest transform", sj.name[k]));
  }
  out.floor_m = detail::lowestOf(skinPositions(model, name), out.restCenters);
  out.frames.reserve(frameCount * jn);
  std::vector<GNode> nodes = model.nodes;
  std::vector<Eigen::Matrix4d> local(nodes.size());
  double value[4];
  for (std::size_t f = 0; f < frameCount; ++f) {
    const double t = out.start_s + static_cast<double>(f) / rate;
    for (const Track& track : tracks) {
      track.sample(t, value);
      GNode& node = nodes[static_cast<std::size_t>(track.node)];
      std::vector<double>& target = track.path == "translation" ? node.translation
                                    : track.path == "rotation"  ? node.rotation
                                                                : node.scale;
      target.assign(value, value + track.components);
    }
    for (std::size_t i = 0; i < nodes.size(); ++i) local[i] = localMatrix(nodes[i]);
    const std::vector<Eigen::Matrix4d> world = worldsOf(nodeParent, local, r);
    for (std::size_t k = 0; k < jn; ++k) {
      const Eigen::Matrix4d& w = world[static_cast<std::size_t>(sj.node[k])];
      const RigidTransform joint = detail::jointMotionOf(w, restInverse[k]);
      if (!joint.translation.allFinite() || !joint.rotation.coeffs().allFinite())
        r.fail(fmt::format("joint '{}' is not finite at {:g} s of animation {}", sj.name[k], t, index));
      out.frames.push_back(joint);
    }
  }
  return out;
}

}  // namespace

bool isGltfPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".glb" || ext == ".gltf" || ext == ".vrm";
}

SkinnedModel parseGltfSkinnedModel(std::string_view bytes, const std::string& name, const std::string& baseDir,
                                   const std::vector<std::string>& parts) {
  return extract(parseDocument(bytes, name, baseDir), name, parts);
}

GltfJointMotion parseGltfJointMotion(std::string_view bytes, const std::string& name, const std::string& baseDir,
                                     double rate, const std::string& animation) {
  return sampleJointMotion(parseDocument(bytes, name, baseDir), name, rate, animation);
}

std::vector<GltfJointMotion> parseGltfJointMotions(std::string_view bytes, const std::string& name, const std::string& baseDir,
                                                   double rate) {
  const GModel model = parseDocument(bytes, name, baseDir);
  std::vector<GltfJointMotion> motions;
  for (std::size_t a = 0; a < model.animations.size(); ++a)
    detail::appendWithinCap(motions, sampleJointMotion(model, name, rate, std::to_string(a)), name);
  return motions;
}

std::vector<GltfJointMotion> readGltfJointMotions(const std::string& path, double rate, const IsolationLimits& limits) {
  const std::string bytes = detail::readWholeFile(path, std::size_t{1} << 30);
  const std::string baseDir = std::filesystem::absolute(path).parent_path().string();
  const std::string result = runIsolated(
      path, "glTF reader", [&] { return serialise(parseGltfJointMotions(bytes, path, baseDir, rate)); }, limits);
  return deserialiseJointMotions(result, path);
}

GltfJointMotion readGltfJointMotion(const std::string& path, double rate, const std::string& animation,
                                    const IsolationLimits& limits) {
  const std::string bytes = detail::readWholeFile(path, std::size_t{1} << 30);
  const std::string baseDir = std::filesystem::absolute(path).parent_path().string();
  const std::string result = runIsolated(
      path, "glTF reader", [&] { return serialise(parseGltfJointMotion(bytes, path, baseDir, rate, animation)); }, limits);
  return deserialiseJointMotion(result, path);
}

MeshParts parseGltfMesh(std::string_view bytes, const std::string& name, const std::string& baseDir,
                        const std::vector<std::string>& parts, bool loose) {
  return extractMesh(parseDocument(bytes, name, baseDir), name, parts, loose);
}

SkinnedModel readGltfSkinnedModel(const std::string& path, const std::vector<std::string>& parts, const IsolationLimits& limits) {
  const std::string bytes = detail::readWholeFile(path, std::size_t{1} << 30);
  const std::string baseDir = std::filesystem::absolute(path).parent_path().string();
  const std::string result =
      runIsolated(path, "glTF reader", [&] { return serialise(parseGltfSkinnedModel(bytes, path, baseDir, parts)); }, limits);
  return deserialiseSkinnedModel(result, path);
}

}  // namespace drape::formats
