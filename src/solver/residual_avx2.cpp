// AVX2 + FMA residual sweep and batched Neo-Hookean stress (see residual_avx2.hpp and
// docs/performance.md "BA kernels against the roofline").
//
// Layout (unchanged Stencils): per term a member index (int) and G^m (d doubles, contiguous,
// so the G of consecutive members are consecutive). Everything is done by in-register
// shuffles of those rows:
//  2D gather, two members per 4-wide vector: g = (G_r, G_r+1), uu = (u_r, u_r+1) (two 128-bit
//     loads), F₀· += dup(uu[0]) g, F₁· += dup(uu[1]) g; the two lanes are summed at the end.
//  2D scatter, two members: (f_r, f_r+1) += (wP₀₀, wP₁₀)·G₀ + (wP₀₁, wP₁₁)·G₁ per 128-bit lane.
//  3D gather, one member per vector: g = (G₀, G₁, G₂, ·) (a 4-wide load whose 4th lane is the
//     next member's G₀, never used; the very last term of the array loads 3 doubles), row a
//     of F += u_a g (u_a broadcast).
//  3D scatter: f_m += col₀ G₀ + col₁ G₁ + col₂ G₂ (columns of w P, 4th lane 0) into a force
//     array padded to 4 doubles per point (one aligned 32-byte add; Model::residual_kernel
//     owns the padded per-thread arrays and sums them into f).
// Partial sums run in two independent chains (even/odd member pairs) to hide the FMA
// latency: the summation order differs from the scalar sweep, results agree to round-off.
//
// The constitutive update runs on four stencils at once (Material::stress4): for the
// Neo-Hookean materials J^(−2/3) = y² with y = J^(−1/3) from an exponent-halving bit guess
// (≤ 3.5 % off) and four Newton steps y ← y (4 − J y³)/3, the last in residual form
// y + y (1 − J y³)/3: ≤ 4·10⁻¹⁶ relative on the whole normal range (pow(J, −2.0/3): 1·10⁻¹⁶
// for J near 1, 3·10⁻¹⁴ at J = e^±700 since −2.0/3 is not −2/3).
#include "residual_avx2.hpp"

#ifdef PDCG_SOLVER_AVX2

#include <immintrin.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>

#define PDCG_AVX2_FN __attribute__((target("avx2,fma")))
#define PDCG_AVX2_INL __attribute__((target("avx2,fma"), always_inline)) inline

namespace pdcg::solver::detail {

bool cpu_has_avx2_fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has && vector_kernels_allowed.load(std::memory_order_relaxed);
}

namespace {

using i64 = std::int64_t;

// ------------------------------------------------------------------------------- 2D
// (u_m0, u_m1): (u_m0,x, u_m0,y, u_m1,x, u_m1,y).
PDCG_AVX2_INL __m256d load_pair2(const double* u, int m0, int m1) {
  return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(u + 2 * static_cast<i64>(m0))),
                              _mm_loadu_pd(u + 2 * static_cast<i64>(m1)), 1);
}

