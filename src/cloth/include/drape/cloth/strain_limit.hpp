#pragma once
// Strain limiting (Provot 1995): the last resort of a frame that no number of substeps keeps
// stable (ClothSolver::stepFrame). Cloth crushed where two body parts' offset surfaces
// overlap can be stretched to two or three times its length; St Venant-Kirchhoff stiffens
// with the square of the stretch, and the explicit step's stable substep shrinks with it
// until even 8 or 32 times the substeps diverge. Holding every edge to a largest stretch
// takes that stiffness away where forces alone cannot.
//
// Stitches (holdStitches) are the same projection over pairs of vertices that share no
// edge: the openings a garment mesh leaves that the garment keeps shut.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "drape/cloth/model.hpp"
#include "drape/cloth/state.hpp"

namespace drape::cloth {

/// Gauss-Seidel passes over the edges per substep: the second catches most of what the
/// first's corrections stretch again where edges share a vertex.
inline constexpr int kStrainLimitSweeps = 2;

/// Pulls every edge longer than (1 + limit) times its rest length back to that length, in
/// `sweeps` passes over the model's edges, moving each end by its share of the weights
/// (`weight`: the inverse masses, 0 for vertices a fixture holds), and takes away the ends'
/// relative velocity along the edge where it stretches the edge further. Corrections are
/// weighted by inverse mass, so linear momentum and the centre of mass are kept; edges within
/// the limit are not touched. Returns how many edge corrections were made.
std::size_t limitStrain(const ClothModel& model, std::span<const double> weight, double limit, int sweeps,
                        ClothState& io);

/// Two vertices of a garment sewn together (a closure, a button, a seam the mesh leaves
/// open): they stay at most `length_m` apart. Beyond the paper.
struct Stitch {
  std::uint32_t a = 0, b = 0;
  double length_m = 0.0;  ///< as far apart as they may be (a scene's stitches: 0, drawn together)
};

/// Stitches that draw each pair of vertices together (length 0): a scene's `stitches` and
/// `drape run --stitch-gaps`.
[[nodiscard]] std::vector<Stitch> stitchesDrawnTogether(std::span<const std::array<std::uint32_t, 2>> pairs);

/// Pulls the two ends of every stitch longer than its length back to it, in `sweeps` passes,
/// as limitStrain pulls an edge (by the inverse-mass weights, taking away the ends' velocity
/// apart along the stitch), every substep: a stitch is a limit, not a spring, so it adds no
/// stiffness the explicit step would have to resolve. Returns how many stitch corrections
/// were made.
std::size_t holdStitches(std::span<const Stitch> stitches, std::span<const double> weight, int sweeps, ClothState& io);

}  // namespace drape::cloth
