// Exact Euclidean distance and feature transform: Felzenszwalb and Huttenlocher, "Distance
// Transforms of Sampled Functions" (Theory of Computing, 2012). A squared distance along
// x by two sweeps, then the lower envelope of parabolas along y and along z; each pass
// is linear in the number of voxels. The feature (nearest surface voxel) rides along.

#include <algorithm>
#include <cmath>
#include <limits>

#include "drape/core/error.hpp"
#include "drape/field/propagation.hpp"
#include "packed_voxel.hpp"

namespace drape::field {
namespace {

constexpr std::int32_t kFar = std::numeric_limits<std::int32_t>::max() / 4;

// Scratch space of one 1D lower-envelope pass.
struct Envelope {
  std::vector<int> v;
  std::vector<double> z;
  explicit Envelope(int n) : v(n), z(n + 1) {}

  // d[q] = min_p (q - p)^2 + f[p]; arg[q] = the minimising p (-1 if every f is far).
  void run(const std::int32_t* f, int n, std::int32_t* d, int* arg) {
    int k = -1;
    for (int q = 0; q < n; ++q) {
      if (f[q] >= kFar) continue;
      const double fq = static_cast<double>(f[q]) + static_cast<double>(q) * q;
      double s = 0;
      while (k >= 0) {
        const int p = v[k];
        s = (fq - (static_cast<double>(f[p]) + static_cast<double>(p) * p)) / (2.0 * (q - p));
        if (s <= z[k]) {
          --k;
        } else {
          break;
        }
      }
      ++k;
      v[k] = q;
      z[k] = k == 0 ? -std::numeric_limits<double>::infinity() : s;
      z[k + 1] = std::numeric_limits<double>::infinity();
    }
    if (k < 0) {
      std::fill(d, d + n, kFar);
      if (arg) std::fill(arg, arg + n, -1);
      return;
    }
    k = 0;
    for (int q = 0; q < n; ++q) {
      while (z[k + 1] < q) ++k;
      const int p = v[k];
      d[q] = (q - p) * (q - p) + f[p];
      if (arg) arg[q] = p;
    }
  }
};

void checkDims(const GridDims& dims) {
  if (dims.nx < 1 || dims.ny < 1 || dims.nz < 1 || dims.nx > kMaxGridSide || dims.ny > kMaxGridSide ||
      dims.nz > kMaxGridSide)
    throw Error("voxel grid " + std::to_string(dims.nx) + "x" + std::to_string(dims.ny) + "x" +
                std::to_string(dims.nz) + " is empty or has a side above " + std::to_string(kMaxGridSide));
}

using packed::px;
using packed::py;
using packed::pz;

// The three passes. `feature` (optional) receives the nearest surface voxel's packed
// coordinates (x | y << 10 | z << 20).
std::vector<std::int32_t> transform(const GridDims& dims, std::span<const std::uint8_t> surface,
                                    std::vector<std::uint32_t>* feature) {
  checkDims(dims);
  const int nx = dims.nx, ny = dims.ny, nz = dims.nz;
  std::vector<std::int32_t> g(dims.count());
  std::vector<std::uint32_t> fx;  // feature x, then feature index
  if (feature) fx.resize(dims.count());
  bool any = false;

  // Pass 1, along x: two sweeps per row.
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y) {
      const std::size_t row = dims.index(0, y, z);
      int last = -1;
      for (int x = 0; x < nx; ++x) {
        if (surface[row + x]) last = x;
        g[row + x] = last < 0 ? kFar : (x - last) * (x - last);
        if (feature) fx[row + x] = static_cast<std::uint32_t>(last);
      }
      if (last >= 0) any = true;
      last = -1;
      for (int x = nx - 1; x >= 0; --x) {
        if (surface[row + x]) last = x;
        if (last >= 0 && (last - x) * (last - x) < g[row + x]) {
          g[row + x] = (last - x) * (last - x);
          if (feature) fx[row + x] = static_cast<std::uint32_t>(last);
        }
      }
    }
  if (!any) throw Error("no surface voxel to propagate from (empty or degenerate mesh)");

