#include "drape/formats/assimp_avatar.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include <assimp/BaseImporter.h>
#include <assimp/Exporter.hpp>
#include <assimp/IOSystem.hpp>
#include <assimp/Importer.hpp>
#include <assimp/MemoryIOWrapper.h>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/mesh_file.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

constexpr std::size_t kMaxVertices = 10'000'000;
constexpr std::size_t kMaxAvatarJoints = 1024;
constexpr std::size_t kMaxFileBytes = std::size_t{1} << 30;

enum class Format { Collada, Fbx };

Format formatOf(const std::string& name) {
  const std::string ext = lowerExtension(name);
  if (ext == ".dae") return Format::Collada;
  if (ext == ".fbx") return Format::Fbx;
  throw Error(fmt::format("{}: drape reads Collada (.dae) and FBX (.fbx) through Assimp, not '{}'", name, ext));
}

const char* formatName(Format f) { return f == Format::Collada ? "Collada" : "FBX"; }
const char* extensionOf(Format f) { return f == Format::Collada ? ".dae" : ".fbx"; }

// ---- the bytes must be what the extension says --------------------------------------

std::string_view skipSpaceAndBom(std::string_view s) {
  if (s.substr(0, 3) == "\xEF\xBB\xBF") s.remove_prefix(3);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  return s;
}

// The XML root element must be <COLLADA>: skip the declaration, comments and a DOCTYPE.
bool hasColladaRoot(std::string_view s) {
  for (;;) {
    s = skipSpaceAndBom(s);
    std::string_view close;
    if (s.substr(0, 4) == "<!--") close = "-->";
    else if (s.substr(0, 2) == "<?") close = "?>";
    else if (s.substr(0, 2) == "<!") close = ">";
    else break;
    const std::size_t end = s.find(close);
    if (end == std::string_view::npos) return false;
    s.remove_prefix(end + close.size());
  }
  if (s.substr(0, 8) != "<COLLADA") return false;
  return s.size() > 8 && (std::isspace(static_cast<unsigned char>(s[8])) || s[8] == '>');
}

int lineAt(std::string_view bytes, std::size_t offset) {
  return 1 + static_cast<int>(std::count(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(offset), '\n'));
}

// Position of the next start tag `<tag ...>` or `<tag>` at or after `from` (not `<tagx`).
std::size_t findStartTag(std::string_view bytes, std::string_view tag, std::size_t from) {
  // Appended rather than "<" + std::string(tag): GCC 12 warns (-Wrestrict) on the inlined
  // operator+ of a literal and a temporary.
  std::string open(1, '<');
  open.append(tag);
  for (std::size_t at = bytes.find(open, from); at != std::string_view::npos; at = bytes.find(open, at + 1)) {
    const std::size_t after = at + open.size();
    if (after < bytes.size() && (bytes[after] == '>' || std::isspace(static_cast<unsigned char>(bytes[after])))) return at;
  }
  return std::string_view::npos;
}

// Assimp's Collada parser dereferences a null pointer on an array without its (required)
// count attribute (found by fuzzing), allocates without bound on a word that is not a
// number in an index list ("abc" in <p> took over 4 GB) and reserves whatever a count
// attribute says; drape checks all three before Assimp sees the bytes.
void checkColladaArrays(std::string_view bytes, const std::string& name) {
  for (const std::string_view tag : {"float_array", "int_array", "Name_array", "IDREF_array", "SIDREF_array", "bool_array", "token_array"})
    for (std::size_t at = findStartTag(bytes, tag, 0); at != std::string_view::npos; at = findStartTag(bytes, tag, at + 1)) {
      const std::string_view startTag = bytes.substr(at, bytes.find('>', at) - at);
      const std::size_t count = startTag.find("count=");
      if (count == std::string_view::npos || !std::isspace(static_cast<unsigned char>(startTag[count - 1])))
        throw Error(fmt::format("{}:{}: <{}> has no count attribute", name, lineAt(bytes, at), tag));
    }
  constexpr std::string_view kCount = "count=\"";
  for (std::size_t at = bytes.find(kCount); at != std::string_view::npos; at = bytes.find(kCount, at + 1)) {
    std::size_t end = at + kCount.size();
    double value = 0.0;
    for (; end < bytes.size() && std::isdigit(static_cast<unsigned char>(bytes[end])); ++end) value = value * 10.0 + (bytes[end] - '0');
    // Every counted item takes at least one byte of the file.
    if (value > static_cast<double>(bytes.size()))
      throw Error(fmt::format("{}:{}: count=\"{:.0f}\" is more than a {}-byte file can hold", name, lineAt(bytes, at), value, bytes.size()));
  }
  // Lists of indices and counts: whole numbers only.
  for (const std::string_view tag : {"p", "v", "vcount", "h", "int_array"}) {
    for (std::size_t at = findStartTag(bytes, tag, 0); at != std::string_view::npos; at = findStartTag(bytes, tag, at + 1)) {
      const std::size_t start = bytes.find('>', at);
      if (start == std::string_view::npos) break;
      const std::size_t stop = std::min(bytes.find('<', start), bytes.size());
      for (std::size_t i = start + 1; i < stop; ++i) {
        const char c = bytes[i];
        if (std::isdigit(static_cast<unsigned char>(c)) || std::isspace(static_cast<unsigned char>(c)) || (c == '-' && tag == "int_array")) continue;
        const std::size_t wordEnd = std::min(bytes.find_first_of(" \t\r\n<", i), stop);
        throw Error(fmt::format("{}:{}: <{}> holds '{}', not a whole number", name, lineAt(bytes, i), tag,
                                bytes.substr(i, std::min<std::size_t>(wordEnd - i, 40))));
      }
    }
  }
}

void checkSignature(std::string_view bytes, Format format, const std::string& name) {
  if (format == Format::Collada) {
    if (!hasColladaRoot(bytes)) throw Error(fmt::format("{}: not a Collada file (no XML root element <COLLADA>)", name));
    return;
  }
  if (bytes.substr(0, 18) == "Kaydara FBX Binary") return;
  if (skipSpaceAndBom(bytes).substr(0, 5) == "; FBX") return;
  throw Error(fmt::format("{}: not an FBX file (neither binary FBX, starting \"Kaydara FBX Binary\", nor ASCII FBX, starting \"; FBX\")", name));
}

// ---- Assimp, restricted to one importer and one file ---------------------------------

// Serves the avatar's own bytes under one internal name and refuses every other path:
// Collada and FBX may name textures or other files, and drape reads none of them.
class OwnBytesOnly final : public Assimp::IOSystem {
 public:
  OwnBytesOnly(std::string_view bytes, std::string internalName) : bytes_(bytes), name_(std::move(internalName)) {}

  bool Exists(const char* path) const override { return path != nullptr && name_ == path; }
  char getOsSeparator() const override { return '/'; }

  Assimp::IOStream* Open(const char* path, const char* mode) override {
    const bool writing = mode != nullptr && (std::strchr(mode, 'w') || std::strchr(mode, 'a') || std::strchr(mode, '+'));
    if (path == nullptr || name_ != path || writing) {
      refused_.emplace_back(path == nullptr ? "" : path);
      return nullptr;
    }
    return new Assimp::MemoryIOStream(reinterpret_cast<const std::uint8_t*>(bytes_.data()), bytes_.size(), false);
  }
  void Close(Assimp::IOStream* stream) override { delete stream; }

