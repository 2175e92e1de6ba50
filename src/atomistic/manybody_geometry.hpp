/// \file
/// Private to the atomistic module: derivatives of a three-body function f(r₁, r₂, c) of two
/// bond vectors u, v (r₁ = |u|, r₂ = |v|, c = cos θ = u·v/(r₁r₂)) with respect to u and v,
/// and their scatter into force states and tangents of a family (docs/potentials.md,
/// "Three-body and bond-order styles"). With û = u/r₁, v̂ = v/r₂:
///   ∇_u r₁ = û,  ∇²_uu r₁ = (I − ûû)/r₁
///   ∇_u c = a_u = (v̂ − c û)/r₁,  ∇_v c = a_v = (û − c v̂)/r₂
///   ∇²_uu c = [3c ûû − (ûv̂ + v̂û) − c I]/r₁²
///   ∇²_uv c = [I − ûû − v̂v̂ + c ûv̂]/(r₁r₂)      ((∇²_uv c)_ab = ∂²c/∂u_a∂v_b)
/// so that ∇_u f = f₁ û + f_c a_u and
///   ∇²_uu f = f₁₁ ûû + f₁c(û a_u + a_u û) + f_cc a_u a_u + f₁ (I − ûû)/r₁ + f_c ∇²_uu c
///   ∇²_uv f = f₁₂ ûv̂ + f₁c û a_v + f₂c a_u v̂ + f_cc a_u a_v + f_c ∇²_uv c
/// (and ∇²_vv f by symmetry). Everything is inline, allocation-free.
#pragma once

#include <cmath>
#include <cstdint>

namespace pdcg::atomistic::detail {

/// Geometry of the angle between u and v.
struct Angle {
  double uh[3], vh[3];  ///< unit vectors
  double r1, r2, c;     ///< lengths and cos θ
  double au[3], av[3];  ///< ∇_u c, ∇_v c

  Angle(const double* u, double r1_, const double* v, double r2_) : r1(r1_), r2(r2_) {
    const double i1 = 1.0 / r1, i2 = 1.0 / r2;
    for (int a = 0; a < 3; ++a) {
      uh[a] = u[a] * i1;
      vh[a] = v[a] * i2;
    }
    c = uh[0] * vh[0] + uh[1] * vh[1] + uh[2] * vh[2];
    for (int a = 0; a < 3; ++a) {
      au[a] = (vh[a] - c * uh[a]) * i1;
      av[a] = (uh[a] - c * vh[a]) * i2;
    }
  }
};

/// First partial derivatives of f(r₁, r₂, c).
struct Partials1 {
  double f1 = 0, f2 = 0, fc = 0;
};
/// Second partial derivatives of f(r₁, r₂, c).
struct Partials2 {
  double f11 = 0, f22 = 0, fcc = 0, f12 = 0, f1c = 0, f2c = 0;
};

/// ∇_u f and ∇_v f.
inline void angle_gradient(const Angle& g, const Partials1& p, double* gu, double* gv) {
  for (int a = 0; a < 3; ++a) {
    gu[a] = p.f1 * g.uh[a] + p.fc * g.au[a];
    gv[a] = p.f2 * g.vh[a] + p.fc * g.av[a];
  }
}

/// ∇²_uu f, ∇²_uv f, ∇²_vv f (row-major 3×3).
inline void angle_hessian(const Angle& g, const Partials1& p, const Partials2& q, double* huu,
                          double* huv, double* hvv) {
  const double c = g.c;
  const double i11 = 1.0 / (g.r1 * g.r1), i22 = 1.0 / (g.r2 * g.r2), i12 = 1.0 / (g.r1 * g.r2);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double d = a == b ? 1.0 : 0.0;
      const double uu = g.uh[a] * g.uh[b], vv = g.vh[a] * g.vh[b];
      const double cuu = (3.0 * c * uu - (g.uh[a] * g.vh[b] + g.vh[a] * g.uh[b]) - c * d) * i11;
      const double cvv = (3.0 * c * vv - (g.vh[a] * g.uh[b] + g.uh[a] * g.vh[b]) - c * d) * i22;
      const double cuv = (d - uu - vv + c * g.uh[a] * g.vh[b]) * i12;
      huu[3 * a + b] = q.f11 * uu + q.f1c * (g.uh[a] * g.au[b] + g.au[a] * g.uh[b]) +
                       q.fcc * g.au[a] * g.au[b] + p.f1 * (d - uu) / g.r1 + p.fc * cuu;
      hvv[3 * a + b] = q.f22 * vv + q.f2c * (g.vh[a] * g.av[b] + g.av[a] * g.vh[b]) +
                       q.fcc * g.av[a] * g.av[b] + p.f2 * (d - vv) / g.r2 + p.fc * cvv;
      huv[3 * a + b] = q.f12 * g.uh[a] * g.vh[b] + q.f1c * g.uh[a] * g.av[b] +
                       q.f2c * g.au[a] * g.vh[b] + q.fcc * g.au[a] * g.av[b] + p.fc * cuv;
    }
}

