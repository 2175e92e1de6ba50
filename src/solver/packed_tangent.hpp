// Internal to the solver module: stencil gather/scatter and the per-stencil material tangent
// packed by major symmetry, shared by the assembled tangent (model.cpp: assemble_rows,
// tangent_row_abs_sums) and the matrix-free operator (model_matvec.cpp).
//
// A hyperelastic tangent A_aJbL = ∂²Ψ/∂F_aJ∂F_bL is symmetric as a d²×d² matrix (index
// i = a·d + J, j = b·d + L). Per stencil only its upper triangle is kept, row-major:
// d²(d²+1)/2 doubles (10 in 2D, 45 in 3D) instead of d⁴ (16, 81), pre-multiplied by w_S.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <utility>

#include "pdcg/solver/material.hpp"

namespace pdcg::solver::detail {

/// Doubles per packed stencil tangent.
constexpr int packed_size(int d) { return d * d * (d * d + 1) / 2; }

/// Position of entry (i, j) of the symmetric d2×d2 matrix in the packed upper triangle
/// (row i starts after Σ_{r<i} (d2 − r) = i·d2 − i(i−1)/2 entries).
constexpr int packed_at(int d2, int i, int j) {
  if (i > j) std::swap(i, j);
  return i * d2 - i * (i - 1) / 2 + (j - i);
}

/// Ac = w · ½(A + Aᵀ) packed (upper triangle, row-major) for dimension d. Returns the
/// relative lack of major symmetry max |A_ij − A_ji| / max |A| (0 for a zero tangent).
inline double pack_tangent(int d, const Tangent& A, double w, double* Ac) {
  const int d2 = d * d;
  double amax = 0.0, dmax = 0.0;
  int p = 0;
  for (int i = 0; i < d2; ++i)
    for (int j = i; j < d2; ++j, ++p) {
      const double aij = A(flat(i / d, i % d), flat(j / d, j % d));
      const double aji = A(flat(j / d, j % d), flat(i / d, i % d));
      amax = std::max(amax, std::abs(aij));
      dmax = std::max(dmax, std::abs(aij - aji));
      Ac[p] = w * 0.5 * (aij + aji);
    }
  return amax > 0 ? dmax / amax : 0.0;
}

/// B[a][b·D + L] = Σ_J A_aJbL g_J for a packed symmetric A (the row gather's contraction of
/// a stencil tangent with G^k), unrolled at compile time: every packed position is a
/// constant, so the packing costs no index arithmetic.
template <int D, int I>
[[gnu::always_inline]] inline double contract_entry(const double* A, const double* g) {
  constexpr int D2 = D * D, a = I / D2, bL = I % D2;
  double t = 0.0;
  [&]<int... J>(std::integer_sequence<int, J...>) {
    ((t += A[std::integral_constant<int, packed_at(D2, a * D + J, bL)>::value] * g[J]), ...);
  }
  (std::make_integer_sequence<int, D>{});
  return t;
}
template <int D>
[[gnu::always_inline]] inline void contract_packed(const double* A, const double* g,
                                                   double (&B)[D][D * D]) {
  [&]<int... I>(std::integer_sequence<int, I...>) {
    ((B[I / (D * D)][I % (D * D)] = contract_entry<D, I>(A, g)), ...);
  }
  (std::make_integer_sequence<int, D * D * D>{});
}

/// Hyperelastic tangents are symmetric to round-off (≈ 1e-16 relative); 1e-8 leaves room
/// for tangents computed by sums over many bonds (Cauchy–Born) and catches a real lack.
constexpr double kMaxAsymmetry = 1e-8;

// dF[a·D + J] = Σ_{m∈S} v_m,a G_S^m,J
template <int D>
[[gnu::always_inline]] inline void gather(const int* idx, const double* grad, std::int64_t r0,
                                          std::int64_t r1, const double* v, double (&dF)[D * D]) {
  for (int i = 0; i < D * D; ++i) dF[i] = 0.0;
  for (auto r = r0; r < r1; ++r) {
    const double* vm = v + static_cast<std::int64_t>(D) * idx[r];
    const double* g = grad + r * D;
    for (int a = 0; a < D; ++a)
      for (int J = 0; J < D; ++J) dF[a * D + J] += vm[a] * g[J];
  }
}
// out_m,a += Σ_J P[a·D + J] G_S^m,J
template <int D>
[[gnu::always_inline]] inline void scatter(const int* idx, const double* grad, std::int64_t r0,
                                           std::int64_t r1, const double (&P)[D * D], double* out) {
  for (auto r = r0; r < r1; ++r) {
    double* om = out + static_cast<std::int64_t>(D) * idx[r];
    const double* g = grad + r * D;
    for (int a = 0; a < D; ++a) {
      double t = 0.0;
      for (int J = 0; J < D; ++J) t += P[a * D + J] * g[J];
      om[a] += t;
    }
  }
}

}  // namespace pdcg::solver::detail
