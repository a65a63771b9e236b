#include "drape/field/distance_field.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <string>

#include "drape/core/error.hpp"

namespace drape::field {
namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

template <class T>
std::size_t bytesOf(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

void checkMesh(const mesh::TriMesh& part) {
  if (part.triangles.empty()) throw Error(part.name + ": the body part has no triangles");
  for (const Vec3& p : part.positions)
    if (!p.allFinite()) throw Error(part.name + ": a vertex position is not finite");
  for (const mesh::Triangle& t : part.triangles)
    for (std::uint32_t v : t)
      if (v >= part.positions.size()) throw Error(part.name + ": a triangle names a vertex that does not exist");
}

}  // namespace

GridPlacement placeGrid(const Aabb& box, const FieldSettings& settings, int border) {
  GridPlacement g;
  const Vec3 extent = box.size();
  const bool fixedDims = settings.dims[0] > 0 && settings.dims[1] > 0 && settings.dims[2] > 0;
  int n[3];
  if (fixedDims) {
    double h = 0;
    for (int a = 0; a < 3; ++a) {
      const int inner = settings.dims[a] - 2 * border;
      if (inner < 1)
        throw Error("--dims " + std::to_string(settings.dims[a]) + " leaves no room inside a border of " +
                    std::to_string(border));
      h = std::max(h, extent[a] / inner);
      n[a] = settings.dims[a];
    }
    if (!(h > 0)) throw Error("the body part's bounding box is empty");
    g.voxelSize = h;
  } else {
    const double h = settings.voxelSize_m;
    if (!(h > 0) || !std::isfinite(h)) throw Error("--voxel must be a positive size in metres");
    for (int a = 0; a < 3; ++a) {
      const double inner = std::max(1.0, std::ceil(extent[a] / h));
      if (inner + 2.0 * border > kMaxGridSide)
        throw Error("--voxel " + std::to_string(h) + " m gives more than " + std::to_string(kMaxGridSide) +
                    " voxels along an axis of this body part (" + std::to_string(extent[a]) + " m)");
      n[a] = static_cast<int>(inner) + 2 * border;
    }
    g.voxelSize = h;
  }
  for (int a = 0; a < 3; ++a)
    if (n[a] > kMaxGridSide) throw Error("a grid side above " + std::to_string(kMaxGridSide) + " voxels");
  g.dims = {n[0], n[1], n[2]};
  if (g.dims.count() > kMaxVoxels)
    throw Error("the grid of " + std::to_string(n[0]) + "x" + std::to_string(n[1]) + "x" + std::to_string(n[2]) +
                " voxels exceeds " + std::to_string(kMaxVoxels) + " voxels: choose a larger --voxel");
  const Vec3 span(n[0] * g.voxelSize, n[1] * g.voxelSize, n[2] * g.voxelSize);
  g.origin = box.center() - 0.5 * span;
  return g;
}

DistanceField DistanceField::build(const mesh::TriMesh& part, const FieldSettings& settings) {
  checkMesh(part);
  if (!(settings.shell_m >= 0) || !(settings.shellVoxels >= 0)) throw Error("--shell must not be negative");
  const bool fixedDims = settings.dims[0] > 0 && settings.dims[1] > 0 && settings.dims[2] > 0;
  const Aabb box = part.bounds();

  // Border: the shell plus the tagged layer plus one voxel of slack.
  int border = settings.borderVoxels;
  if (border <= 0) {
    if (fixedDims) {
      border = 8;
    } else {
      const double shellVox = settings.shellVoxels > 0 ? settings.shellVoxels : settings.shell_m / settings.voxelSize_m;
      border = static_cast<int>(std::ceil(shellVox - 1e-9)) + 2;
    }
  }
  const GridPlacement grid = placeGrid(box, settings, border);
  const double shellVox = settings.shellVoxels > 0 ? settings.shellVoxels : settings.shell_m / grid.voxelSize;
  if (border < 2 || border - 1 < static_cast<int>(std::ceil(shellVox - 1e-9)))
    throw Error("--border " + std::to_string(border) + " voxels cannot hold the shell of " + std::to_string(shellVox) +
                " voxels plus the border layer");

  DistanceField f;
  f.dims_ = grid.dims;
  f.voxelSize_ = grid.voxelSize;
  f.metresPerUnit_ = grid.voxelSize / kUnitsPerVoxel;
  f.origin_ = grid.origin;
  f.bodyBounds_ = box;
  f.shell_m_ = shellVox * grid.voxelSize;
  f.method_ = settings.method;

  // 1. Voxelize.
  auto start = std::chrono::steady_clock::now();
  Voxelization vox = voxelize(part, grid);
  f.stats_.voxelizeMs = msSince(start);

  // 2. Propagate.
  start = std::chrono::steady_clock::now();
  std::vector<std::uint8_t> surface(vox.flags.size());
  for (std::size_t i = 0; i < surface.size(); ++i) surface[i] = vox.flags[i] & kVoxelSurface;
  PropagationOptions options;
  options.shellDistance2 = static_cast<int>(std::floor(shellVox * shellVox + 1e-9));
  Propagation prop = settings.method == FieldMethod::Exact ? exactFeatureTransform(grid.dims, surface, options)
                                                           : propagateDvdp(grid.dims, surface, options);
  f.stats_.propagateMs = msSince(start);

  // 3. Compact storage: signed fixed-point distances, flags, normals.
  start = std::chrono::steady_clock::now();
  const std::size_t n = grid.dims.count();
  f.flags_ = std::move(vox.flags);
  f.distance_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::min(32767.0, std::round(std::sqrt(static_cast<double>(prop.distance2[i])) * kUnitsPerVoxel));
    const bool negative = (f.flags_[i] & kVoxelInside) && !(f.flags_[i] & kVoxelSurface);
    f.distance_[i] = static_cast<std::int16_t>(negative ? -d : d);
    if (f.flags_[i] & kVoxelInside) ++f.stats_.insideVoxels;
  }
  f.surfaceVoxels_ = std::move(vox.surfaceVoxels);
  f.surfaceNormalStart_ = std::move(vox.normalStart);
  f.surfaceNormals_ = std::move(vox.normals);

