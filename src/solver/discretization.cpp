#include "pdcg/solver/discretization.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numeric>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/cut_cells.hpp"

namespace pdcg::solver {

InfluenceFunction gaussian_influence() {
  return [](double r, double delta) { return std::exp(-4.0 * r * r / (delta * delta)); };
}

bool crosses(const Crack& c, const Vec3& a_in, const Vec3& b_in) {
  // Canonical order of the ends: the orientation tests round differently for a–b and b–a
  // when the bond passes through a crack tip, which made families asymmetric.
  const bool swap = std::make_pair(a_in.x(), a_in.y()) > std::make_pair(b_in.x(), b_in.y());
  const Vec3& a = swap ? b_in : a_in;
  const Vec3& b = swap ? a_in : b_in;
  // Proper intersection of segments a–b and c.from–c.to in the xy-plane.
  auto orient = [](double ax, double ay, double bx, double by, double cx, double cy) {
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
  };
  const double d1 = orient(c.from.x(), c.from.y(), c.to.x(), c.to.y(), a.x(), a.y());
  const double d2 = orient(c.from.x(), c.from.y(), c.to.x(), c.to.y(), b.x(), b.y());
  const double d3 = orient(a.x(), a.y(), b.x(), b.y(), c.from.x(), c.from.y());
  const double d4 = orient(a.x(), a.y(), b.x(), b.y(), c.to.x(), c.to.y());
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

namespace {

using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 4, 4>;
using SmallVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1>;

// First-order PDDO on one stencil; writes dim doubles per member into grad.
// Returns the reciprocal condition number of the scaled moment matrix.
double pddo_stencil(int dim, const std::vector<Vec3>& x, const std::vector<double>& vol, int center,
                    const int* members, std::size_t n, double delta, const InfluenceFunction& w,
                    double* grad, const double* factor = nullptr) {
  const int np = dim + 1;
  SmallMat A = SmallMat::Zero(np, np);
  SmallVec p(np);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 xi = (x[members[k]] - x[center]) / delta;
    p(0) = 1.0;
    for (int a = 0; a < dim; ++a) p(a + 1) = xi(a);
    const double f = factor ? factor[k] : 1.0;  // a member's share (softening: damage)
    A.noalias() += (w(xi.norm() * delta, delta) * vol[members[k]] * f) * p * p.transpose();
  }
  Eigen::SelfAdjointEigenSolver<SmallMat> es(A, Eigen::EigenvaluesOnly);
  const double rc = es.eigenvalues()(0) / es.eigenvalues()(np - 1);
  if (!(rc > 0)) return rc;
  const Eigen::LDLT<SmallMat> ldlt(A);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 xi = (x[members[k]] - x[center]) / delta;
    p(0) = 1.0;
    for (int a = 0; a < dim; ++a) p(a + 1) = xi(a);
    const SmallVec c = ldlt.solve(p);
    const double s =
        w(xi.norm() * delta, delta) * vol[members[k]] * (factor ? factor[k] : 1.0) / delta;
    for (int a = 0; a < dim; ++a) grad[k * dim + a] = s * c(a + 1);
  }
  return rc;
}

/// Surface vectors of the points bordering a circular hole (2D) from the true circle: the
/// points are ordered by their angle θ_k about the centre and point k owns the arc Γ_k between
/// the mid-angles a_k = (θ_{k−1} + θ_k)/2 and b_k = (θ_k + θ_{k+1})/2 (cyclic), so
/// s_k = −∫_{Γ_k} n dS = −R (sin b_k − sin a_k, cos a_k − cos b_k) with n the circle's normal
/// pointing away from the centre (into the body; the body's outward normal on the hole is −n).
/// The arcs tile the circle, so Σ_k s_k = −∮ n dS = 0 to round-off.
void circle_surface(const Hole& h, const std::vector<Vec3>& x, std::vector<int> pts,
                    std::vector<Vec3>& surf) {
  const std::size_t n = pts.size();
  if (n < 2) return;  // one point owns the whole circle: ∮ n dS = 0
  std::vector<std::pair<double, int>> th(n);
  for (std::size_t k = 0; k < n; ++k)
    th[k] = {std::atan2(x[pts[k]].y() - h.center.y(), x[pts[k]].x() - h.center.x()), pts[k]};
  std::sort(th.begin(), th.end());
  const double R = h.radius, two_pi = 2.0 * std::acos(-1.0);
  for (std::size_t k = 0; k < n; ++k) {
    double tp = th[(k + n - 1) % n].first, tn = th[(k + 1) % n].first;
    const double t = th[k].first;
    if (k == 0) tp -= two_pi;
    if (k + 1 == n) tn += two_pi;
    const double a = 0.5 * (tp + t), b = 0.5 * (t + tn);
    surf[th[k].second] += -R * Vec3(std::sin(b) - std::sin(a), std::cos(a) - std::cos(b), 0.0);
  }
}

/// Surface vectors of the points bordering a spherical hole (3D): a nearest-point partition
/// of the true sphere. The sphere is cut into cells of uniform polar angle θ and azimuth φ
/// (edge ≈ Δx/4 at the equator); each cell's exact ∫ n dS is given to the surface point
/// nearest to the cell's centre, so s_k = −∫_{Γ_k} n dS with Γ_k the union of the cells
/// nearest to point k (the point's Voronoi region on the sphere, resolved to the cell size).
/// The cells tile the sphere, so Σ_k s_k = −∮ n dS = 0 to round-off. `lat` are the points'
/// lattice indices (nearest-point search in the lattice around the cell centre).
void sphere_surface(const Hole& h, const std::vector<Vec3>& x,
                    const std::vector<std::array<long, 3>>& lat, const std::vector<int>& pts,
                    const Vec3& origin, double dx, double shift, std::vector<Vec3>& surf) {
  if (pts.size() < 2) return;
  std::array<long, 3> lo, hi;
  lo.fill(std::numeric_limits<long>::max());
  hi.fill(std::numeric_limits<long>::min());
  for (int p : pts)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], lat[p][a]);
      hi[a] = std::max(hi[a], lat[p][a]);
    }
  const long nx = hi[0] - lo[0] + 1, ny = hi[1] - lo[1] + 1, nz = hi[2] - lo[2] + 1;
  std::vector<int> box(nx * ny * nz, -1);
  for (int p : pts)
    box[(lat[p][0] - lo[0]) + nx * ((lat[p][1] - lo[1]) + ny * (lat[p][2] - lo[2]))] = p;
  const double R = h.radius, pi = std::acos(-1.0);
  const long nt = std::max(8L, static_cast<long>(std::ceil(4.0 * pi * R / dx)));
  const long nf = 2 * nt;
  const long rmax = std::max({nx, ny, nz});
  for (long j = 0; j < nt; ++j) {
    const double t0 = pi * j / nt, t1 = pi * (j + 1) / nt, tc = 0.5 * (t0 + t1);
    const double m0 = std::cos(t0), m1 = std::cos(t1);
    // ∫ sin θ dμ-part of n_x, n_y: ∫_{μ1}^{μ0} √(1−μ²) dμ = g(μ0) − g(μ1), g = (μ√(1−μ²) + asin
    // μ)/2
    auto g = [](double m) {
      return 0.5 * (m * std::sqrt(std::max(0.0, 1 - m * m)) + std::asin(m));
    };
    const double G = g(m0) - g(m1);
    for (long l = 0; l < nf; ++l) {
      const double f0 = 2 * pi * l / nf, f1 = 2 * pi * (l + 1) / nf, fc = 0.5 * (f0 + f1);
      // ∫ n dS over the cell, dS = R² dμ dφ (θ from the +z axis, μ = cos θ)
      const Vec3 ndS = R * R *
                       Vec3(G * (std::sin(f1) - std::sin(f0)), G * (std::cos(f0) - std::cos(f1)),
                            0.5 * (m0 * m0 - m1 * m1) * (f1 - f0));
      const Vec3 c = h.center + R * Vec3(std::sin(tc) * std::cos(fc), std::sin(tc) * std::sin(fc),
                                         std::cos(tc));
      std::array<long, 3> r0;
      for (int a = 0; a < 3; ++a) r0[a] = std::lround((c(a) - origin(a)) / dx - shift);
      int best = -1;
      double bd = std::numeric_limits<double>::infinity();
      for (long rho = 0; rho <= rmax; ++rho) {
        for (long kz = -rho; kz <= rho; ++kz)
          for (long ky = -rho; ky <= rho; ++ky)
            for (long kx = -rho; kx <= rho; ++kx) {
              if (std::max({std::abs(kx), std::abs(ky), std::abs(kz)}) != rho) continue;
              const long ix = r0[0] + kx - lo[0], iy = r0[1] + ky - lo[1], iz = r0[2] + kz - lo[2];
              if (ix < 0 || iy < 0 || iz < 0 || ix >= nx || iy >= ny || iz >= nz) continue;
              const int p = box[ix + nx * (iy + ny * iz)];
              if (p < 0) continue;
              const double dd = (x[p] - c).norm();
              if (dd < bd || (dd == bd && p < best)) {
                bd = dd;
                best = p;
              }
            }
        // every point of ring ρ + 1 is at least (ρ + 1/2) Δx from c
        if (best >= 0 && bd < (rho + 0.5) * dx) break;
      }
      surf[best] -= ndS;
    }
  }
}

