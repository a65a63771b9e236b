// Discrete Voronoi Distance Propagation (paper section 4.3.2).
//
// The grid is padded by one guard layer tagged "processed" so that expanding a voxel never
// needs a bounds test. Per voxel the working array holds the squared distance of the
// iteration that assigned it (kUnprocessed before). Sets S_i hold the voxels each
// iteration assigned; within the shell they also hold each voxel's Voronoi references
// (surface voxels, as packed padded coordinates). A set is released after the last
// iteration whose actions source from it.

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "drape/core/error.hpp"
#include "drape/field/propagation.hpp"
#include "packed_voxel.hpp"

namespace drape::field {
namespace {

// Unprocessed voxels hold kUnprocessed or more: kUnprocessed + the best squared distance
// offered to them so far (ShellExact), so one load answers both questions.
constexpr std::int32_t kUnprocessed = 1 << 30;
constexpr std::int32_t kNoOffer = kUnprocessed + 0xffff;
constexpr std::int32_t kGuard = -1;

using packed::pack;
using packed::px;
using packed::py;
using packed::pz;

// Neighbour sets by connectivity: 0 face (6), 1 edge (12), 2 corner (8), 3 all 26.
struct Neighbours {
  std::vector<std::int64_t> delta;          // linear offset in the padded grid
  std::vector<std::array<int, 3>> offset;  // the same as (dx, dy, dz)
};

std::array<Neighbours, 4> neighbourSets(const GridDims& padded) {
  std::array<Neighbours, 4> sets;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nonZero = (dx != 0) + (dy != 0) + (dz != 0);
        if (nonZero == 0) continue;
        Neighbours& n = sets[nonZero - 1];  // 1: face, 2: edge, 3: corner
        n.delta.push_back(dx + static_cast<std::int64_t>(padded.nx) * (dy + static_cast<std::int64_t>(padded.ny) * dz));
        n.offset.push_back({dx, dy, dz});
        sets[3].delta.push_back(n.delta.back());
        sets[3].offset.push_back({dx, dy, dz});
      }
  return sets;
}

struct VoxelSet {
  std::vector<std::uint32_t> voxels;    // padded-grid indices
  std::vector<std::uint32_t> coords;    // packed padded coordinates (sets with references)
  std::vector<std::uint32_t> refStart;  // sets with references: size voxels + 1
  std::vector<std::uint32_t> refs;      // packed padded coordinates of surface voxels
  // Connectivities this set has been expanded by. An expansion assigns every unprocessed
  // neighbour of that connectivity, so a second action with the same source set and
  // connectivity can only find processed voxels: it is skipped (same result, less work).
  std::uint8_t expanded = 0;

  void release() {
    std::vector<std::uint32_t>().swap(voxels);
    std::vector<std::uint32_t>().swap(coords);
    std::vector<std::uint32_t>().swap(refStart);
    std::vector<std::uint32_t>().swap(refs);
  }
};

struct RefPair {
  std::uint32_t slot;  // index of the destination in the set being built
  std::uint32_t ref;
};

// A reference that reached a voxel early: it is offered again at its own iteration.
struct Deferred {
  std::uint32_t voxel;   // padded index
  std::uint32_t coords;  // packed padded coordinates of the voxel
  std::uint32_t ref;
};

// Groups the (slot, reference) pairs of one iteration into the set's compressed rows,
// dropping duplicates (a reference reaching a voxel from several sources).
void collectReferences(std::vector<RefPair>& pairs, VoxelSet& set) {
  const std::size_t n = set.voxels.size();
  set.refStart.assign(n + 1, 0);
  for (const RefPair& p : pairs) ++set.refStart[p.slot + 1];
  for (std::size_t k = 0; k < n; ++k) set.refStart[k + 1] += set.refStart[k];
  std::vector<std::uint32_t> fill(set.refStart.begin(), set.refStart.end() - 1);
  set.refs.resize(pairs.size());
  for (const RefPair& p : pairs) set.refs[fill[p.slot]++] = p.ref;
  std::uint32_t write = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t first = set.refStart[k], last = set.refStart[k + 1];
    std::sort(set.refs.begin() + first, set.refs.begin() + last);
    set.refStart[k] = write;
    for (std::uint32_t r = first; r < last; ++r)
      if (r == first || set.refs[r] != set.refs[r - 1]) set.refs[write++] = set.refs[r];
  }
  set.refStart[n] = write;
  set.refs.resize(write);
}

}  // namespace