  // Per surface voxel: the unit mean of its triangles' normals, found through a scratch map.
  std::unique_ptr<std::uint32_t[]> surfaceSlot(new std::uint32_t[n]);
  std::vector<Vec3f> surfaceMean(f.surfaceVoxels_.size());
  for (std::size_t k = 0; k < f.surfaceVoxels_.size(); ++k) {
    surfaceSlot[f.surfaceVoxels_[k]] = static_cast<std::uint32_t>(k);
    Vec3f sum = Vec3f::Zero();
    for (std::uint32_t j = f.surfaceNormalStart_[k]; j < f.surfaceNormalStart_[k + 1]; ++j) sum += f.surfaceNormals_[j];
    surfaceMean[k] = sum.norm() > 0 ? Vec3f(sum.normalized()) : Vec3f::Zero();
  }

  // Normals: the Voronoi cell's surface normals within the shell, the gradient beyond.
  f.normal_.assign(n, 0);
  std::vector<std::uint8_t> haveNormal(n, 0);
  for (std::size_t k = 0; k < prop.shellVoxels.size(); ++k) {
    const std::uint32_t v = prop.shellVoxels[k];
    f.flags_[v] |= kVoxelShell;
    Vec3f sum = Vec3f::Zero();
    for (std::uint32_t r : prop.refsOf(k)) sum += surfaceMean[surfaceSlot[r]];
    if (sum.squaredNorm() > 1e-12f) {
      f.normal_[v] = encodeNormal(sum.cast<double>().normalized());
      haveNormal[v] = 1;
    }
  }
  const GridDims& d = grid.dims;
  for (int z = 0; z < d.nz; ++z)
    for (int y = 0; y < d.ny; ++y)
      for (int x = 0; x < d.nx; ++x) {
        const std::uint32_t v = d.index(x, y, z);
        if (haveNormal[v]) continue;
        auto at = [&](int xx, int yy, int zz) {
          return static_cast<double>(f.distance_[d.index(std::clamp(xx, 0, d.nx - 1), std::clamp(yy, 0, d.ny - 1),
                                                         std::clamp(zz, 0, d.nz - 1))]);
        };
        const Vec3 g(at(x + 1, y, z) - at(x - 1, y, z), at(x, y + 1, z) - at(x, y - 1, z),
                     at(x, y, z + 1) - at(x, y, z - 1));
        f.normal_[v] = g.squaredNorm() > 0 ? encodeNormal(g.normalized()) : encodeNormal(Vec3::UnitZ());
      }
  f.shellVoxels_ = std::move(prop.shellVoxels);
  f.refStart_ = std::move(prop.refStart);
  f.refs_ = std::move(prop.refs);
  (void)decodedNormals();  // built here, not in the first collision step that reads a normal
  f.stats_.finishMs = msSince(start);

  for (auto* v : {&f.shellVoxels_, &f.refStart_, &f.refs_, &f.surfaceVoxels_, &f.surfaceNormalStart_})
    v->shrink_to_fit();
  f.surfaceNormals_.shrink_to_fit();
  f.stats_.voxels = n;
  f.stats_.surfaceVoxels = f.surfaceVoxels_.size();
  f.stats_.shellVoxels = f.shellVoxels_.size();
  f.stats_.references = f.refs_.size();
  f.stats_.bytes = f.memoryBytes();
  return f;
}