// F_S − I of one 2D stencil, terms [r, e): out = (F00, F01, F10, F11).
PDCG_AVX2_INL void gather2(const int* idx, const double* grad, i64 r, i64 e, const double* u,
                           __m128d& row0, __m128d& row1) {
  __m256d a0 = _mm256_setzero_pd(), a1 = _mm256_setzero_pd();
  __m256d b0 = _mm256_setzero_pd(), b1 = _mm256_setzero_pd();
  for (; r + 4 <= e; r += 4) {
    const __m256d g = _mm256_loadu_pd(grad + 2 * r);
    const __m256d uu = load_pair2(u, idx[r], idx[r + 1]);
    a0 = _mm256_fmadd_pd(_mm256_movedup_pd(uu), g, a0);
    a1 = _mm256_fmadd_pd(_mm256_permute_pd(uu, 0xF), g, a1);
    const __m256d h = _mm256_loadu_pd(grad + 2 * r + 4);
    const __m256d vv = load_pair2(u, idx[r + 2], idx[r + 3]);
    b0 = _mm256_fmadd_pd(_mm256_movedup_pd(vv), h, b0);
    b1 = _mm256_fmadd_pd(_mm256_permute_pd(vv, 0xF), h, b1);
  }
  if (r + 2 <= e) {
    const __m256d g = _mm256_loadu_pd(grad + 2 * r);
    const __m256d uu = load_pair2(u, idx[r], idx[r + 1]);
    a0 = _mm256_fmadd_pd(_mm256_movedup_pd(uu), g, a0);
    a1 = _mm256_fmadd_pd(_mm256_permute_pd(uu, 0xF), g, a1);
    r += 2;
  }
  a0 = _mm256_add_pd(a0, b0);
  a1 = _mm256_add_pd(a1, b1);
  row0 = _mm_add_pd(_mm256_castpd256_pd128(a0), _mm256_extractf128_pd(a0, 1));
  row1 = _mm_add_pd(_mm256_castpd256_pd128(a1), _mm256_extractf128_pd(a1, 1));
  if (r < e) {
    const __m128d g = _mm_loadu_pd(grad + 2 * r);
    const __m128d um = _mm_loadu_pd(u + 2 * static_cast<i64>(idx[r]));
    row0 = _mm_fmadd_pd(_mm_movedup_pd(um), g, row0);
    row1 = _mm_fmadd_pd(_mm_permute_pd(um, 3), g, row1);
  }
}

PDCG_AVX2_INL void add2(double* f, int m, __m128d v) {
  double* fm = f + 2 * static_cast<i64>(m);
  _mm_storeu_pd(fm, _mm_add_pd(v, _mm_loadu_pd(fm)));
}

// f_m += w P G^m for the terms [r, e) of one 2D stencil; c0 = (wP00, wP10, wP00, wP10),
// c1 = (wP01, wP11, wP01, wP11).
PDCG_AVX2_INL void scatter2(const int* idx, const double* grad, i64 r, i64 e, double* f, __m256d c0,
                            __m256d c1) {
  for (; r + 4 <= e; r += 4) {
    const __m256d g = _mm256_loadu_pd(grad + 2 * r), h = _mm256_loadu_pd(grad + 2 * r + 4);
    const __m256d v =
        _mm256_fmadd_pd(c1, _mm256_permute_pd(g, 0xF), _mm256_mul_pd(c0, _mm256_movedup_pd(g)));
    const __m256d w =
        _mm256_fmadd_pd(c1, _mm256_permute_pd(h, 0xF), _mm256_mul_pd(c0, _mm256_movedup_pd(h)));
    add2(f, idx[r], _mm256_castpd256_pd128(v));
    add2(f, idx[r + 1], _mm256_extractf128_pd(v, 1));
    add2(f, idx[r + 2], _mm256_castpd256_pd128(w));
    add2(f, idx[r + 3], _mm256_extractf128_pd(w, 1));
  }
  if (r + 2 <= e) {
    const __m256d g = _mm256_loadu_pd(grad + 2 * r);
    const __m256d v =
        _mm256_fmadd_pd(c1, _mm256_permute_pd(g, 0xF), _mm256_mul_pd(c0, _mm256_movedup_pd(g)));
    add2(f, idx[r], _mm256_castpd256_pd128(v));
    add2(f, idx[r + 1], _mm256_extractf128_pd(v, 1));
    r += 2;
  }
  if (r < e) {
    const __m128d g = _mm_loadu_pd(grad + 2 * r);
    const __m128d v = _mm_fmadd_pd(_mm256_castpd256_pd128(c1), _mm_permute_pd(g, 3),
                                   _mm_mul_pd(_mm256_castpd256_pd128(c0), _mm_movedup_pd(g)));
    double* fr = f + 2 * static_cast<i64>(idx[r]);
    _mm_storeu_pd(fr, _mm_add_pd(_mm_loadu_pd(fr), v));
  }
}