Propagation propagateDvdp(const GridDims& dims, std::span<const std::uint8_t> surface,
                          const PropagationOptions& options) {
  if (dims.nx < 1 || dims.ny < 1 || dims.nz < 1 || dims.nx > kMaxGridSide || dims.ny > kMaxGridSide ||
      dims.nz > kMaxGridSide)
    throw Error("voxel grid " + std::to_string(dims.nx) + "x" + std::to_string(dims.ny) + "x" +
                std::to_string(dims.nz) + " is empty or has a side above " + std::to_string(kMaxGridSide));
  const GridDims padded{dims.nx + 2, dims.ny + 2, dims.nz + 2};
  const bool withRefs = options.shellDistance2 >= 0;
  if (options.shellDistance2 > 60000) throw Error("the shell is wider than 244 voxels");
  const std::array<Neighbours, 4> neighbours = neighbourSets(padded);

  // Working distances: guard layer, then unprocessed voxels and the surface S0.
  std::vector<std::int32_t> work(padded.count(), kGuard);
  std::vector<VoxelSet> sets(1);
  std::size_t remaining = 0;
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y) {
      const std::uint32_t row = dims.index(0, y, z);
      const std::uint32_t prow = padded.index(1, y + 1, z + 1);
      for (int x = 0; x < dims.nx; ++x) {
        if (surface[row + x]) {
          work[prow + x] = 0;
          sets[0].voxels.push_back(prow + x);
          if (withRefs) {
            sets[0].coords.push_back(pack(x + 1, y + 1, z + 1));
            sets[0].refs.push_back(pack(x + 1, y + 1, z + 1));
          }
        } else {
          work[prow + x] = kNoOffer;
          ++remaining;
        }
      }
    }
  if (sets[0].voxels.empty()) throw Error("no surface voxel to propagate from (empty or degenerate mesh)");
  if (withRefs) {
    sets[0].refStart.resize(sets[0].voxels.size() + 1);
    for (std::size_t k = 0; k <= sets[0].voxels.size(); ++k) sets[0].refStart[k] = static_cast<std::uint32_t>(k);
  }

  // Shell output, in the order sets complete; slot[] maps a padded voxel to its entry.
  std::vector<std::uint32_t> slot(withRefs ? padded.count() : 0, 0);
  std::vector<std::uint32_t> outStart, outRefs;
  auto emitShellSet = [&](const VoxelSet& set) {
    for (std::size_t k = 0; k < set.voxels.size(); ++k) {
      slot[set.voxels[k]] = static_cast<std::uint32_t>(outStart.size());
      outStart.push_back(static_cast<std::uint32_t>(outRefs.size()));
      outRefs.insert(outRefs.end(), set.refs.begin() + set.refStart[k], set.refs.begin() + set.refStart[k + 1]);
    }
  };
  if (withRefs) emitShellSet(sets[0]);

  const int shellRadius = withRefs ? static_cast<int>(std::ceil(std::sqrt(options.shellDistance2))) : 0;
  const LookupTable* table = &LookupTable::forRadius(std::max(64, shellRadius + 2));
  const bool exactShell = withRefs && options.variant == DvdpVariant::ShellExact;
  std::vector<RefPair> pairs;

  // ShellExact: references offered to the 26 neighbours of each completed shell set, queued
  // at the iteration of their own distance; an unprocessed voxel's work[] value holds the
  // best distance offered to it so far, so only improving offers are queued.
  int shellIterations = 0;
  while (exactShell && shellIterations < table->iterationCount() &&
         table->iterationLength2[shellIterations] <= options.shellDistance2)
    ++shellIterations;
  std::vector<std::vector<Deferred>> deferred(static_cast<std::size_t>(shellIterations));
  const auto& all = neighbours[3];
  std::array<std::int64_t, 9> rowsAround{};
  for (int dz = -1, r = 0; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy) rowsAround[r++] = padded.nx * (dy + static_cast<std::int64_t>(padded.ny) * dz);
  auto offer = [&](const VoxelSet& set) {
    for (std::size_t e = 0; e < set.voxels.size(); ++e) {
      const std::uint32_t u = set.voxels[e];
      const std::uint32_t uc = set.coords[e];
      if (e + 4 < set.voxels.size()) {  // the 9 rows of the 3x3x3 block a few voxels ahead
        const std::int64_t ahead = set.voxels[e + 4] - 1;
        for (const std::int64_t row : rowsAround) __builtin_prefetch(&work[ahead + row]);
      }
      for (std::size_t k = 0; k < all.delta.size(); ++k) {
        const std::uint32_t v = static_cast<std::uint32_t>(u + all.delta[k]);
        std::int32_t& w = work[v];
        if (w < kUnprocessed) continue;
        const int vx = px(uc) + all.offset[k][0], vy = py(uc) + all.offset[k][1], vz = pz(uc) + all.offset[k][2];
        for (std::uint32_t r = set.refStart[e]; r < set.refStart[e + 1]; ++r) {
          const std::uint32_t ref = set.refs[r];
          const int dx = vx - px(ref), dy = vy - py(ref), dz = vz - pz(ref);
          const int ref2 = dx * dx + dy * dy + dz * dz;
          if (ref2 > options.shellDistance2 || kUnprocessed + ref2 > w) continue;
          w = kUnprocessed + ref2;
          deferred[table->iterationOfLength2[ref2]].push_back({v, pack(vx, vy, vz), ref});
        }
      }
    }
  };
  if (exactShell) offer(sets[0]);

  for (int i = 1; remaining > 0; ++i) {
    if (i >= table->iterationCount()) {
      if (table->radius > 4 * kMaxGridSide) throw Error("DVDP ran past its lookup table", ExitCode::Internal);
      table = &LookupTable::forRadius(table->radius * 2);
    }
    const std::int32_t length2 = table->iterationLength2[i];
    const bool inShell = length2 <= options.shellDistance2;
    sets.emplace_back();
    VoxelSet& out = sets.back();
    pairs.clear();
    if (inShell && exactShell) {
      // The references queued for this distance: every voxel reached, every way.
      const std::vector<Deferred>& queue = deferred[i];
      for (std::size_t q = 0; q < queue.size(); ++q) {
        const Deferred& e = queue[q];
        if (q + 8 < queue.size()) {  // the queue is in offer order, scattered over the grid
          __builtin_prefetch(&work[queue[q + 8].voxel]);
          __builtin_prefetch(&slot[queue[q + 8].voxel]);
        }
        std::int32_t& d = work[e.voxel];
        if (d < length2) continue;  // assigned at a smaller distance meanwhile
        if (d >= kUnprocessed) {
          d = length2;
          slot[e.voxel] = static_cast<std::uint32_t>(out.voxels.size());
          out.voxels.push_back(e.voxel);
          out.coords.push_back(e.coords);
          --remaining;
        }
        pairs.push_back({slot[e.voxel], e.ref});
      }
      std::vector<Deferred>().swap(deferred[i]);
    } else {
      // The paper's actions: expand each source set to its neighbours of the action's
      // connectivity; unprocessed ones take this iteration's distance.
      for (int a = table->actionStart[i]; a < table->actionStart[i + 1]; ++a) {
        const TableAction action = table->actions[a];
        VoxelSet& source = sets[action.sourceIteration];
        const std::uint8_t bit = static_cast<std::uint8_t>(1u << static_cast<int>(action.connectivity));
        if (source.expanded & bit) continue;
        source.expanded |= bit;
        const Neighbours& nb = neighbours[static_cast<int>(action.connectivity)];
        const std::size_t nn = nb.delta.size();
        if (inShell) {
          // Paper variant within the shell: accumulate the references of every source.
          for (std::size_t e = 0; e < source.voxels.size(); ++e) {
            const std::uint32_t u = source.voxels[e];
            for (std::size_t k = 0; k < nn; ++k) {
              const std::uint32_t v = static_cast<std::uint32_t>(u + nb.delta[k]);
              const std::int32_t d = work[v];
              if (d < length2) continue;  // processed earlier, or the guard layer
              if (d >= kUnprocessed) {
                work[v] = length2;
                slot[v] = static_cast<std::uint32_t>(out.voxels.size());
                out.voxels.push_back(v);
                const std::uint32_t uc = source.coords[e];
                out.coords.push_back(
                    pack(px(uc) + nb.offset[k][0], py(uc) + nb.offset[k][1], pz(uc) + nb.offset[k][2]));
                --remaining;
              }
              for (std::uint32_t r = source.refStart[e]; r < source.refStart[e + 1]; ++r)
                pairs.push_back({slot[v], source.refs[r]});
            }
          }
        } else {
          // Beyond the shell: distance only.
          const std::size_t count = source.voxels.size();
          for (std::size_t e = 0; e < count; ++e) {
            const std::uint32_t u = source.voxels[e];
            if (e + 4 < count) {
              const std::uint32_t ahead = source.voxels[e + 4];
              for (std::size_t k = 0; k < nn; ++k) __builtin_prefetch(&work[ahead + nb.delta[k]]);
            }
            for (std::size_t k = 0; k < nn; ++k) {
              const std::uint32_t v = static_cast<std::uint32_t>(u + nb.delta[k]);
              if (work[v] < kUnprocessed) continue;
              work[v] = length2;
              out.voxels.push_back(v);
              --remaining;
            }
          }
        }
      }
    }
    if (inShell && withRefs) {
      collectReferences(pairs, out);
      emitShellSet(out);
      // The last shell set has nothing to offer: its neighbours lie beyond the shell.
      if (exactShell && i + 1 < shellIterations) offer(out);
    }
    // Release the sets nothing later depends on.
    for (int a = table->actionStart[i]; a < table->actionStart[i + 1]; ++a) {
      const int j = table->actions[a].sourceIteration;
      if (table->lastUse[j] == i) sets[j].release();
    }
  }

  // Unpad; gather the shell references in voxel order.
  Propagation result;
  result.dims = dims;
  result.shellDistance2 = options.shellDistance2;
  result.distance2.resize(dims.count());
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y) {
      const std::uint32_t row = dims.index(0, y, z);
      const std::uint32_t prow = padded.index(1, y + 1, z + 1);
      for (int x = 0; x < dims.nx; ++x) {
        const std::int32_t d = work[prow + x];
        result.distance2[row + x] = d;
        if (!withRefs || d > options.shellDistance2) continue;
        const std::uint32_t k = slot[prow + x];
        const std::uint32_t last = k + 1 < outStart.size() ? outStart[k + 1] : static_cast<std::uint32_t>(outRefs.size());
        result.shellVoxels.push_back(row + x);
        result.refStart.push_back(static_cast<std::uint32_t>(result.refs.size()));
        for (std::uint32_t r = outStart[k]; r < last; ++r) {
          const std::uint32_t ref = outRefs[r];
          result.refs.push_back(dims.index(px(ref) - 1, py(ref) - 1, pz(ref) - 1));
        }
      }
    }
  result.refStart.push_back(static_cast<std::uint32_t>(result.refs.size()));
  return result;
}

}  // namespace drape::field