bool DistanceField::containsPoint(const Vec3& p) const {
  const Vec3 c = (p - origin_) / voxelSize_;
  return c.x() >= 0 && c.y() >= 0 && c.z() >= 0 && c.x() < dims_.nx && c.y() < dims_.ny && c.z() < dims_.nz;
}

std::uint32_t DistanceField::voxelAt(const Vec3& p) const {
  const Vec3 c = (p - origin_) / voxelSize_;
  const int x = std::clamp(static_cast<int>(std::floor(c.x())), 0, dims_.nx - 1);
  const int y = std::clamp(static_cast<int>(std::floor(c.y())), 0, dims_.ny - 1);
  const int z = std::clamp(static_cast<int>(std::floor(c.z())), 0, dims_.nz - 1);
  return dims_.index(x, y, z);
}

Aabb DistanceField::bounds() const {
  Aabb box;
  box.min = origin_;
  box.max = origin_ + Vec3(dims_.nx, dims_.ny, dims_.nz) * voxelSize_;
  return box;
}

double DistanceField::distanceAt(const Vec3& p) const { return distanceAtVoxel(toVoxel(p)); }

Vec3 DistanceField::normalAt(const Vec3& p) const { return sampleAtVoxel(toVoxel(p)).normal; }

PointLocation DistanceField::locate(const Vec3& p) const {
  PointLocation l;
  l.voxel = voxelAt(p);
  l.inVolume = containsPoint(p) && !isBorder(l.voxel);
  l.distance_m = distanceAt(p);
  return l;
}

std::span<const std::uint32_t> DistanceField::references(std::uint32_t voxel) const {
  const auto it = std::lower_bound(shellVoxels_.begin(), shellVoxels_.end(), voxel);
  if (it == shellVoxels_.end() || *it != voxel) return {};
  const std::size_t k = static_cast<std::size_t>(it - shellVoxels_.begin());
  return {refs_.data() + refStart_[k], refStart_[k + 1] - refStart_[k]};
}

std::span<const Vec3f> DistanceField::surfaceNormals(std::uint32_t voxel) const {
  const auto it = std::lower_bound(surfaceVoxels_.begin(), surfaceVoxels_.end(), voxel);
  if (it == surfaceVoxels_.end() || *it != voxel) return {};
  const std::size_t k = static_cast<std::size_t>(it - surfaceVoxels_.begin());
  return {surfaceNormals_.data() + surfaceNormalStart_[k], surfaceNormalStart_[k + 1] - surfaceNormalStart_[k]};
}

std::size_t DistanceField::memoryBytes() const {
  return bytesOf(distance_) + bytesOf(flags_) + bytesOf(normal_) + bytesOf(shellVoxels_) + bytesOf(refStart_) +
         bytesOf(refs_) + bytesOf(surfaceVoxels_) + bytesOf(surfaceNormalStart_) + bytesOf(surfaceNormals_);
}

std::uint16_t DistanceField::encodeNormal(const Vec3& n) {
  // Octahedral mapping into two signed bytes.
  const double l1 = std::abs(n.x()) + std::abs(n.y()) + std::abs(n.z());
  double u = n.x() / l1, v = n.y() / l1;
  if (n.z() < 0) {
    const double uu = (1 - std::abs(v)) * (u >= 0 ? 1 : -1);
    const double vv = (1 - std::abs(u)) * (v >= 0 ? 1 : -1);
    u = uu;
    v = vv;
  }
  const auto q = [](double a) { return static_cast<std::uint8_t>(static_cast<std::int8_t>(std::lround(a * 127))); };
  return static_cast<std::uint16_t>(q(u) | (q(v) << 8));
}

Vec3 DistanceField::decodeNormal(std::uint16_t code) {
  const double u = static_cast<std::int8_t>(code & 0xff) / 127.0;
  const double v = static_cast<std::int8_t>(code >> 8) / 127.0;
  Vec3 n(u, v, 1 - std::abs(u) - std::abs(v));
  if (n.z() < 0) {
    n.x() = (1 - std::abs(v)) * (u >= 0 ? 1 : -1);
    n.y() = (1 - std::abs(u)) * (v >= 0 ? 1 : -1);
  }
  return n.normalized();
}

const Vec3f* DistanceField::decodedNormals() {
  static const std::vector<Vec3f> table = [] {
    std::vector<Vec3f> t(65536);
    for (std::size_t code = 0; code < t.size(); ++code) t[code] = decodeNormal(static_cast<std::uint16_t>(code)).cast<float>();
    return t;
  }();
  return table.data();
}

}  // namespace drape::field
