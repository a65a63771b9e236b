#pragma once
// Sewing a garment's openings shut from the command line: `drape make-scene --stitch-gaps`
// writes the stitches into the scene, `drape run --stitch-gaps` uses them at once, and
// `drape inspect` describes a scene's.

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "drape/core/error.hpp"
#include "drape/mesh/topology.hpp"

namespace drape::cli {

using StitchPairs = std::vector<std::array<std::uint32_t, 2>>;

/// The pairs of boundary vertices facing each other across at most gap_m
/// (mesh::facingBoundaryPairs); throws naming --stitch-gaps and the garment when there are none.
inline StitchPairs openingsToSew(const mesh::TriMesh& garment, const mesh::Topology& topology, const std::string& name,
                                 double gap_m) {
  StitchPairs pairs = mesh::facingBoundaryPairs(garment, topology, gap_m);
  if (pairs.empty())
    throw Error(fmt::format("--stitch-gaps {:g}: no two boundary vertices of garment '{}' face each other within "
                            "{:g} m (the edges of an opening: on two boundaries, or at least 6 boundary edges apart "
                            "along one)",
                            gap_m, name, gap_m));
  return pairs;
}

/// The farthest apart two stitched vertices are in the garment as modelled, m.
inline double widestStitch_m(const mesh::TriMesh& garment, const StitchPairs& pairs) {
  double widest = 0.0;
  for (const auto& [a, b] : pairs) widest = std::max(widest, (garment.positions[a] - garment.positions[b]).norm());
  return widest;
}

}  // namespace drape::cli