  [[nodiscard]] const std::vector<std::string>& refused() const { return refused_; }

 private:
  std::string_view bytes_;
  std::string name_;
  std::vector<std::string> refused_;
};

// Unregisters (and frees) every importer but the one for `extension`, so a file the
// importer rejects cannot fall through to another format's reader.
void keepOnlyImporterFor(Assimp::Importer& importer, const char* extension) {
  Assimp::BaseImporter* const keep = importer.GetImporter(extension);
  if (keep == nullptr) throw Error(fmt::format("this Assimp has no importer for {}", extension), ExitCode::Internal);
  std::vector<Assimp::BaseImporter*> others;
  for (std::size_t i = 0; i < importer.GetImporterCount(); ++i)
    if (importer.GetImporter(i) != keep) others.push_back(importer.GetImporter(i));
  for (Assimp::BaseImporter* other : others) {
    importer.UnregisterLoader(other);
    delete other;  // UnregisterLoader hands ownership back
  }
  if (importer.GetImporterCount() != 1) throw Error("could not restrict Assimp to one importer", ExitCode::Internal);
}

void configure(Assimp::Importer& importer, bool animations) {
  importer.SetPropertyInteger(AI_CONFIG_PP_LBW_MAX_WEIGHTS, 4);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_NO_SKELETON_MESHES, true);
  // Helper nodes for FBX pivots would sit between bones and become joints of their own; but
  // Assimp splits the animation of a node with pivots into channels of those helpers
  // (translation, rotation, scale), so the scene an animation is read from keeps them.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, animations);
  // Less to parse from untrusted bytes: nothing of these is used.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_TEXTURES, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_CAMERAS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_LIGHTS, false);
  // Read in both: the skin's scene names the animations the avatar carries (its nodes are
  // the same whether animation curves are read or not; only the pivots above change them).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_ANIMATIONS, true);
}

constexpr unsigned kPostProcess = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                  aiProcess_LimitBoneWeights | aiProcess_ValidateDataStructure;

std::string refusalNote(const OwnBytesOnly& io) {
  if (io.refused().empty()) return "";
  return fmt::format(" (it asked for '{}', which drape does not open: only the file itself is read)", io.refused().front());
}

// ---- the scene as drape's plain data --------------------------------------------------

Eigen::Matrix4d toEigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

aiMatrix4x4 toAssimp(const Eigen::Matrix4d& e) {
  aiMatrix4x4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m[static_cast<unsigned>(r)][static_cast<unsigned>(c)] = static_cast<ai_real>(e(r, c));
  return m;
}

// A number from the scene metadata, whatever numeric type the importer stored it as.
std::optional<double> metadataNumber(const aiScene& scene, const char* key) {
  const aiMetadata* meta = scene.mMetaData;
  if (meta == nullptr) return std::nullopt;
  for (unsigned i = 0; i < meta->mNumProperties; ++i) {
    if (std::strcmp(meta->mKeys[i].C_Str(), key) != 0 || meta->mValues[i].mData == nullptr) continue;
    const void* data = meta->mValues[i].mData;
    switch (meta->mValues[i].mType) {
      case AI_INT32: return *static_cast<const std::int32_t*>(data);
      case AI_UINT64: return static_cast<double>(*static_cast<const std::uint64_t*>(data));
      case AI_FLOAT: return *static_cast<const float*>(data);
      case AI_DOUBLE: return *static_cast<const double*>(data);
      default: return std::nullopt;
    }
  }
  return std::nullopt;
}

// FBX: the importer leaves units and axes to the caller. UnitScaleFactor is centimetres
// per file unit; CoordAxis and UpAxis (with signs) name the file's right and up axes, and
// front follows from right-handedness (tools disagree on FrontAxisSign's meaning).
Eigen::Matrix4d fbxToMetresYUp(const aiScene& scene, const std::string& name) {
  const double unitCm = metadataNumber(scene, "UnitScaleFactor").value_or(1.0);
  if (!std::isfinite(unitCm) || unitCm < 1e-6 || unitCm > 1e6)
    throw Error(fmt::format("{}: FBX UnitScaleFactor {} is not a usable unit", name, unitCm));
  const double up = metadataNumber(scene, "UpAxis").value_or(1.0);
  const double upSign = metadataNumber(scene, "UpAxisSign").value_or(1.0);
  const double right = metadataNumber(scene, "CoordAxis").value_or(0.0);
  const double rightSign = metadataNumber(scene, "CoordAxisSign").value_or(1.0);
  auto valid = [](double axis) { return axis == 0.0 || axis == 1.0 || axis == 2.0; };
  if (!valid(up) || !valid(right) || up == right || std::abs(upSign) != 1.0 || std::abs(rightSign) != 1.0)
    throw Error(fmt::format("{}: FBX axes UpAxis {} / CoordAxis {} (with signs {}, {}) are not two different axes", name,
                            up, right, upSign, rightSign));
  const Vec3 rightRow = rightSign * Vec3::Unit(static_cast<int>(right));
  const Vec3 upRow = upSign * Vec3::Unit(static_cast<int>(up));
  Eigen::Matrix3d axes;
  axes.row(0) = rightRow.transpose();
  axes.row(1) = upRow.transpose();
  axes.row(2) = rightRow.cross(upRow).transpose();
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = axes * (unitCm * 0.01);
  return m;
}

struct SceneReader {
  const aiScene& scene;
  const std::string& name;
  Eigen::Matrix4d toMetres;  // applied on the left of every world matrix
  std::unordered_map<const aiNode*, Eigen::Matrix4d> world;

  [[noreturn]] void fail(const std::string& what) const { throw Error(fmt::format("{}: {}", name, what)); }

  // World matrices of every node, iteratively (a deep malformed tree must not recurse).
  void computeWorlds() {
    std::vector<const aiNode*> stack{scene.mRootNode};
    world[scene.mRootNode] = toMetres * toEigen(scene.mRootNode->mTransformation);
    while (!stack.empty()) {
      const aiNode* node = stack.back();
      stack.pop_back();
      for (unsigned i = 0; i < node->mNumChildren; ++i) {
        const aiNode* child = node->mChildren[i];
        if (child == nullptr || world.count(child) != 0) fail("its node tree is not a tree");
        world[child] = world[node] * toEigen(child->mTransformation);
        stack.push_back(child);
      }
    }
  }

  // Meshes with bones and triangles, each with the first node that places it.
  std::vector<std::pair<const aiMesh*, const aiNode*>> skinnedMeshes() const {
    std::vector<std::pair<const aiMesh*, const aiNode*>> out;
    std::vector<bool> seen(scene.mNumMeshes, false);
    std::vector<const aiNode*> stack{scene.mRootNode};
    while (!stack.empty()) {
      const aiNode* node = stack.back();
      stack.pop_back();
      for (unsigned i = 0; i < node->mNumMeshes; ++i) {
        const unsigned m = node->mMeshes[i];
        if (m >= scene.mNumMeshes || seen[m]) continue;
        seen[m] = true;
        const aiMesh* mesh = scene.mMeshes[m];
        if (mesh->HasBones() && (mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) != 0) out.emplace_back(mesh, node);
      }
      for (unsigned i = node->mNumChildren; i-- > 0;) stack.push_back(node->mChildren[i]);
    }
    return out;
  }

