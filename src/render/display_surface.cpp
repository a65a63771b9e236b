#include "drape/render/display_surface.hpp"

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "drape/core/error.hpp"

namespace drape::render {
namespace {

namespace osd = OpenSubdiv::Far;
namespace sdc = OpenSubdiv::Sdc;

/// A position as OpenSubdiv's primvar refiner wants it: cleared, then summed with weights.
struct Point {
  double x, y, z;
  void Clear(void* = nullptr) { x = y = z = 0.0; }
  void AddWithWeight(const Point& p, double w) {
    x += w * p.x;
    y += w * p.y;
    z += w * p.z;
  }
};

/// A vertex state refined as the state of the heaviest source of the rule (the first of
/// equal ones): a vertex's own child takes the vertex's (its weight is at least 7/16 of the
/// vertex rule, each neighbour's at most 3/16), an edge's child one end's.
struct State {
  std::uint8_t bits;
  double weight;
  void Clear(void* = nullptr) {
    bits = 0;
    weight = -1.0;
  }
  void AddWithWeight(const State& s, double w) {
    if (w > weight) {
      weight = w;
      bits = s.bits;
    }
  }
};

}  // namespace

struct LoopSurface::Impl {
  std::unique_ptr<osd::TopologyRefiner> refiner;
  std::vector<std::size_t> levelStart;  ///< first vertex of each level in the one buffer of all levels
  std::vector<mesh::Triangle> triangles;
  std::vector<std::int32_t> childOf;  ///< per simulated vertex: its own child in the last level, or -1
  std::vector<Point> points;  ///< every level's vertices, one level after the other
  std::vector<State> states;
  std::vector<Point> limit;

  [[nodiscard]] int levels() const { return refiner->GetMaxLevel(); }
  [[nodiscard]] std::size_t refinedCount() const {
    return static_cast<std::size_t>(refiner->GetLevel(levels()).GetNumVertices());
  }
};

LoopSurface::LoopSurface(std::size_t vertexCount, std::span<const mesh::Triangle> triangles, int levels)
    : impl_(std::make_unique<Impl>()) {
  if (levels < 1 || levels > 8) throw Error(fmt::format("subdivision levels must be 1 to 8, not {}", levels));
  std::vector<int> perFace(triangles.size(), 3);
  std::vector<int> indices;
  indices.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const mesh::Triangle& tri = triangles[t];
    for (const std::uint32_t v : tri)
      if (v >= vertexCount)
        throw Error(fmt::format("triangle {} uses vertex {} of a mesh of {}", t + 1, v, vertexCount));
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2])
      throw Error(fmt::format("triangle {} repeats a vertex ({} {} {})", t + 1, tri[0], tri[1], tri[2]));
    indices.insert(indices.end(), tri.begin(), tri.end());
  }
  osd::TopologyDescriptor descriptor;
  descriptor.numVertices = static_cast<int>(vertexCount);
  descriptor.numFaces = static_cast<int>(triangles.size());
  descriptor.numVertsPerFace = perFace.data();
  descriptor.vertIndicesPerFace = indices.data();
  // The garment's open edges (a hem, a cuff) stay where the cloth ends: boundary edges are
  // sharp, as a hem is, and the corners of a boundary keep their place.
  sdc::Options options;
  options.SetVtxBoundaryInterpolation(sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  using Factory = osd::TopologyRefinerFactory<osd::TopologyDescriptor>;
  impl_->refiner.reset(Factory::Create(descriptor, Factory::Options(sdc::SCHEME_LOOP, options)));
  if (!impl_->refiner) throw Error("OpenSubdiv refused the mesh's topology");
  osd::TopologyRefiner::UniformOptions uniform(levels);
  uniform.fullTopologyInLastLevel = true;  // the limit needs the last level's neighbourhoods
  impl_->refiner->RefineUniform(uniform);

  impl_->levelStart.assign(1, 0);
  for (int l = 0; l <= levels; ++l)
    impl_->levelStart.push_back(impl_->levelStart.back() +
                                static_cast<std::size_t>(impl_->refiner->GetLevel(l).GetNumVertices()));
  impl_->points.resize(impl_->levelStart.back());
  impl_->states.resize(impl_->levelStart.back());
  impl_->limit.resize(impl_->refinedCount());

  const osd::TopologyLevel& last = impl_->refiner->GetLevel(levels);
  impl_->triangles.resize(static_cast<std::size_t>(last.GetNumFaces()));
  for (int f = 0; f < last.GetNumFaces(); ++f) {
    const auto v = last.GetFaceVertices(f);
    impl_->triangles[static_cast<std::size_t>(f)] = {static_cast<std::uint32_t>(v[0]), static_cast<std::uint32_t>(v[1]),
                                                     static_cast<std::uint32_t>(v[2])};
  }
  // Each simulated vertex's child of its child ... down to the last level.
  impl_->childOf.assign(vertexCount, -1);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    int child = static_cast<int>(v);
    for (int l = 0; l < levels && child >= 0; ++l) child = impl_->refiner->GetLevel(l).GetVertexChildVertex(child);
    impl_->childOf[v] = child;
  }
}

LoopSurface::~LoopSurface() = default;
LoopSurface::LoopSurface(LoopSurface&&) noexcept = default;
LoopSurface& LoopSurface::operator=(LoopSurface&&) noexcept = default;

std::size_t LoopSurface::vertexCount() const { return impl_->refinedCount(); }
const std::vector<mesh::Triangle>& LoopSurface::triangles() const { return impl_->triangles; }