// ------------------------------------------------------------------------------- 3D
// (G₀, G₁, G₂, ·) of term r; `safe`: the last term of the array (no 4th double to read).
PDCG_AVX2_INL __m256d load_g3(const double* grad, i64 r, bool safe) {
  const double* g = grad + 3 * r;
  if (!safe) return _mm256_loadu_pd(g);
  return _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(g)), _mm_load_sd(g + 2), 1);
}

// Row a of F += u_m,a (G₀, G₁, G₂, ·) for one member.
PDCG_AVX2_INL void acc3(__m256d* a, __m256d g, const double* um) {
  a[0] = _mm256_fmadd_pd(_mm256_broadcast_sd(um), g, a[0]);
  a[1] = _mm256_fmadd_pd(_mm256_broadcast_sd(um + 1), g, a[1]);
  a[2] = _mm256_fmadd_pd(_mm256_broadcast_sd(um + 2), g, a[2]);
}

// F_S − I of one 3D stencil, terms [r, e): rows (lane 3 unused). Terms r < last may read 4
// doubles of G. Two accumulator sets (even / odd members), four members per iteration.
PDCG_AVX2_INL void gather3(const int* idx, const double* grad, i64 r, i64 e, i64 last,
                           const double* u, __m256d* row) {
  const __m256d z = _mm256_setzero_pd();
  __m256d a[3] = {z, z, z}, b[3] = {z, z, z};
  auto up = [u](int m) { return u + 3 * static_cast<i64>(m); };
  const i64 ef = std::min(e, last);
  for (; r + 4 <= ef; r += 4) {
    acc3(a, _mm256_loadu_pd(grad + 3 * r), up(idx[r]));
    acc3(b, _mm256_loadu_pd(grad + 3 * r + 3), up(idx[r + 1]));
    acc3(a, _mm256_loadu_pd(grad + 3 * r + 6), up(idx[r + 2]));
    acc3(b, _mm256_loadu_pd(grad + 3 * r + 9), up(idx[r + 3]));
  }
  if (r + 2 <= ef) {
    acc3(a, _mm256_loadu_pd(grad + 3 * r), up(idx[r]));
    acc3(b, _mm256_loadu_pd(grad + 3 * r + 3), up(idx[r + 1]));
    r += 2;
  }
  for (; r < e; ++r) acc3(a, load_g3(grad, r, r >= last), up(idx[r]));
  for (int c = 0; c < 3; ++c) row[c] = _mm256_add_pd(a[c], b[c]);
}

// f_m (padded to 4 doubles, 32-byte aligned) += (v₀, v₁, v₂, 0).
PDCG_AVX2_INL void add3(double* fm, __m256d v) {
  _mm256_store_pd(fm, _mm256_add_pd(v, _mm256_load_pd(fm)));
}

// (w P G^m, 0) = c0 G₀ + c1 G₁ + c2 G₂ for one member.
PDCG_AVX2_INL __m256d term3(const __m256d* c, const double* g) {
  __m256d v = _mm256_mul_pd(c[0], _mm256_broadcast_sd(g));
  v = _mm256_fmadd_pd(c[1], _mm256_broadcast_sd(g + 1), v);
  return _mm256_fmadd_pd(c[2], _mm256_broadcast_sd(g + 2), v);
}

// f_m += w P G^m for the terms [r, e) of one 3D stencil; c[J] = (wP0J, wP1J, wP2J, 0).
PDCG_AVX2_INL void scatter3(const int* idx, const double* grad, i64 r, i64 e, double* f,
                            const __m256d* c) {
  auto fp = [f](int m) { return f + 4 * static_cast<i64>(m); };
  for (; r + 4 <= e; r += 4) {
    const double* g = grad + 3 * r;
    const __m256d v0 = term3(c, g), v1 = term3(c, g + 3), v2 = term3(c, g + 6),
                  v3 = term3(c, g + 9);
    add3(fp(idx[r]), v0);
    add3(fp(idx[r + 1]), v1);
    add3(fp(idx[r + 2]), v2);
    add3(fp(idx[r + 3]), v3);
  }
  for (; r < e; ++r) add3(fp(idx[r]), term3(c, grad + 3 * r));
}