  const aiNode* boneNode(const aiBone& bone) const {
    const aiNode* node = scene.mRootNode->FindNode(bone.mName);
    if (node == nullptr) fail(fmt::format("bone '{}' names no node of the scene", bone.mName.C_Str()));
    return node;
  }

  static int depth(const aiNode* node) {
    int d = 0;
    for (const aiNode* p = node->mParent; p != nullptr; p = p->mParent) ++d;
    return d;
  }

  // The skeleton root: the deepest node that is an ancestor of (or is) every bone node.
  static const aiNode* commonAncestor(const aiNode* a, const aiNode* b) {
    int da = depth(a), db = depth(b);
    for (; da > db; --da) a = a->mParent;
    for (; db > da; --db) b = b->mParent;
    while (a != b) {
      a = a->mParent;
      b = b->mParent;
    }
    return a;
  }
};

// Joints: every bone's node and the nodes between it and the skeleton root, in the
// node tree's depth-first order (parents first).
std::vector<const aiNode*> skeletonNodes(const SceneReader& r, const std::vector<const aiNode*>& bones) {
  const aiNode* root = bones.front();
  for (const aiNode* b : bones) root = SceneReader::commonAncestor(root, b);
  std::unordered_set<const aiNode*> member{root};
  for (const aiNode* b : bones)
    for (const aiNode* n = b; n != root && member.insert(n).second; n = n->mParent)
      if (member.size() > kMaxAvatarJoints) r.fail(fmt::format("its skeleton has more than {} joints", kMaxAvatarJoints));
  std::vector<const aiNode*> order;
  std::vector<const aiNode*> stack{root};
  while (!stack.empty()) {
    const aiNode* node = stack.back();
    stack.pop_back();
    order.push_back(node);
    for (unsigned i = node->mNumChildren; i-- > 0;)
      if (member.count(node->mChildren[i]) != 0) stack.push_back(node->mChildren[i]);
  }
  return order;
}

struct Influence {
  std::uint16_t bone = 0;  // index into the mesh's bones
  float weight = 0.0f;
};

// Appends one mesh: positions skinned with the rest-pose nodes (as glTF viewers do), at
// most four influences per vertex, normalised. A vertex no bone weighs follows the
// skeleton root and stays where its mesh node puts it.
void appendMesh(const SceneReader& r, const aiMesh& mesh, const aiNode& meshNode,
                const std::unordered_map<const aiNode*, std::uint16_t>& jointOf, SkinnedModel& out) {
  const std::size_t count = mesh.mNumVertices;
  if (out.positions.size() + count > kMaxVertices) r.fail(fmt::format("it has more than {} vertices", kMaxVertices));
  if (mesh.mNumBones > 65535) r.fail("a mesh has more than 65535 bones");
  std::vector<std::vector<Influence>> influences(count);
  std::vector<Eigen::Matrix4d> skinMatrix(mesh.mNumBones);
  std::vector<std::uint16_t> boneJoint(mesh.mNumBones);
  for (unsigned b = 0; b < mesh.mNumBones; ++b) {
    const aiBone& bone = *mesh.mBones[b];
    const aiNode* node = r.boneNode(bone);
    skinMatrix[b] = r.world.at(node) * toEigen(bone.mOffsetMatrix);
    boneJoint[b] = jointOf.at(node);
    for (unsigned k = 0; k < bone.mNumWeights; ++k) {
      const aiVertexWeight& w = bone.mWeights[k];
      if (w.mVertexId >= count) r.fail(fmt::format("bone '{}' weighs vertex {}, but the mesh has {}", bone.mName.C_Str(), w.mVertexId, count));
      if (!std::isfinite(w.mWeight) || w.mWeight < 0.0f) r.fail(fmt::format("bone '{}' has a bad weight {}", bone.mName.C_Str(), w.mWeight));
      if (w.mWeight > 0.0f) influences[w.mVertexId].push_back({static_cast<std::uint16_t>(b), w.mWeight});
    }
  }
  const Eigen::Matrix4d meshWorld = r.world.at(&meshNode);
  const auto base = static_cast<std::uint32_t>(out.positions.size());
  for (std::size_t v = 0; v < count; ++v) {
    std::vector<Influence>& in = influences[v];
    std::sort(in.begin(), in.end(), [](const Influence& a, const Influence& b) { return a.weight > b.weight; });
    if (in.size() > 4) in.resize(4);
    double total = 0.0;
    for (const Influence& i : in) total += i.weight;
    std::array<std::uint16_t, 4> joints{};
    std::array<float, 4> weights{};
    Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
    if (total > 1e-9) {
      for (std::size_t k = 0; k < in.size(); ++k) {
        joints[k] = boneJoint[in[k].bone];
        weights[k] = static_cast<float>(in[k].weight / total);
        m += (in[k].weight / total) * skinMatrix[in[k].bone];
      }
    } else {
      weights[0] = 1.0f;
      m = meshWorld;
    }
    const aiVector3D& p = mesh.mVertices[v];
    const Eigen::Vector4d h = m * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
    if (!h.allFinite()) r.fail(fmt::format("vertex {} is not finite after skinning", v));
    out.positions.emplace_back(h.x(), h.y(), h.z());
    out.vertexJoints.push_back(joints);
    out.vertexWeights.push_back(weights);
  }
  for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
    const aiFace& face = mesh.mFaces[f];
    if (face.mNumIndices != 3) continue;  // points and lines left by triangulation
    mesh::Triangle tri;
    for (unsigned c = 0; c < 3; ++c) {
      if (face.mIndices[c] >= count) r.fail(fmt::format("face {} names vertex {}, but the mesh has {}", f, face.mIndices[c], count));
      tri[c] = base + face.mIndices[c];
    }
    if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2]) out.triangles.push_back(tri);
  }
}

SceneReader readerFor(const aiScene& scene, Format format, const std::string& name) {
  const Eigen::Matrix4d toMetres = format == Format::Fbx ? fbxToMetresYUp(scene, name) : Eigen::Matrix4d::Identity();
  SceneReader r{scene, name, toMetres, {}};
  if (scene.mRootNode == nullptr) r.fail("has no node tree");
  r.computeWorlds();
  return r;
}

// The skin's skeleton (parents first) and the skinned meshes with the nodes that place them.
std::vector<const aiNode*> skinSkeleton(const SceneReader& r,
                                        std::vector<std::pair<const aiMesh*, const aiNode*>>& meshes) {
  meshes = r.skinnedMeshes();
  if (meshes.empty()) r.fail("has no skinned triangle mesh (a mesh with bones is needed)");
  std::vector<const aiNode*> bones;
  for (const auto& [mesh, node] : meshes)
    for (unsigned b = 0; b < mesh->mNumBones; ++b) bones.push_back(r.boneNode(*mesh->mBones[b]));
  return skeletonNodes(r, bones);
}

std::string jointName(const aiNode& node, std::size_t index) {
  return node.mName.length > 0 ? node.mName.C_Str() : fmt::format("joint{}", index);
}

std::vector<std::string> animationNames(const aiScene& scene) {
  std::vector<std::string> names;
  for (unsigned a = 0; a < scene.mNumAnimations; ++a)
    names.push_back(detail::animationName(scene.mAnimations[a] == nullptr ? "" : scene.mAnimations[a]->mName.C_Str(), a));
  return names;
}

