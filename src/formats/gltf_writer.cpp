#include "drape/formats/gltf_writer.hpp"

// Debian ships tinygltf compiled: include the header only, without its implementation macro.
#include <tiny_gltf.h>

#include <Eigen/SVD>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/pc2.hpp"
#include "drape/formats/run_manifest.hpp"

namespace drape::formats {
namespace {

/// Builds one glTF model with a single binary buffer: every accessor gets its own buffer
/// view, 4-byte aligned, with min/max where the spec asks for them.
class ModelBuilder {
 public:
  ModelBuilder() {
    model_.asset.version = "2.0";
    model_.asset.generator = "drape";
    model_.buffers.emplace_back();
    model_.scenes.emplace_back();
    model_.defaultScene = 0;
  }

  /// VEC3 float accessor (positions, normals, translations); min/max when `bounds`.
  int addVec3(const std::vector<float>& xyz, bool bounds, int target) {
    const int view = addView(xyz.data(), xyz.size() * sizeof(float), target);
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.type = TINYGLTF_TYPE_VEC3;
    a.count = xyz.size() / 3;
    if (bounds) setBounds(a, xyz, 3);
    return push(model_.accessors, a);
  }

  /// Float accessor of `components` per element (1 scalar, 4 VEC4), for animation data.
  int addFloats(const std::vector<float>& values, int components, bool bounds) {
    const int view = addView(values.data(), values.size() * sizeof(float), 0);
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.type = components == 1 ? TINYGLTF_TYPE_SCALAR : TINYGLTF_TYPE_VEC4;
    a.count = values.size() / static_cast<std::size_t>(components);
    if (bounds) setBounds(a, values, components);
    return push(model_.accessors, a);
  }

