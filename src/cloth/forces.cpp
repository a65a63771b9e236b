#include "drape/cloth/forces.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace drape::cloth {
namespace {

/// a * b + c, as one fused multiply-add (one rounding) where the build's processor has them.
/// The kernels fuse where they say so, not where the compiler may (the build does not
/// contract, docs/ARCHITECTURE.md "Build"): an edit elsewhere in the file cannot change
/// their rounding. On AVX2 the fused kernels take about a tenth less time (their loops
/// issue fewer instructions, docs/PERFORMANCE.md); a build without FMA (the portable and
/// the test builds) multiplies and adds.
inline double madd(double a, double b, double c) {
#ifdef __FMA__
  return __builtin_fma(a, b, c);
#else
  return a * b + c;
#endif
}

struct V3 {
  double x, y, z;
};
inline V3 sub(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 add(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 mul(V3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
/// a s + b t.
inline V3 combine(V3 a, double s, V3 b, double t) {
  return {madd(a.x, s, b.x * t), madd(a.y, s, b.y * t), madd(a.z, s, b.z * t)};
}
inline double dot(V3 a, V3 b) { return madd(a.x, b.x, madd(a.y, b.y, a.z * b.z)); }
inline V3 cross(V3 a, V3 b) {
  return {madd(a.y, b.z, -(a.z * b.y)), madd(a.z, b.x, -(a.x * b.z)), madd(a.x, b.y, -(a.y * b.x))};
}
inline V3 load(const double* x, const double* y, const double* z, std::int64_t i) { return {x[i], y[i], z[i]}; }

/// Symmetric 2x2 tensor (11, 22, 12).
struct Sym2 {
  double a, b, c;
};

/// Scales the compressive principal part of the stress S by `scale` (S and the strain share
/// principal directions, so a tension direction keeps its full stress). Branch-free (every
/// case computed, one selected) so that the membrane loop vectorises. With principal
/// stresses s1 >= s2, the compressive part s2 u2 u2^T uses the projector
/// u2 u2^T = (S - s1 I) / (s2 - s1), and s2 (S - s1 I) = s2 S - det(S) I: no eigenvector to
/// find and normalise, one square root and one division per element (they are what the
/// loop waits on).
inline Sym2 softenCompression(Sym2 s, double scale) {
  const double mean = 0.5 * (s.a + s.b);
  const double half = 0.5 * (s.a - s.b);
  const double radius = std::sqrt(madd(half, half, s.c * s.c));
  const double s1 = mean + radius, s2 = mean - radius;
  const double det = madd(s.a, s.b, -(s.c * s.c));
  // Selected only where s2 < 0 < s1, so 2 radius > 0 there; the bound keeps other lanes finite.
  const double f = (scale - 1.0) / std::max(2.0 * radius, 1e-300);
  const Sym2 mixed{madd(-f, madd(s2, s.a, -det), s.a), madd(-f, madd(s2, s.b, -det), s.b), madd(-f * s2, s.c, s.c)};
  const Sym2 both{s.a * scale, s.b * scale, s.c * scale};
  const bool tension = s2 >= 0.0, compression = s1 <= 0.0;
  return {tension ? s.a : compression ? both.a : mixed.a, tension ? s.b : compression ? both.b : mixed.b,
          tension ? s.c : compression ? both.c : mixed.c};
}

/// body(begin, end) over [0, count): at once without `loop`, else in pieces of at least
/// `grain` on TBB's threads (the pieces' work must not overlap).
template <typename Body>
void forPieces(PieceLoop* loop, std::size_t count, std::size_t grain, const Body& body) {
  if (loop == nullptr || count <= grain) {
    if (count > 0) body(std::size_t{0}, count);
    return;
  }
  (*loop)(count, grain, body);
}

/// One of the loops, or none (one thread) without them.
PieceLoop* loopOf(ForceLoops* loops, PieceLoop ForceLoops::*which) { return loops ? &(loops->*which) : nullptr; }

/// Elements (vertices) per piece of a parallel pass: a few microseconds of work each.
constexpr std::size_t kPieceElements = 256;

struct MembraneConstants {
  double lambda, mu, beta, softScale;
};

// The kernels run in two passes. Pass 1 (per element, gathers only, no scatter) computes
// every element's corner forces into the workspace, one column per component; pass 2
// (scalar) adds them to the vertices per vertex over its corners (CSR): the membrane every
// substep (4.1 instead of 4.3 us on a 480-triangle sheet against a scatter), the hinges
// every bendEvery substeps. Pass 1 takes its arrays as restrict parameters: GCC 12
// vectorises it so (gathers included), and not with the same pointers as function locals.
// GCC builds each gathered vector from scalar loads and inserts; in a run (elements whose
// corners are consecutive vertices, model.hpp) one vector load per coordinate does, and
// vertices whose corners come from the same runs are summed eight at a time: 5.1 -> 3.7-3.9
// us for the membrane of the 480-triangle walking skirt. Pass 2 adds in the element lists'
// order, so the forces are the same to the bit with and without runs.

/// Membrane pass 1: the corner forces of every triangle into w (columns f0x f0y f0z f1x f1y
/// f1z f2x f2y f2z; f0 = -(f1 + f2)). Corner c of triangle t is vertex ic[t]. With kRuns, n
/// blocks of kKernelRun triangles in runs (MembraneArrays), the first at blocks[k]: their
/// vertices are loaded as vectors from the block's first ones instead of gathered.
template <bool kDamp, bool kSoften, bool kRuns>
void membraneCornerForces(std::size_t n, const std::int32_t* __restrict blocks, const MembraneConstants& k,
                          const double* __restrict x, const double* __restrict y, const double* __restrict z,
                          const double* __restrict vx, const double* __restrict vy, const double* __restrict vz,
                          const std::int32_t* __restrict i0, const std::int32_t* __restrict i1,
                          const std::int32_t* __restrict i2, const double* __restrict g1u,
                          const double* __restrict g1v, const double* __restrict g2u, const double* __restrict g2v,
                          const double* __restrict area, double* __restrict f0x, double* __restrict f0y,
                          double* __restrict f0z, double* __restrict f1x, double* __restrict f1y,
                          double* __restrict f1z, double* __restrict f2x, double* __restrict f2y,
                          double* __restrict f2z) {
  const double lambda = k.lambda, mu = k.mu, beta = k.beta, softScale = k.softScale;
  const auto element = [&](std::size_t t, std::int64_t j0, std::int64_t j1, std::int64_t j2)
                           __attribute__((always_inline)) {
    // Deformation gradient columns Fu, Fv (F = d1 (x) g1 + d2 (x) g2).
    const V3 p0 = load(x, y, z, j0);
    const V3 d1 = sub(load(x, y, z, j1), p0);
    const V3 d2 = sub(load(x, y, z, j2), p0);
    const V3 fu = combine(d1, g1u[t], d2, g2u[t]);
    const V3 fv = combine(d1, g1v[t], d2, g2v[t]);

    // Green strain E = (F^T F - I) / 2 and St Venant-Kirchhoff plane stress S (N/m).
    const double e11 = 0.5 * (dot(fu, fu) - 1.0), e22 = 0.5 * (dot(fv, fv) - 1.0), e12 = 0.5 * dot(fu, fv);
    const double tr = e11 + e22;
    Sym2 s{madd(lambda, tr, 2.0 * mu * e11), madd(lambda, tr, 2.0 * mu * e22), 2.0 * mu * e12};
    if constexpr (kSoften) s = softenCompression(s, softScale);

    // Internal damping: the same constitutive law applied to the strain rate, times beta (s).
    if constexpr (kDamp) {
      const V3 w0 = load(vx, vy, vz, j0);
      const V3 w1 = sub(load(vx, vy, vz, j1), w0);
      const V3 w2 = sub(load(vx, vy, vz, j2), w0);
      const V3 du = combine(w1, g1u[t], w2, g2u[t]);
      const V3 dv = combine(w1, g1v[t], w2, g2v[t]);
      const double r11 = dot(fu, du), r22 = dot(fv, dv), r12 = 0.5 * (dot(du, fv) + dot(fu, dv));
      const double rtr = r11 + r22;
      s.a = madd(beta, madd(lambda, rtr, 2.0 * mu * r11), s.a);
      s.b = madd(beta, madd(lambda, rtr, 2.0 * mu * r22), s.b);
      s.c = madd(beta * 2.0 * mu, r12, s.c);
    }

    // First Piola stress P = F S; f_i = -A P g_i = c_i1 Fu + c_i2 Fv.
    const double A = area[t];
    const double c11 = -A * madd(s.a, g1u[t], s.c * g1v[t]), c12 = -A * madd(s.c, g1u[t], s.b * g1v[t]);
    const double c21 = -A * madd(s.a, g2u[t], s.c * g2v[t]), c22 = -A * madd(s.c, g2u[t], s.b * g2v[t]);
    const V3 f1 = combine(fu, c11, fv, c12);
    const V3 f2 = combine(fu, c21, fv, c22);
    f0x[t] = -(f1.x + f2.x);
    f0y[t] = -(f1.y + f2.y);
    f0z[t] = -(f1.z + f2.z);
    f1x[t] = f1.x;
    f1y[t] = f1.y;
    f1z[t] = f1.z;
    f2x[t] = f2.x;
    f2y[t] = f2.y;
    f2z[t] = f2.z;
  };
  if constexpr (kRuns) {
    for (std::size_t k = 0; k < n; ++k) {
      const auto f = static_cast<std::size_t>(blocks[k]);
      const std::int64_t a = i0[f], b = i1[f], c = i2[f];
      for (std::int64_t l = 0; l < kKernelRun; ++l) element(f + l, a + l, b + l, c + l);
    }
  } else {
    for (std::size_t t = 0; t < n; ++t) element(t, i0[t], i1[t], i2[t]);
  }
}

/// A vector of doubles as wide as the processor's (GCC's vector extension): eight on AVX-512,
/// four on AVX2, four as pairs of SSE2 registers in a portable build. A block of kKernelRun
/// vertices is summed kLanes at a time. Eight lanes as one vector on AVX2 compiled to
/// spills through the stack: about a fifth of the membrane's time on the walking skirt went
/// to this pass (docs/PERFORMANCE.md). GCC did not vectorise the loop over a block's lanes.
/// Passed by reference: by value, a build without AVX-512 would pass it another way than one
/// with (GCC and Clang warn, -Wpsabi).
#ifdef __AVX512F__
inline constexpr std::int32_t kLanes = 8;
#else
inline constexpr std::int32_t kLanes = 4;
#endif
static_assert(kKernelRun % kLanes == 0);
using Lanes = double __attribute__((vector_size(kLanes * sizeof(double))));
inline void addLanes(Lanes& sum, const double* p) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  sum += v;
}
inline void addToLanes(double* p, const Lanes& sum) {
  Lanes v;
  std::memcpy(&v, p, sizeof v);
  v += sum;
  std::memcpy(p, &v, sizeof v);
}

/// Membrane pass 2: each vertex sums its corners' forces (loads only: a scatter's
/// read-modify-writes would chain through store forwarding where triangles share vertices):
/// the vertex blocks (MembraneArrays) as vectors, the other vertices one by one. Each lane
/// adds its vertex's corners in the same order as a vertex summed alone.
void gatherMembraneBlocks(std::size_t blocks, const std::int32_t* __restrict first,
                          const std::int32_t* __restrict start, const std::int32_t* __restrict offset, std::size_t n,
                          const double* __restrict w, double* __restrict fx, double* __restrict fy,
                          double* __restrict fz) {
  for (std::size_t b = 0; b < blocks; ++b) {
    const std::int32_t v = first[b];
    for (std::int32_t h = 0; h < kKernelRun; h += kLanes) {
      Lanes sx{}, sy{}, sz{};
      for (std::int32_t k = start[v]; k < start[v + 1]; ++k) {
        const double* c = w + offset[k] + h;
        addLanes(sx, c);
        addLanes(sy, c + n);
        addLanes(sz, c + 2 * n);
      }
      addToLanes(fx + v + h, sx);
      addToLanes(fy + v + h, sy);
      addToLanes(fz + v + h, sz);
    }
  }
}

void gatherMembraneSingles(std::size_t count, const std::int32_t* __restrict vertices,
                           const std::int32_t* __restrict start, const std::int32_t* __restrict offset, std::size_t n,
                           const double* __restrict w, double* __restrict fx, double* __restrict fy,
                           double* __restrict fz) {
  for (std::size_t i = 0; i < count; ++i) {
    const std::int32_t v = vertices[i];
    double sx = 0.0, sy = 0.0, sz = 0.0;
    for (std::int32_t k = start[v]; k < start[v + 1]; ++k) {
      const double* c = w + offset[k];
      sx += c[0];
      sy += c[n];
      sz += c[2 * n];
    }
    fx[v] += sx;
    fy[v] += sy;
    fz[v] += sz;
  }
}

template <bool kDamp, bool kSoften>
void membraneKernel(const ClothModel& model, ClothState& io, ForceLoops* loops) {
  const MembraneArrays& el = model.membraneArrays();
  const std::size_t n = el.area.size();
  const MembraneConstants k{model.lambdaT(), model.muT(), model.material().damping_s,
                            model.material().compressionScale};
  const double *x = io.x.data(), *y = io.y.data(), *z = io.z.data();
  const double *vx = io.vx.data(), *vy = io.vy.data(), *vz = io.vz.data();
  double* w = io.work.data();  // nine columns of n
  const auto r = static_cast<std::size_t>(el.runEnd);
  constexpr std::size_t kPieceBlocks = kPieceElements / kKernelRun;
  const auto membraneRunsPiece = [&](std::size_t b, std::size_t e) {
    membraneCornerForces<kDamp, kSoften, true>(e - b, el.runBlocks.data() + b, k, x, y, z, vx, vy, vz,
                                               el.v0.data(), el.v1.data(), el.v2.data(), el.g1u.data(),
                                               el.g1v.data(), el.g2u.data(), el.g2v.data(), el.area.data(), w,
                                               w + n, w + 2 * n, w + 3 * n, w + 4 * n, w + 5 * n, w + 6 * n,
                                               w + 7 * n, w + 8 * n);
  };
  forPieces(loopOf(loops, &ForceLoops::membraneRuns), el.runBlocks.size(), kPieceBlocks, membraneRunsPiece);
  const auto membraneElementsPiece = [&](std::size_t b, std::size_t e) {
    const std::size_t o = r + b;
    membraneCornerForces<kDamp, kSoften, false>(
        e - b, nullptr, k, x, y, z, vx, vy, vz, el.v0.data() + o, el.v1.data() + o, el.v2.data() + o,
        el.g1u.data() + o, el.g1v.data() + o, el.g2u.data() + o, el.g2v.data() + o, el.area.data() + o, w + o,
        w + n + o, w + 2 * n + o, w + 3 * n + o, w + 4 * n + o, w + 5 * n + o, w + 6 * n + o, w + 7 * n + o,
        w + 8 * n + o);
  };
  forPieces(loopOf(loops, &ForceLoops::membraneElements), n - r, kPieceElements, membraneElementsPiece);
  const auto blocksPiece = [&](std::size_t b, std::size_t e) {
    gatherMembraneBlocks(e - b, el.vertexBlocks.data() + b, el.cornerStart.data(), el.cornerOffset.data(), n, w,
                         io.fx.data(), io.fy.data(), io.fz.data());
  };
  forPieces(loopOf(loops, &ForceLoops::membraneBlocks), el.vertexBlocks.size(), kPieceBlocks, blocksPiece);
  const auto singlesPiece = [&](std::size_t b, std::size_t e) {
    gatherMembraneSingles(e - b, el.singleVertices.data() + b, el.cornerStart.data(), el.cornerOffset.data(), n, w,
                          io.fx.data(), io.fy.data(), io.fz.data());
  };
  forPieces(loopOf(loops, &ForceLoops::membraneVertices), el.singleVertices.size(), kPieceElements, singlesPiece);
}

/// Bending pass 1: the forces on a, b, e0 and e1 of every hinge into w (columns fa, fb, fe0,
/// fe1, x y z each; fe1 = -(fa + fb + fe0)). With kRuns, n blocks of hinges in runs, as
/// the membrane's triangles.
template <bool kRuns>
void hingeCornerForces(std::size_t n, const std::int32_t* __restrict blocks, const double* __restrict x,
                       const double* __restrict y, const double* __restrict z, const std::int32_t* __restrict ie0,
                       const std::int32_t* __restrict ie1, const std::int32_t* __restrict ia,
                       const std::int32_t* __restrict ib, const double* __restrict restPsi,
                       const double* __restrict k, double scale, double* __restrict fax, double* __restrict fay,
                       double* __restrict faz, double* __restrict fbx, double* __restrict fby,
                       double* __restrict fbz, double* __restrict fex, double* __restrict fey,
                       double* __restrict fez, double* __restrict f1x, double* __restrict f1y,
                       double* __restrict f1z) {
  const auto hinge = [&](std::size_t i, std::int64_t j3, std::int64_t j4, std::int64_t j1, std::int64_t j2)
                         __attribute__((always_inline)) {
    // Hinge normals with edge-local orientation (see BendElement) and the edge vector.
    const V3 x3 = load(x, y, z, j3), x4 = load(x, y, z, j4);
    const V3 x1 = load(x, y, z, j1), x2 = load(x, y, z, j2);
    const V3 e = sub(x4, x3);
    const V3 n1 = cross(sub(x1, x3), sub(x1, x4));
    const V3 n2 = cross(sub(x2, x4), sub(x2, x3));
    // A collapsed hinge has no direction: its force is zero (selects, not a branch).
    const double n1sq = dot(n1, n1), n2sq = dot(n2, n2), esq = dot(e, e);
    const bool ok = n1sq > 1e-300 && n2sq > 1e-300 && esq > 1e-300;
    const double n1s = ok ? n1sq : 1.0, n2s = ok ? n2sq : 1.0, es = ok ? esq : 1.0;

    // One division for the four reciprocals below (|N1| |N2|, |N1|^2, |N2|^2, |e|): divisions
    // and square roots are what this kernel waits on.
    const double q = std::sqrt(n1s * n2s);
    const double inv = 1.0 / (q * es);
    const double invQ = es * inv, invEs = q * inv;

    // cos(theta); psi = 2 sin(theta/2), dpsi/dtheta = cos(theta/2), so psi dpsi/dtheta =
    // sin(theta), signed: N1 x N2 lies along e, and (N1 x N2).e = |N1| |N2| |e| sin(theta).
    // No square root for psi, and no cancellation in 1 - cos(theta) at small angles.
    const double c = std::min(1.0, std::max(-1.0, dot(n1, n2) * invQ));
    const double cosHalf = std::sqrt(0.5 * (1.0 + c));
    const double elen = std::sqrt(es), invE = elen * invEs;
    const double sinTheta = dot(cross(n1, n2), e) * invQ * invE;

    // dtheta/dx_i = -u_i with Bridson et al. (2003)'s u_i, which sum to zero exactly:
    //   u_a = |e| N1 / |N1|^2, u_b = |e| N2 / |N2|^2,
    //   u_e0 = ((a - e1).e N1 / |N1|^2 + (b - e1).e N2 / |N2|^2) / |e|, u_e1 = -(u_a + u_b + u_e0).
    // f_i = -k (psi - psi0) dpsi/dx_i = k (psi - psi0) cos(theta/2) u_i = k (sin(theta) - psi0 cos(theta/2)) u_i.
    const double stiffness = k[i] * scale, rest = restPsi[i];  // loaded unconditionally: a select, not a masked load
    const double m = ok ? stiffness * (sinTheta - rest * cosHalf) : 0.0;
    const double r1 = m * n2s * invQ * invQ, r2 = m * n1s * invQ * invQ;  // m / |N1|^2, m / |N2|^2
    const V3 fa = mul(n1, r1 * elen), fb = mul(n2, r2 * elen);
    const V3 fe0 = combine(n1, r1 * dot(sub(x1, x4), e) * invE, n2, r2 * dot(sub(x2, x4), e) * invE);
    fax[i] = fa.x;
    fay[i] = fa.y;
    faz[i] = fa.z;
    fbx[i] = fb.x;
    fby[i] = fb.y;
    fbz[i] = fb.z;
    fex[i] = fe0.x;
    fey[i] = fe0.y;
    fez[i] = fe0.z;
    const V3 fe1 = mul(add(add(fa, fb), fe0), -1.0);
    f1x[i] = fe1.x;
    f1y[i] = fe1.y;
    f1z[i] = fe1.z;
  };
  if constexpr (kRuns) {
    for (std::size_t k = 0; k < n; ++k) {
      const auto f = static_cast<std::size_t>(blocks[k]);
      const std::int64_t e0 = ie0[f], e1 = ie1[f], a = ia[f], b = ib[f];
      for (std::int64_t l = 0; l < kKernelRun; ++l) hinge(f + l, e0 + l, e1 + l, a + l, b + l);
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) hinge(i, ie0[i], ie1[i], ia[i], ib[i]);
  }
}

/// Bending pass 2: each vertex adds its hinge forces, loads only, in the order of
/// bending(): the same sums, to the bit, as adding each hinge's four forces in turn.
void gatherHinges(std::size_t vertices, std::size_t n, const std::int32_t* __restrict start,
                  const std::int32_t* __restrict offset, const double* __restrict w, double* __restrict fx,
                  double* __restrict fy, double* __restrict fz) {
  for (std::size_t v = 0; v < vertices; ++v) {
    double sx = fx[v], sy = fy[v], sz = fz[v];
    for (std::int32_t k = start[v]; k < start[v + 1]; ++k) {
      const double* c = w + offset[k];
      sx += c[0];
      sy += c[n];
      sz += c[2 * n];
    }
    fx[v] = sx;
    fy[v] = sy;
    fz[v] = sz;
  }
}

}  // namespace

void clearForces(ClothState& io) {
  std::fill(io.fx.begin(), io.fx.end(), 0.0);
  std::fill(io.fy.begin(), io.fy.end(), 0.0);
  std::fill(io.fz.begin(), io.fz.end(), 0.0);
}

void accumulateMembraneForces(const ClothModel& model, ClothState& io, ForceLoops* loops) {
  const bool damp = model.material().damping_s > 0.0;
  const bool soften = model.material().compressionScale < 1.0;
  if (model.membraneArrays().area.size() < kParallelFrom_elements) loops = nullptr;
  if (damp && soften) membraneKernel<true, true>(model, io, loops);
  else if (damp) membraneKernel<true, false>(model, io, loops);
  else if (soften) membraneKernel<false, true>(model, io, loops);
  else membraneKernel<false, false>(model, io, loops);
}

void accumulateBendingForces(const ClothModel& model, ClothState& io, double scale, ForceLoops* loops) {
  const BendArrays& h = model.bendArrays();
  const std::size_t n = h.stiffness.size();
  if (n < kParallelFrom_elements) loops = nullptr;
  const double *x = io.x.data(), *y = io.y.data(), *z = io.z.data();
  double* w = io.work.data();  // twelve columns of n
  const auto r = static_cast<std::size_t>(h.runEnd);
  const auto hingeRunsPiece = [&](std::size_t b, std::size_t e) {
    hingeCornerForces<true>(e - b, h.runBlocks.data() + b, x, y, z, h.e0.data(), h.e1.data(), h.a.data(),
                            h.b.data(), h.restPsi.data(), h.stiffness.data(), scale, w, w + n, w + 2 * n, w + 3 * n,
                            w + 4 * n, w + 5 * n, w + 6 * n, w + 7 * n, w + 8 * n, w + 9 * n, w + 10 * n,
                            w + 11 * n);
  };
  forPieces(loopOf(loops, &ForceLoops::hingeRuns), h.runBlocks.size(), kPieceElements / kKernelRun, hingeRunsPiece);
  const auto hingesPiece = [&](std::size_t b, std::size_t e) {
    const std::size_t o = r + b;
    hingeCornerForces<false>(e - b, nullptr, x, y, z, h.e0.data() + o, h.e1.data() + o, h.a.data() + o,
                             h.b.data() + o, h.restPsi.data() + o, h.stiffness.data() + o, scale, w + o, w + n + o,
                             w + 2 * n + o, w + 3 * n + o, w + 4 * n + o, w + 5 * n + o, w + 6 * n + o,
                             w + 7 * n + o, w + 8 * n + o, w + 9 * n + o, w + 10 * n + o, w + 11 * n + o);
  };
  forPieces(loopOf(loops, &ForceLoops::hinges), n - r, kPieceElements, hingesPiece);
  const auto hingeVerticesPiece = [&](std::size_t b, std::size_t e) {
    gatherHinges(e - b, n, h.cornerStart.data() + b, h.cornerOffset.data(), w, io.fx.data() + b, io.fy.data() + b,
                 io.fz.data() + b);
  };
  forPieces(loopOf(loops, &ForceLoops::hingeVertices), io.size(), kPieceElements, hingeVerticesPiece);
}

namespace {

/// f -= c A (v - wind), per vertex. Restrict parameters, not locals: GCC 12 ignores restrict
/// on local pointers here, wanted a run-time check of every pair of the seven arrays for
/// overlap (more than it allows) and left the loop scalar.
void dragLoop(std::size_t n, double c, const Vec3& wind, const double* __restrict area, const double* __restrict vx,
              const double* __restrict vy, const double* __restrict vz, double* __restrict fx, double* __restrict fy,
              double* __restrict fz) {
  const double wx = wind.x(), wy = wind.y(), wz = wind.z();
  for (std::size_t i = 0; i < n; ++i) {
    const double k = c * area[i];
    fx[i] -= k * (vx[i] - wx);
    fy[i] -= k * (vy[i] - wy);
    fz[i] -= k * (vz[i] - wz);
  }
}

}  // namespace

void accumulateDragForces(const ClothModel& model, const StepSettings& settings, ClothState& io) {
  const double c = settings.airViscosity_Ns_m3;
  if (c <= 0.0) return;
  dragLoop(io.size(), c, settings.wind_m_s, model.vertexArea().data(), io.vx.data(), io.vy.data(), io.vz.data(),
           io.fx.data(), io.fy.data(), io.fz.data());
}

double membraneEnergy(const ClothModel& model, const ClothState& s) {
  const double lambda = model.lambdaT(), mu = model.muT();
  double energy = 0.0;
  for (const MembraneElement& el : model.membrane()) {
    const V3 p0 = load(s.x.data(), s.y.data(), s.z.data(), el.v0);
    const V3 d1 = sub(load(s.x.data(), s.y.data(), s.z.data(), el.v1), p0);
    const V3 d2 = sub(load(s.x.data(), s.y.data(), s.z.data(), el.v2), p0);
    const V3 fu = add(mul(d1, el.g1u), mul(d2, el.g2u));
    const V3 fv = add(mul(d1, el.g1v), mul(d2, el.g2v));
    const double e11 = 0.5 * (dot(fu, fu) - 1.0), e22 = 0.5 * (dot(fv, fv) - 1.0), e12 = 0.5 * dot(fu, fv);
    const double tr = e11 + e22;
    // W = A (mu E:E + lambda/2 tr(E)^2)
    energy += el.restArea_m2 * (mu * (e11 * e11 + e22 * e22 + 2.0 * e12 * e12) + 0.5 * lambda * tr * tr);
  }
  return energy;
}

double bendingEnergy(const ClothModel& model, const ClothState& s) {
  double energy = 0.0;
  for (const BendElement& h : model.bending()) {
    const V3 x3 = load(s.x.data(), s.y.data(), s.z.data(), h.e0), x4 = load(s.x.data(), s.y.data(), s.z.data(), h.e1);
    const V3 x1 = load(s.x.data(), s.y.data(), s.z.data(), h.a), x2 = load(s.x.data(), s.y.data(), s.z.data(), h.b);
    const V3 e = sub(x4, x3);
    const V3 n1 = cross(sub(x1, x3), sub(x1, x4));
    const V3 n2 = cross(sub(x2, x4), sub(x2, x3));
    const double n1sq = dot(n1, n1), n2sq = dot(n2, n2);
    if (n1sq <= 1e-300 || n2sq <= 1e-300) continue;
    const double c = std::clamp(dot(n1, n2) / std::sqrt(n1sq * n2sq), -1.0, 1.0);
    const double sign = dot(cross(n1, n2), e) < 0.0 ? -1.0 : 1.0;
    const double d = sign * std::sqrt(2.0 * (1.0 - c)) - h.restPsi;
    energy += 0.5 * h.stiffness_Nm * d * d;
  }
  return energy;
}

double kineticEnergy(const ClothModel& model, const ClothState& s) {
  double energy = 0.0;
  const auto& m = model.mass();
  for (std::size_t i = 0; i < s.size(); ++i)
    energy += 0.5 * m[i] * (s.vx[i] * s.vx[i] + s.vy[i] * s.vy[i] + s.vz[i] * s.vz[i]);
  return energy;
}

double gravityEnergy(const ClothModel& model, const ClothState& s, const Vec3& g) {
  double energy = 0.0;
  const auto& m = model.mass();
  for (std::size_t i = 0; i < s.size(); ++i) energy -= m[i] * (g.x() * s.x[i] + g.y() * s.y[i] + g.z() * s.z[i]);
  return energy;
}

EdgeStrain edgeStrain(const ClothModel& model, const ClothState& s) {
  EdgeStrain worst;
  const auto& a = model.edgeV0();
  const auto& b = model.edgeV1();
  const auto& rest = model.edgeRestLength();
  for (std::size_t e = 0; e < rest.size(); ++e) {
    if (!(rest[e] > 0.0)) continue;
    const double dx = s.x[b[e]] - s.x[a[e]], dy = s.y[b[e]] - s.y[a[e]], dz = s.z[b[e]] - s.z[a[e]];
    const double strain = (std::sqrt(dx * dx + dy * dy + dz * dz) - rest[e]) / rest[e];
    if (std::isnan(strain)) {
      worst.stretch = worst.compression = strain;
      return worst;
    }
    if (strain > worst.stretch) worst.stretch = strain;
    if (-strain > worst.compression) worst.compression = -strain;
  }
  return worst;
}

}  // namespace drape::cloth