// What a mesh placed by `node` is called: the node's name, else the mesh's, else "mesh <m>".
std::string partName(const aiNode& node, const aiMesh& mesh, unsigned m) {
  const std::string nodeName = node.mName.C_Str(), meshName = mesh.mName.C_Str();
  return !nodeName.empty() ? nodeName : !meshName.empty() ? meshName : fmt::format("mesh {}", m);
}

// The skin's rest model. Its skeleton comes from every skinned mesh, as the motion readers'
// does; its triangles from those of `parts` only when some are named (by node or mesh name).
SkinnedModel extract(const aiScene& scene, Format format, const std::string& name, const std::vector<std::string>& parts) {
  const SceneReader r = readerFor(scene, format, name);
  std::vector<std::pair<const aiMesh*, const aiNode*>> meshes;
  const std::vector<const aiNode*> skeleton = skinSkeleton(r, meshes);

  SkinnedModel out;
  out.source = name;
  out.animations = animationNames(scene);
  std::unordered_map<const aiNode*, std::uint16_t> jointOf;
  for (std::size_t j = 0; j < skeleton.size(); ++j) {
    const aiNode* node = skeleton[j];
    jointOf[node] = static_cast<std::uint16_t>(j);
    SkinnedJoint joint;
    joint.name = jointName(*node, j);
    joint.parent = j == 0 ? -1 : jointOf.at(node->mParent);
    joint.restWorld = r.world.at(node);
    out.joints.push_back(std::move(joint));
  }
  std::vector<bool> matched(parts.size(), false);
  for (const auto& [mesh, node] : meshes) {
    const auto m = static_cast<unsigned>(std::find(scene.mMeshes, scene.mMeshes + scene.mNumMeshes, mesh) - scene.mMeshes);
    const std::string part = partName(*node, *mesh, m);
    if (std::find(out.meshes.begin(), out.meshes.end(), part) == out.meshes.end()) out.meshes.push_back(part);
    if (!partWanted(parts, matched, part, mesh->mName.C_Str())) continue;
    const std::size_t before = out.triangles.size();
    appendMesh(r, *mesh, *node, jointOf, out);
    if (out.triangles.size() > before && std::find(out.meshesRead.begin(), out.meshesRead.end(), part) == out.meshesRead.end())
      out.meshesRead.push_back(part);
  }
  checkPartsMatched(parts, matched, out.meshes, name, "skinned meshes");
  if (out.triangles.empty()) r.fail(parts.empty() ? "its skinned meshes have no triangles" : "the meshes asked for have no triangles");
  return out;
}

// ---- animations -------------------------------------------------------------------------

// Assimp's key times are ticks. Where a file gives no rate it leaves mTicksPerSecond 0, and
// its own viewer then plays 25 ticks per second.
double secondsPerTick(const aiAnimation& a) {
  return a.mTicksPerSecond > 0 && std::isfinite(a.mTicksPerSecond) ? 1.0 / a.mTicksPerSecond : 1.0 / 25.0;
}

// The value at `t` of keys at `times` (seconds, ascending): held before the first key and
// after the last, `mix`ed between the two around t.
template <typename V, typename Mix>
V sampleKeys(const std::vector<double>& times, const std::vector<V>& values, double t, Mix mix) {
  if (t <= times.front()) return values.front();
  if (t >= times.back()) return values.back();
  const auto next = static_cast<std::size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  const double span = times[next] - times[next - 1];
  return span > 0 ? mix(values[next - 1], values[next], (t - times[next - 1]) / span) : values[next];
}

// One node's channel of an animation: translation and scale keys linear, rotations by
// SLERP; a part without keys stays as the node's own transform has it.
struct NodeTrack {
  std::size_t node = 0;  // index into MotionNodes::nodes
  std::vector<double> positionTimes, rotationTimes, scaleTimes;
  std::vector<Vec3> positions, scales;
  std::vector<Quat> rotations;

  [[nodiscard]] Eigen::Matrix4d local(double t, const Eigen::Matrix4d& own) const {
    Vec3 position = own.block<3, 1>(0, 3);
    Eigen::Matrix3d linear = own.topLeftCorner<3, 3>();
    Vec3 scale(linear.col(0).norm(), linear.col(1).norm(), linear.col(2).norm());
    const auto lerp = [](const Vec3& a, const Vec3& b, double u) -> Vec3 { return a + u * (b - a); };
    if (!positions.empty()) position = sampleKeys(positionTimes, positions, t, lerp);
    if (!scales.empty()) scale = sampleKeys(scaleTimes, scales, t, lerp);
    Eigen::Matrix3d rotation;
    if (!rotations.empty()) {
      rotation = sampleKeys(rotationTimes, rotations, t, [](const Quat& a, const Quat& b, double u) { return a.slerp(u, b); })
                     .toRotationMatrix();
    } else {
      for (int c = 0; c < 3; ++c) linear.col(c) /= scale[c] > 0 ? scale[c] : 1.0;
      rotation = linear;
    }
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() = rotation * scale.asDiagonal();
    m.block<3, 1>(0, 3) = position;
    return m;
  }
};

// The nodes of the animated scene whose transforms place the skin's joints: every node from
// the root down to a joint (FBX's pivot helpers between joints included), parents first.
struct MotionNodes {
  std::vector<const aiNode*> nodes;
  std::vector<int> parent;
  std::vector<std::size_t> joint;  // the node index of each skin joint

  MotionNodes() = default;
  MotionNodes(const aiScene& scene, const std::vector<const aiNode*>& jointNodes) {
    std::unordered_set<const aiNode*> member;
    for (const aiNode* j : jointNodes)
      for (const aiNode* n = j; n != nullptr && member.insert(n).second; n = n->mParent) {
      }
    std::unordered_map<const aiNode*, std::size_t> index;
    std::vector<const aiNode*> stack{scene.mRootNode};
    while (!stack.empty()) {
      const aiNode* node = stack.back();
      stack.pop_back();
      index[node] = nodes.size();
      parent.push_back(node->mParent != nullptr && index.count(node->mParent) != 0 ? static_cast<int>(index.at(node->mParent)) : -1);
      nodes.push_back(node);
      for (unsigned i = node->mNumChildren; i-- > 0;)
        if (member.count(node->mChildren[i]) != 0) stack.push_back(node->mChildren[i]);
    }
    for (const aiNode* j : jointNodes) joint.push_back(index.at(j));
  }
};

template <typename Key>
std::vector<double> keyTimes(const Key* keys, unsigned count, double perTick, const std::string& where, const SceneReader& r) {
  std::vector<double> times;
  for (unsigned k = 0; k < count; ++k) {
    const double t = keys[k].mTime * perTick;
    if (!std::isfinite(t) || std::abs(t) > 86400.0)
      r.fail(fmt::format("{}: key time {} is not a time within a day", where, keys[k].mTime));
    if (!times.empty() && t < times.back()) r.fail(fmt::format("{}: key {} comes before key {} in time", where, k, k - 1));
    times.push_back(t);
  }
  return times;
}

