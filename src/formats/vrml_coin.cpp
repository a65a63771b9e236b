// The Coin3D side of the VRML97 reader: the only file in drape that includes Coin. It runs
// in the reader's child process (vrml_read.cpp), on text the pre-scan has already checked,
// and turns Coin's scene graph into drape's vrml::Document.

#include <Inventor/SoDB.h>
#include <Inventor/SoInput.h>
#include <Inventor/SoPrimitiveVertex.h>
#include <Inventor/VRMLnodes/SoVRMLBox.h>
#include <Inventor/VRMLnodes/SoVRMLCone.h>
#include <Inventor/VRMLnodes/SoVRMLCoordinate.h>
#include <Inventor/VRMLnodes/SoVRMLCylinder.h>
#include <Inventor/VRMLnodes/SoVRMLElevationGrid.h>
#include <Inventor/VRMLnodes/SoVRMLExtrusion.h>
#include <Inventor/VRMLnodes/SoVRMLGroup.h>
#include <Inventor/VRMLnodes/SoVRMLIndexedFaceSet.h>
#include <Inventor/VRMLnodes/SoVRMLInline.h>
#include <Inventor/VRMLnodes/SoVRMLSphere.h>
#include <Inventor/actions/SoCallbackAction.h>
#include <Inventor/engines/SoEngineOutput.h>
#include <Inventor/engines/SoNodeEngine.h>
#include <Inventor/errors/SoDebugError.h>
#include <Inventor/errors/SoMemoryError.h>
#include <Inventor/errors/SoReadError.h>
#include <Inventor/fields/SoMFBool.h>
#include <Inventor/fields/SoMFColor.h>
#include <Inventor/fields/SoMFFloat.h>
#include <Inventor/fields/SoMFInt32.h>
#include <Inventor/fields/SoMFNode.h>
#include <Inventor/fields/SoMFRotation.h>
#include <Inventor/fields/SoMFString.h>
#include <Inventor/fields/SoMFTime.h>
#include <Inventor/fields/SoMFVec2f.h>
#include <Inventor/fields/SoMFVec3f.h>
#include <Inventor/fields/SoSFBool.h>
#include <Inventor/fields/SoSFColor.h>
#include <Inventor/fields/SoSFFloat.h>
#include <Inventor/fields/SoSFInt32.h>
#include <Inventor/fields/SoSFNode.h>
#include <Inventor/fields/SoSFRotation.h>
#include <Inventor/fields/SoSFString.h>
#include <Inventor/fields/SoSFTime.h>
#include <Inventor/fields/SoSFVec2f.h>
#include <Inventor/fields/SoSFVec3f.h>
#include <Inventor/lists/SoFieldList.h>
#include <Inventor/misc/SoProto.h>
#include <Inventor/misc/SoProtoInstance.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <unordered_map>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "vrml_internal.hpp"

namespace drape::formats::vrml::detail {

extern const std::string_view kPreludeText;

namespace {

// ---- Coin's messages ---------------------------------------------------------------------
// Coin reports through handlers, never to our stderr: read errors become drape errors with
// the file and line, other messages become warnings.

struct Messages {
  std::vector<std::string> readErrors;  ///< "message (line N)" as Coin worded them
  std::vector<int> readErrorLines;
  std::vector<std::string> other;
};
Messages* gMessages = nullptr;

std::string firstLine(const std::string& s) {
  const std::size_t end = s.find('\n');
  return end == std::string::npos ? s : s.substr(0, end);
}

void onReadError(const SoError* error, void*) {
  if (gMessages == nullptr) return;
  const std::string text = error->getDebugString().getString();
  int line = 0;
  const std::string marker = "Occurred at line";
  if (const std::size_t at = text.find(marker); at != std::string::npos) {
    std::size_t i = at + marker.size();
    while (i < text.size() && text[i] == ' ') ++i;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9' && line < 100'000'000)
      line = line * 10 + (text[i++] - '0');
  }
  std::string what = firstLine(text);
  const std::string prefix = "Coin read error: ";
  if (what.rfind(prefix, 0) == 0) what = what.substr(prefix.size());
  for (std::size_t at = what.find("\"VRML"); at != std::string::npos; at = what.find("\"VRML", at))
    what.erase(at + 1, 4);
  gMessages->readErrors.push_back(what);
  gMessages->readErrorLines.push_back(line);
}

void onOtherError(const SoError* error, void*) {
  if (gMessages != nullptr) gMessages->other.push_back(firstLine(error->getDebugString().getString()));
}

// ---- Reading one file with Coin ----------------------------------------------------------

struct VrmlReader;
VrmlReader* gReader = nullptr;

SoProto* fetchExternProto(SoInput* in, const SbString* urls, int count, void* closure);

/// The state of one readWithCoin call: the files open (for Inline cycles), graphs kept
/// alive, the first problem met inside a Coin callback (reported once Coin returns).
struct VrmlReader {
  std::vector<std::string> fileStack;
  std::vector<std::string> dirStack;  ///< where relative URLs of the file being read point
  std::vector<SoNode*> keepAlive;
  std::string pendingError;
  std::vector<std::string> warnings;