/// Cut-cell volumes (docs/solver.md §2, "Cut-cell volumes"). Cell of a lattice node: the
/// Δx-cube about it clipped to the box (the dual cell of a vertex grid). A point whose cell a
/// hole h with exact[h] cuts gets V = |cell| − Σ_h |cell ∩ hole_h| (the holes are disjoint).
/// A cell whose node lies in a hole (no point) but which overlaps the body ("orphan") is split
/// into sub-cells (8² in 2D, 3³ in 3D); the body part of each goes to the nearest point among
/// the 3^d lattice neighbours (a Voronoi partition at the sub-cell resolution), so Σ V is the
/// body's measure |box| − Σ_h |hole_h ∩ box| to round-off. An orphan cell that a non-exact hole
/// touches, or with no neighbouring point, keeps its body part out (never met on the scenes).
void cut_cell_volumes(const GridSpec& spec, const std::vector<char>& exact,
                      const std::vector<std::array<long, 3>>& lattice,
                      const std::array<long, 3>& nl, double shift, const std::vector<Vec3>& x,
                      std::vector<double>& vol) {
  const int d = spec.dimension;
  const double dx = spec.spacing;
  const std::size_t nh = spec.holes.size();
  bool any = false;
  for (std::size_t h = 0; h < nh; ++h) any = any || exact[h];
  if (!any) return;
  std::vector<int> at(nl[0] * nl[1] * nl[2], -1);
  auto flat = [&](long i, long j, long k) { return i + nl[0] * (j + nl[1] * k); };
  for (std::size_t p = 0; p < lattice.size(); ++p)
    at[flat(lattice[p][0], lattice[p][1], lattice[p][2])] = static_cast<int>(p);
  auto node = [&](long i, long j, long k) {
    Vec3 q = spec.origin + dx * Vec3(i + shift, j + shift, d == 3 ? k + shift : 0.0);
    if (d == 2) q.z() = 0.0;
    return q;
  };
  auto cell = [&](const Vec3& q, Vec3& lo, Vec3& hi) {
    lo = q - Vec3::Constant(0.5 * dx);
    hi = q + Vec3::Constant(0.5 * dx);
    for (int a = 0; a < d; ++a) {
      lo(a) = std::max(lo(a), spec.origin(a));
      hi(a) = std::min(hi(a), spec.origin(a) + spec.size(a));
    }
    double m = 1.0;
    for (int a = 0; a < d; ++a) m *= std::max(0.0, hi(a) - lo(a));
    return m;
  };
  // Body measure of a box: |box| − Σ_h |box ∩ hole_h|; false if a non-exact hole cuts it.
  auto body_part = [&](const Vec3& lo, const Vec3& hi, double box, double& body) {
    body = box;
    for (std::size_t h = 0; h < nh; ++h) {
      const double m = cell_hole_measure(d, lo, hi, spec.holes[h].center, spec.holes[h].radius);
      if (m > 0 && !exact[h]) return false;
      body -= m;
    }
    body = std::max(0.0, body);
    return true;
  };
  // Lattice cells within reach of an exact hole (each visited once).
  std::vector<char> seen(at.size(), 0);
  std::vector<std::array<long, 3>> cells;
  for (std::size_t h = 0; h < nh; ++h) {
    if (!exact[h]) continue;
    const auto& H = spec.holes[h];
    std::array<long, 3> lo{0, 0, 0}, hi{0, 0, 0};
    for (int a = 0; a < d; ++a) {
      lo[a] = std::max(0L, static_cast<long>(
                               std::floor((H.center(a) - H.radius - spec.origin(a)) / dx - shift)) -
                               1);
      hi[a] = std::min(
          nl[a] - 1,
          static_cast<long>(std::ceil((H.center(a) + H.radius - spec.origin(a)) / dx - shift)) + 1);
    }
    for (long k = lo[2]; k <= hi[2]; ++k)
      for (long j = lo[1]; j <= hi[1]; ++j)
        for (long i = lo[0]; i <= hi[0]; ++i)
          if (!seen[flat(i, j, k)]) {
            seen[flat(i, j, k)] = 1;
            cells.push_back({i, j, k});
          }
  }
  std::vector<double> add(vol.size(), 0.0);
  const int nsub = d == 2 ? 8 : 3;
  for (const auto& c : cells) {
    const Vec3 q = node(c[0], c[1], c[2]);
    Vec3 lo, hi;
    const double box = cell(q, lo, hi);
    double body = 0;
    if (!body_part(lo, hi, box, body)) continue;
    const int p = at[flat(c[0], c[1], c[2])];
    if (p >= 0) {
      vol[p] = body;
      continue;
    }
    if (!(body > 0)) continue;
    // Orphan: sub-cells to the nearest neighbouring point.
    std::vector<int> nb;
    for (long k = (d == 3 ? -1 : 0); k <= (d == 3 ? 1 : 0); ++k)
      for (long j = -1; j <= 1; ++j)
        for (long i = -1; i <= 1; ++i) {
          const long a = c[0] + i, b = c[1] + j, e = c[2] + k;
          if (a < 0 || b < 0 || e < 0 || a >= nl[0] || b >= nl[1] || e >= nl[2]) continue;
          if (at[flat(a, b, e)] >= 0) nb.push_back(at[flat(a, b, e)]);
        }
    if (nb.empty()) continue;
    const Vec3 step = (hi - lo) / nsub;
    for (int sk = 0; sk < (d == 3 ? nsub : 1); ++sk)
      for (int sj = 0; sj < nsub; ++sj)
        for (int si = 0; si < nsub; ++si) {
          Vec3 slo = lo + Vec3(si * step.x(), sj * step.y(), d == 3 ? sk * step.z() : 0.0);
          Vec3 shi = lo + Vec3((si + 1) * step.x(), (sj + 1) * step.y(),
                               d == 3 ? (sk + 1) * step.z() : 0.0);
          double sbox = 1.0;
          for (int a = 0; a < d; ++a) sbox *= shi(a) - slo(a);
          double sbody = 0;
          body_part(slo, shi, sbox, sbody);
          if (!(sbody > 0)) continue;
          Vec3 mid = 0.5 * (slo + shi);
          if (d == 2) mid.z() = 0.0;
          int best = nb[0];
          for (int m : nb)
            if ((x[m] - mid).squaredNorm() < (x[best] - mid).squaredNorm()) best = m;
          add[best] += sbody;
        }
  }
  for (std::size_t p = 0; p < vol.size(); ++p) vol[p] += add[p];
}

}  // namespace