std::vector<NodeTrack> readTracks(const aiScene& scene, const aiAnimation& anim, const std::string& animName,
                                  const MotionNodes& motionNodes, const SceneReader& r) {
  std::unordered_map<const aiNode*, std::size_t> index;
  for (std::size_t i = 0; i < motionNodes.nodes.size(); ++i) index[motionNodes.nodes[i]] = i;
  const double perTick = secondsPerTick(anim);
  std::vector<NodeTrack> tracks;
  std::unordered_set<const aiNode*> driven;
  for (unsigned c = 0; c < anim.mNumChannels; ++c) {
    const aiNodeAnim* channel = anim.mChannels[c];
    if (channel == nullptr) continue;
    const std::string where = fmt::format("animation '{}' channel '{}'", animName, channel->mNodeName.C_Str());
    const aiNode* node = scene.mRootNode->FindNode(channel->mNodeName);
    if (node == nullptr) r.fail(fmt::format("{}: names no node of the scene", where));
    if (!driven.insert(node).second) r.fail(fmt::format("{}: a second channel drives the same node", where));
    const auto at = index.find(node);
    if (at == index.end()) continue;  // a node that places no joint
    NodeTrack t;
    t.node = at->second;
    t.positionTimes = keyTimes(channel->mPositionKeys, channel->mNumPositionKeys, perTick, where, r);
    t.rotationTimes = keyTimes(channel->mRotationKeys, channel->mNumRotationKeys, perTick, where, r);
    t.scaleTimes = keyTimes(channel->mScalingKeys, channel->mNumScalingKeys, perTick, where, r);
    for (unsigned k = 0; k < channel->mNumPositionKeys; ++k) {
      const aiVector3D& v = channel->mPositionKeys[k].mValue;
      t.positions.emplace_back(v.x, v.y, v.z);
    }
    for (unsigned k = 0; k < channel->mNumScalingKeys; ++k) {
      const aiVector3D& v = channel->mScalingKeys[k].mValue;
      t.scales.emplace_back(v.x, v.y, v.z);
    }
    for (unsigned k = 0; k < channel->mNumRotationKeys; ++k) {
      const aiQuaternion& q = channel->mRotationKeys[k].mValue;
      const Quat rotation(q.w, q.x, q.y, q.z);
      if (!rotation.coeffs().allFinite() || rotation.norm() < 1e-6)
        r.fail(fmt::format("{}: rotation key {} is not a rotation", where, k));
      t.rotations.push_back(rotation.normalized());
    }
    for (const Vec3& v : t.positions)
      if (!v.allFinite()) r.fail(fmt::format("{}: a translation key is not finite", where));
    for (const Vec3& v : t.scales)
      if (!v.allFinite()) r.fail(fmt::format("{}: a scale key is not finite", where));
    if (!t.positions.empty() || !t.rotations.empty() || !t.scales.empty()) tracks.push_back(std::move(t));
  }
  return tracks;
}

// What every animation of a file is sampled against: the skin's joints and rest pose as the
// avatar reader finds them (in the scene read without animations, pivots collapsed), and
// the same joints, found by name, in the scene read with its animations.
struct MotionRig {
  SceneReader skin;
  const aiScene& animated;
  Eigen::Matrix4d toMetres;
  std::vector<std::string> joints;
  std::vector<int> parents;
  std::vector<Vec3> restCenters;
  std::vector<Eigen::Matrix4d> restInverse;
  double floor_m = 0.0;
  MotionNodes nodes;

  static std::vector<const aiNode*> skeletonOf(const SceneReader& r) {
    std::vector<std::pair<const aiMesh*, const aiNode*>> meshes;
    return skinSkeleton(r, meshes);
  }
  static std::vector<const aiNode*> findJoints(const aiScene& animated, const std::vector<const aiNode*>& skeleton,
                                               const SceneReader& r) {
    std::vector<const aiNode*> found;
    for (const aiNode* j : skeleton) {
      const aiNode* node = animated.mRootNode == nullptr ? nullptr : animated.mRootNode->FindNode(j->mName);
      if (node == nullptr) r.fail(fmt::format("joint '{}' is missing from the scene read with its animations", j->mName.C_Str()));
      found.push_back(node);
    }
    return found;
  }

  MotionRig(const aiScene& skinScene, const aiScene& animatedScene, Format format, const std::string& name)
      : skin(readerFor(skinScene, format, name)),
        animated(animatedScene),
        toMetres(format == Format::Fbx ? fbxToMetresYUp(animatedScene, name) : Eigen::Matrix4d::Identity()),
        floor_m(detail::lowestOf(extract(skinScene, format, name, {}).positions, {})) {
    const std::vector<const aiNode*> skeleton = skeletonOf(skin);
    nodes = MotionNodes(animatedScene, findJoints(animatedScene, skeleton, skin));
    for (std::size_t k = 0; k < skeleton.size(); ++k) {
      joints.push_back(jointName(*skeleton[k], k));
      const auto parent = std::find(skeleton.begin(), skeleton.begin() + static_cast<std::ptrdiff_t>(k), skeleton[k]->mParent);
      parents.push_back(k == 0 ? -1 : static_cast<int>(parent - skeleton.begin()));
      const Eigen::Matrix4d& w = skin.world.at(skeleton[k]);
      restCenters.push_back(w.block<3, 1>(0, 3));
      restInverse.push_back(w.inverse());
      if (!restInverse.back().allFinite()) skin.fail(fmt::format("joint '{}' has a singular rest transform", joints.back()));
    }
  }

  [[nodiscard]] SkinnedJointMotion sample(std::size_t index, double rate) const {
    const std::string& name = skin.name;
    SkinnedJointMotion out;
    out.animationNames = animationNames(animated);
    out.animation = out.animationNames[index];
    out.rate = rate;
    const aiAnimation* anim = animated.mAnimations[index];
    if (anim == nullptr) skin.fail(fmt::format("animation '{}' is missing", out.animation));
    const std::vector<NodeTrack> tracks = readTracks(animated, *anim, out.animation, nodes, skin);
    if (tracks.empty()) skin.fail(fmt::format("animation '{}' moves no joint of the skin", out.animation));
    out.start_s = std::numeric_limits<double>::infinity();
    out.end_s = -std::numeric_limits<double>::infinity();
    for (const NodeTrack& t : tracks)
      for (const std::vector<double>* times : {&t.positionTimes, &t.rotationTimes, &t.scaleTimes})
        if (!times->empty()) {
          out.start_s = std::min(out.start_s, times->front());
          out.end_s = std::max(out.end_s, times->back());
        }
    const std::size_t jn = joints.size();
    const std::size_t frameCount = detail::motionFrameCount(out.start_s, out.end_s, rate, jn, out.animation, name);
    out.joints = joints;
    out.parents = parents;
    out.floor_m = floor_m;
    out.restCenters = restCenters;
    const std::size_t nn = nodes.nodes.size();
    std::vector<Eigen::Matrix4d> own(nn), local(nn), world(nn);
    for (std::size_t i = 0; i < nn; ++i) own[i] = toEigen(nodes.nodes[i]->mTransformation);
    out.frames.reserve(frameCount * jn);
    for (std::size_t f = 0; f < frameCount; ++f) {
      const double t = out.start_s + static_cast<double>(f) / rate;
      local = own;
      for (const NodeTrack& track : tracks) local[track.node] = track.local(t, own[track.node]);
      for (std::size_t i = 0; i < nn; ++i) {
        const int p = nodes.parent[i];
        world[i] = (p < 0 ? toMetres : world[static_cast<std::size_t>(p)]) * local[i];
      }
      for (std::size_t k = 0; k < jn; ++k) {
        const RigidTransform joint = detail::jointMotionOf(world[nodes.joint[k]], restInverse[k]);
        if (!joint.translation.allFinite() || !joint.rotation.coeffs().allFinite())
          skin.fail(fmt::format("joint '{}' is not finite at {:g} s of animation '{}'", joints[k], t, out.animation));
        out.frames.push_back(joint);
      }
    }
    return out;
  }
};