  ~VrmlReader() {
    for (SoNode* n : keepAlive) n->unref();
  }

  SoNode* read(const std::string& text, const std::string& file) {
    Messages messages;
    Messages* saved = gMessages;
    gMessages = &messages;
    SoInput in;
    in.setBuffer(text.data(), text.size());
    SoNode* root = SoDB::readAllVRML(&in);
    gMessages = saved;
    if (!pendingError.empty()) {
      if (root != nullptr) root->ref(), root->unref();
      const std::string e = pendingError;
      pendingError.clear();
      throw Error(e);
    }
    // Coin reports a missing texture image as a read error; drape does not need textures.
    for (std::size_t i = 0; i < messages.readErrors.size();) {
      if (messages.readErrors[i].rfind("Could not read texture file", 0) == 0) {
        warnings.push_back(fmt::format("{}: {} (drawn without it; drape does not need it to simulate)",
                                       SourcePos{file, messages.readErrorLines[i], 0}.str(), messages.readErrors[i]));
        messages.readErrors.erase(messages.readErrors.begin() + static_cast<std::ptrdiff_t>(i));
        messages.readErrorLines.erase(messages.readErrorLines.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        ++i;
      }
    }
    if (root == nullptr || !messages.readErrors.empty()) {
      if (root != nullptr) root->ref(), root->unref();
      if (messages.readErrors.empty()) throw Error(fmt::format("{}: the VRML97 reader could not read the file", file));
      throw Error::at({file, messages.readErrorLines.front(), 0}, messages.readErrors.front());
    }
    root->ref();
    keepAlive.push_back(root);
    return root;
  }
};

std::pair<std::string, std::string> splitFragment(const std::string& url) {
  const std::size_t hash = url.find('#');
  if (hash == std::string::npos) return {url, ""};
  return {url.substr(0, hash), url.substr(hash + 1)};
}

SoProto* fetchExternProto(SoInput*, const SbString* urls, int count, void*) {
  VrmlReader* reader = gReader;
  if (reader == nullptr || reader->fileStack.empty()) return nullptr;
  const std::string& file = reader->fileStack.back();
  const std::string baseDir = reader->dirStack.back();
  std::vector<std::string> tried;
  try {
    for (int i = 0; i < count; ++i) {
      const auto [url, fragment] = splitFragment(urls[i].getString());
      tried.push_back(urls[i].getString());
      std::string path = resolveUrl(url, baseDir);
      std::string text;
      std::string name = path;
      if (!path.empty()) {
        text = readBytes(path);
      } else if (std::filesystem::path(url).filename() == "drape-nodes.wrl") {
        text = std::string(kPreludeText);  // drape's own prelude, built in
        name = "drape-nodes.wrl";
      } else {
        continue;
      }
      const ScanResult scanned = scan(text, name, scanOptions());
      reader->fileStack.push_back(name);
      reader->dirStack.push_back(std::filesystem::path(name).parent_path().string());
      SoNode* root = reader->read(scanned.text, name);
      reader->dirStack.pop_back();
      reader->fileStack.pop_back();
      SoProto* found = nullptr;
      if (root->isOfType(SoProto::getClassTypeId())) found = static_cast<SoProto*>(root);
      if (root->isOfType(SoGroup::getClassTypeId())) {
        auto* group = static_cast<SoGroup*>(root);
        for (int c = 0; c < group->getNumChildren() && found == nullptr; ++c) {
          SoNode* child = group->getChild(c);
          if (!child->isOfType(SoProto::getClassTypeId())) continue;
          auto* proto = static_cast<SoProto*>(child);
          if (fragment.empty() || fragment == proto->getProtoName().getString()) found = proto;
        }
      }
      if (found != nullptr) return found;
      reader->pendingError = fmt::format("{}: EXTERNPROTO URL '{}' has no PROTO {}", file, urls[i].getString(),
                                         fragment.empty() ? std::string("at all") : fragment);
      return nullptr;
    }
  } catch (const Error& e) {
    reader->pendingError = e.what();
    return nullptr;
  }
  reader->pendingError = fmt::format("{}: EXTERNPROTO target not found: {} (looked in {})", file,
                                     fmt::join(tried, ", "), baseDir.empty() ? std::string(".") : baseDir);
  return nullptr;
}

void initCoinOnce() {
  static bool done = false;
  if (done) return;
  done = true;
  SoDB::init();
  SoReadError::setHandlerCallback(onReadError, nullptr);
  SoDebugError::setHandlerCallback(onOtherError, nullptr);
  SoMemoryError::setHandlerCallback(onOtherError, nullptr);
  SoError::setHandlerCallback(onOtherError, nullptr);
  // drape resolves Inline URLs itself, through the same scan as every other file.
  SoVRMLInline::setReadAsSoFile(FALSE);
  SoProto::setFetchExternProtoCallback(fetchExternProto, nullptr);
  VrmlReader prelude;
  gReader = &prelude;
  prelude.fileStack.push_back("drape-nodes.wrl");
  prelude.dirStack.push_back("");
  const std::string text(kPreludeText);
  SoNode* root = prelude.read(text, "drape-nodes.wrl");
  // The prelude's PROTOs stay known to later reads as long as their graph lives.
  root->ref();
  gReader = nullptr;
}

// ---- Coin graph -> Document --------------------------------------------------------------

std::string typeName(const SoNode* node) {
  std::string name = node->getTypeId().getName().getString();
  if (name.rfind("VRML", 0) == 0) name = name.substr(4);
  return name;
}

void triangleCallback(void* data, SoCallbackAction*, const SoPrimitiveVertex* a, const SoPrimitiveVertex* b,
                      const SoPrimitiveVertex* c);

struct Welder {
  std::map<std::array<float, 3>, std::uint32_t> index;
  Node* node = nullptr;
  std::uint32_t add(const SbVec3f& p) {
    const std::array<float, 3> key{p[0], p[1], p[2]};
    const auto [it, inserted] = index.emplace(key, static_cast<std::uint32_t>(node->positions.size()));
    if (inserted) node->positions.emplace_back(p[0], p[1], p[2]);
    return it->second;
  }
};

void triangleCallback(void* data, SoCallbackAction*, const SoPrimitiveVertex* a, const SoPrimitiveVertex* b,
                      const SoPrimitiveVertex* c) {
  auto* w = static_cast<Welder*>(data);
  const mesh::Triangle t{w->add(a->getPoint()), w->add(b->getPoint()), w->add(c->getPoint())};
  if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) w->node->triangles.push_back(t);
}

class Converter {
 public:
  Converter(VrmlReader& reader, Document& doc, const std::vector<NodeSite>& sites) : reader_(reader), doc_(doc) {
    sites_.push_back(&sites);
  }

