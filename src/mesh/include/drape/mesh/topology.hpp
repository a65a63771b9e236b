#pragma once
// Cloth topology, the "winged-edge-like" form of the paper (section 4.1): every edge with
// its one or two faces and the vertices opposite it, plus boundary loops. Built once per
// garment mesh (a Build* pass); the simulation only reads it.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "drape/mesh/trimesh.hpp"

namespace drape::mesh {

inline constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

struct Edge {
  std::uint32_t v0, v1;          ///< v0 < v1
  std::uint32_t face0, face1;    ///< adjacent triangles; face1 == kNone on a boundary
  std::uint32_t opposite0, opposite1;  ///< vertex of face0 / face1 not on the edge
  [[nodiscard]] bool boundary() const { return face1 == kNone; }
};

struct Topology {
  std::vector<Edge> edges;
  /// For each triangle, its three edges (edge i joins corners i and i+1).
  std::vector<std::array<std::uint32_t, 3>> triangleEdges;
  /// Closed loops of boundary vertices, each in order along the boundary.
  std::vector<std::vector<std::uint32_t>> boundaryLoops;

  [[nodiscard]] std::size_t interiorEdgeCount() const;

  /// Builds the topology of `mesh`. Throws drape::Error naming mesh.name on an index out
  /// of range, a degenerate triangle (repeated vertex or area below minArea), or a
  /// non-manifold edge (more than two faces). Vertices used by no triangle are allowed.
  [[nodiscard]] static Topology build(const TriMesh& mesh, double minArea = 0.0);
};

/// Tolerant check used by loaders that may keep non-manifold meshes (body parts):
/// the number of edges with more than two faces.
[[nodiscard]] std::size_t countNonManifoldEdges(const TriMesh& mesh);

/// Pairs of boundary vertices that face each other across a gap the mesh leaves open (the
/// two fronts of a jacket, the edges of a slit): each boundary vertex's nearest boundary
/// vertex within maxGap_m that is not its neighbour along the boundary (on another loop, or
/// at least minSeparation boundary edges away along its own), kept where the two are each
/// other's nearest. Each pair (a < b) once, sorted. The closures a garment's stitches sew.
/// Throws drape::Error when maxGap_m is not a positive number.
[[nodiscard]] std::vector<std::array<std::uint32_t, 2>> facingBoundaryPairs(const TriMesh& mesh,
                                                                            const Topology& topology,
                                                                            double maxGap_m, int minSeparation = 6);

}  // namespace drape::mesh