/// A local vector of a many-body term as a combination of at most two bonds of the family:
/// s0 Y_b0 + s1 Y_b1 (b1 < 0: one bond only). u = Y_j is {j, +1}; u = −Y_j is {j, −1};
/// w = Y_l − Y_j is {l, +1, j, −1}.
struct LocalVector {
  std::int64_t b0 = 0;
  double s0 = 1.0;
  std::int64_t b1 = -1;
  double s1 = 0.0;
};

/// t_b += s ∂f/∂(local vector) for the bonds of the local vector.
inline void scatter_gradient(double* t, const LocalVector& x, const double* g) {
  double* t0 = t + 3 * x.b0;
  for (int a = 0; a < 3; ++a) t0[a] += x.s0 * g[a];
  if (x.b1 >= 0) {
    double* t1 = t + 3 * x.b1;
    for (int a = 0; a < 3; ++a) t1[a] += x.s1 * g[a];
  }
}

/// K_{b b'} += s s' H for the bonds b of x and b' of y (H = ∂²f/∂x∂y, 3×3 row-major, scaled
/// by `w`); n = family size.
inline void scatter_block(double* K, std::int64_t n, const LocalVector& x, const LocalVector& y,
                          const double* H, double w) {
  const std::int64_t bx[2] = {x.b0, x.b1}, by[2] = {y.b0, y.b1};
  const double sx[2] = {x.s0, x.s1}, sy[2] = {y.s0, y.s1};
  for (int p = 0; p < 2; ++p) {
    if (bx[p] < 0) continue;
    for (int q = 0; q < 2; ++q) {
      if (by[q] < 0) continue;
      double* k = K + (bx[p] * n + by[q]) * 9;
      const double s = w * sx[p] * sy[q];
      for (int e = 0; e < 9; ++e) k[e] += s * H[e];
    }
  }
}

/// The three blocks of a two-vector term f(x, y): K += w [H_xx, H_xy; H_yx, H_yy].
inline void scatter_pair_hessian(double* K, std::int64_t n, const LocalVector& x,
                                 const LocalVector& y, const double* hxx, const double* hxy,
                                 const double* hyy, double w) {
  double hyx[9];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) hyx[3 * a + b] = hxy[3 * b + a];
  scatter_block(K, n, x, x, hxx, w);
  scatter_block(K, n, x, y, hxy, w);
  scatter_block(K, n, y, x, hyx, w);
  scatter_block(K, n, y, y, hyy, w);
}

/// Block of a radial function h(r) of one vector x: h'' x̂x̂ + h'/r (I − x̂x̂), scaled by w.
inline void scatter_radial(double* K, std::int64_t n, const LocalVector& x, const double* xv,
                           double r, double d1, double d2, double w) {
  double H[9];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double ee = xv[a] * xv[b] / (r * r);
      H[3 * a + b] = d2 * ee + d1 / r * ((a == b ? 1.0 : 0.0) - ee);
    }
  scatter_block(K, n, x, x, H, w);
}

}  // namespace pdcg::atomistic::detail
