// `drape inspect MESH.obj`: vertex, triangle, edge and boundary counts of an OBJ mesh.

#include <fmt/ostream.h>

#include "command.hpp"
#include "drape/formats/obj.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::cli {
namespace {

void inspectObj(const std::string& path, std::ostream& out) {
  const mesh::TriMesh m = formats::readObj(path);
  const Aabb box = m.bounds();
  fmt::print(out, "{}: OBJ mesh (file units)\n", path);
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

const bool registered_cmd_inspect_obj = registerInspector({".obj"}, "OBJ meshes: counts, bounds, boundary loops", &inspectObj);

}  // namespace
}  // namespace drape::cli