  // Passes 2 and 3, along y and z: gather a column, take the envelope, scatter.
  const int longest = std::max({nx, ny, nz});
  Envelope envelope(longest);
  std::vector<std::int32_t> column(longest), result(longest);
  std::vector<int> arg(longest);
  std::vector<std::uint32_t> featureColumn(feature ? longest : 0);
  for (int pass = 0; pass < 2; ++pass) {
    const int n = pass == 0 ? ny : nz;
    const std::size_t stride = pass == 0 ? static_cast<std::size_t>(nx) : static_cast<std::size_t>(nx) * ny;
    const int outer = pass == 0 ? nz : ny;
    for (int o = 0; o < outer; ++o)
      for (int x = 0; x < nx; ++x) {
        const std::size_t base = pass == 0 ? dims.index(x, 0, o) : dims.index(x, o, 0);
        for (int q = 0; q < n; ++q) column[q] = g[base + q * stride];
        envelope.run(column.data(), n, result.data(), feature ? arg.data() : nullptr);
        if (feature) {
          for (int q = 0; q < n; ++q) featureColumn[q] = fx[base + q * stride];
          for (int q = 0; q < n; ++q) {
            if (arg[q] < 0) continue;
            const std::uint32_t f = featureColumn[arg[q]];
            // After pass 2 a feature is x | y << 10; pass 3 adds z << 20.
            fx[base + q * stride] = f | (static_cast<std::uint32_t>(arg[q]) << (pass == 0 ? 10 : 20));
          }
        }
        for (int q = 0; q < n; ++q) g[base + q * stride] = result[q];
      }
  }
  if (feature) *feature = std::move(fx);
  return g;
}

}  // namespace

std::vector<std::int32_t> exactDistance2(const GridDims& dims, std::span<const std::uint8_t> surface) {
  return transform(dims, surface, nullptr);
}

Propagation exactFeatureTransform(const GridDims& dims, std::span<const std::uint8_t> surface,
                                  const PropagationOptions& options) {
  Propagation result;
  result.dims = dims;
  result.shellDistance2 = options.shellDistance2;
  std::vector<std::uint32_t> feature;
  result.distance2 = transform(dims, surface, options.shellDistance2 >= 0 ? &feature : nullptr);
  if (options.shellDistance2 < 0) {
    result.refStart.push_back(0);
    return result;
  }
  // References in the shell: the voxel's feature and the equally near features of its neighbours.
  std::uint32_t candidates[27];
  const std::int64_t sy = dims.nx, sz = static_cast<std::int64_t>(dims.nx) * dims.ny;
  for (int z = 0; z < dims.nz; ++z)
    for (int y = 0; y < dims.ny; ++y)
      for (int x = 0; x < dims.nx; ++x) {
        const std::uint32_t v = dims.index(x, y, z);
        const std::int32_t d2 = result.distance2[v];
        if (d2 > options.shellDistance2) continue;
        int count = 0;
        const bool interior = x > 0 && y > 0 && z > 0 && x < dims.nx - 1 && y < dims.ny - 1 && z < dims.nz - 1;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              if (!interior && !dims.contains(x + dx, y + dy, z + dz)) continue;
              const std::uint32_t f = feature[v + dx + dy * sy + dz * sz];
              const int ex = x - px(f), ey = y - py(f), ez = z - pz(f);
              if (ex * ex + ey * ey + ez * ez == d2) candidates[count++] = f;
            }
        std::sort(candidates, candidates + count);
        result.shellVoxels.push_back(v);
        result.refStart.push_back(static_cast<std::uint32_t>(result.refs.size()));
        for (int c = 0; c < count; ++c)
          if (c == 0 || candidates[c] != candidates[c - 1])
            result.refs.push_back(dims.index(px(candidates[c]), py(candidates[c]), pz(candidates[c])));
      }
  result.refStart.push_back(static_cast<std::uint32_t>(result.refs.size()));
  return result;
}

}  // namespace drape::field