// ---- writing ----------------------------------------------------------------------------

void checkWritable(const SkinnedModel& model, const std::string& path) {
  const std::size_t n = model.positions.size();
  if (model.joints.empty()) throw Error(fmt::format("{}: an avatar without joints cannot be written as a skinned model", path));
  if (model.joints.size() > kMaxAvatarJoints) throw Error(fmt::format("{}: more than {} joints", path, kMaxAvatarJoints));
  if (model.vertexJoints.size() != n || model.vertexWeights.size() != n)
    throw Error(fmt::format("{}: the skin has weights for {} of {} vertices", path, model.vertexWeights.size(), n));
  for (std::size_t j = 0; j < model.joints.size(); ++j)
    if (model.joints[j].parent >= static_cast<int>(j)) throw Error(fmt::format("{}: joint '{}' comes before its parent", path, model.joints[j].name));
  for (const mesh::Triangle& t : model.triangles)
    for (std::uint32_t i : t)
      if (i >= n) throw Error(fmt::format("{}: a triangle names vertex {} of {}", path, i, n));
  for (const auto& joints : model.vertexJoints)
    for (std::uint16_t j : joints)
      if (j >= model.joints.size()) throw Error(fmt::format("{}: a vertex names joint {} of {}", path, j, model.joints.size()));
}

aiMesh* buildMesh(const SkinnedModel& model, const std::vector<Eigen::Matrix4d>& jointWorld, double unitsPerMetre) {
  auto mesh = std::make_unique<aiMesh>();
  mesh->mName = aiString(model.source.empty() ? std::string("skin") : std::filesystem::path(model.source).stem().string());
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mMaterialIndex = 0;
  mesh->mNumVertices = static_cast<unsigned>(model.positions.size());
  mesh->mVertices = new aiVector3D[mesh->mNumVertices];
  for (std::size_t v = 0; v < model.positions.size(); ++v) {
    const Vec3 p = model.positions[v] * unitsPerMetre;
    mesh->mVertices[v] = aiVector3D(static_cast<ai_real>(p.x()), static_cast<ai_real>(p.y()), static_cast<ai_real>(p.z()));
  }
  mesh->mNumFaces = static_cast<unsigned>(model.triangles.size());
  mesh->mFaces = new aiFace[mesh->mNumFaces];
  for (std::size_t t = 0; t < model.triangles.size(); ++t) {
    aiFace& face = mesh->mFaces[t];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3]{model.triangles[t][0], model.triangles[t][1], model.triangles[t][2]};
  }
  std::vector<std::vector<aiVertexWeight>> weightsOf(model.joints.size());
  for (std::size_t v = 0; v < model.positions.size(); ++v)
    for (std::size_t k = 0; k < 4; ++k)
      if (model.vertexWeights[v][k] > 0.0f)
        weightsOf[model.vertexJoints[v][k]].emplace_back(static_cast<unsigned>(v), model.vertexWeights[v][k]);
  std::vector<aiBone*> bones;
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    if (weightsOf[j].empty()) continue;  // exporters write a bone per influence, not per joint
    auto* bone = new aiBone();
    bone->mName = aiString(model.joints[j].name);
    bone->mOffsetMatrix = toAssimp(jointWorld[j].inverse());  // the mesh node is the identity
    bone->mNumWeights = static_cast<unsigned>(weightsOf[j].size());
    bone->mWeights = new aiVertexWeight[bone->mNumWeights];
    std::copy(weightsOf[j].begin(), weightsOf[j].end(), bone->mWeights);
    bones.push_back(bone);
  }
  mesh->mNumBones = static_cast<unsigned>(bones.size());
  mesh->mBones = new aiBone*[bones.size()];
  std::copy(bones.begin(), bones.end(), mesh->mBones);
  return mesh.release();
}

void addChildren(aiNode* parent, const std::vector<aiNode*>& children) {
  if (children.empty()) return;
  parent->mNumChildren = static_cast<unsigned>(children.size());
  parent->mChildren = new aiNode*[children.size()];
  for (std::size_t i = 0; i < children.size(); ++i) {
    parent->mChildren[i] = children[i];
    children[i]->mParent = parent;
  }
}

// The skeleton as nodes with local transforms, plus one node carrying the skinned mesh.
aiNode* buildNodes(const SkinnedModel& model, const std::vector<Eigen::Matrix4d>& jointWorld, const std::string& meshName) {
  auto* root = new aiNode("drape_avatar");
  std::vector<aiNode*> nodes;
  std::vector<std::vector<aiNode*>> children(model.joints.size());
  std::vector<aiNode*> top;
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    auto* node = new aiNode(model.joints[j].name);
    const int p = model.joints[j].parent;
    const Eigen::Matrix4d local = p < 0 ? jointWorld[j] : Eigen::Matrix4d(jointWorld[static_cast<std::size_t>(p)].inverse() * jointWorld[j]);
    node->mTransformation = toAssimp(local);
    (p < 0 ? top : children[static_cast<std::size_t>(p)]).push_back(node);
    nodes.push_back(node);
  }
  for (std::size_t j = 0; j < nodes.size(); ++j) addChildren(nodes[j], children[j]);
  auto* meshNode = new aiNode(meshName);
  meshNode->mNumMeshes = 1;
  meshNode->mMeshes = new unsigned[1]{0};
  top.push_back(meshNode);
  addChildren(root, top);
  return root;
}

