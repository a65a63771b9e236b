#pragma once
// drape's own form of a VRML97 scene graph, as the VRML97 reader hands it over: plain
// nodes with their fields, shared nodes (DEF/USE) stored once and referred to by index,
// PROTO instances with their type name and fields, Inline files read in, ROUTEs as field
// sources, and geometry already turned into triangles. No Coin3D type appears here: the
// reader runs Coin in a child process and sends this tree back serialised.

#include <cstdint>
#include <string>
#include <vector>

#include "drape/core/math.hpp"
#include "drape/mesh/trimesh.hpp"

namespace drape::formats::vrml {

enum class FieldKind : std::uint8_t {
  Bool,      ///< numbers: 0 or 1
  Int,       ///< numbers
  Float,     ///< numbers (SFTime too)
  Vec2,      ///< numbers, 2 per value
  Vec3,      ///< numbers, 3 per value (SFVec3f, SFColor)
  Rotation,  ///< numbers, 4 per value: axis x y z, angle in radians
  String,    ///< strings
  Node,      ///< nodes (indices into Document::nodes, -1 for NULL)
  Other,     ///< strings: the value as VRML text (SFImage and the like)
};

struct Field {
  std::string name;
  FieldKind kind = FieldKind::Other;
  bool multiple = false;  ///< an MF field
  std::vector<double> numbers;
  std::vector<std::string> strings;
  std::vector<std::int32_t> nodes;
  bool isDefault = true;            ///< not written in the file (the PROTO's or VRML97's default)
  int line = 0;                     ///< line it was written on, when known (drape's nodes)
  std::int32_t routeFromNode = -1;  ///< a ROUTE feeds this field from that node's ...
  std::string routeFromField;       ///< ... eventOut
};

struct Node {
  std::string type;    ///< VRML97 type ("Transform", "IndexedFaceSet") or PROTO name ("ClothSet")
  std::string def;     ///< DEF name, or ""
  bool proto = false;  ///< an instance of a PROTO or EXTERNPROTO
  std::string file;    ///< the file it was read from (differs from the document's inside Inlines)
  int line = 0;        ///< where it was written, when known (drape's nodes); 0 otherwise
  std::vector<Field> fields;
  /// A PROTO instance's body (its first node, a standard node with the instance's fields
  /// wired in): what a browser draws. -1 for standard nodes.
  std::int32_t body = -1;
  /// Inline: the root of the inlined file's nodes (a Group), or -1 when not loaded.
  std::int32_t inlined = -1;
  /// Geometry (IndexedFaceSet, Box, Sphere, Cylinder, Cone, Extrusion, ElevationGrid):
  /// triangles in the node's own coordinates, counter-clockwise seen from outside. An
  /// IndexedFaceSet keeps its coordinates and their order (vertex i is coord point i);
  /// polygons become fans. Primitives are Coin's tessellation with shared corners welded.
  bool hasMesh = false;
  std::vector<Vec3> positions;
  std::vector<mesh::Triangle> triangles;

  [[nodiscard]] const Field* field(const std::string& name) const {
    for (const Field& f : fields)
      if (f.name == name) return &f;
    return nullptr;
  }
  /// What drape calls the node (an H-Anim Joint, a ClothSet, ...): its `name` field, else its
  /// DEF name; "" when it has neither.
  [[nodiscard]] std::string nameOrDef() const {
    const Field* f = field("name");
    return f != nullptr && !f->strings.empty() && !f->strings[0].empty() ? f->strings[0] : def;
  }
};

struct Document {
  std::string file;
  std::vector<Node> nodes;
  std::vector<std::int32_t> roots;    ///< top-level nodes, in file order
  std::vector<std::string> warnings;  ///< "file:line: what", e.g. a missing texture image
};

}  // namespace drape::formats::vrml