// In-place 4×4 transpose of four rows.
PDCG_AVX2_INL void transpose4(__m256d* r) {
  const __m256d t0 = _mm256_unpacklo_pd(r[0], r[1]), t1 = _mm256_unpackhi_pd(r[0], r[1]);
  const __m256d t2 = _mm256_unpacklo_pd(r[2], r[3]), t3 = _mm256_unpackhi_pd(r[2], r[3]);
  r[0] = _mm256_permute2f128_pd(t0, t2, 0x20);
  r[1] = _mm256_permute2f128_pd(t1, t3, 0x20);
  r[2] = _mm256_permute2f128_pd(t0, t2, 0x31);
  r[3] = _mm256_permute2f128_pd(t1, t3, 0x31);
}

// ------------------------------------------------------------------------------- sweep
template <int D>
PDCG_AVX2_INL bool sweep(const Stencils& S, std::size_t s0, std::size_t s1, const double* u,
                         double* f, const Material& material) {
  constexpr int C = D * D;
  const int* idx = S.index.data();
  const double* grad = S.grad.data();
  const i64* off = S.offsets.data();
  const double* weight = S.weight.data();
  const int* center = S.center.data();
  const i64 last = S.offsets.back() - 1;  // the last term of the array (3D: guarded G load)
  bool ok = true;
  alignas(32) double Fb[4 * C], Pb[4 * C];
  int pts[4];
  __m256d row[4];  // 2D: F, then P, of the four stencils as rows (F00, F01, F10, F11)
  const __m256d ident = _mm256_setr_pd(1.0, 0.0, 0.0, 1.0);
  __m256d row3[3][4];  // 3D: row a of F of stencil k, then column J of P of stencil k
  const __m256d e3[3] = {_mm256_setr_pd(1.0, 0.0, 0.0, 0.0), _mm256_setr_pd(0.0, 1.0, 0.0, 0.0),
                         _mm256_setr_pd(0.0, 0.0, 1.0, 0.0)};
  for (std::size_t sb = s0; sb < s1; sb += 4) {
    const int nb = static_cast<int>(std::min<std::size_t>(4, s1 - sb));
    // Gather F of up to four stencils (SoA: component c of stencil k at Fb[4c + k]).
    for (int k = 0; k < nb; ++k) {
      const std::size_t s = sb + static_cast<std::size_t>(k);
      pts[k] = center[s];
      if constexpr (D == 2) {
        __m128d r0, r1;
        gather2(idx, grad, off[s], off[s + 1], u, r0, r1);
        row[k] = _mm256_add_pd(_mm256_set_m128d(r1, r0), ident);  // (F00, F01, F10, F11)
      } else {
        __m256d r3[3];
        gather3(idx, grad, off[s], off[s + 1], last, u, r3);
        for (int a = 0; a < 3; ++a) row3[a][k] = _mm256_add_pd(r3[a], e3[a]);
      }
    }
    for (int k = nb; k < 4; ++k) {  // padding lanes: the identity (admissible, P = 0)
      pts[k] = pts[0];
      if constexpr (D == 2) {
        row[k] = ident;
      } else {
        for (int a = 0; a < 3; ++a) row3[a][k] = e3[a];
      }
    }
    if constexpr (D == 2) {  // rows per stencil -> components per lane (4×4 transpose)
      transpose4(row);
      for (int c = 0; c < 4; ++c) _mm256_store_pd(Fb + 4 * c, row[c]);
    } else {  // row a of the four stencils -> components (a, J) per lane
      for (int a = 0; a < 3; ++a) {
        transpose4(row3[a]);
        for (int J = 0; J < 3; ++J) _mm256_store_pd(Fb + 4 * (3 * a + J), row3[a][J]);
      }
    }
    const unsigned good = material.stress4(pts, Fb, Pb);
    if constexpr (D == 2) {
      for (int c = 0; c < 4; ++c) row[c] = _mm256_load_pd(Pb + 4 * c);
      transpose4(row);  // row[k] = (P00, P01, P10, P11) of stencil k
    } else {  // components (a, J) per lane -> column J of each stencil: (P0J, P1J, P2J, 0)
      for (int J = 0; J < 3; ++J) {
        row3[J][0] = _mm256_load_pd(Pb + 4 * J);
        row3[J][1] = _mm256_load_pd(Pb + 4 * (3 + J));
        row3[J][2] = _mm256_load_pd(Pb + 4 * (6 + J));
        row3[J][3] = _mm256_setzero_pd();
        transpose4(row3[J]);
      }
    }
    for (int k = 0; k < nb; ++k) {
      if (!((good >> k) & 1u)) {
        ok = false;
        continue;
      }
      const std::size_t s = sb + static_cast<std::size_t>(k);
      const double w = weight[s];
      if constexpr (D == 2) {
        const __m256d q = _mm256_mul_pd(row[k], _mm256_set1_pd(w));
        scatter2(idx, grad, off[s], off[s + 1], f, _mm256_permute4x64_pd(q, 0x88),
                 _mm256_permute4x64_pd(q, 0xDD));
      } else {
        const __m256d wv = _mm256_set1_pd(w);
        const __m256d c3[3] = {_mm256_mul_pd(row3[0][k], wv), _mm256_mul_pd(row3[1][k], wv),
                               _mm256_mul_pd(row3[2][k], wv)};
        scatter3(idx, grad, off[s], off[s + 1], f, c3);
      }
    }
  }
  return ok;
}