// The skinned joints' frames of one animation as keys of their nodes' local transforms.
// Assimp 5.2's Collada and FBX exporters write a key's mTime as seconds whatever
// mTicksPerSecond says, so the animation runs at one tick per second.
aiAnimation* buildAnimation(const SkinnedModel& model, const std::vector<Eigen::Matrix4d>& jointWorld,
                            const SkinnedJointMotion& motion, double unitsPerMetre, const std::string& path) {
  const std::size_t jn = model.joints.size(), frames = motion.frameCount();
  if (frames == 0) throw Error(fmt::format("{}: animation '{}' has no frames", path, motion.animation));
  std::vector<std::size_t> source(jn);
  for (std::size_t j = 0; j < jn; ++j) {
    const auto it = std::find(motion.joints.begin(), motion.joints.end(), model.joints[j].name);
    if (it == motion.joints.end())
      throw Error(fmt::format("{}: animation '{}' does not move joint '{}' of the avatar", path, motion.animation,
                              model.joints[j].name));
    source[j] = static_cast<std::size_t>(it - motion.joints.begin());
  }
  auto anim = std::make_unique<aiAnimation>();
  anim->mName = aiString(motion.animation);
  anim->mTicksPerSecond = 1.0;
  // Assimp's FBX writer stores the stack's stop time in whole ticks, rounded down, and its
  // reader drops the keys after it: rounded up, the last key stays in.
  anim->mDuration = std::ceil(motion.start_s + static_cast<double>(frames - 1) / motion.rate);
  anim->mNumChannels = static_cast<unsigned>(jn);
  anim->mChannels = new aiNodeAnim*[jn]();
  for (std::size_t j = 0; j < jn; ++j) {
    auto* channel = new aiNodeAnim();
    anim->mChannels[j] = channel;
    channel->mNodeName = aiString(model.joints[j].name);
    channel->mNumPositionKeys = channel->mNumRotationKeys = channel->mNumScalingKeys = static_cast<unsigned>(frames);
    channel->mPositionKeys = new aiVectorKey[frames];
    channel->mRotationKeys = new aiQuatKey[frames];
    channel->mScalingKeys = new aiVectorKey[frames];
  }
  std::vector<Eigen::Matrix4d> world(jn);
  for (std::size_t f = 0; f < frames; ++f) {
    const double t = motion.start_s + static_cast<double>(f) / motion.rate;
    const RigidTransform* frame = motion.frames.data() + f * motion.joints.size();
    for (std::size_t j = 0; j < jn; ++j) {
      const RigidTransform& m = frame[source[j]];
      world[j].setIdentity();
      world[j].topLeftCorner<3, 3>() = m.rotation.toRotationMatrix() * jointWorld[j].topLeftCorner<3, 3>();
      world[j].block<3, 1>(0, 3) = unitsPerMetre * m.translation;
      const int p = model.joints[j].parent;
      const Eigen::Matrix4d local = p < 0 ? world[j] : Eigen::Matrix4d(world[static_cast<std::size_t>(p)].inverse() * world[j]);
      Eigen::Matrix3d linear = local.topLeftCorner<3, 3>();
      const Vec3 scale(linear.col(0).norm(), linear.col(1).norm(), linear.col(2).norm());
      for (int c = 0; c < 3; ++c) linear.col(c) /= scale[c];
      const Quat q = Quat(linear).normalized();
      const Vec3 position = local.block<3, 1>(0, 3);
      aiNodeAnim& channel = *anim->mChannels[j];
      channel.mPositionKeys[f] = aiVectorKey(t, aiVector3D(static_cast<ai_real>(position.x()), static_cast<ai_real>(position.y()),
                                                           static_cast<ai_real>(position.z())));
      channel.mRotationKeys[f] = aiQuatKey(t, aiQuaternion(static_cast<ai_real>(q.w()), static_cast<ai_real>(q.x()),
                                                           static_cast<ai_real>(q.y()), static_cast<ai_real>(q.z())));
      channel.mScalingKeys[f] = aiVectorKey(t, aiVector3D(static_cast<ai_real>(scale.x()), static_cast<ai_real>(scale.y()),
                                                          static_cast<ai_real>(scale.z())));
    }
  }
  return anim.release();
}

std::unique_ptr<aiScene> buildScene(const SkinnedModel& model, bool fbx,
                                    const std::vector<SkinnedJointMotion>& animations, const std::string& path) {
  // FBX is written in centimetres: Assimp's FBX exporter declares UnitScaleFactor 1.
  const double unitsPerMetre = fbx ? 100.0 : 1.0;
  // Joint frames in the written units: the same rotation, translations scaled.
  Eigen::Matrix4d scale = Eigen::Matrix4d::Identity();
  scale.topLeftCorner<3, 3>() *= unitsPerMetre;
  std::vector<Eigen::Matrix4d> jointWorld;
  for (const SkinnedJoint& j : model.joints) jointWorld.push_back(scale * j.restWorld * scale.inverse());

  auto scene = std::make_unique<aiScene>();
  scene->mNumMaterials = 1;
  scene->mMaterials = new aiMaterial*[1];
  scene->mMaterials[0] = new aiMaterial();
  const aiString materialName("skin");
  scene->mMaterials[0]->AddProperty(&materialName, AI_MATKEY_NAME);
  scene->mNumMeshes = 1;
  scene->mMeshes = new aiMesh*[1];
  scene->mMeshes[0] = buildMesh(model, jointWorld, unitsPerMetre);
  scene->mRootNode = buildNodes(model, jointWorld, std::string(scene->mMeshes[0]->mName.C_Str()) + "_mesh");
  if (!animations.empty()) {
    scene->mNumAnimations = static_cast<unsigned>(animations.size());
    scene->mAnimations = new aiAnimation*[animations.size()]();
    for (std::size_t a = 0; a < animations.size(); ++a)
      scene->mAnimations[a] = buildAnimation(model, jointWorld, animations[a], unitsPerMetre, path);
  }
  return scene;
}

}  // namespace

bool isAssimpAvatarPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".dae" || ext == ".fbx";
}

namespace {

// Imports Collada or FBX bytes (with their animations or without) under the safety rules of
// the header; the scene lives as long as `importer`.
const aiScene& importScene(Assimp::Importer& importer, std::string_view bytes, const std::string& name, bool animations) {
  const Format format = formatOf(name);
  checkSignature(bytes, format, name);
  if (format == Format::Collada) checkColladaArrays(bytes, name);
  keepOnlyImporterFor(importer, extensionOf(format));
  configure(importer, animations);
  const std::string internalName = std::string("avatar") + extensionOf(format);
  auto* io = new OwnBytesOnly(bytes, internalName);
  importer.SetIOHandler(io);  // the importer owns and deletes it
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(internalName, kPostProcess);
  } catch (const std::exception& e) {
    throw Error(fmt::format("{}: Assimp's {} importer failed: {}{}", name, formatName(format), e.what(), refusalNote(*io)));
  }
  if (scene == nullptr)
    throw Error(fmt::format("{}: Assimp's {} importer failed: {}{}", name, formatName(format), importer.GetErrorString(), refusalNote(*io)));
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0)
    throw Error(fmt::format("{}: has no mesh (Assimp reports the {} scene as incomplete)", name, formatName(format)));
  return *scene;
}

// ---- static meshes (a garment, a mask) -------------------------------------------------

// A mesh's positions at rest: placed by its node, or where it has bones skinned with the
// rest-pose nodes (every influence, normalised; a vertex no bone weighs stays where its
// node puts it).
std::vector<Vec3> restPositions(const SceneReader& r, const aiMesh& mesh, const aiNode& node) {
  const std::size_t count = mesh.mNumVertices;
  const Eigen::Matrix4d nodeWorld = r.world.at(&node);
  std::vector<Eigen::Matrix4d> sum(mesh.HasBones() ? count : 0, Eigen::Matrix4d::Zero());
  std::vector<double> total(sum.size(), 0.0);
  for (unsigned b = 0; b < mesh.mNumBones; ++b) {
    const aiBone& bone = *mesh.mBones[b];
    const Eigen::Matrix4d skin = r.world.at(r.boneNode(bone)) * toEigen(bone.mOffsetMatrix);
    for (unsigned k = 0; k < bone.mNumWeights; ++k) {
      const aiVertexWeight& w = bone.mWeights[k];
      if (w.mVertexId >= count) r.fail(fmt::format("bone '{}' weighs vertex {}, but the mesh has {}", bone.mName.C_Str(), w.mVertexId, count));
      if (!std::isfinite(w.mWeight) || w.mWeight < 0.0f) r.fail(fmt::format("bone '{}' has a bad weight {}", bone.mName.C_Str(), w.mWeight));
      sum[w.mVertexId] += w.mWeight * skin;
      total[w.mVertexId] += w.mWeight;
    }
  }
  std::vector<Vec3> out;
  out.reserve(count);
  for (std::size_t v = 0; v < count; ++v) {
    const Eigen::Matrix4d m = !sum.empty() && total[v] > 1e-9 ? Eigen::Matrix4d(sum[v] / total[v]) : nodeWorld;
    const aiVector3D& p = mesh.mVertices[v];
    const Eigen::Vector4d h = m * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
    if (!h.allFinite()) r.fail(fmt::format("vertex {} of mesh '{}' is not finite at rest", v, mesh.mName.C_Str()));
    out.emplace_back(h.x(), h.y(), h.z());
  }
  return out;
}