  std::int32_t convertRoot(SoNode* root, const std::string& file) {
    files_.push_back(file);
    const std::int32_t index = convert(root, true);
    files_.pop_back();
    return index;
  }

 private:
  std::int32_t convert(SoNode* node, bool remap) {
    if (node == nullptr) return -1;
    SoFieldContainer* container = node;
    SoProtoInstance* instance = nullptr;
    if (node->isOfType(SoProtoInstance::getClassTypeId())) {
      instance = static_cast<SoProtoInstance*>(node);
    } else if (remap) {
      instance = SoProtoInstance::findProtoInstance(node);
    }
    if (instance != nullptr) container = instance;
    if (const auto it = index_.find(container); it != index_.end()) return it->second;

    const auto index = static_cast<std::int32_t>(doc_.nodes.size());
    index_[container] = index;
    doc_.nodes.emplace_back();
    Node out;
    out.file = files_.back();
    out.def = container->getName().getString();
    if (instance != nullptr) {
      out.type = instance->getProtoName().getString();
      out.proto = true;
    } else {
      out.type = typeName(node);
    }
    const NodeSite* site = fields(*container, out);
    if (site != nullptr) out.line = site->line;
    if (instance != nullptr) out.body = convert(instance->getRootNode(), false);
    if (instance == nullptr) special(node, out);
    doc_.nodes[static_cast<std::size_t>(index)] = std::move(out);
    return index;
  }