Discretization Discretization::grid(const GridSpec& spec, const DiscretizationOptions& opt) {
  if (spec.dimension != 2 && spec.dimension != 3)
    throw InputError("unsupported dimension")
        .key("dimension")
        .value(std::to_string(spec.dimension))
        .expected("2 or 3");
  if (!(spec.spacing > 0))
    throw InputError("grid spacing must be positive")
        .key("geometry.spacing")
        .value(fmt::format("{}", spec.spacing))
        .expected("a positive length");
  const int d = spec.dimension;
  std::array<long, 3> n{1, 1, 1};
  for (int a = 0; a < d; ++a) {
    if (!(spec.size(a) > 0))
      throw InputError("body size must be positive")
          .key("geometry.size")
          .value(fmt::format("{}", spec.size(a)))
          .expected("positive lengths");
    n[a] = std::lround(spec.size(a) / spec.spacing);
    if (n[a] < 1 || std::abs(n[a] * spec.spacing - spec.size(a)) > 1e-6 * spec.size(a))
      throw InputError("body size is not a whole number of spacings")
          .key("geometry.size")
          .value(fmt::format("{} / {}", spec.size(a), spec.spacing))
          .expected("size = n · spacing for an integer n")
          .fix("choose a spacing that divides the size");
  }
  const double dx = spec.spacing;
  const bool vert = spec.nodes == GridNodes::vertices;
  const double slack = 1e-9 * dx;  // vertices on the boundary stay inside despite round-off
  auto inside = [&](const Vec3& p) {
    for (int a = 0; a < d; ++a)
      if (p(a) < spec.origin(a) - slack || p(a) > spec.origin(a) + spec.size(a) + slack)
        return false;
    for (const auto& h : spec.holes) {
      Vec3 r = p - h.center;
      if (d == 2) r.z() = 0;
      // Vertices on the circle are removed (kept, they stick out of the staircase as
      // single points held by their families only).
      if (r.norm() < h.radius * (vert ? 1 + 1e-9 : 1.0)) return false;
    }
    return true;
  };
  const long extra = vert ? 1 : 0;  // vertices: n + 1 points per axis
  const double shift = vert ? 0.0 : 0.5;
  std::vector<Vec3> x;
  std::vector<double> vol;
  // Dual-cell extent along each axis (vertices: half a spacing at the two ends).
  std::vector<Vec3> extent;
  std::vector<std::array<long, 3>> lattice;
  // Coordinates from lattice indices only (a neighbour's position is recomputed the same
  // way, so a point on a hole's circle is in or out consistently for both tests).
  auto node = [&](long i, long j, long k) {
    Vec3 p = spec.origin + dx * Vec3(i + shift, j + shift, d == 3 ? k + shift : 0.0);
    if (d == 2) p.z() = 0.0;
    return p;
  };
  for (long k = 0; k < (d == 3 ? n[2] + extra : 1); ++k)
    for (long j = 0; j < n[1] + extra; ++j)
      for (long i = 0; i < n[0] + extra; ++i) {
        const Vec3 p = node(i, j, k);
        if (!inside(p)) continue;
        Vec3 ext = Vec3::Constant(dx);
        const long idx[3] = {i, j, k};
        if (vert)
          for (int a = 0; a < d; ++a)
            if (idx[a] == 0 || idx[a] == n[a]) ext(a) = 0.5 * dx;
        x.push_back(p);
        extent.push_back(ext);
        lattice.push_back({i, j, k});
        double v = 1;
        for (int a = 0; a < d; ++a) v *= ext(a);
        vol.push_back(v);
      }
  if (x.empty())
    throw InputError("the geometry holds no grid point")
        .key("geometry")
        .fix("check size, spacing and holes");
  // Holes whose surface vectors come from the true circle / sphere: entirely inside the box
  // and disjoint from every other hole (otherwise the staircase faces below are kept).
  const std::size_t nh = spec.holes.size();
  std::vector<char> exact(nh, 1);
  auto planar = [&](Vec3 r) {
    if (d == 2) r.z() = 0;
    return r;
  };
  for (std::size_t h = 0; h < nh; ++h) {
    const auto& H = spec.holes[h];
    for (int a = 0; a < d; ++a)
      if (H.center(a) - H.radius < spec.origin(a) ||
          H.center(a) + H.radius > spec.origin(a) + spec.size(a))
        exact[h] = 0;
    for (std::size_t o = 0; o < nh; ++o)
      if (o != h &&
          planar(H.center - spec.holes[o].center).norm() < H.radius + spec.holes[o].radius)
        exact[h] = 0;
  }
  // The hole a missing neighbour q lies in (−1: none, q is outside the box).
  auto hole_of = [&](const Vec3& q) {
    for (int a = 0; a < d; ++a)
      if (q(a) < spec.origin(a) - slack || q(a) > spec.origin(a) + spec.size(a) + slack) return -1;
    for (std::size_t h = 0; h < nh; ++h)
      if (planar(q - spec.holes[h].center).norm() < spec.holes[h].radius * (vert ? 1 + 1e-9 : 1.0))
        return static_cast<int>(h);
    return -1;
  };
  if (spec.cut_cells) {
    const std::array<long, 3> nl{n[0] + extra, n[1] + extra, d == 3 ? n[2] + extra : 1};
    cut_cell_volumes(spec, exact, lattice, nl, shift, x, vol);
  }
  std::vector<std::vector<int>> on_hole(nh);
  std::vector<Vec3> surf(x.size(), Vec3::Zero());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (int a = 0; a < d; ++a)
      for (int sgn : {-1, 1}) {
        Vec3 e = Vec3::Zero();
        e(a) = sgn;
        auto l = lattice[i];
        l[a] += sgn;
        const Vec3 q = node(l[0], l[1], l[2]);
        bool face = !inside(q);
        if (face) {
          const int h = hole_of(q);
          if (h >= 0 && exact[h]) {  // s_k from the true surface below
            if (on_hole[h].empty() || on_hole[h].back() != static_cast<int>(i))
              on_hole[h].push_back(static_cast<int>(i));
            continue;
          }
        }
        for (const auto& c : spec.cracks) face = face || crosses(c, x[i], q);
        if (!face) continue;
        double area = 1;  // the dual-cell face normal to axis a
        for (int b = 0; b < d; ++b)
          if (b != a) area *= extent[i](b);
        surf[i] += area * e;
      }
  for (std::size_t h = 0; h < nh; ++h) {
    if (d == 2)
      circle_surface(spec.holes[h], x, on_hole[h], surf);
    else
      sphere_surface(spec.holes[h], x, lattice, on_hole[h], spec.origin, dx, shift, surf);
  }
  return from_points(d, std::move(x), std::move(vol), std::move(surf), dx, spec.cracks, opt);
}

