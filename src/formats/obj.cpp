#include "drape/formats/obj.hpp"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/formats/part_names.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

std::string firstLine(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line;
}

void requireReadableFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(fmt::format("{}: no such file", path));
  if (std::filesystem::is_directory(path, ec)) throw Error(fmt::format("{}: is a directory, expected an OBJ file", path));
  std::ifstream probe(path);
  if (!probe) throw Error(fmt::format("{}: cannot be read", path));
}

/// Whether group `shapeName` is one of `groups` (names or shell patterns; every group when
/// there are none), marking in `matched` those that answer.
bool wanted(const std::string& shapeName, const std::vector<std::string>& groups, std::vector<bool>& matched) {
  bool keep = groups.empty();
  for (std::size_t k = 0; k < groups.size(); ++k)
    if (nameMatches(groups[k], shapeName)) keep = matched[k] = true;
  return keep;
}

// tinyobjloader reads a coordinate it cannot parse ("nan", "abc") as 0 and one too large
// (1e999) as infinity, and reports neither; drape checks every `v` line's x y z first so
// that such a file is an error naming the line and column. Lines end as tinyobjloader
// ends them: at "\n", "\r\n" or a lone "\r".
void checkVertexLines(std::string_view text, const std::string& name) {
  static constexpr const char* kAxes[3] = {"x", "y", "z"};
  int lineNo = 0;
  for (std::size_t pos = 0; pos < text.size();) {
    const std::size_t end = std::min(text.find_first_of("\r\n", pos), text.size());
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    ++lineNo;
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string_view::npos || line[first] != 'v' || first + 1 >= line.size() ||
        (line[first + 1] != ' ' && line[first + 1] != '\t'))
      continue;
    const std::vector<detail::LineWord> words = detail::lineWords(line.substr(first + 2), 3, '#');
    const int offset = static_cast<int>(first) + 2;
    for (std::size_t k = 0; k < 3; ++k) {
      if (k == words.size()) {
        const int column = words.empty() ? static_cast<int>(first) + 2
                                         : offset + words.back().column + static_cast<int>(words.back().text.size());
        throw Error::at({name, lineNo, column}, fmt::format("expected 3 coordinates (x y z) on a vertex line, found {}", k));
      }
      if (!detail::finiteNumber(words[k].text)) {
        throw Error::at({name, lineNo, offset + words[k].column},
                        fmt::format("expected a number for the vertex's {} coordinate, found '{}'", kAxes[k],
                                    words[k].text.substr(0, 40)));
      }
    }
  }
}

/// What tinyobjloader read: positions and the faces of each g/o group.
struct TinyObj {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
};

// `materials` resolves mtllib lines (nullptr: ignored). drape uses only the geometry, but
// tinyobjloader's own complaints about a material file come first in its error text.
TinyObj loadWithTinyObj(std::string_view text, const std::string& name, tinyobj::MaterialReader* materials) {
  std::istringstream in{std::string(text)};
  TinyObj obj;
  std::vector<tinyobj::material_t> materialList;
  std::string warnings, errors;
  // triangulate = false: fans below keep the polygon's vertex order; no vertex colours.
  if (!tinyobj::LoadObj(&obj.attrib, &obj.shapes, &materialList, &warnings, &errors, &in, materials, false, false)) {
    const std::string err = firstLine(errors);
    throw Error(fmt::format("{}: {}", name, err.empty() ? "not a readable OBJ file" : err));
  }
  return obj;
}