// y = x^(−1/3) for 4 positive normal doubles (see the top of the file).
PDCG_AVX2_INL __m256d inv_cbrt(__m256d x) {
  const __m256i bits = _mm256_castpd_si256(x);
  const __m256i hi = _mm256_srli_epi64(bits, 32);
  // ⌊hi/3⌋ = (hi · 0x55555556) >> 32 for hi < 2³¹
  const __m256i q = _mm256_srli_epi64(_mm256_mul_epu32(hi, _mm256_set1_epi64x(0x55555556)), 32);
  __m256d y = _mm256_castsi256_pd(
      _mm256_slli_epi64(_mm256_sub_epi64(_mm256_set1_epi64x(0x553ef0ff), q), 32));
  const __m256d third = _mm256_set1_pd(1.0 / 3.0), four = _mm256_set1_pd(4.0);
  for (int it = 0; it < 3; ++it) {
    const __m256d y3 = _mm256_mul_pd(_mm256_mul_pd(y, y), y);
    y = _mm256_mul_pd(_mm256_mul_pd(y, _mm256_fnmadd_pd(x, y3, four)), third);
  }
  const __m256d t = _mm256_mul_pd(_mm256_mul_pd(x, y), y);
  const __m256d e = _mm256_fnmadd_pd(t, y, _mm256_set1_pd(1.0));  // 1 − x y³
  return _mm256_fmadd_pd(_mm256_mul_pd(y, e), third, y);
}

// f_a f_b − f_c f_e
PDCG_AVX2_INL __m256d minor2(const __m256d* f, int a, int b, int c, int e) {
  return _mm256_fmsub_pd(f[a], f[b], _mm256_mul_pd(f[c], f[e]));
}

}  // namespace

PDCG_AVX2_FN bool stencil_sweep_avx2(int d, const Stencils& S, std::size_t s0, std::size_t s1,
                                     const double* u, double* f, const Material& material) {
  return d == 2 ? sweep<2>(S, s0, s1, u, f, material) : sweep<3>(S, s0, s1, u, f, material);
}