Discretization Discretization::from_points(int dimension, std::vector<Vec3> x,
                                           std::vector<double> volume, std::vector<Vec3> surface,
                                           double spacing, std::vector<Crack> cracks,
                                           const DiscretizationOptions& opt) {
  Discretization D;
  D.dim_ = dimension;
  D.dx_ = spacing;
  D.delta_ = opt.horizon > 0 ? opt.horizon : opt.horizon_factor * spacing;
  if (!(D.delta_ >= spacing))
    throw InputError("horizon smaller than the grid spacing")
        .key("horizon")
        .value(fmt::format("{}", D.delta_))
        .expected(
            fmt::format("a horizon of at least the spacing {} (typically 3.015 spacings)", spacing))
        .fix("use horizon: {factor: 3.015}");
  D.x_ = std::move(x);
  D.vol_ = std::move(volume);
  D.surface_ = std::move(surface);
  D.cracks_ = std::move(cracks);
  D.build(opt);
  return D;
}

void Discretization::build(const DiscretizationOptions& opt) {
  opt_ = opt;
  const std::size_t N = x_.size();
  const int d = dim_;
  // ---- families by a cell list (cell size δ) ----
  Vec3 lo = x_[0], hi = x_[0];
  for (const auto& p : x_) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::array<long, 3> nc{1, 1, 1};
  for (int a = 0; a < d; ++a)
    nc[a] = std::max<long>(1, static_cast<long>((hi(a) - lo(a)) / delta_) + 1);
  auto cell_of = [&](const Vec3& p, int a) {
    return std::clamp<long>(static_cast<long>((p(a) - lo(a)) / delta_), 0, nc[a] - 1);
  };
  std::vector<std::int64_t> cell_start(nc[0] * nc[1] * nc[2] + 1, 0);
  std::vector<int> cell_points(N);
  std::vector<long> cid(N);
  for (std::size_t i = 0; i < N; ++i) {
    cid[i] = cell_of(x_[i], 0) + nc[0] * (cell_of(x_[i], 1) + nc[1] * cell_of(x_[i], 2));
    ++cell_start[cid[i] + 1];
  }
  std::partial_sum(cell_start.begin(), cell_start.end(), cell_start.begin());
  {
    std::vector<std::int64_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (std::size_t i = 0; i < N; ++i) cell_points[fill[cid[i]]++] = static_cast<int>(i);
  }
  // Points at exactly δ (e.g. m = 3) belong to the family: relative slack 1e-9.
  const double r2max = delta_ * delta_ * (1.0 + 1e-9);
  std::vector<std::vector<int>> fam(N);
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t i = 0; i < N; ++i) {
    const long cx = cell_of(x_[i], 0), cy = cell_of(x_[i], 1), cz = cell_of(x_[i], 2);
    for (long kz = std::max(0L, cz - 1); kz <= std::min(nc[2] - 1, cz + 1); ++kz)
      for (long ky = std::max(0L, cy - 1); ky <= std::min(nc[1] - 1, cy + 1); ++ky)
        for (long kx = std::max(0L, cx - 1); kx <= std::min(nc[0] - 1, cx + 1); ++kx) {
          const long c = kx + nc[0] * (ky + nc[1] * kz);
          for (auto q = cell_start[c]; q < cell_start[c + 1]; ++q) {
            const int j = cell_points[q];
            if (j == static_cast<int>(i) || (x_[j] - x_[i]).squaredNorm() > r2max) continue;
            bool cut = false;
            for (const auto& cr : cracks_) cut = cut || crosses(cr, x_[i], x_[j]);
            if (!cut) fam[i].push_back(j);
          }
        }
    std::sort(fam[i].begin(), fam[i].end());
  }
  families_.offsets.assign(N + 1, 0);
  for (std::size_t i = 0; i < N; ++i)
    families_.offsets[i + 1] = families_.offsets[i] + fam[i].size();
  families_.index.resize(families_.offsets[N]);
  for (std::size_t i = 0; i < N; ++i)
    std::copy(fam[i].begin(), fam[i].end(), families_.index.begin() + families_.offsets[i]);
  fam.clear();
  fam.shrink_to_fit();
  const std::size_t nb = families_.index.size();

  std::atomic<long> bad{-1};
  double bad_rc = 0;
  auto report_bad = [&](long i, double rc) {
    long expected = -1;
    if (bad.compare_exchange_strong(expected, i)) bad_rc = rc;
  };
  // ---- point stencils {i} ∪ H_i ----
  point_.offsets.assign(N + 1, 0);
  for (std::size_t i = 0; i < N; ++i)
    point_.offsets[i + 1] = point_.offsets[i] + 1 + (families_.end(i) - families_.begin(i));
  point_.index.resize(point_.offsets[N]);
  point_.grad.resize(point_.offsets[N] * d);
  point_.center.resize(N);
  point_.weight.resize(N);
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t i = 0; i < N; ++i) {
    int* m = point_.index.data() + point_.offsets[i];
    std::size_t k = 0;
    bool placed = false;
    for (auto q = families_.begin(i); q < families_.end(i); ++q) {
      const int j = families_.index[q];
      if (!placed && j > static_cast<int>(i)) {
        m[k++] = static_cast<int>(i);
        placed = true;
      }
      m[k++] = j;
    }
    if (!placed) m[k++] = static_cast<int>(i);
    point_.center[i] = static_cast<int>(i);
    point_.weight[i] = vol_[i];
    const double rc = pddo_stencil(d, x_, vol_, static_cast<int>(i), m, k, delta_, opt.influence,
                                   point_.grad.data() + point_.offsets[i] * d);
    if (!(rc >= opt.min_reciprocal_condition)) report_bad(static_cast<long>(i), rc);
  }
  if (bad >= 0)
    throw NumericalError(fmt::format(
        "the family of the point at ({:.6g}, {:.6g}, {:.6g}) is too small for a well-posed "
        "first-order PDDO (reciprocal condition {:.3g} of its moment matrix, {} neighbours); "
        "enlarge the horizon or remove isolated points",
        x_[bad](0), x_[bad](1), x_[bad](2), bad_rc, families_.end(bad) - families_.begin(bad)));

  // ---- BA stencils B_ij = {i, j} ∪ (H_i ∩ H_j) and weights φ̂_ij ----
  std::vector<std::int64_t> bsize(nb);
  std::vector<double> phi(nb);
  std::vector<double> famvol(N);
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t i = 0; i < N; ++i) {
    double s = vol_[i];
    for (auto q = families_.begin(i); q < families_.end(i); ++q) s += vol_[families_.index[q]];
    famvol[i] = s;
  }
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t i = 0; i < N; ++i) {
    const int* hi_b = families_.index.data() + families_.begin(i);
    const int* hi_e = families_.index.data() + families_.end(i);
    double norm = 0.0;
    for (auto q = families_.begin(i); q < families_.end(i); ++q) {
      const int j = families_.index[q];
      const int* hj_b = families_.index.data() + families_.begin(j);
      const int* hj_e = families_.index.data() + families_.end(j);
      std::int64_t cnt = 2;
      double v = vol_[i] + vol_[j];
      const int *a = hi_b, *b = hj_b;
      while (a != hi_e && b != hj_e) {
        if (*a < *b)
          ++a;
        else if (*b < *a)
          ++b;
        else {
          ++cnt;
          v += vol_[*a];
          ++a;
          ++b;
        }
      }
      bsize[q] = cnt;
      phi[q] = v / famvol[i];
      norm += phi[q] * vol_[j];
    }
    for (auto q = families_.begin(i); q < families_.end(i); ++q) phi[q] /= norm;
  }
  phi_hat_ = phi;
  bond_.offsets.assign(nb + 1, 0);
  for (std::size_t q = 0; q < nb; ++q) bond_.offsets[q + 1] = bond_.offsets[q] + bsize[q];
  bond_.index.resize(bond_.offsets[nb]);
  bond_.grad.resize(bond_.offsets[nb] * d);
  bond_.center.resize(nb);
  bond_.weight.resize(nb);
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t i = 0; i < N; ++i) {
    const int* hi_b = families_.index.data() + families_.begin(i);
    const int* hi_e = families_.index.data() + families_.end(i);
    for (auto q = families_.begin(i); q < families_.end(i); ++q) {
      const int j = families_.index[q];
      int* m = bond_.index.data() + bond_.offsets[q];
      std::size_t k = 0;
      const int *a = hi_b, *b = families_.index.data() + families_.begin(j),
                *b_e = families_.index.data() + families_.end(j);
      while (a != hi_e && b != b_e) {
        if (*a < *b)
          ++a;
        else if (*b < *a)
          ++b;
        else {
          m[k++] = *a;
          ++a;
          ++b;
        }
      }
      m[k++] = static_cast<int>(i);
      m[k++] = j;
      std::sort(m, m + k);
      bond_.center[q] = static_cast<int>(i);
      bond_.weight[q] = vol_[i] * phi_hat_[q] * vol_[j];
      const double rc = pddo_stencil(d, x_, vol_, static_cast<int>(i), m, k, delta_, opt.influence,
                                     bond_.grad.data() + bond_.offsets[q] * d);
      if (!(rc >= opt.min_reciprocal_condition)) report_bad(static_cast<long>(i), rc);
    }
  }
  if (bad >= 0)
    throw NumericalError(fmt::format(
        "a bond-associated family B_ij of the point at ({:.6g}, {:.6g}, {:.6g}) is too small for a "
        "well-posed first-order PDDO (reciprocal condition {:.3g}); enlarge the horizon "
        "(horizon: {{factor: 3.015}} or more) or refine the grid near that point",
        x_[bad](0), x_[bad](1), x_[bad](2), bad_rc));
}