  /// Converts every field; returns the source site when the node is one of drape's.
  const NodeSite* fields(SoFieldContainer& container, Node& out) {
    SoFieldList list;
    container.getFields(list);
    // Coin leaves eventIns out of getFields(); the one drape follows (an interpolator's
    // set_fraction, fed by a TimeSensor) is looked up by name.
    if (SoField* fraction = container.getField("set_fraction"); fraction != nullptr && list.find(fraction) < 0)
      list.append(fraction);
    const NodeSite* site = nullptr;
    for (int i = 0; i < list.getLength(); ++i) {
      SoField* f = list[i];
      SbName name;
      container.getFieldName(f, name);
      if (std::string(name.getString()) == "drapeNodeId") {
        const int id = static_cast<SoSFInt32*>(f)->getValue();
        if (id >= 0 && static_cast<std::size_t>(id) < sites_.back()->size())
          site = &(*sites_.back())[static_cast<std::size_t>(id)];
        continue;
      }
      Field field;
      field.name = name.getString();
      field.isDefault = f->isDefault();
      value(*f, field);
      route(*f, field);
      out.fields.push_back(std::move(field));
    }
    if (site == nullptr) site = matchSite(out);
    if (site != nullptr)
      for (Field& field : out.fields)
        if (const auto it = site->fieldLines.find(field.name); it != site->fieldLines.end()) field.line = it->second;
    return site;
  }

  /// A file that declares drape's PROTOs itself has no drapeNodeId tags: its nodes are
  /// matched to the scan's sites by DEF name, else by order of appearance.
  const NodeSite* matchSite(const Node& out) {
    const auto& sites = *sites_.back();
    for (const NodeSite& s : sites)
      if (!out.def.empty() && s.type == out.type && s.def == out.def) return &s;
    int& next = nextSite_[out.type];
    int seen = 0;
    for (const NodeSite& s : sites) {
      if (s.type != out.type || !s.def.empty()) continue;
      if (seen++ == next) {
        ++next;
        return &s;
      }
    }
    return nullptr;
  }

  template <typename SF, typename MF, typename Put>
  bool numeric(SoField& f, Field& field, FieldKind kind, Put put) {
    if (f.isOfType(SF::getClassTypeId())) {
      field.kind = kind;
      put(static_cast<SF&>(f).getValue(), field.numbers);
      return true;
    }
    if (f.isOfType(MF::getClassTypeId())) {
      field.kind = kind;
      field.multiple = true;
      auto& mf = static_cast<MF&>(f);
      for (int i = 0; i < mf.getNum(); ++i) put(mf[i], field.numbers);
      return true;
    }
    return false;
  }

  void value(SoField& f, Field& field) {
    const auto scalar = [](auto v, std::vector<double>& out) { out.push_back(static_cast<double>(v)); };
    const auto vec2 = [](const SbVec2f& v, std::vector<double>& out) { out.insert(out.end(), {v[0], v[1]}); };
    const auto vec3 = [](const auto& v, std::vector<double>& out) { out.insert(out.end(), {v[0], v[1], v[2]}); };
    // Coin keeps a rotation as a single-precision quaternion; its own axis-angle getter takes
    // acos of w in float, which loses small angles to about 3e-4 rad. The angle from atan2 of
    // the quaternion's parts, in double, keeps them to the float parts' 1e-7.
    const auto rotation = [](const SbRotation& r, std::vector<double>& out) {
      float x = 0, y = 0, z = 0, w = 1;
      r.getValue(x, y, z, w);
      const double s = std::sqrt(double{x} * x + double{y} * y + double{z} * z);
      if (s == 0.0) out.insert(out.end(), {0.0, 0.0, 1.0, 0.0});
      else out.insert(out.end(), {x / s, y / s, z / s, 2.0 * std::atan2(s, double{w})});
    };
    const auto time = [](const SbTime& t, std::vector<double>& out) { out.push_back(t.getValue()); };
    if (numeric<SoSFFloat, SoMFFloat>(f, field, FieldKind::Float, scalar)) return;
    if (numeric<SoSFInt32, SoMFInt32>(f, field, FieldKind::Int, scalar)) return;
    if (numeric<SoSFBool, SoMFBool>(f, field, FieldKind::Bool, scalar)) return;
    if (numeric<SoSFTime, SoMFTime>(f, field, FieldKind::Float, time)) return;
    if (numeric<SoSFVec2f, SoMFVec2f>(f, field, FieldKind::Vec2, vec2)) return;
    if (numeric<SoSFVec3f, SoMFVec3f>(f, field, FieldKind::Vec3, vec3)) return;
    if (numeric<SoSFColor, SoMFColor>(f, field, FieldKind::Vec3, vec3)) return;
    if (numeric<SoSFRotation, SoMFRotation>(f, field, FieldKind::Rotation, rotation)) return;
    if (f.isOfType(SoSFString::getClassTypeId())) {
      field.kind = FieldKind::String;
      field.strings.emplace_back(static_cast<SoSFString&>(f).getValue().getString());
      return;
    }
    if (f.isOfType(SoMFString::getClassTypeId())) {
      field.kind = FieldKind::String;
      field.multiple = true;
      auto& mf = static_cast<SoMFString&>(f);
      for (int i = 0; i < mf.getNum(); ++i) field.strings.emplace_back(mf[i].getString());
      return;
    }
    if (f.isOfType(SoSFNode::getClassTypeId())) {
      field.kind = FieldKind::Node;
      field.nodes.push_back(child(static_cast<SoSFNode&>(f).getValue()));
      return;
    }
    if (f.isOfType(SoMFNode::getClassTypeId())) {
      field.kind = FieldKind::Node;
      field.multiple = true;
      auto& mf = static_cast<SoMFNode&>(f);
      for (int i = 0; i < mf.getNum(); ++i) {
        SoNode* n = mf[i];
        if (n != nullptr && n->isOfType(SoProto::getClassTypeId())) continue;  // a declaration, not a child
        field.nodes.push_back(child(n));
      }
      return;
    }
    field.kind = FieldKind::Other;
    SbString text;
    f.get(text);
    field.strings.emplace_back(text.getString());
  }