// P = μ J^(−2/3) (F − ⅓ tr C F⁻ᵀ) + K/4 (J² − J⁻²) F⁻ᵀ  (material.hpp), on four gradients.
PDCG_AVX2_FN unsigned neo_hookean_stress4_avx2(int d, double mu, double K, const double* F,
                                               double* P) {
  __m256d J, I1;
  __m256d f[9], cof[9];
  const int n = d * d;
  for (int c = 0; c < n; ++c) f[c] = _mm256_loadu_pd(F + 4 * c);
  if (d == 2) {
    // plane strain: F₃₃ = 1; in-plane cofactors (J F⁻ᵀ) = (F11, −F10, −F01, F00)
    J = _mm256_fmsub_pd(f[0], f[3], _mm256_mul_pd(f[1], f[2]));
    I1 = _mm256_add_pd(
        _mm256_fmadd_pd(f[0], f[0], _mm256_mul_pd(f[1], f[1])),
        _mm256_fmadd_pd(f[2], f[2], _mm256_fmadd_pd(f[3], f[3], _mm256_set1_pd(1.0))));
    const __m256d neg = _mm256_set1_pd(-0.0);
    cof[0] = f[3];
    cof[1] = _mm256_xor_pd(f[2], neg);
    cof[2] = _mm256_xor_pd(f[1], neg);
    cof[3] = f[0];
  } else {
    cof[0] = minor2(f, 4, 8, 5, 7);
    cof[1] = minor2(f, 5, 6, 3, 8);
    cof[2] = minor2(f, 3, 7, 4, 6);
    cof[3] = minor2(f, 2, 7, 1, 8);
    cof[4] = minor2(f, 0, 8, 2, 6);
    cof[5] = minor2(f, 1, 6, 0, 7);
    cof[6] = minor2(f, 1, 5, 2, 4);
    cof[7] = minor2(f, 2, 3, 0, 5);
    cof[8] = minor2(f, 0, 4, 1, 3);
    J = _mm256_fmadd_pd(f[0], cof[0], _mm256_fmadd_pd(f[1], cof[1], _mm256_mul_pd(f[2], cof[2])));
    I1 = _mm256_mul_pd(f[0], f[0]);
    for (int c = 1; c < 9; ++c) I1 = _mm256_fmadd_pd(f[c], f[c], I1);
  }
  // admissible: 0 < J < ∞ (NaN fails both)
  const __m256d valid = _mm256_and_pd(_mm256_cmp_pd(J, _mm256_setzero_pd(), _CMP_GT_OQ),
                                      _mm256_cmp_pd(J, _mm256_set1_pd(HUGE_VAL), _CMP_LT_OQ));
  const unsigned mask = static_cast<unsigned>(_mm256_movemask_pd(valid));
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d Js = _mm256_blendv_pd(one, J, valid);
  const __m256d out = _mm256_or_pd(_mm256_cmp_pd(Js, _mm256_set1_pd(1e-290), _CMP_LT_OQ),
                                   _mm256_cmp_pd(Js, _mm256_set1_pd(1e290), _CMP_GT_OQ));
  if (_mm256_movemask_pd(out) != 0) return kNotHandled;
  const __m256d y = inv_cbrt(Js);
  const __m256d Jm23 = _mm256_mul_pd(y, y);
  const __m256d iJ = _mm256_div_pd(one, Js);
  const __m256d J2 = _mm256_mul_pd(Js, Js), iJ2 = _mm256_mul_pd(iJ, iJ);
  const __m256d c1 = _mm256_mul_pd(_mm256_set1_pd(mu), Jm23);
  const __m256d c2 = _mm256_mul_pd(_mm256_mul_pd(c1, I1), _mm256_set1_pd(1.0 / 3.0));
  const __m256d c3 = _mm256_mul_pd(_mm256_set1_pd(0.25 * K), _mm256_sub_pd(J2, iJ2));
  // P = c1 F + (c3 − c2) F⁻ᵀ = c1 F + (c3 − c2)/J cof
  const __m256d k = _mm256_mul_pd(_mm256_sub_pd(c3, c2), iJ);
  for (int c = 0; c < n; ++c)
    _mm256_storeu_pd(P + 4 * c, _mm256_fmadd_pd(c1, f[c], _mm256_mul_pd(k, cof[c])));
  return mask;
}

}  // namespace pdcg::solver::detail

#endif  // PDCG_SOLVER_AVX2