// ---------------------------------------------------------------- rupture

void Discretization::enable_rupture() {
  if (!broken_.empty()) return;
  broken_.assign(families_.index.size(), 0);
  suppressed_.assign(bond_.size(), 0);
  point_off_.assign(x_.size(), 0);
}

bool Discretization::suppress_point_stencil(int k) {
  if (point_off_.empty()) throw Error("internal error: suppress_point_stencil without rupture");
  if (point_off_[k]) return false;
  point_off_[k] = 1;
  std::fill(point_.grad.begin() + point_.offsets[k] * dim_,
            point_.grad.begin() + point_.offsets[k + 1] * dim_, 0.0);
  return true;
}

std::vector<int> Discretization::suppressed_point_stencils() const {
  std::vector<int> out;
  for (std::size_t k = 0; k < point_off_.size(); ++k)
    if (point_off_[k]) out.push_back(static_cast<int>(k));
  return out;
}

std::int64_t Discretization::bond_index(int i, int j) const {
  const int* b = families_.index.data() + families_.begin(i);
  const int* e = families_.index.data() + families_.end(i);
  const int* p = std::lower_bound(b, e, j);
  return (p != e && *p == j) ? families_.begin(i) + (p - b) : -1;
}

bool Discretization::break_bond(int i, int j) {
  if (broken_.empty()) throw Error("internal error: break_bond without enable_rupture");
  const std::int64_t q = bond_index(i, j), r = bond_index(j, i);
  if (q < 0 || r < 0) throw Error("internal error: break_bond of a pair that is not a bond");
  if (broken_[q]) return false;
  broken_[q] = broken_[r] = 1;
  ++n_broken_;
  dirty_.push_back(i);
  dirty_.push_back(j);
  return true;
}

