#include "drape/formats/obj.hpp"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "drape/core/error.hpp"

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

bool wanted(const std::string& shapeName, const std::vector<std::string>& groups) {
  return groups.empty() || std::find(groups.begin(), groups.end(), shapeName) != groups.end();
}

}  // namespace

mesh::TriMesh readObj(const std::string& path, const ObjReadOptions& options) {
  requireReadableFile(path);
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // fans below keep the polygon's vertex order
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    const std::string err = firstLine(reader.Error());
    throw Error(fmt::format("{}: {}", path, err.empty() ? "not a readable OBJ file" : err));
  }

  const auto& attrib = reader.GetAttrib();
  mesh::TriMesh out;
  out.name = path;
  const std::size_t vertexCount = attrib.vertices.size() / 3;
  out.positions.reserve(vertexCount);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    const Vec3 p(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
    if (!p.allFinite()) throw Error(fmt::format("{}: vertex {} has a non-finite coordinate", path, v + 1));
    out.positions.push_back(p * options.metresPerUnit);
  }

  std::vector<std::uint32_t> polygon;
  for (const auto& shape : reader.GetShapes()) {
    if (!wanted(shape.name, options.groups)) continue;
    std::size_t offset = 0;
    for (const auto faceSize : shape.mesh.num_face_vertices) {
      polygon.clear();
      for (std::size_t k = 0; k < faceSize; ++k) {
        const int index = shape.mesh.indices[offset + k].vertex_index;
        if (index < 0 || static_cast<std::size_t>(index) >= vertexCount) {
          throw Error(fmt::format("{}: a face in group '{}' refers to vertex {} but the file has {} vertices",
                                  path, shape.name, index + 1, vertexCount));
        }
        polygon.push_back(static_cast<std::uint32_t>(index));
      }
      offset += faceSize;
      if (polygon.size() < 3) throw Error(fmt::format("{}: a face in group '{}' has fewer than 3 vertices", path, shape.name));
      mesh::triangulatePolygon(polygon, out.triangles);
    }
  }
  if (out.triangles.empty()) {
    throw Error(options.groups.empty()
                    ? fmt::format("{}: no faces found, expected a triangle or polygon mesh", path)
                    : fmt::format("{}: no faces in the requested group(s) {}", path, fmt::join(options.groups, ", ")));
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