  int addIndices(const std::vector<mesh::Triangle>& triangles) {
    const int view =
        addView(triangles.data(), triangles.size() * sizeof(mesh::Triangle), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    tinygltf::Accessor a;
    a.bufferView = view;
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.type = TINYGLTF_TYPE_SCALAR;
    a.count = triangles.size() * 3;
    return push(model_.accessors, a);
  }

  int addMaterial(const std::string& name, const std::array<float, 4>& colour, bool doubleSided) {
    tinygltf::Material m;
    m.name = name;
    m.pbrMetallicRoughness.baseColorFactor = {colour[0], colour[1], colour[2], colour[3]};
    m.pbrMetallicRoughness.metallicFactor = 0.0;
    m.pbrMetallicRoughness.roughnessFactor = 0.85;
    m.doubleSided = doubleSided;
    return push(model_.materials, m);
  }

  int addNode(tinygltf::Node node) {
    const int index = push(model_.nodes, std::move(node));
    model_.scenes[0].nodes.push_back(index);
    return index;
  }
  int addMesh(tinygltf::Mesh mesh) { return push(model_.meshes, std::move(mesh)); }
  tinygltf::Animation& animation() {
    if (model_.animations.empty()) {
      model_.animations.emplace_back();
      model_.animations[0].name = "take";
    }
    return model_.animations[0];
  }
  tinygltf::Model& model() { return model_; }

 private:
  template <typename T>
  static int push(std::vector<T>& list, T item) {
    list.push_back(std::move(item));
    return static_cast<int>(list.size()) - 1;
  }

  int addView(const void* bytes, std::size_t size, int target) {
    std::vector<unsigned char>& data = model_.buffers[0].data;
    while (data.size() % 4 != 0) data.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = data.size();
    v.byteLength = size;
    v.target = target;
    const auto* begin = static_cast<const unsigned char*>(bytes);
    data.insert(data.end(), begin, begin + size);
    return push(model_.bufferViews, v);
  }

  static void setBounds(tinygltf::Accessor& a, const std::vector<float>& values, int components) {
    a.minValues.assign(static_cast<std::size_t>(components), std::numeric_limits<double>::infinity());
    a.maxValues.assign(static_cast<std::size_t>(components), -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < values.size(); ++i) {
      const std::size_t c = i % static_cast<std::size_t>(components);
      a.minValues[c] = std::min(a.minValues[c], static_cast<double>(values[i]));
      a.maxValues[c] = std::max(a.maxValues[c], static_cast<double>(values[i]));
    }
  }

  tinygltf::Model model_;
};

std::vector<float> toFloats(const std::vector<Vec3>& points) {
  std::vector<float> out;
  out.reserve(points.size() * 3);
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) out.push_back(static_cast<float>(p[k]));
  return out;
}

/// Unit area-weighted vertex normals; vertices no triangle uses get +Y (glTF wants unit normals).
std::vector<Vec3> unitNormals(const std::vector<Vec3>& positions, const std::vector<mesh::Triangle>& triangles) {
  std::vector<Vec3> n;
  mesh::vertexNormals(positions, triangles, n);
  for (Vec3& v : n)
    if (v.isZero()) v = Vec3::UnitY();
  return n;
}

void checkTriangles(const std::string& path, const std::string& name, const std::vector<mesh::Triangle>& triangles,
                    std::size_t vertices) {
  if (triangles.empty() || vertices == 0) throw Error(fmt::format("{}: mesh '{}' has no triangles", path, name));
  for (const mesh::Triangle& t : triangles)
    for (std::uint32_t v : t)
      if (v >= vertices) throw Error(fmt::format("{}: mesh '{}' refers to vertex {} of {}", path, name, v, vertices));
}

std::vector<float> frameTimes(std::size_t frames, double rate) {
  std::vector<float> t(frames);
  for (std::size_t i = 0; i < frames; ++i) t[i] = static_cast<float>(static_cast<double>(i) / rate);
  return t;
}

/// A deforming mesh: frame 0 is the base, frames 1..N-1 are morph targets (position and
/// normal deltas), and the weights animation holds target i-1 at 1 at frame i.
void addDeforming(ModelBuilder& b, const GltfDeformingMesh& m, int timeAccessor, const std::string& path) {
  const std::size_t frames = m.frames.size();
  const std::vector<Vec3>& base = m.frames[0];
  checkTriangles(path, m.name, m.triangles, base.size());
  const std::vector<Vec3> baseNormals = unitNormals(base, m.triangles);
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.attributes["POSITION"] = b.addVec3(toFloats(base), true, TINYGLTF_TARGET_ARRAY_BUFFER);
  prim.attributes["NORMAL"] = b.addVec3(toFloats(baseNormals), false, TINYGLTF_TARGET_ARRAY_BUFFER);
  prim.indices = b.addIndices(m.triangles);
  prim.material = b.addMaterial(m.name, m.colour, m.doubleSided);
  for (std::size_t f = 1; f < frames; ++f) {
    if (m.frames[f].size() != base.size()) {
      throw Error(fmt::format("{}: mesh '{}' has {} points at frame {}, {} at frame 0", path, m.name,
                              m.frames[f].size(), f, base.size()));
    }
    const std::vector<Vec3> normals = unitNormals(m.frames[f], m.triangles);
    std::vector<Vec3> dp(base.size()), dn(base.size());
    for (std::size_t v = 0; v < base.size(); ++v) {
      dp[v] = m.frames[f][v] - base[v];
      dn[v] = normals[v] - baseNormals[v];
    }
    prim.targets.push_back({{"POSITION", b.addVec3(toFloats(dp), true, TINYGLTF_TARGET_ARRAY_BUFFER)},
                            {"NORMAL", b.addVec3(toFloats(dn), false, TINYGLTF_TARGET_ARRAY_BUFFER)}});
  }
  tinygltf::Mesh mesh;
  mesh.name = m.name;
  mesh.primitives.push_back(std::move(prim));
  const std::size_t targets = frames - 1;
  mesh.weights.assign(targets, 0.0);
  tinygltf::Node node;
  node.name = m.name;
  node.mesh = b.addMesh(std::move(mesh));
  const int nodeIndex = b.addNode(std::move(node));
  if (targets == 0) return;

  std::vector<float> weights(frames * targets, 0.0f);
  for (std::size_t f = 1; f < frames; ++f) weights[f * targets + (f - 1)] = 1.0f;
  tinygltf::AnimationSampler sampler;
  sampler.input = timeAccessor;
  sampler.output = b.addFloats(weights, 1, false);
  sampler.interpolation = "LINEAR";
  tinygltf::Animation& anim = b.animation();
  anim.samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = static_cast<int>(anim.samplers.size()) - 1;
  channel.target_node = nodeIndex;
  channel.target_path = "weights";
  anim.channels.push_back(channel);
}

/// A rigid part: its mesh in its own frame on a node whose translation and rotation follow
/// the per-frame transforms (rotations kept in one hemisphere so LINEAR slerps the short way).
void addRigid(ModelBuilder& b, const GltfRigidMesh& m, int timeAccessor, std::size_t frames, const std::string& path) {
  checkTriangles(path, m.name, m.mesh.triangles, m.mesh.positions.size());
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  prim.attributes["POSITION"] = b.addVec3(toFloats(m.mesh.positions), true, TINYGLTF_TARGET_ARRAY_BUFFER);
  prim.attributes["NORMAL"] =
      b.addVec3(toFloats(unitNormals(m.mesh.positions, m.mesh.triangles)), false, TINYGLTF_TARGET_ARRAY_BUFFER);
  prim.indices = b.addIndices(m.mesh.triangles);
  prim.material = b.addMaterial(m.name, m.colour, m.doubleSided);
  tinygltf::Mesh mesh;
  mesh.name = m.name;
  mesh.primitives.push_back(std::move(prim));
  tinygltf::Node node;
  node.name = m.name;
  node.mesh = b.addMesh(std::move(mesh));
  const RigidTransform& first = m.frames[0];
  node.translation = {first.translation.x(), first.translation.y(), first.translation.z()};
  const Quat q0 = first.rotation.normalized();
  node.rotation = {q0.x(), q0.y(), q0.z(), q0.w()};
  const int nodeIndex = b.addNode(std::move(node));
  if (frames < 2) return;

  std::vector<float> translations, rotations;
  Quat previous = q0;
  for (const RigidTransform& x : m.frames) {
    Quat q = x.rotation.normalized();
    if (q.dot(previous) < 0.0) q.coeffs() *= -1.0;
    previous = q;
    for (int k = 0; k < 3; ++k) translations.push_back(static_cast<float>(x.translation[k]));
    for (double c : {q.x(), q.y(), q.z(), q.w()}) rotations.push_back(static_cast<float>(c));
  }
  tinygltf::Animation& anim = b.animation();
  const auto addChannel = [&](int output, const char* pathName) {
    tinygltf::AnimationSampler sampler;
    sampler.input = timeAccessor;
    sampler.output = output;
    sampler.interpolation = "LINEAR";
    anim.samplers.push_back(sampler);
    tinygltf::AnimationChannel channel;
    channel.sampler = static_cast<int>(anim.samplers.size()) - 1;
    channel.target_node = nodeIndex;
    channel.target_path = pathName;
    anim.channels.push_back(channel);
  };
  addChannel(b.addVec3(translations, false, 0), "translation");
  addChannel(b.addFloats(rotations, 4, false), "rotation");
}

constexpr std::array<float, 4> kGarmentColour = {0.60f, 0.04f, 0.05f, 1.0f};  // linear, the renderer's cloth red
constexpr std::array<float, 4> kSegmentColour = {0.61f, 0.51f, 0.43f, 1.0f};  // linear, clay
constexpr std::array<float, 4> kDrawnColour = {0.106f, 0.076f, 0.061f, 1.0f};  // linear, the renderer's darker clay

/// A scene's sRGB colour as glTF's linear base colour (the renderer's 2.2 gamma).
std::array<float, 4> linearColour(const Vec3& srgb) {
  return {static_cast<float>(std::pow(srgb.x(), 2.2)), static_cast<float>(std::pow(srgb.y(), 2.2)),
          static_cast<float>(std::pow(srgb.z(), 2.2)), 1.0f};
}

}  // namespace

void writeGlb(const std::string& path, const GltfAnimation& animation) {
  if (!(animation.frameRate > 0.0) || !std::isfinite(animation.frameRate))
    throw Error(fmt::format("{}: frame rate must be positive", path));
  if (animation.deforming.empty() && animation.rigid.empty()) throw Error(fmt::format("{}: nothing to export", path));
  const std::size_t frames =
      !animation.deforming.empty() ? animation.deforming[0].frames.size() : animation.rigid[0].frames.size();
  if (frames == 0) throw Error(fmt::format("{}: the animation has no frames", path));
  for (const GltfDeformingMesh& m : animation.deforming)
    if (m.frames.size() != frames)
      throw Error(fmt::format("{}: mesh '{}' has {} frames, others {}", path, m.name, m.frames.size(), frames));
  for (const GltfRigidMesh& m : animation.rigid)
    if (m.frames.size() != frames)
      throw Error(fmt::format("{}: part '{}' has {} frames, others {}", path, m.name, m.frames.size(), frames));

  ModelBuilder b;
  const int times = frames > 1 ? b.addFloats(frameTimes(frames, animation.frameRate), 1, true) : -1;
  for (const GltfDeformingMesh& m : animation.deforming) addDeforming(b, m, times, path);
  for (const GltfRigidMesh& m : animation.rigid) addRigid(b, m, times, frames, path);
  b.model().buffers[0].data.resize((b.model().buffers[0].data.size() + 3) / 4 * 4, 0);

  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToFile(&b.model(), path, /*embedImages=*/true, /*embedBuffers=*/true,
                                   /*prettyPrint=*/false, /*writeBinary=*/true)) {
    throw Error(fmt::format("{}: cannot be written", path));
  }
}