std::size_t Discretization::rebuild_broken(double min_rc) {
  if (dirty_.empty()) {
    rebuilt_centres_.clear();
    return 0;
  }
  const double rc_min = min_rc > 0 ? min_rc : opt_.min_reciprocal_condition;
  const int d = dim_;
  const std::size_t N = x_.size();
  // Centres to rebuild: the ends of the broken bonds and their reference families.
  std::vector<char> mark(N, 0);
  for (int p : dirty_) {
    mark[p] = 1;
    for (auto q = families_.begin(p); q < families_.end(p); ++q) mark[families_.index[q]] = 1;
  }
  dirty_.clear();
  std::vector<int>& centres = rebuilt_centres_;
  centres.clear();
  for (std::size_t i = 0; i < N; ++i)
    if (mark[i]) centres.push_back(static_cast<int>(i));
  // A member's share of a rebuilt stencil: 0 if its bond is broken, else the bond's stiffness
  // factor (1 − d of a softening law; 1 without one), so that a lens loses a member
  // continuously as the bond to it softens, and at d = 1 exactly as at a break.
  auto keep = [&](int a, int b) {
    const std::int64_t q = bond_index(a, b);
    if (q < 0 || broken_[q]) return 0.0;
    return bond_factor_.empty() ? 1.0 : bond_factor_[q];
  };
  std::size_t rebuilt = 0;
#pragma omp parallel reduction(+ : rebuilt)
  {
    std::vector<int> act;
    std::vector<double> g, share;
    std::vector<char> on;
#pragma omp for schedule(dynamic, 8)
    for (std::size_t c = 0; c < centres.size(); ++c) {
      const int i = centres[c];
      // point stencil {i} ∪ intact H_i
      {
        const auto b = point_.offsets[i], e = point_.offsets[i + 1];
        act.clear();
        share.clear();
        on.assign(e - b, 0);
        for (auto r = b; r < e; ++r) {
          const int m = point_.index[r];
          const double f = m == i ? 1.0 : keep(i, m);
          if (f > 0) {
            act.push_back(m);
            share.push_back(f);
            on[r - b] = 1;
          }
        }
        g.assign(act.size() * d, 0.0);
        const double rc = pddo_stencil(d, x_, vol_, i, act.data(), act.size(), delta_,
                                       opt_.influence, g.data(), share.data());
        const bool ok = rc >= rc_min && !point_off_[i];
        std::size_t k = 0;  // advances over the active members only
        for (auto r = b; r < e; ++r) {
          for (int a = 0; a < d; ++a)
            point_.grad[r * d + a] = (ok && on[r - b]) ? g[k * d + a] : 0.0;
          if (on[r - b]) ++k;
        }
        ++rebuilt;
      }
      // BA stencils of i: members, G, φ
      double famvol = vol_[i];
      for (auto q = families_.begin(i); q < families_.end(i); ++q)
        famvol += vol_[families_.index[q]] * keep(i, families_.index[q]);
      double norm = 0.0;
      for (auto q = families_.begin(i); q < families_.end(i); ++q) {
        const int j = families_.index[q];
        const auto b = bond_.offsets[q], e = bond_.offsets[q + 1];
        double* G = bond_.grad.data() + b * d;
        phi_hat_[q] = 0.0;
        suppressed_[q] = 0;
        if (broken_[q]) {
          std::fill(G, G + (e - b) * d, 0.0);
          ++rebuilt;
          continue;
        }
        act.clear();
        share.clear();
        on.assign(e - b, 0);
        double v = 0.0;
        for (auto r = b; r < e; ++r) {
          const int m = bond_.index[r];
          const double f = (m == i || m == j) ? 1.0 : keep(i, m) * keep(j, m);
          if (f > 0) {
            act.push_back(m);
            share.push_back(f);
            on[r - b] = 1;
            v += vol_[m] * f;
          }
        }
        g.assign(act.size() * d, 0.0);
        const double rc = pddo_stencil(d, x_, vol_, i, act.data(), act.size(), delta_,
                                       opt_.influence, g.data(), share.data());
        const bool ok = rc >= rc_min;
        std::size_t k = 0;
        for (auto r = b; r < e; ++r) {
          for (int a = 0; a < d; ++a) G[(r - b) * d + a] = (ok && on[r - b]) ? g[k * d + a] : 0.0;
          if (on[r - b]) ++k;
        }
        if (ok) {
          phi_hat_[q] = v / famvol;
          // the family partitions unity with each bond's stiffness factor (Σ φ̂V(1 − d) = 1)
          norm += phi_hat_[q] * vol_[j] * (bond_factor_.empty() ? 1.0 : bond_factor_[q]);
        } else {
          suppressed_[q] = 1;
        }
        ++rebuilt;
      }
      for (auto q = families_.begin(i); q < families_.end(i); ++q) {
        if (norm > 0) phi_hat_[q] /= norm;
        bond_.weight[q] = vol_[i] * phi_hat_[q] * vol_[families_.index[q]] *
                          (bond_factor_.empty() ? 1.0 : bond_factor_[q]);
      }
    }
  }
  n_suppressed_ = static_cast<std::size_t>(std::count(suppressed_.begin(), suppressed_.end(), 1));
  return rebuilt;
}

void Discretization::set_bond_stiffness_factor(std::int64_t q, double factor) {
  if (!(factor >= 0.0 && factor <= 1.0))
    throw Error(fmt::format("internal error: bond stiffness factor {} outside [0, 1]", factor));
  if (bond_factor_.empty()) bond_factor_.assign(bond_.size(), 1.0);
  if (bond_factor_[q] == factor) return;
  bond_factor_[q] = factor;
  bond_.weight[q] = intact_bond_weight(q) * factor;
  // the stencils holding this bond's end as a member follow at the next rebuild_broken
  dirty_.push_back(bond_.center[q]);
  dirty_.push_back(families_.index[q]);
}

std::vector<double> Discretization::damage() const {
  const std::size_t N = x_.size();
  std::vector<double> D(N, 0.0);
  if (broken_.empty()) return D;
  for (std::size_t i = 0; i < N; ++i) {
    const auto n = families_.end(i) - families_.begin(i);
    if (n == 0) continue;
    std::int64_t k = 0;
    for (auto q = families_.begin(i); q < families_.end(i); ++q) k += broken_[q];
    D[i] = static_cast<double>(k) / static_cast<double>(n);
  }
  return D;
}

}  // namespace pdcg::solver
