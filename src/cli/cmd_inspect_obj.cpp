// `drape inspect MESH.obj`: vertex, triangle, edge and boundary counts of a mesh; and the
// same for the static meshes of a glTF, Collada or FBX file (cmd_inspect_motion.cpp sends a
// file without a skin here).

#include <fmt/ostream.h>
#include <fmt/ranges.h>

#include "command.hpp"
#include "drape/core/files.hpp"
#include "drape/formats/mesh_file.hpp"
#include "drape/mesh/topology.hpp"
#include "inspect_mesh.hpp"

namespace drape::cli {

void inspectMeshFile(const std::string& path, std::ostream& out) {
  const formats::MeshFile file = formats::readMeshFile(path);
  const mesh::TriMesh& m = file.mesh;
  const Aabb box = m.bounds();
  if (lowerExtension(path) == ".obj") {
    fmt::print(out, "{}: OBJ mesh (file units)\n", path);
  } else {
    fmt::print(out, "{}: static mesh, as drape make-scene --garment reads it (m)\n", path);
    fmt::print(out, "  meshes     {} ({})\n", file.partsRead.size(), fmt::join(file.partsRead, ", "));
    fmt::print(out, "  welded     {} split vertices into others at the same position; {} triangles dropped as repeated "
                    "or collapsed\n", file.welded, file.droppedTriangles);
  }
  fmt::print(out, "  vertices   {}\n  triangles  {}\n", m.vertexCount(), m.triangleCount());
  fmt::print(out, "  bounds     [{:.4g} {:.4g} {:.4g}] .. [{:.4g} {:.4g} {:.4g}]\n", box.min.x(), box.min.y(),
             box.min.z(), box.max.x(), box.max.y(), box.max.z());
  const std::size_t nonManifold = mesh::countNonManifoldEdges(m);
  if (nonManifold > 0) {
    fmt::print(out, "  non-manifold edges {} (cannot be simulated as cloth)\n", nonManifold);
    return;
  }
  const mesh::Topology t = mesh::Topology::build(m);
  fmt::print(out, "  edges      {} ({} on the boundary)\n", t.edges.size(), t.edges.size() - t.interiorEdgeCount());
  fmt::print(out, "  boundary loops {}\n", t.boundaryLoops.size());
  for (const auto& loop : t.boundaryLoops) fmt::print(out, "    {} vertices\n", loop.size());
}

namespace {

const bool registered_cmd_inspect_obj =
    registerInspector({".obj"}, "OBJ meshes: counts, bounds, boundary loops", &inspectMeshFile);

}  // namespace
}  // namespace drape::cli