RigidFit fitRigid(const std::vector<Vec3>& from, const std::vector<Vec3>& to) {
  RigidFit fit;
  if (from.empty() || from.size() != to.size()) {
    fit.maxError_m = std::numeric_limits<double>::infinity();
    return fit;
  }
  Vec3 cf = Vec3::Zero(), ct = Vec3::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) {
    cf += from[i];
    ct += to[i];
  }
  cf /= static_cast<double>(from.size());
  ct /= static_cast<double>(to.size());
  Mat3 h = Mat3::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) h += (from[i] - cf) * (to[i] - ct).transpose();
  const Eigen::JacobiSVD<Mat3> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 d = Mat3::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  const Mat3 r = svd.matrixV() * d * svd.matrixU().transpose();
  fit.transform.rotation = Quat(r).normalized();
  fit.transform.translation = ct - r * cf;
  for (std::size_t i = 0; i < from.size(); ++i)
    fit.maxError_m = std::max(fit.maxError_m, (fit.transform.apply(from[i]) - to[i]).norm());
  return fit;
}

RunExportSummary exportRunToGlb(const std::string& runDirectory, const std::string& glbPath, ExportedBody body,
                                double rigidTolerance_m) {
  const RunManifest manifest = readRunManifest(runDirectory);
  std::set<std::string> skinned;  // the characters whose skinned body is in the run
  for (const RunMesh& rm : manifest.meshes)
    if (rm.role == "skin") skinned.insert(rm.character);
  const bool skins = body == ExportedBody::Skin;
  const std::filesystem::path dir(runDirectory);
  if (manifest.frames <= 0) throw Error(fmt::format("{}: the run has no frames", (dir / "manifest.json").string()));
  GltfAnimation animation;
  animation.frameRate = manifest.frameRate;
  RunExportSummary summary;
  summary.frames = manifest.frames;
  for (const RunMesh& rm : manifest.meshes) {
    // By default the file carries the body as its segments, rigid nodes a few kilobytes
    // each, where the skinned body (and its drawn meshes) would be a morph target per frame.
    if ((rm.role == "skin" || rm.role == "drawn") && !skins) continue;
    if (rm.role == "segment" && skins && skinned.count(rm.character) > 0) continue;
    const std::string objPath = (dir / rm.topology).string();
    const std::string pc2Path = (dir / rm.cache).string();
    mesh::TriMesh topology = readObj(objPath);
    Pc2Cache cache = readPc2(pc2Path);
    if (cache.pointCount != topology.vertexCount()) {
      throw Error(fmt::format("{}: {} points per sample, but {} has {} vertices", pc2Path, cache.pointCount, objPath,
                              topology.vertexCount()));
    }
    if (static_cast<long>(cache.frames.size()) < manifest.frames) {
      throw Error(
          fmt::format("{}: {} samples, the manifest says {} frames", pc2Path, cache.frames.size(), manifest.frames));
    }
    cache.frames.resize(static_cast<std::size_t>(manifest.frames));
    // Among several characters, a part's node is named for its character too.
    const std::string name = rm.character.empty() ? rm.name : rm.character + "/" + rm.name;
    if (rm.role != "garment" && rm.role != "segment" && rm.role != "skin" && rm.role != "drawn") {
      throw Error(fmt::format("{}: mesh '{}' has role '{}' (expected garment, segment, skin or drawn)",
                              (dir / "manifest.json").string(), rm.name, rm.role));
    }

    // A segment whose every frame is a rigid motion of frame 0 becomes a TRS-animated node,
    // its mesh centred on its own centroid so the node's pivot sits inside the part.
    if (rm.role == "segment") {
      std::vector<RigidTransform> motion;
      bool rigid = true;
      for (const std::vector<Vec3>& f : cache.frames) {
        const RigidFit fit = fitRigid(cache.frames[0], f);
        if (!(fit.maxError_m <= rigidTolerance_m)) {
          rigid = false;
          break;
        }
        motion.push_back(fit.transform);
      }
      if (rigid) {
        Vec3 centre = Vec3::Zero();
        for (const Vec3& p : cache.frames[0]) centre += p;
        centre /= static_cast<double>(cache.frames[0].size());
        GltfRigidMesh part;
        part.name = name;
        part.mesh.name = name;
        part.mesh.triangles = topology.triangles;
        for (const Vec3& p : cache.frames[0]) part.mesh.positions.push_back(p - centre);
        for (const RigidTransform& x : motion) part.frames.push_back({x.rotation, x.rotation * centre + x.translation});
        part.colour = kSegmentColour;
        animation.rigid.push_back(std::move(part));
        ++summary.rigid;
        continue;
      }
    }
    GltfDeformingMesh m;
    m.name = name;
    m.triangles = std::move(topology.triangles);
    m.frames = std::move(cache.frames);
    m.colour = rm.role == "garment" ? (rm.colour ? linearColour(*rm.colour) : kGarmentColour)
               : rm.role == "drawn" ? kDrawnColour
                                    : kSegmentColour;
    if (rm.role == "skin" || rm.role == "drawn") ++summary.skins;
    m.doubleSided = rm.role == "garment";
    animation.deforming.push_back(std::move(m));
    ++summary.deforming;
  }
  writeGlb(glbPath, animation);
  return summary;
}

}  // namespace drape::formats
