// vrml::Document <-> FlatBuffers bytes (vrml_tree.fbs): the hand-over from the VRML97
// reader's child process. The parent verifies the buffer before trusting any offset in it.

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "vrml_internal.hpp"
#include "vrml_tree_generated.h"

namespace drape::formats::vrml::detail {
namespace {

namespace fb = flatbuffers;

fb::Offset<wire::Field> put(fb::FlatBufferBuilder& b, const Field& f) {
  std::vector<fb::Offset<fb::String>> strings;
  strings.reserve(f.strings.size());
  for (const std::string& s : f.strings) strings.push_back(b.CreateString(s));
  return wire::CreateFieldDirect(b, f.name.c_str(), static_cast<std::uint8_t>(f.kind), f.multiple, &f.numbers, &strings,
                                 &f.nodes, f.isDefault, f.line, f.routeFromNode, f.routeFromField.c_str());
}

fb::Offset<wire::Node> put(fb::FlatBufferBuilder& b, const Node& n) {
  std::vector<fb::Offset<wire::Field>> fields;
  fields.reserve(n.fields.size());
  for (const Field& f : n.fields) fields.push_back(put(b, f));
  std::vector<double> positions;
  positions.reserve(n.positions.size() * 3);
  for (const Vec3& p : n.positions) positions.insert(positions.end(), {p.x(), p.y(), p.z()});
  std::vector<std::uint32_t> triangles;
  triangles.reserve(n.triangles.size() * 3);
  for (const mesh::Triangle& t : n.triangles) triangles.insert(triangles.end(), t.begin(), t.end());
  return wire::CreateNodeDirect(b, n.type.c_str(), n.def.c_str(), n.proto, n.file.c_str(), n.line, &fields, n.body,
                                n.inlined, n.hasMesh, &positions, &triangles);
}

std::string str(const fb::String* s) { return s == nullptr ? std::string() : s->str(); }

template <typename T>
std::vector<T> vec(const fb::Vector<T>* v) {
  return v == nullptr ? std::vector<T>() : std::vector<T>(v->begin(), v->end());
}

}  // namespace

std::string toWire(const Document& document) {
  fb::FlatBufferBuilder b(1 << 16);
  std::vector<fb::Offset<wire::Node>> nodes;
  nodes.reserve(document.nodes.size());
  for (const Node& n : document.nodes) nodes.push_back(put(b, n));
  std::vector<fb::Offset<fb::String>> warnings;
  for (const std::string& w : document.warnings) warnings.push_back(b.CreateString(w));
  b.Finish(wire::CreateDocumentDirect(b, document.file.c_str(), &nodes, &document.roots, &warnings));
  return {reinterpret_cast<const char*>(b.GetBufferPointer()), b.GetSize()};
}

Document fromWire(std::string_view bytes, const std::string& what) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  fb::Verifier verifier(data, bytes.size(), 64, 100'000'000);
  if (!wire::VerifyDocumentBuffer(verifier))
    throw Error(fmt::format("{}: the VRML97 reader sent a damaged scene", what), ExitCode::Internal);
  const wire::Document* in = wire::GetDocument(data);
  Document doc;
  doc.file = str(in->file());
  doc.roots = vec(in->roots());
  if (in->warnings() != nullptr)
    for (const fb::String* w : *in->warnings()) doc.warnings.push_back(str(w));
  const auto nodeCount = static_cast<std::int32_t>(in->nodes() == nullptr ? 0 : in->nodes()->size());
  const auto checkIndex = [&](std::int32_t i) {
    if (i < -1 || i >= nodeCount)
      throw Error(fmt::format("{}: the VRML97 reader sent a node index out of range", what), ExitCode::Internal);
  };
  for (std::int32_t r : doc.roots) checkIndex(r);
  if (in->nodes() != nullptr) {
    doc.nodes.reserve(in->nodes()->size());
    for (const wire::Node* n : *in->nodes()) {
      Node out;
      out.type = str(n->type());
      out.def = str(n->def());
      out.proto = n->proto();
      out.file = str(n->file());
      out.line = n->line();
      out.body = n->body();
      out.inlined = n->inlined();
      checkIndex(out.body);
      checkIndex(out.inlined);
      out.hasMesh = n->has_mesh();
      const std::vector<double> p = vec(n->positions());
      out.positions.reserve(p.size() / 3);
      for (std::size_t i = 0; i + 2 < p.size(); i += 3) out.positions.emplace_back(p[i], p[i + 1], p[i + 2]);
      const std::vector<std::uint32_t> t = vec(n->triangles());
      for (std::size_t i = 0; i + 2 < t.size(); i += 3) out.triangles.push_back({t[i], t[i + 1], t[i + 2]});
      if (n->fields() != nullptr) {
        for (const wire::Field* f : *n->fields()) {
          Field field;
          field.name = str(f->name());
          field.kind =
              static_cast<FieldKind>(std::min<std::uint8_t>(f->kind(), static_cast<std::uint8_t>(FieldKind::Other)));
          field.multiple = f->multiple();
          field.numbers = vec(f->numbers());
          if (f->strings() != nullptr)
            for (const fb::String* s : *f->strings()) field.strings.push_back(str(s));
          field.nodes = vec(f->nodes());
          for (std::int32_t i : field.nodes) checkIndex(i);
          field.isDefault = f->is_default();
          field.line = f->line();
          field.routeFromNode = f->route_from_node();
          checkIndex(field.routeFromNode);
          field.routeFromField = str(f->route_from_field());
          out.fields.push_back(std::move(field));
        }
      }
      doc.nodes.push_back(std::move(out));
    }
  }
  return doc;
}

}  // namespace drape::formats::vrml::detail
