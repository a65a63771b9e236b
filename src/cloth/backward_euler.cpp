#include "drape/cloth/backward_euler.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "drape/core/error.hpp"

namespace drape::cloth {
namespace {

double dot(std::span<const double> a, std::span<const double> b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

struct P3 {
  double x, y, z;
};
P3 operator+(P3 a, P3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
P3 operator-(P3 a, P3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
P3 operator*(P3 a, double s) { return {a.x * s, a.y * s, a.z * s}; }
double dot(P3 a, P3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
P3 cross(P3 a, P3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }

/// Vertex i of a state's positions, or of a 3 n vector (x block, y block, z block).
P3 at(const ClothState& s, std::size_t i) { return {s.x[i], s.y[i], s.z[i]}; }
P3 at(std::span<const double> v, std::size_t n, std::size_t i) { return {v[i], v[n + i], v[2 * n + i]}; }
void add(std::span<double> v, std::size_t n, std::size_t i, P3 a) {
  v[i] += a.x;
  v[n + i] += a.y;
  v[2 * n + i] += a.z;
}

/// The symmetric 2x2 stress (S11, S22, S12) with its negative principal part dropped.
void tensionOnly(double& a, double& b, double& c) {
  const double mean = 0.5 * (a + b), half = 0.5 * (a - b);
  const double radius = std::sqrt(half * half + c * c);
  const double s1 = mean + radius, s2 = mean - radius;
  if (s2 >= 0.0) return;
  if (s1 <= 0.0) {
    a = b = c = 0.0;
    return;
  }
  // s1 u1 u1^T with u1 u1^T = (S - s2 I) / (s1 - s2).
  const double f = s1 / (s1 - s2);
  a = f * (a - s2);
  b = f * (b - s2);
  c = f * c;
}

}  // namespace

void BackwardEuler::prepare(const ClothModel& model, const StepSettings& settings,
                            std::span<const std::uint8_t> fixed) {
  const std::size_t n = model.vertexCount();
  if (!fixed.empty() && fixed.size() != n)
    throw Error("backward Euler: one fixture flag per vertex expected", ExitCode::Internal);
  held_.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v)
    held_[v] = static_cast<std::uint8_t>((!fixed.empty() && fixed[v]) || !(model.inverseMass()[v] > 0.0));
  pinched_.clear();
  pinched_.reserve(n);
  isPinched_.assign(n, 0);
  dragPerArea_ = settings.airViscosity_Ns_m3;
  tolerance_ = settings.implicitTolerance;
  gradient_.assign(6 * model.membrane().size(), 0.0);
  stress_.assign(3 * model.membrane().size(), 0.0);
  hinge_.assign(12 * model.bending().size(), 0.0);
  for (std::vector<double>* v : {&rhs_, &dv_, &r_, &z_, &d_, &q_}) v->assign(3 * n, 0.0);
  precond_.assign(9 * n, 0.0);
  buildPattern(model);
}

void BackwardEuler::holdPinched(std::span<const PinchedPoint> points) {
  addHolds(points, held_, isPinched_, pinched_);
}

void BackwardEuler::linearise(const ClothModel& model, const ClothState& s) {
  const double lambda = model.lambdaT(), mu = model.muT();
  const std::vector<MembraneElement>& elements = model.membrane();
  for (std::size_t t = 0; t < elements.size(); ++t) {
    const MembraneElement& el = elements[t];
    const P3 p0 = at(s, el.v0);
    const P3 d1 = at(s, el.v1) - p0, d2 = at(s, el.v2) - p0;
    const P3 fu = d1 * el.g1u + d2 * el.g2u, fv = d1 * el.g1v + d2 * el.g2v;
    const double e11 = 0.5 * (dot(fu, fu) - 1.0), e22 = 0.5 * (dot(fv, fv) - 1.0), e12 = 0.5 * dot(fu, fv);
    const double tr = e11 + e22;
    double a = lambda * tr + 2.0 * mu * e11, b = lambda * tr + 2.0 * mu * e22, c = 2.0 * mu * e12;
    tensionOnly(a, b, c);
    double* g = &gradient_[6 * t];
    g[0] = fu.x, g[1] = fu.y, g[2] = fu.z, g[3] = fv.x, g[4] = fv.y, g[5] = fv.z;
    stress_[3 * t] = a, stress_[3 * t + 1] = b, stress_[3 * t + 2] = c;
  }
  // Hinges: grad psi = -cos(theta / 2) u with Bridson et al.'s u (forces.cpp states them).
  const std::vector<BendElement>& hinges = model.bending();
  for (std::size_t i = 0; i < hinges.size(); ++i) {
    const BendElement& hg = hinges[i];
    const P3 x3 = at(s, hg.e0), x4 = at(s, hg.e1), x1 = at(s, hg.a), x2 = at(s, hg.b);
    const P3 e = x4 - x3;
    const P3 n1 = cross(x1 - x3, x1 - x4), n2 = cross(x2 - x4, x2 - x3);
    const double n1sq = dot(n1, n1), n2sq = dot(n2, n2), esq = dot(e, e);
    double* w = &hinge_[12 * i];
    if (!(n1sq > 1e-300 && n2sq > 1e-300 && esq > 1e-300)) {  // collapsed: no direction, as in the forces
      std::fill(w, w + 12, 0.0);
      continue;
    }
    const double elen = std::sqrt(esq);
    const double c = std::clamp(dot(n1, n2) / std::sqrt(n1sq * n2sq), -1.0, 1.0);
    const double scale = std::sqrt(std::max(0.0, hg.stiffness_Nm)) * std::sqrt(0.5 * (1.0 + c));
    const P3 ua = n1 * (elen / n1sq), ub = n2 * (elen / n2sq);
    const P3 ue0 = n1 * (dot(x1 - x4, e) / (elen * n1sq)) + n2 * (dot(x2 - x4, e) / (elen * n2sq));
    const P3 ue1 = (ua + ub + ue0) * -1.0;
    const P3 corners[4] = {ua * scale, ub * scale, ue0 * scale, ue1 * scale};
    for (int k = 0; k < 4; ++k) {
      w[3 * k] = corners[k].x;
      w[3 * k + 1] = corners[k].y;
      w[3 * k + 2] = corners[k].z;
    }
  }
}

void BackwardEuler::stiffnessTimes(const ClothModel& model, std::span<const double> p, double material,
                                   double geometric, std::span<double> out) const {
  const std::size_t n = model.vertexCount();
  std::fill(out.begin(), out.end(), 0.0);
  const double lambda = model.lambdaT(), mu = model.muT();
  const std::vector<MembraneElement>& elements = model.membrane();
  for (std::size_t t = 0; t < elements.size(); ++t) {
    const MembraneElement& el = elements[t];
    const double* g = &gradient_[6 * t];
    const P3 fu{g[0], g[1], g[2]}, fv{g[3], g[4], g[5]};
    const P3 q0 = at(p, n, el.v0);
    const P3 q1 = at(p, n, el.v1) - q0, q2 = at(p, n, el.v2) - q0;
    const P3 du = q1 * el.g1u + q2 * el.g2u, dv = q1 * el.g1v + q2 * el.g2v;  // dF's columns
    // Material: F dS with dS = C : sym(F^T dF). Geometric: dF S+.
    const double de11 = dot(fu, du), de22 = dot(fv, dv), de12 = 0.5 * (dot(fu, dv) + dot(fv, du));
    const double dtr = de11 + de22;
    const double ds11 = lambda * dtr + 2.0 * mu * de11, ds22 = lambda * dtr + 2.0 * mu * de22, ds12 = 2.0 * mu * de12;
    const double s11 = stress_[3 * t], s22 = stress_[3 * t + 1], s12 = stress_[3 * t + 2];
    const P3 pu = (fu * ds11 + fv * ds12) * material + (du * s11 + dv * s12) * geometric;
    const P3 pv = (fu * ds12 + fv * ds22) * material + (du * s12 + dv * s22) * geometric;
    const double A = el.restArea_m2;
    const P3 c1 = (pu * el.g1u + pv * el.g1v) * A, c2 = (pu * el.g2u + pv * el.g2v) * A;
    add(out, n, el.v1, c1);
    add(out, n, el.v2, c2);
    add(out, n, el.v0, (c1 + c2) * -1.0);
  }
  const std::vector<BendElement>& hinges = model.bending();
  for (std::size_t i = 0; i < hinges.size(); ++i) {
    const BendElement& hg = hinges[i];
    const double* w = &hinge_[12 * i];
    const std::uint32_t v[4] = {hg.a, hg.b, hg.e0, hg.e1};
    double along = 0.0;
    for (int k = 0; k < 4; ++k) along += dot(P3{w[3 * k], w[3 * k + 1], w[3 * k + 2]}, at(p, n, v[k]));
    along *= geometric;
    for (int k = 0; k < 4; ++k) add(out, n, v[k], P3{w[3 * k], w[3 * k + 1], w[3 * k + 2]} * along);
  }
}

void BackwardEuler::buildPattern(const ClothModel& model) {
  // Each vertex's neighbours through a triangle or a hinge (the hinge's two tips are coupled
  // though no edge joins them), itself included, in order: the rows of a block CSR matrix.
  const std::size_t n = model.vertexCount();
  std::vector<std::vector<std::uint32_t>> near(n);
  const auto couple = [&](std::span<const std::uint32_t> corners) {
    for (const std::uint32_t r : corners)
      for (const std::uint32_t c : corners) near[r].push_back(c);
  };
  for (const MembraneElement& el : model.membrane()) couple(std::array<std::uint32_t, 3>{el.v0, el.v1, el.v2});
  for (const BendElement& hg : model.bending()) couple(std::array<std::uint32_t, 4>{hg.a, hg.b, hg.e0, hg.e1});
  rowStart_.assign(n + 1, 0);
  column_.clear();
  diagonal_.assign(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    near[v].push_back(static_cast<std::uint32_t>(v));
    std::sort(near[v].begin(), near[v].end());
    near[v].erase(std::unique(near[v].begin(), near[v].end()), near[v].end());
    for (const std::uint32_t c : near[v]) {
      if (c == v) diagonal_[v] = static_cast<std::uint32_t>(column_.size());
      column_.push_back(c);
    }
    rowStart_[v + 1] = static_cast<std::uint32_t>(column_.size());
  }
  const auto block = [&](std::uint32_t r, std::uint32_t c) {
    const auto first = column_.begin() + rowStart_[r], last = column_.begin() + rowStart_[r + 1];
    return static_cast<std::uint32_t>(std::lower_bound(first, last, c) - column_.begin());
  };
  membraneBlock_.clear();
  for (const MembraneElement& el : model.membrane()) {
    const std::uint32_t v[3] = {el.v0, el.v1, el.v2};
    for (const std::uint32_t r : v)
      for (const std::uint32_t c : v) membraneBlock_.push_back(block(r, c));
  }
  hingeBlock_.clear();
  for (const BendElement& hg : model.bending()) {
    const std::uint32_t v[4] = {hg.a, hg.b, hg.e0, hg.e1};
    for (const std::uint32_t r : v)
      for (const std::uint32_t c : v) hingeBlock_.push_back(block(r, c));
  }
  matrix_.assign(9 * column_.size(), 0.0);
}

void BackwardEuler::assemble(const ClothModel& model, double h) {
  // The blocks of applySystem's operator. Membrane, corners r and c with barycentric
  // gradients g_r, g_c: with a = Fu g_u, b = Fv g_v, e = (Fu g_v + Fv g_u) / 2 per corner,
  // the material block is A (lambda (a_r + b_r)(a_c + b_c)^T + 2 mu (a_r a_c^T + b_r b_c^T +
  // 2 e_r e_c^T)) and the geometric one A (g_r . S+ g_c) I; a hinge's is w_r w_c^T.
  const double beta = model.material().damping_s;
  const double material = h * h + h * beta, geometric = h * h;
  const double lambda = model.lambdaT(), mu = model.muT();
  std::fill(matrix_.begin(), matrix_.end(), 0.0);
  // Block (r, c) and, off the diagonal, its transpose at (c, r): the matrix is symmetric.
  const auto addBlock = [&](std::uint32_t rc, std::uint32_t cr, const double* k) {
    double* m = &matrix_[9 * static_cast<std::size_t>(rc)];
    for (int i = 0; i < 9; ++i) m[i] += k[i];
    if (cr == rc) return;
    double* t = &matrix_[9 * static_cast<std::size_t>(cr)];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) t[3 * j + i] += k[3 * i + j];
  };
  const std::vector<MembraneElement>& elements = model.membrane();
  for (std::size_t t = 0; t < elements.size(); ++t) {
    const MembraneElement& el = elements[t];
    const double* g = &gradient_[6 * t];
    const double fu[3] = {g[0], g[1], g[2]}, fv[3] = {g[3], g[4], g[5]};
    const double s11 = stress_[3 * t], s22 = stress_[3 * t + 1], s12 = stress_[3 * t + 2];
    const double gu[3] = {-(el.g1u + el.g2u), el.g1u, el.g2u}, gv[3] = {-(el.g1v + el.g2v), el.g1v, el.g2v};
    // With a_r, b_r, e_r combinations of Fu and Fv, each block is a combination of Fu Fu^T,
    // Fv Fv^T, Fu Fv^T and its transpose, with coefficients from g_r and g_c.
    double uu[9], vv[9], uv[9];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        uu[3 * i + j] = fu[i] * fu[j];
        vv[3 * i + j] = fv[i] * fv[j];
        uv[3 * i + j] = fu[i] * fv[j];
      }
    const double A = el.restArea_m2 * material, G = el.restArea_m2 * geometric;
    const std::uint32_t* blocks = &membraneBlock_[9 * t];
    for (int r = 0; r < 3; ++r)
      for (int c = r; c < 3; ++c) {
        const double cuu = A * ((lambda + 2.0 * mu) * gu[r] * gu[c] + mu * gv[r] * gv[c]);
        const double cvv = A * ((lambda + 2.0 * mu) * gv[r] * gv[c] + mu * gu[r] * gu[c]);
        const double cuv = A * (lambda * gu[r] * gv[c] + mu * gv[r] * gu[c]);
        const double cvu = A * (lambda * gv[r] * gu[c] + mu * gu[r] * gv[c]);
        const double geo = G * (gu[r] * (s11 * gu[c] + s12 * gv[c]) + gv[r] * (s12 * gu[c] + s22 * gv[c]));
        double k[9];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            k[3 * i + j] = cuu * uu[3 * i + j] + cvv * vv[3 * i + j] + cuv * uv[3 * i + j] + cvu * uv[3 * j + i];
        k[0] += geo, k[4] += geo, k[8] += geo;
        addBlock(blocks[3 * r + c], blocks[3 * c + r], k);
      }
  }
  const std::vector<BendElement>& hinges = model.bending();
  for (std::size_t i = 0; i < hinges.size(); ++i) {
    const double* w = &hinge_[12 * i];
    const std::uint32_t* blocks = &hingeBlock_[16 * i];
    for (int r = 0; r < 4; ++r)
      for (int c = r; c < 4; ++c) {
        double k[9];
        for (int a = 0; a < 3; ++a)
          for (int b = 0; b < 3; ++b) k[3 * a + b] = geometric * w[3 * r + a] * w[3 * c + b];
        addBlock(blocks[4 * r + c], blocks[4 * c + r], k);
      }
  }
  const std::size_t n = model.vertexCount();
  const std::vector<double>& m = model.mass();
  const std::vector<double>& area = model.vertexArea();
  for (std::size_t v = 0; v < n; ++v) {
    double* d = &matrix_[9 * static_cast<std::size_t>(diagonal_[v])];
    const double diagonal = m[v] + h * dragPerArea_ * area[v];
    d[0] += diagonal, d[4] += diagonal, d[8] += diagonal;
  }
  invertDiagonalBlocks();
}

void BackwardEuler::invertDiagonalBlocks() {
  const std::size_t n = held_.size();
  for (std::size_t v = 0; v < n; ++v) {
    double* inverse = &precond_[9 * v];
    if (held_[v]) {
      std::fill(inverse, inverse + 9, 0.0);
      continue;
    }
    // The inverse of a symmetric positive definite 3x3 by its adjugate.
    const double* b = &matrix_[9 * static_cast<std::size_t>(diagonal_[v])];
    const double c00 = b[4] * b[8] - b[5] * b[7], c01 = b[2] * b[7] - b[1] * b[8], c02 = b[1] * b[5] - b[2] * b[4];
    const double c11 = b[0] * b[8] - b[2] * b[6], c12 = b[2] * b[3] - b[0] * b[5], c22 = b[0] * b[4] - b[1] * b[3];
    const double inv = 1.0 / (b[0] * c00 + b[1] * (b[5] * b[6] - b[3] * b[8]) + b[2] * (b[3] * b[7] - b[4] * b[6]));
    inverse[0] = c00 * inv, inverse[1] = c01 * inv, inverse[2] = c02 * inv;
    inverse[3] = c01 * inv, inverse[4] = c11 * inv, inverse[5] = c12 * inv;
    inverse[6] = c02 * inv, inverse[7] = c12 * inv, inverse[8] = c22 * inv;
  }
}

void BackwardEuler::filter(std::span<double> v) const {
  const std::size_t n = held_.size();
  for (std::size_t i = 0; i < n; ++i)
    if (held_[i]) v[i] = v[n + i] = v[2 * n + i] = 0.0;
  filterPinched(v);
}

void BackwardEuler::filterPinched(std::span<double> v) const {
  const std::size_t n = held_.size();
  for (const HeldPoint& p : pinched_) {
    const std::size_t i = p.vertex;
    const Vec3 a = p.filtered(Vec3(v[i], v[n + i], v[2 * n + i]));
    v[i] = a.x(), v[n + i] = a.y(), v[2 * n + i] = a.z();
  }
}

void BackwardEuler::applySystem(std::span<const double> p, std::span<double> out) const {
  const std::size_t n = held_.size();
  for (std::size_t v = 0; v < n; ++v) {
    double ox = 0.0, oy = 0.0, oz = 0.0;
    if (!held_[v])
      for (std::uint32_t k = rowStart_[v]; k < rowStart_[v + 1]; ++k) {
        const double* m = &matrix_[9 * static_cast<std::size_t>(k)];
        const std::size_t c = column_[k];
        const double px = p[c], py = p[n + c], pz = p[2 * n + c];
        ox += m[0] * px + m[1] * py + m[2] * pz;
        oy += m[3] * px + m[4] * py + m[5] * pz;
        oz += m[6] * px + m[7] * py + m[8] * pz;
      }
    out[v] = ox;
    out[n + v] = oy;
    out[2 * n + v] = oz;
  }
}

void BackwardEuler::advance(const ClothModel& model, const Vec3& g, double h, ClothState& s) {
  const std::size_t n = s.size();
  if (held_.size() != n) prepare(model, StepSettings{}, {});  // a caller that did not (tests of the integrator alone)
  const std::vector<double>& m = model.mass();
  const double gravity[3] = {g.x(), g.y(), g.z()};
  const double* const f0[3] = {s.fx.data(), s.fy.data(), s.fz.data()};
  const double* const v0[3] = {s.vx.data(), s.vy.data(), s.vz.data()};
  linearise(model, s);

  // Right-hand side h (f0 + M g) + h^2 K v0 (K = -df/dx: minus the stiffness product).
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < n; ++i) d_[c * n + i] = v0[c][i];
  stiffnessTimes(model, d_, h * h, h * h, rhs_);
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < n; ++i) rhs_[c * n + i] = h * (f0[c][i] + m[i] * gravity[c]) - rhs_[c * n + i];
  filter(rhs_);