  std::int32_t child(SoNode* n) { return n == nullptr ? -1 : convert(n, true); }

  void route(SoField& f, Field& field) {
    if (f.isConnectedFromEngine()) {
      SoEngineOutput* output = nullptr;
      if (f.getConnectedEngine(output) && output != nullptr && output->isNodeEngineOutput()) {
        SoNodeEngine* engine = output->getNodeContainer();
        SbName name;
        if (engine != nullptr && engine->getOutputName(output, name)) {
          field.routeFromNode = convert(engine, true);
          field.routeFromField = name.getString();
        }
      }
    } else if (f.isConnectedFromField()) {
      SoField* master = nullptr;
      if (f.getConnectedField(master) && master != nullptr) {
        SoFieldContainer* owner = master->getContainer();
        SbName name;
        if (owner != nullptr && owner->isOfType(SoNode::getClassTypeId()) && owner->getFieldName(master, name)) {
          field.routeFromNode = convert(static_cast<SoNode*>(owner), true);
          field.routeFromField = name.getString();
        }
      }
    }
  }

  /// Inline contents, geometry triangles, texture checks.
  void special(SoNode* node, Node& out) {
    if (node->isOfType(SoVRMLInline::getClassTypeId())) return inlineFile(static_cast<SoVRMLInline*>(node), out);
    if (node->isOfType(SoVRMLIndexedFaceSet::getClassTypeId()))
      return faceSet(static_cast<SoVRMLIndexedFaceSet*>(node), out);
    if (node->isOfType(SoVRMLBox::getClassTypeId()) || node->isOfType(SoVRMLSphere::getClassTypeId()) ||
        node->isOfType(SoVRMLCylinder::getClassTypeId()) || node->isOfType(SoVRMLCone::getClassTypeId()) ||
        node->isOfType(SoVRMLExtrusion::getClassTypeId()) || node->isOfType(SoVRMLElevationGrid::getClassTypeId()))
      return tessellate(node, out);
  }

