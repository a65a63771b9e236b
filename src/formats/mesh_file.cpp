#include "drape/formats/mesh_file.hpp"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "drape/core/error.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/gltf_avatar.hpp"
#include "drape/formats/obj.hpp"
#include "drape/formats/part_names.hpp"
#include "drape/mesh/weld.hpp"
#include "plain_data.hpp"
#include "text_scan.hpp"

namespace drape::formats {
namespace {

using detail::Cursor;
using detail::put;
using detail::putVector;

std::string serialise(const MeshParts& parts) {
  std::string s;
  std::vector<double> xyz;
  xyz.reserve(3 * parts.mesh.positions.size());
  for (const Vec3& p : parts.mesh.positions) xyz.insert(xyz.end(), {p.x(), p.y(), p.z()});
  putVector(s, xyz);
  putVector(s, parts.mesh.triangles);
  detail::putStrings(s, parts.read);
  detail::putStrings(s, parts.all);
  return s;
}

MeshParts deserialiseMeshParts(std::string_view bytes, const std::string& name) {
  Cursor c{bytes, 0, name};
  MeshParts parts;
  parts.mesh.name = name;
  const std::vector<double> xyz = c.getVector<double>();
  if (xyz.size() % 3 != 0) throw Error(fmt::format("{}: the reader returned bad data", name));
  for (std::size_t i = 0; i < xyz.size(); i += 3) parts.mesh.positions.emplace_back(xyz[i], xyz[i + 1], xyz[i + 2]);
  parts.mesh.triangles = c.getVector<mesh::Triangle>();
  for (const mesh::Triangle& t : parts.mesh.triangles)
    for (std::uint32_t v : t)
      if (v >= parts.mesh.positions.size()) throw Error(fmt::format("{}: the reader returned bad data", name));
  parts.read = c.getStrings();
  parts.all = c.getStrings();
  if (c.at != bytes.size()) throw Error(fmt::format("{}: the reader returned bad data", name));
  return parts;
}

constexpr std::size_t kMaxMeshFileBytes = std::size_t{1} << 30;

MeshParts readIsolated(const std::string& path, const std::string& ext, const std::vector<std::string>& parts, bool loose,
                       const IsolationLimits& limits) {
  const std::string bytes = detail::readWholeFile(path, kMaxMeshFileBytes);
  if (isGltfPath(path)) {
    const std::string baseDir = std::filesystem::absolute(path).parent_path().string();
    return deserialiseMeshParts(
        runIsolated(path, "glTF reader", [&] { return serialise(parseGltfMesh(bytes, path, baseDir, parts, loose)); }, limits), path);
  }
  const std::string reader = fmt::format("{} reader (Assimp)", ext == ".dae" ? "Collada" : "FBX");
  return deserialiseMeshParts(runIsolated(path, reader, [&] { return serialise(parseAssimpMesh(bytes, path, parts, loose)); }, limits),
                              path);
}

}  // namespace

bool partWanted(const std::vector<std::string>& parts, std::vector<bool>& matched, const std::string& part,
                const std::string& meshName) {
  if (parts.empty()) return true;
  bool keep = false;
  for (std::size_t k = 0; k < parts.size(); ++k)
    if (nameMatches(parts[k], part) || (!meshName.empty() && nameMatches(parts[k], meshName))) keep = matched[k] = true;
  return keep;
}

void checkPartsMatched(const std::vector<std::string>& parts, const std::vector<bool>& matched,
                       const std::vector<std::string>& all, const std::string& name, const std::string& what) {
  for (std::size_t k = 0; k < parts.size(); ++k)
    if (!matched[k])
      throw Error(fmt::format("{}: has no node or mesh {} '{}' (its {}: {})", name,
                              isNamePattern(parts[k]) ? "matching" : "named", parts[k], what,
                              all.empty() ? std::string("none") : fmt::format("{}", fmt::join(all, ", "))));
}

void checkMeshParts(const MeshParts& read, const std::vector<std::string>& parts, const std::vector<bool>& matched,
                    bool loose, const std::string& name) {
  checkPartsMatched(parts, matched, read.all, name);
  if (read.mesh.triangles.empty() && (!loose || read.mesh.positions.empty()))
    throw Error(fmt::format("{}: {}", name,
                            loose ? (parts.empty() ? "has no mesh" : "the parts asked for have no vertices")
                                  : (parts.empty() ? "has no triangle mesh" : "the parts asked for have no triangles")));
}

std::string describeRead(const MeshFile& file) {
  if (file.partsRead.size() <= 1 && file.welded == 0 && file.droppedTriangles == 0) return "";
  return fmt::format("{} ({} vertices, {} triangles{}{})",
                     file.partsRead.size() == 1 ? fmt::format("mesh {}", file.partsRead.front())
                                                : fmt::format("{} meshes: {}", file.partsRead.size(), fmt::join(file.partsRead, ", ")),
                     file.mesh.vertexCount(), file.mesh.triangleCount(),
                     file.welded > 0 ? fmt::format("; {} split vertices welded", file.welded) : "",
                     file.droppedTriangles > 0 ? fmt::format("; {} repeated or collapsed triangles dropped", file.droppedTriangles)
                                               : "");
}

bool isMeshFilePath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  return ext == ".obj" || isGltfPath(path) || ext == ".dae" || ext == ".fbx";
}

MeshFile readMeshFile(const std::string& path, const MeshFileOptions& options, const IsolationLimits& limits) {
  const std::string ext = lowerExtension(path);
  MeshFile out;
  if (ext == ".obj") {
    ObjReadOptions read;
    read.metresPerUnit = options.metresPerUnit;
    read.groups = options.parts;
    // The other groups' vertices are no part of a garment chosen by group.
    read.keepUnusedVertices = options.parts.empty() || options.looseVertices;
    std::vector<std::string> groups;
    out.mesh = readObj(path, read, &groups);
    if (!options.parts.empty()) out.partsRead = std::move(groups);
    return out;
  }
  if (!isMeshFilePath(path))
    throw Error(fmt::format("{}: drape reads meshes from OBJ, glTF (.gltf, .glb, .vrm), Collada (.dae) and FBX (.fbx), not '{}'",
                            path, ext));
  if (!(options.weldTolerance_m > 0.0) || !std::isfinite(options.weldTolerance_m))
    throw Error(fmt::format("{}: the weld tolerance must be > 0 m, got {}", path, options.weldTolerance_m));
  const MeshParts parts = readIsolated(path, ext, options.parts, options.looseVertices, limits);
  mesh::Welded welded = mesh::weld(parts.mesh, options.weldTolerance_m, options.looseVertices);
  if (welded.mesh.triangles.empty() && !options.looseVertices)
    throw Error(fmt::format("{}: its triangles ({}) all collapse when the vertices within {:g} m of each other are welded: "
                            "no surface is left", path, parts.mesh.triangleCount(), options.weldTolerance_m));
  out.mesh = std::move(welded.mesh);
  out.mesh.name = path;
  out.partsRead = parts.read;
  out.welded = welded.merged;
  out.droppedTriangles = welded.collapsed + welded.duplicates;
  return out;
}

}  // namespace drape::formats