  assemble(model, h);
  const auto precondition = [&](std::span<const double> in, std::span<double> out) {
    for (std::size_t i = 0; i < n; ++i) {
      const double* b = &precond_[9 * i];
      const double px = in[i], py = in[n + i], pz = in[2 * n + i];
      out[i] = b[0] * px + b[1] * py + b[2] * pz;
      out[n + i] = b[3] * px + b[4] * py + b[5] * pz;
      out[2 * n + i] = b[6] * px + b[7] * py + b[8] * pz;
    }
    filterPinched(out);  // S P^-1 S: the held ones' blocks are zero already
  };

  // Preconditioned conjugate gradients from the last substep's dv, filtered (Baraff and
  // Witkin's modified PCG: every vector stays in the filter's range). The system is positive
  // definite by construction; the curvature test guards against what rounding could still
  // make of it.
  precondition(rhs_, d_);
  const double fromZero = dot(rhs_, d_);  // the residual's measure starting from dv = 0
  const double target = tolerance_ * tolerance_ * fromZero;
  filterPinched(dv_);  // a vertex held now may have moved freely in the last solve (held ones' dv stays 0)
  applySystem(dv_, q_);
  filterPinched(q_);
  for (std::size_t i = 0; i < 3 * n; ++i) r_[i] = rhs_[i] - q_[i];
  precondition(r_, d_);
  double rz = dot(r_, d_);
  if (!(rz <= fromZero)) {  // a worse start than none (after a substep that went unstable): from 0
    std::fill(dv_.begin(), dv_.end(), 0.0);
    std::copy(rhs_.begin(), rhs_.end(), r_.begin());
    precondition(r_, d_);
    rz = fromZero;
  }
  ++stats_.solves;
  bool converged = !(rz > target);
  for (int k = 0; k < kMaxIterations && !converged; ++k) {
    applySystem(d_, q_);
    filterPinched(q_);
    ++stats_.iterations;
    const double curvature = dot(d_, q_);
    if (!(curvature > 0.0)) {
      ++stats_.indefinite;
      if (k == 0)  // the preconditioned residual from the warm start: a damped explicit step
        for (std::size_t i = 0; i < 3 * n; ++i) dv_[i] += d_[i];
      converged = true;
      break;
    }
    const double alpha = rz / curvature;
    for (std::size_t i = 0; i < 3 * n; ++i) {
      dv_[i] += alpha * d_[i];
      r_[i] -= alpha * q_[i];
    }
    precondition(r_, z_);
    const double rzNext = dot(r_, z_);
    if (rzNext <= target) {
      converged = true;
      break;
    }
    const double b = rzNext / rz;
    for (std::size_t i = 0; i < 3 * n; ++i) d_[i] = z_[i] + b * d_[i];
    rz = rzNext;
  }
  if (!converged) ++stats_.unconverged;

  // v1 = v0 + dv; the held vertices take gravity alone (the fixtures place the bound ones,
  // and a massless vertex falls, as in the explicit steps), the pinched ones keep their
  // velocity along the parts' normals (their dv has no component there); x1 = x0 + h v1.
  double* const v[3] = {s.vx.data(), s.vy.data(), s.vz.data()};
  double* const x[3] = {s.x.data(), s.y.data(), s.z.data()};
  for (std::size_t c = 0; c < 3; ++c)
    for (std::size_t i = 0; i < n; ++i) {
      v[c][i] += held_[i] ? h * gravity[c] : dv_[c * n + i];
      x[c][i] += h * v[c][i];
    }
  clearHolds(isPinched_, pinched_);  // for this solve alone
}

}  // namespace drape::cloth