mesh::TriMesh buildMesh(const TinyObj& obj, const std::string& name, const ObjReadOptions& options,
                        std::vector<std::string>* groupsRead) {
  const auto& attrib = obj.attrib;
  mesh::TriMesh out;
  out.name = name;
  const std::size_t vertexCount = attrib.vertices.size() / 3;
  out.positions.reserve(vertexCount);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    const Vec3 p(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
    if (!p.allFinite()) throw Error(fmt::format("{}: vertex {} has a non-finite coordinate", name, v + 1));
    out.positions.push_back(p * options.metresPerUnit);
  }

  std::vector<std::uint32_t> polygon;
  std::vector<bool> matched(options.groups.size(), false);
  for (const auto& shape : obj.shapes) {
    if (!wanted(shape.name, options.groups, matched)) continue;
    if (groupsRead != nullptr && !shape.mesh.num_face_vertices.empty() &&
        std::find(groupsRead->begin(), groupsRead->end(), shape.name) == groupsRead->end())
      groupsRead->push_back(shape.name);
    std::size_t offset = 0;
    for (const auto faceSize : shape.mesh.num_face_vertices) {
      polygon.clear();
      for (std::size_t k = 0; k < faceSize; ++k) {
        const int index = shape.mesh.indices[offset + k].vertex_index;
        if (index < 0 || static_cast<std::size_t>(index) >= vertexCount) {
          throw Error(fmt::format("{}: a face in group '{}' refers to vertex {} but the file has {} vertices",
                                  name, shape.name, index + 1, vertexCount));
        }
        polygon.push_back(static_cast<std::uint32_t>(index));
      }
      offset += faceSize;
      if (polygon.size() < 3) throw Error(fmt::format("{}: a face in group '{}' has fewer than 3 vertices", name, shape.name));
      mesh::triangulatePolygon(polygon, out.triangles);
    }
  }
  for (std::size_t k = 0; k < options.groups.size(); ++k) {
    if (matched[k]) continue;
    std::vector<std::string> groups;
    for (const auto& shape : obj.shapes)
      if (std::find(groups.begin(), groups.end(), shape.name) == groups.end()) groups.push_back(shape.name);
    // A body's file can hold hundreds of helper groups: the first few say what they are.
    constexpr std::size_t kListed = 12;
    const std::size_t listed = std::min(groups.size(), kListed);
    throw Error(fmt::format(
        "{}: has no g/o group {} '{}' (its groups: {}{})", name,
        isNamePattern(options.groups[k]) ? "matching" : "named", options.groups[k],
        groups.empty() ? std::string("none")
                       : fmt::format("{}", fmt::join(groups.begin(), groups.begin() + static_cast<long>(listed), ", ")),
        groups.size() > listed ? fmt::format(", ... {} in all", groups.size()) : ""));
  }
  if (out.triangles.empty()) {
    throw Error(options.groups.empty()
                    ? fmt::format("{}: no faces found, expected a triangle or polygon mesh", name)
                    : fmt::format("{}: no faces in the requested group(s) {}", name, fmt::join(options.groups, ", ")));
  }

  if (!options.keepUnusedVertices) {
    std::vector<std::uint32_t> remap(out.positions.size(), mesh::kNoVertex);
    std::vector<Vec3> kept;
    for (auto& tri : out.triangles) {
      for (auto& v : tri) {
        if (remap[v] == mesh::kNoVertex) {
          remap[v] = static_cast<std::uint32_t>(kept.size());
          kept.push_back(out.positions[v]);
        }
        v = remap[v];
      }
    }
    out.positions = std::move(kept);
  }
  return out;
}

mesh::TriMesh parseWith(std::string_view text, const std::string& name, const ObjReadOptions& options,
                        tinyobj::MaterialReader* materials, std::vector<std::string>* groupsRead) {
  checkVertexLines(text, name);
  return buildMesh(loadWithTinyObj(text, name, materials), name, options, groupsRead);
}

}  // namespace

mesh::TriMesh parseObj(std::string_view text, const std::string& name, const ObjReadOptions& options,
                       std::vector<std::string>* groupsRead) {
  return parseWith(text, name, options, nullptr, groupsRead);  // text has no folder to find an .mtl in
}

mesh::TriMesh readObj(const std::string& path, const ObjReadOptions& options, std::vector<std::string>* groupsRead) {
  requireReadableFile(path);
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  // Material files beside the OBJ, as tinyobjloader's own file reader finds them.
  const std::size_t slash = path.find_last_of('/');
  tinyobj::MaterialFileReader materials(slash == std::string::npos ? std::string() : path.substr(0, slash + 1));
  return parseWith(text.str(), path, options, &materials, groupsRead);
}

void writeObj(const std::string& path, std::span<const Vec3> positions,
              std::span<const mesh::Triangle> triangles, const std::string& comment) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) throw Error(fmt::format("{}: cannot be written", path));
  std::string text;
  text.reserve(positions.size() * 40 + triangles.size() * 24 + 64);
  if (!comment.empty()) text += fmt::format("# {}\n", comment);
  for (const Vec3& p : positions) text += fmt::format("v {:.6f} {:.6f} {:.6f}\n", p.x(), p.y(), p.z());
  for (const auto& t : triangles) text += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !ok) throw Error(fmt::format("{}: write failed", path));
}

}  // namespace drape::formats
