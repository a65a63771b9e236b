#pragma once
// Distance propagation from the surface voxels S0 over a whole voxel grid: DVDP (the
// paper's Discrete Voronoi Distance Propagation, section 4.3.2) and an exact separable
// Euclidean feature transform (Felzenszwalb and Huttenlocher, 2012) as its reference.
// Both give, per voxel, the squared distance in voxel units to the nearest surface voxel
// centre, and within the shell the Voronoi references: the surface voxels at that distance.

#include <cstdint>
#include <span>
#include <vector>

#include "drape/field/grid.hpp"

namespace drape::field {

/// Voxel connectivity of a DVDP action: which neighbours of a source voxel it expands to.
enum class Connectivity : std::uint8_t {
  Face,    ///< the 6 face neighbours, offsets like (1, 0, 0)
  Edge,    ///< the 12 edge neighbours, offsets like (1, 0, 1)
  Corner,  ///< the 8 corner neighbours, offsets like (1, 1, 1)
};

/// One integer offset of the lookup table, inside the tetrahedron 0 <= y <= z <= x.
/// 12 bytes: tables of a few hundred voxels' radius hold millions of offsets.
struct TableOffset {
  std::int16_t x = 0, y = 0, z = 0;
  Connectivity connectivity = Connectivity::Face;  ///< of this offset relative to its source
  std::int32_t length2 = 0;                        ///< x^2 + y^2 + z^2

  /// The source offset of Table 1 (the origin has none: returns itself).
  [[nodiscard]] TableOffset source() const;
};

/// One DVDP action: expand every voxel of set S_sourceIteration to its neighbours of the
/// given connectivity; the distance assigned is the iteration's length.
struct TableAction {
  int sourceIteration = 0;
  Connectivity connectivity = Connectivity::Face;
};

/// The DVDP lookup table (paper Figures 3-5, Table 1): every offset within a radius in the
/// tetrahedron y <= z <= x, ordered by length; one iteration per distinct length; each
/// iteration's actions (distinct source sets and connectivities of its offsets). Source
/// rules (Table 1, checked against the offsets themselves): x > z: (x-1, y, z), a face
/// neighbour; x = z, y = 0: (x-1, y, z-1), an edge neighbour (the paper's table says
/// 8-connected); x = z, y > 0: (x-1, y-1, z-1), a corner neighbour (the paper says 12).
class LookupTable {
 public:
  /// The table for offsets of length <= radius (voxels). Built once and cached; grows when
  /// a larger radius is asked for. Thread-safe.
  [[nodiscard]] static const LookupTable& forRadius(int radius);
  /// Builds a table without the cache (tests).
  [[nodiscard]] static LookupTable build(int radius);

  int radius = 0;
  std::vector<TableOffset> offsets;        ///< ordered by length2, then x, z, y
  std::vector<int> iterationLength2;       ///< per iteration: its squared length (iteration 0 = 0)
  std::vector<int> iterationOffsetStart;   ///< offsets of iteration i: [start[i], start[i+1])
  std::vector<int> actionStart;            ///< actions of iteration i: [actionStart[i], actionStart[i+1])
  std::vector<TableAction> actions;
  /// Per iteration: the last iteration that sources from it, so its set can be released
  /// after that one; -1 when that lies beyond this table's radius (not known here).
  std::vector<int> lastUse;
  std::vector<int> iterationOfLength2;  ///< squared length -> iteration index, -1 if no offset has it

  [[nodiscard]] int iterationCount() const { return static_cast<int>(iterationLength2.size()); }
};

/// Which propagation produces the field.
enum class FieldMethod : std::uint8_t {
  Dvdp,   ///< the paper's DVDP (references checked within the shell, see docs/FIELDS.md)
  Exact,  ///< exact separable Euclidean feature transform
};

/// How DVDP treats the shell (beyond it both are the paper's distance-only propagation).
enum class DvdpVariant : std::uint8_t {
  /// The paper as written: every voxel an action reaches takes the iteration's distance and
  /// accumulates the references of all the sources that reached it.
  Paper,
  /// Within the shell, references are checked: each completed set offers its references to
  /// its 26 neighbours, queued at the iteration of their exact distance; a voxel takes the
  /// first iteration that reaches it with all the references at that distance. Exact on
  /// every case tested (tests/field); the default.
  ShellExact,
};

struct PropagationOptions {
  /// Voronoi references are kept for voxels whose squared distance (voxel units) is at most
  /// this: the shell T3 squared (36 for the paper's T3 = 6). Negative: no references at all
  /// (the paper's "distance field (0)").
  int shellDistance2 = 36;
  DvdpVariant variant = DvdpVariant::ShellExact;
};

/// Result of a propagation over a grid of `dims` voxels.
struct Propagation {
  GridDims dims;
  std::vector<std::int32_t> distance2;  ///< per voxel: squared distance (voxel units) to the nearest surface voxel
  /// Voxels with references (distance2 <= shellDistance2), in increasing index order, and
  /// their references: surface voxel indices refs[refStart[k] .. refStart[k+1]) for shellVoxels[k].
  std::vector<std::uint32_t> shellVoxels;
  std::vector<std::uint32_t> refStart;
  std::vector<std::uint32_t> refs;
  int shellDistance2 = 36;

  [[nodiscard]] std::span<const std::uint32_t> refsOf(std::size_t shellSlot) const {
    return {refs.data() + refStart[shellSlot], refStart[shellSlot + 1] - refStart[shellSlot]};
  }
};

/// DVDP from the surface voxels (surface[i] != 0). Every voxel of the grid gets a distance:
/// within the shell as options.variant says, beyond it by the paper's distance-only
/// propagation (its measured error: docs/FIELDS.md).
/// Throws drape::Error if there is no surface voxel or a side exceeds kMaxGridSide.
[[nodiscard]] Propagation propagateDvdp(const GridDims& dims, std::span<const std::uint8_t> surface,
                                        const PropagationOptions& options);

/// Exact Euclidean feature transform (three separable passes of the lower envelope of
/// parabolas, linear time). References in the shell: the voxel's own nearest surface voxel
/// plus the nearest surface voxels of its 26 neighbours that are equally near (ties).
[[nodiscard]] Propagation exactFeatureTransform(const GridDims& dims, std::span<const std::uint8_t> surface,
                                                const PropagationOptions& options);

/// Squared distance transform only (no features, no references): the fastest exact field.
[[nodiscard]] std::vector<std::int32_t> exactDistance2(const GridDims& dims, std::span<const std::uint8_t> surface);

}  // namespace drape::field
