#pragma once
// Vertices that are one point of the surface, merged: files made for rendering (glTF,
// Collada, FBX, a skinned avatar) split a vertex wherever its texture coordinates or
// normals change, and a garment's sewing patterns come as pieces whose seams coincide.
// The cloth needs the surface's own connectivity, or its pieces fall apart.

#include <cstdint>
#include <vector>

#include "drape/mesh/trimesh.hpp"

namespace drape::mesh {

/// Vertex index map that merges vertices at the same position (within `tolerance` m,
/// positions rounded to a grid of that pitch): each vertex maps to the lowest-numbered
/// vertex at its position.
[[nodiscard]] std::vector<std::uint32_t> weldByPosition(const TriMesh& mesh, double tolerance = 1e-7);

struct Welded {
  TriMesh mesh;                  ///< vertices renumbered in order of first use by a triangle
  std::size_t merged = 0;        ///< vertices that became another vertex
  std::size_t collapsed = 0;     ///< triangles dropped: two corners became one vertex
  std::size_t duplicates = 0;    ///< triangles dropped: the same three vertices as an earlier one
  std::size_t unused = 0;        ///< vertices no triangle uses, dropped (0 with keepLoose)
};

/// `mesh` with its vertices welded by position (weldByPosition), the triangles that welding
/// collapses or repeats (a two-sided copy, a piece modelled twice) dropped, and only the
/// vertices the triangles use kept; with `keepLoose`, the others too (after them, in the
/// order of the mesh's vertices: a mask's loose points).
[[nodiscard]] Welded weld(const TriMesh& mesh, double tolerance = 1e-7, bool keepLoose = false);

}  // namespace drape::mesh