void LoopSurface::positions(std::span<const Vec3> coarse, std::vector<Vec3>& out) {
  Impl& s = *impl_;
  const std::size_t n0 = s.levelStart[1];
  if (coarse.size() != n0)
    throw Error(fmt::format("subdivision: {} positions for a mesh of {} vertices", coarse.size(), n0));
  const osd::PrimvarRefinerReal<double> refine(*s.refiner);
  // The limit surface of the points in the first n0 of `points`, into `limit`.
  const auto limitSurface = [&] {
    for (int l = 1; l <= s.levels(); ++l) {
      Point* const src = s.points.data() + s.levelStart[static_cast<std::size_t>(l) - 1];
      Point* dst = s.points.data() + s.levelStart[static_cast<std::size_t>(l)];
      refine.Interpolate(l, src, dst);
    }
    Point* const lastLevel = s.points.data() + s.levelStart[static_cast<std::size_t>(s.levels())];
    Point* limit = s.limit.data();
    refine.Limit(lastLevel, limit);
  };
  // Loop's limit surface lies inside a convex mesh (8-9 % of the radius of an 80-triangle
  // sphere, inside its triangles' centroids): drawn so, a sleeve would sink into the arm it
  // is simulated around. So the mesh is first moved out by what the limit takes off at each
  // simulated vertex (c = x + (x - L x)), and the surface of c passes near the simulated
  // vertices again (that sphere's within 0.2-1.1 % of its radius; tests/render).
  for (std::size_t v = 0; v < n0; ++v) s.points[v] = {coarse[v].x(), coarse[v].y(), coarse[v].z()};
  limitSurface();
  for (std::size_t v = 0; v < n0; ++v) {
    if (s.childOf[v] < 0) continue;  // a vertex of no triangle: no surface to correct
    const Point& at = s.limit[static_cast<std::size_t>(s.childOf[v])];
    s.points[v] = {2.0 * coarse[v].x() - at.x, 2.0 * coarse[v].y() - at.y, 2.0 * coarse[v].z() - at.z};
  }
  limitSurface();
  out.resize(s.limit.size());
  for (std::size_t v = 0; v < s.limit.size(); ++v) out[v] = Vec3(s.limit[v].x, s.limit[v].y, s.limit[v].z);
}

void LoopSurface::states(std::span<const std::uint8_t> coarse, std::vector<std::uint8_t>& out) {
  Impl& s = *impl_;
  const std::size_t n0 = s.levelStart[1];
  if (coarse.size() != n0)
    throw Error(fmt::format("subdivision: {} vertex states for a mesh of {} vertices", coarse.size(), n0));
  for (std::size_t v = 0; v < n0; ++v) s.states[v] = {coarse[v], 1.0};
  const osd::PrimvarRefinerReal<double> refine(*s.refiner);
  for (int l = 1; l <= s.levels(); ++l) {
    State* const src = s.states.data() + s.levelStart[static_cast<std::size_t>(l) - 1];
    State* dst = s.states.data() + s.levelStart[static_cast<std::size_t>(l)];
    refine.Interpolate(l, src, dst);
  }
  const State* lastLevel = s.states.data() + s.levelStart[static_cast<std::size_t>(s.levels())];
  out.resize(s.refinedCount());
  for (std::size_t v = 0; v < out.size(); ++v)
    out[v] = static_cast<std::uint8_t>(lastLevel[v].bits & vertex_state::kCollisionMask);
  // The simulated vertices' own children keep their pin and bound flags too.
  for (std::size_t v = 0; v < n0; ++v)
    if (s.childOf[v] >= 0) out[static_cast<std::size_t>(s.childOf[v])] = coarse[v];
}

SubdividedSource::SubdividedSource(FrameSource& inner, int levels) : inner_(inner), meshes_(inner.meshes()) {
  surfaces_.resize(meshes_.size());
  if (levels <= 0) return;
  for (std::size_t m = 0; m < meshes_.size(); ++m) {
    MeshInfo& info = meshes_[m];
    if (info.role != MeshRole::Garment) continue;
    try {
      surfaces_[m].emplace(info.vertexCount, info.triangles, levels);
    } catch (const Error& e) {
      spdlog::warn("garment '{}' is drawn as simulated, not subdivided: {}", info.name, e.what());
      continue;
    }
    info.vertexCount = surfaces_[m]->vertexCount();
    info.triangles = surfaces_[m]->triangles();
  }
}

SubdividedSource::~SubdividedSource() = default;

bool SubdividedSource::read(std::int64_t index, Frame& out) {
  if (!inner_.read(index, coarse_)) return false;
  out.index = coarse_.index;
  out.time = coarse_.time;
  out.stages = coarse_.stages;
  out.positions.resize(coarse_.positions.size());
  out.states.resize(coarse_.states.size());
  for (std::size_t m = 0; m < coarse_.positions.size(); ++m) {
    const bool refined = m < surfaces_.size() && surfaces_[m].has_value();
    if (!refined) {
      out.positions[m] = coarse_.positions[m];
      if (m < coarse_.states.size()) out.states[m] = coarse_.states[m];
      continue;
    }
    surfaces_[m]->positions(coarse_.positions[m], out.positions[m]);
    if (m < coarse_.states.size()) {
      if (coarse_.states[m].empty()) out.states[m].clear();
      else surfaces_[m]->states(coarse_.states[m], out.states[m]);
    }
  }
  return true;
}

}  // namespace drape::render