MeshParts extractMesh(const aiScene& scene, Format format, const std::string& name, const std::vector<std::string>& parts,
                      bool loose) {
  const SceneReader r = readerFor(scene, format, name);
  MeshParts out;
  out.mesh.name = name;
  std::vector<bool> matched(parts.size(), false);
  std::vector<const aiNode*> stack{scene.mRootNode};
  while (!stack.empty()) {
    const aiNode* node = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const unsigned m = node->mMeshes[i];
      if (m >= scene.mNumMeshes || scene.mMeshes[m] == nullptr) r.fail(fmt::format("node '{}' names mesh {}, which does not exist", node->mName.C_Str(), m));
      const aiMesh& mesh = *scene.mMeshes[m];
      const std::string meshName = mesh.mName.C_Str();
      const std::string part = partName(*node, mesh, m);
      if (std::find(out.all.begin(), out.all.end(), part) == out.all.end()) out.all.push_back(part);
      const bool keep = partWanted(parts, matched, part, meshName);
      // A mesh of points or lines only: loose vertices, which only a mask keeps.
      if (!keep || ((mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0 && !loose)) continue;
      const std::vector<Vec3> positions = restPositions(r, mesh, *node);
      if (out.mesh.positions.size() + positions.size() > kMaxVertices) r.fail(fmt::format("it has more than {} vertices", kMaxVertices));
      const auto base = static_cast<std::uint32_t>(out.mesh.positions.size());
      out.mesh.positions.insert(out.mesh.positions.end(), positions.begin(), positions.end());
      const std::size_t before = out.mesh.triangles.size();
      for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
        const aiFace& face = mesh.mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines left by triangulation
        mesh::Triangle tri;
        for (unsigned c = 0; c < 3; ++c) {
          if (face.mIndices[c] >= positions.size()) r.fail(fmt::format("face {} names vertex {}, but the mesh has {}", f, face.mIndices[c], positions.size()));
          tri[c] = base + face.mIndices[c];
        }
        if (tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2]) out.mesh.triangles.push_back(tri);
      }
      if ((out.mesh.triangles.size() > before || (loose && !positions.empty())) &&
          std::find(out.read.begin(), out.read.end(), part) == out.read.end())
        out.read.push_back(part);
    }
    for (unsigned i = node->mNumChildren; i-- > 0;) stack.push_back(node->mChildren[i]);
  }
  checkMeshParts(out, parts, matched, loose, name);
  return out;
}

}  // namespace

SkinnedModel parseAssimpSkinnedModel(std::string_view bytes, const std::string& name, const std::vector<std::string>& parts) {
  Assimp::Importer importer;
  return extract(importScene(importer, bytes, name, false), formatOf(name), name, parts);
}

SkinnedJointMotion parseAssimpJointMotion(std::string_view bytes, const std::string& name, double rate,
                                          const std::string& animation) {
  Assimp::Importer skinImporter, animatedImporter;
  const aiScene& animated = importScene(animatedImporter, bytes, name, true);
  const std::size_t index = detail::chooseAnimation(animationNames(animated), animation, name);
  const MotionRig rig(importScene(skinImporter, bytes, name, false), animated, formatOf(name), name);
  return rig.sample(index, rate);
}

std::vector<SkinnedJointMotion> parseAssimpJointMotions(std::string_view bytes, const std::string& name, double rate) {
  Assimp::Importer skinImporter, animatedImporter;
  const aiScene& animated = importScene(animatedImporter, bytes, name, true);
  std::vector<SkinnedJointMotion> motions;
  if (animated.mNumAnimations == 0) return motions;
  const MotionRig rig(importScene(skinImporter, bytes, name, false), animated, formatOf(name), name);
  for (std::size_t a = 0; a < animated.mNumAnimations; ++a) detail::appendWithinCap(motions, rig.sample(a, rate), name);
  return motions;
}

SkinnedJointMotion readAssimpJointMotion(const std::string& path, double rate, const std::string& animation,
                                         const IsolationLimits& limits) {
  const std::string bytes = detail::readWholeFile(path, kMaxFileBytes);
  const std::string reader = fmt::format("{} reader (Assimp)", formatName(formatOf(path)));
  const std::string result =
      runIsolated(path, reader, [&] { return serialise(parseAssimpJointMotion(bytes, path, rate, animation)); }, limits);
  return deserialiseJointMotion(result, path);
}

std::vector<SkinnedJointMotion> readAssimpJointMotions(const std::string& path, double rate, const IsolationLimits& limits) {
  const std::string bytes = detail::readWholeFile(path, kMaxFileBytes);
  const std::string reader = fmt::format("{} reader (Assimp)", formatName(formatOf(path)));
  const std::string result = runIsolated(path, reader, [&] { return serialise(parseAssimpJointMotions(bytes, path, rate)); }, limits);
  return deserialiseJointMotions(result, path);
}

MeshParts parseAssimpMesh(std::string_view bytes, const std::string& name, const std::vector<std::string>& parts,
                          bool loose) {
  Assimp::Importer importer;
  return extractMesh(importScene(importer, bytes, name, false), formatOf(name), name, parts, loose);
}

SkinnedModel readAssimpSkinnedModel(const std::string& path, const std::vector<std::string>& parts, const IsolationLimits& limits) {
  const Format format = formatOf(path);
  const std::string bytes = detail::readWholeFile(path, kMaxFileBytes);
  const std::string reader = fmt::format("{} reader (Assimp)", formatName(format));
  const std::string result =
      runIsolated(path, reader, [&] { return serialise(parseAssimpSkinnedModel(bytes, path, parts)); }, limits);
  return deserialiseSkinnedModel(result, path);
}

void writeAssimpSkinnedModel(const std::string& path, const SkinnedModel& model,
                             const std::vector<SkinnedJointMotion>& animations) {
  const std::string ext = lowerExtension(path);
  if (ext != ".dae" && ext != ".fbx")
    throw Error(fmt::format("{}: drape writes skinned avatars as Collada (.dae) or FBX (.fbx), not '{}'", path, ext));
  checkWritable(model, path);
  const bool fbx = ext == ".fbx";
  const std::unique_ptr<aiScene> scene = buildScene(model, fbx, animations, path);
  const char* formatId = fbx ? "fbxa" : "collada";
  // In the limited child too: the exporter is Assimp code, and a crash there must not end drape.
  (void)runIsolated(path, fmt::format("{} writer (Assimp)", fbx ? "FBX" : "Collada"), [&] {
    Assimp::Exporter exporter;
    if (exporter.Export(scene.get(), formatId, path) != AI_SUCCESS)
      throw Error(fmt::format("{}: Assimp's {} exporter failed: {}", path, fbx ? "FBX" : "Collada", exporter.GetErrorString()));
    return std::string();
  });
}

}  // namespace drape::formats