  void faceSet(SoVRMLIndexedFaceSet* ifs, Node& out) {
    out.hasMesh = true;
    SoNode* coordNode = ifs->coord.getValue();
    if (coordNode != nullptr && coordNode->isOfType(SoVRMLCoordinate::getClassTypeId())) {
      const SoMFVec3f& points = static_cast<SoVRMLCoordinate*>(coordNode)->point;
      out.positions.reserve(static_cast<std::size_t>(points.getNum()));
      for (int i = 0; i < points.getNum(); ++i) out.positions.emplace_back(points[i][0], points[i][1], points[i][2]);
    }
    const bool ccw = ifs->ccw.getValue();
    const auto count = static_cast<std::int64_t>(out.positions.size());
    std::vector<std::uint32_t> polygon;
    const auto flush = [&] {
      const std::size_t before = out.triangles.size();
      if (polygon.size() >= 3) mesh::triangulatePolygon(polygon, out.triangles);
      if (!ccw)
        for (std::size_t t = before; t < out.triangles.size(); ++t) std::swap(out.triangles[t][1], out.triangles[t][2]);
      polygon.clear();
    };
    const SoMFInt32& index = ifs->coordIndex;
    for (int i = 0; i < index.getNum(); ++i) {
      const std::int32_t v = index[i];
      if (v < 0) {
        flush();
        continue;
      }
      if (v >= count) {
        throw Error(fmt::format("{}: IndexedFaceSet{}: coordIndex {} is out of range ({} coordinates)", files_.back(),
                                out.def.empty() ? "" : " " + out.def, v, count));
      }
      polygon.push_back(static_cast<std::uint32_t>(v));
    }
    flush();
  }

  void tessellate(SoNode* node, Node& out) {
    out.hasMesh = true;
    Welder welder;
    welder.node = &out;
    SoCallbackAction action;
    action.addTriangleCallback(SoNode::getClassTypeId(), triangleCallback, &welder);
    action.apply(node);
  }

  void inlineFile(SoVRMLInline* node, Node& out) {
    const std::string baseDir = reader_.dirStack.back();
    std::vector<std::string> urls;
    for (int i = 0; i < node->url.getNum(); ++i) {
      urls.emplace_back(node->url[i].getString());
      const std::string path = resolveUrl(urls.back(), baseDir);
      if (path.empty()) continue;
      if (std::find(reader_.fileStack.begin(), reader_.fileStack.end(), path) != reader_.fileStack.end())
        throw Error(fmt::format("{}: Inline '{}' includes itself (directly or through other Inlines)", files_.back(),
                                urls.back()));
      if (reader_.fileStack.size() > 16)
        throw Error(fmt::format("{}: Inline files nested deeper than 16", files_.back()));
      const std::string text = readBytes(path);
      const ScanResult scanned = scan(text, path, scanOptions());
      reader_.fileStack.push_back(path);
      reader_.dirStack.push_back(std::filesystem::path(path).parent_path().string());
      SoNode* root = reader_.read(scanned.text, path);
      sites_.push_back(&scanned.sites);
      files_.push_back(path);
      out.inlined = convert(root, true);
      files_.pop_back();
      sites_.pop_back();
      reader_.dirStack.pop_back();
      reader_.fileStack.pop_back();
      return;
    }
    if (urls.empty()) return;
    throw Error(fmt::format("{}: Inline file not found: {} (looked in {})", files_.back(), fmt::join(urls, ", "),
                            baseDir.empty() ? std::string(".") : baseDir));
  }

  VrmlReader& reader_;
  Document& doc_;
  std::vector<const std::vector<NodeSite>*> sites_;
  std::vector<std::string> files_;
  std::unordered_map<const SoFieldContainer*, std::int32_t> index_;
  std::map<std::string, int> nextSite_;
};

}  // namespace

Document readWithCoin(const ScanResult& scanned, const std::string& file, const std::string& baseDir) {
  initCoinOnce();
  VrmlReader reader;
  gReader = &reader;
  struct Reset {
    ~Reset() { gReader = nullptr; }
  } reset;
  reader.fileStack.push_back(file);
  reader.dirStack.push_back(baseDir);
  SoNode* root = reader.read(scanned.text, file);
  Document doc;
  doc.file = file;
  Converter converter(reader, doc, scanned.sites);
  // A file with several top-level nodes comes back as one Group holding them; a file with
  // one comes back as that node.
  if (root->getTypeId() == SoVRMLGroup::getClassTypeId() && root->getName() == SbName::empty() &&
      SoProtoInstance::findProtoInstance(root) == nullptr) {
    auto* group = static_cast<SoVRMLGroup*>(root);
    for (int i = 0; i < group->getNumChildren(); ++i) {
      SoNode* child = group->getChild(i);
      if (child->isOfType(SoProto::getClassTypeId())) continue;
      doc.roots.push_back(converter.convertRoot(child, file));
    }
  } else if (!root->isOfType(SoProto::getClassTypeId())) {
    doc.roots.push_back(converter.convertRoot(root, file));
  }
  doc.warnings.insert(doc.warnings.end(), reader.warnings.begin(), reader.warnings.end());
  return doc;
}

}  // namespace drape::formats::vrml::detail
