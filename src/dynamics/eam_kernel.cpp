#include "eam_kernel.hpp"

#include <algorithm>
#include <cstddef>
#include <stdexcept>

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PDCG_EAM_SIMD 1
#include <immintrin.h>
#if defined(__AVX2__) && defined(__FMA__)
#define PDCG_EAM_TARGET
#else
#define PDCG_EAM_TARGET __attribute__((target("avx2,fma")))
#endif
#endif

namespace pdcg::dynamics::detail {

EamRows make_eam_rows(const atomistic::EamView& E) {
  EamRows R;
  R.ntypes = E.ntypes;
  R.nr = E.nr;
  R.single = E.ntypes == 1;
  R.dens_stride = R.single ? 4 : 8;
  R.force_stride = R.single ? 8 : 12;
  R.rdr = E.rdr;
  R.cutsq = E.cutforcesq;
  const int n1 = E.ntypes + 1;
  const auto knots = static_cast<std::size_t>(E.nr + 1);
  const auto pairs = static_cast<std::size_t>(E.ntypes * E.ntypes);
  R.dens.assign(pairs * knots * static_cast<std::size_t>(R.dens_stride), 0.0);
  R.force.assign(pairs * knots * static_cast<std::size_t>(R.force_stride), 0.0);
  R.pair_knot.assign(static_cast<std::size_t>(n1 * n1), 0);
  std::size_t pair = 0;
  for (int kt = 1; kt <= E.ntypes; ++kt)
    for (int jt = 1; jt <= E.ntypes; ++jt, ++pair) {
      const auto p0 = pair * knots;
      R.pair_knot[static_cast<std::size_t>(kt * n1 + jt)] = static_cast<std::int32_t>(p0);
      const double* a = E.rhor[static_cast<std::size_t>(jt * n1 + kt)];  // ρ_{j→k}
      const double* b = E.rhor[static_cast<std::size_t>(kt * n1 + jt)];  // ρ_{k→j}
      const double* z = E.z2r[static_cast<std::size_t>(kt * n1 + jt)];   // r·φ
      for (std::size_t m = 0; m < knots; ++m) {
        double* d = R.dens.data() + (p0 + m) * static_cast<std::size_t>(R.dens_stride);
        double* f = R.force.data() + (p0 + m) * static_cast<std::size_t>(R.force_stride);
        const double* am = a + 7 * m;
        const double* bm = b + 7 * m;
        const double* zm = z + 7 * m;
        std::copy(am + 3, am + 7, d);
        std::copy(am, am + 3, f);
        if (!R.single) {
          std::copy(bm + 3, bm + 7, d + 4);
          std::copy(bm, bm + 3, f + 3);
        }
        std::copy(zm + 3, zm + 7, f + (R.single ? 3 : 6));
      }
    }
  return R;
}

#ifdef PDCG_EAM_SIMD

bool eam_avx2_available() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}

namespace {

/// 4×4 transpose: o_i = (a_i, b_i, c_i, d_i).
PDCG_EAM_TARGET inline void transpose(__m256d a, __m256d b, __m256d c, __m256d d, __m256d& o0,
                                      __m256d& o1, __m256d& o2, __m256d& o3) {
  const __m256d t0 = _mm256_unpacklo_pd(a, b), t1 = _mm256_unpackhi_pd(a, b);
  const __m256d t2 = _mm256_unpacklo_pd(c, d), t3 = _mm256_unpackhi_pd(c, d);
  o0 = _mm256_permute2f128_pd(t0, t2, 0x20);
  o1 = _mm256_permute2f128_pd(t1, t3, 0x20);
  o2 = _mm256_permute2f128_pd(t0, t2, 0x31);
  o3 = _mm256_permute2f128_pd(t1, t3, 0x31);
}

/// Distance and table cell of 4 half bonds b..b+3 of the point at (xk, yk, zk); (dx, dy, dz)
/// = −Y = y_k − y_j; row: the byte offsets of the lanes' table rows (m·stride·8).
struct Block {
  __m256d dx, dy, dz, r, p, mask;
  alignas(32) std::int64_t row[4];
};

template <int kStride>
PDCG_EAM_TARGET inline void block(Block& B, const double* y, const std::int32_t* nb,
                                  std::int64_t left, __m256d xk, __m256d yk, __m256d zk,
                                  __m256d cutsq, __m256d rdr, __m128i nr1) {
  // the 4 neighbours' (x, y, z, ·) rows (the position array has one padding double)
  __m256d X, Y, Z, W;
  transpose(_mm256_loadu_pd(y + 3 * static_cast<std::int64_t>(nb[0])),
            _mm256_loadu_pd(y + 3 * static_cast<std::int64_t>(nb[1])),
            _mm256_loadu_pd(y + 3 * static_cast<std::int64_t>(nb[2])),
            _mm256_loadu_pd(y + 3 * static_cast<std::int64_t>(nb[3])), X, Y, Z, W);
  // −Y = y_k − y_j (the force pass then adds s·(−Y) to f_j with one memory operand)
  B.dx = _mm256_sub_pd(xk, X);
  B.dy = _mm256_sub_pd(yk, Y);
  B.dz = _mm256_sub_pd(zk, Z);
  const __m256d rsq =
      _mm256_fmadd_pd(B.dz, B.dz, _mm256_fmadd_pd(B.dy, B.dy, _mm256_mul_pd(B.dx, B.dx)));
  B.mask = _mm256_cmp_pd(rsq, cutsq, _CMP_LT_OQ);
  if (left < 4) {  // a family's last block: lanes past its end
    const __m128i valid =
        _mm_cmplt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(static_cast<int>(left)));
    B.mask = _mm256_and_pd(B.mask, _mm256_castsi256_pd(_mm256_cvtepi32_epi64(valid)));
  }
  B.r = _mm256_sqrt_pd(rsq);
  // LAMMPS's cell: p = r·rdr + 1 (no FMA: the scalar loop's rounding, the same m), m = ⌊p⌋
  // clamped to nr − 1 (and to ≥ 1: NaN or masked lanes must still index the table), p −= m,
  // p ≤ 1
  const __m256d one = _mm256_set1_pd(1.0);
  __m256d rr = _mm256_mul_pd(B.r, rdr);
  asm("" : "+x"(rr));  // keeps the compiler from contracting r·rdr + 1 into an FMA
  const __m256d q = _mm256_add_pd(rr, one);
  const __m128i m = _mm_max_epi32(_mm_min_epi32(_mm256_cvttpd_epi32(q), nr1), _mm_set1_epi32(1));
  B.p = _mm256_min_pd(_mm256_sub_pd(q, _mm256_cvtepi32_pd(m)), one);
  _mm256_store_si256(reinterpret_cast<__m256i*>(B.row),
                     _mm256_cvtepi32_epi64(_mm_mullo_epi32(m, _mm_set1_epi32(8 * kStride))));
}

PDCG_EAM_TARGET inline double hsum(__m256d v) {
  const __m128d s = _mm_add_pd(_mm256_castpd256_pd128(v), _mm256_extractf128_pd(v, 1));
  return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
}

/// Coefficients o..o+3 of the 4 lanes' rows (lane rows at base + row offset + pair offset).
struct Rows {
  const char* lane[4];
};

PDCG_EAM_TARGET inline void columns(const Rows& L, int o, __m256d& c0, __m256d& c1, __m256d& c2,
                                    __m256d& c3) {
  transpose(_mm256_loadu_pd(reinterpret_cast<const double*>(L.lane[0]) + o),
            _mm256_loadu_pd(reinterpret_cast<const double*>(L.lane[1]) + o),
            _mm256_loadu_pd(reinterpret_cast<const double*>(L.lane[2]) + o),
            _mm256_loadu_pd(reinterpret_cast<const double*>(L.lane[3]) + o), c0, c1, c2, c3);
}

/// The lanes' row addresses: the table, the pair (kt, type of the lane's neighbour) and the
/// knot m.
template <bool kSingle, int kStride>
PDCG_EAM_TARGET inline Rows lanes(const double* table, const Block& B, const int* jt,
                                  const std::int32_t* pk) {
  Rows L;
  const char* t = reinterpret_cast<const char*>(table);
  for (int q = 0; q < 4; ++q) {
    L.lane[q] = t + B.row[q];
    if constexpr (!kSingle) L.lane[q] += static_cast<std::ptrdiff_t>(pk[jt[q]]) * 8 * kStride;
  }
  return L;
}

/// What both passes read of the half lists and the tables, held as locals of the pass (the
/// stores to rho and f would otherwise make the compiler reload them through h and R).
struct Sweep {
  const std::int64_t* offset;
  const std::int32_t* neighbor;
  const int* ntype;
  const std::int32_t* pair_knot;
  const int* type;
  int n1;
  __m256d cutsq, rdr;
  __m128i nr1;
};

PDCG_EAM_TARGET inline Sweep sweep_of(const EamRows& R, const EamHalf& h) {
  return {h.offset,
          h.neighbor,
          h.neighbor_type,
          R.pair_knot.data(),
          h.type,
          R.ntypes + 1,
          _mm256_set1_pd(R.cutsq),
          _mm256_set1_pd(R.rdr),
          _mm_set1_epi32(R.nr - 1)};
}

/// Point k of a pass: its position in the 4 lanes and (several types) the table offsets of
/// its type pairs.
struct Centre {
  __m256d x, y, z;
  const std::int32_t* pk;
};

template <bool kSingle>
PDCG_EAM_TARGET inline Centre centre(const Sweep& S, const double* y, std::int64_t k) {
  return {_mm256_set1_pd(y[3 * k]), _mm256_set1_pd(y[3 * k + 1]), _mm256_set1_pd(y[3 * k + 2]),
          kSingle ? nullptr : S.pair_knot + S.type[k] * S.n1};
}

/// The block of the half bonds b..b+3 (of b1) of the centre C, and the lanes' rows of `table`.
template <bool kSingle, int kStride>
PDCG_EAM_TARGET inline Rows bonds(Block& B, const Sweep& S, const Centre& C, const double* table,
                                  const double* y, std::int64_t b, std::int64_t b1) {
  block<kStride>(B, y, S.neighbor + b, b1 - b, C.x, C.y, C.z, S.cutsq, S.rdr, S.nr1);
  return lanes<kSingle, kStride>(table, B, S.ntype + b, C.pk);
}

PDCG_EAM_TARGET inline __m256d cubic(__m256d c3, __m256d c4, __m256d c5, __m256d c6, __m256d p) {
  return _mm256_fmadd_pd(_mm256_fmadd_pd(_mm256_fmadd_pd(c3, p, c4), p, c5), p, c6);
}

template <bool kSingle>
PDCG_EAM_TARGET void density(const EamRows& R, const EamHalf& h, std::int64_t k0, std::int64_t k1,
                             const double* y, double* rho) {
  constexpr int kStride = kSingle ? 4 : 8;
  const Sweep S = sweep_of(R, h);
  const double* c = R.dens.data();
  for (std::int64_t k = k0; k < k1; ++k) {
    const Centre C = centre<kSingle>(S, y, k);
    __m256d acc = _mm256_setzero_pd();
    const std::int64_t b1 = S.offset[k + 1];
    for (std::int64_t b = S.offset[k]; b < b1; b += 4) {
      const std::int32_t* nb = S.neighbor + b;
      Block B;
      const Rows L = bonds<kSingle, kStride>(B, S, C, c, y, b, b1);
      __m256d a3, a4, a5, a6;
      columns(L, 0, a3, a4, a5, a6);
      const __m256d a = _mm256_and_pd(B.mask, cubic(a3, a4, a5, a6, B.p));  // ρ_{j→k}
      acc = _mm256_add_pd(acc, a);
      alignas(32) double t[4];
      if constexpr (kSingle) {
        _mm256_store_pd(t, a);
      } else {
        columns(L, 4, a3, a4, a5, a6);
        _mm256_store_pd(t, _mm256_and_pd(B.mask, cubic(a3, a4, a5, a6, B.p)));  // ρ_{k→j}
      }
      // masked lanes add +0 to a valid point (the padding of the neighbour arrays)
      rho[nb[0]] += t[0];
      rho[nb[1]] += t[1];
      rho[nb[2]] += t[2];
      rho[nb[3]] += t[3];
    }
    rho[k] += hsum(acc);
  }
}

template <bool kSingle>
PDCG_EAM_TARGET double forces(const EamRows& R, const EamHalf& h, std::int64_t k0, std::int64_t k1,
                              const double* y, const double* fp, double* f) {
  constexpr int kStride = kSingle ? 8 : 12;
  const Sweep S = sweep_of(R, h);
  const __m256d rdr = S.rdr;
  const __m256d one = _mm256_set1_pd(1.0), zero = _mm256_setzero_pd();
  const __m256d three = _mm256_set1_pd(3.0);
  const double* c = R.force.data();
  __m256d energy = _mm256_setzero_pd();
  for (std::int64_t k = k0; k < k1; ++k) {
    const Centre C = centre<kSingle>(S, y, k);
    const __m256d fpk = _mm256_set1_pd(fp[k]);
    __m256d fk = zero;  // (Σ s·(−Y), 0)
    const std::int64_t b1 = S.offset[k + 1];
    for (std::int64_t b = S.offset[k]; b < b1; b += 4) {
      const std::int32_t* nb = S.neighbor + b;
      Block B;
      const Rows L = bonds<kSingle, kStride>(B, S, C, c, y, b, b1);
      const __m256d p = B.p;
      const __m256d fpj = _mm256_setr_pd(fp[nb[0]], fp[nb[1]], fp[nb[2]], fp[nb[3]]);
      // rows: one type [ρ'0..2, z3 | z4..6, ·], several [ρ'_{j→k}0..2, ρ'_{k→j}0 | ρ'_{k→j}1..2,
      // z3, z4 | z5, z6, ·, ·]
      __m256d c0, c1, c2, c3, c4, c5, c6, c7;
      columns(L, 0, c0, c1, c2, c3);
      columns(L, 4, c4, c5, c6, c7);
      __m256d rhojp, s, z3, z4, z5, z6;
      rhojp = _mm256_fmadd_pd(_mm256_fmadd_pd(c0, p, c1), p, c2);
      if constexpr (kSingle) {
        z3 = c3, z4 = c4, z5 = c5, z6 = c6;
      } else {
        __m256d c8, c9, c10, c11;
        columns(L, 8, c8, c9, c10, c11);
        const __m256d rhokp = _mm256_fmadd_pd(_mm256_fmadd_pd(c3, p, c4), p, c5);
        z3 = c6, z4 = c7, z5 = c8, z6 = c9;
        s = _mm256_mul_pd(fpj, rhokp);
      }
      const __m256d z2 = cubic(z3, z4, z5, z6, p);
      // (r·φ)' = ((3 z3 p + 2 z4) p + z5)/dr: LAMMPS's derivative row ([0..2] = 3 z3/dr,
      // 2 z4/dr, z5/dr) from the value row, equal to round-off
      const __m256d z2p = _mm256_mul_pd(
          _mm256_fmadd_pd(_mm256_fmadd_pd(_mm256_mul_pd(three, z3), p, _mm256_add_pd(z4, z4)), p,
                          z5),
          rdr);
      const __m256d recip = _mm256_div_pd(one, B.r);
      const __m256d phi = _mm256_mul_pd(z2, recip);
      const __m256d phip = _mm256_fmsub_pd(z2p, recip, _mm256_mul_pd(phi, recip));
      if constexpr (kSingle)
        s = _mm256_fmadd_pd(_mm256_add_pd(fpk, fpj), rhojp, phip);
      else
        s = _mm256_fmadd_pd(fpk, rhojp, _mm256_add_pd(s, phip));
      s = _mm256_and_pd(B.mask, _mm256_mul_pd(s, recip));
      energy = _mm256_add_pd(energy, _mm256_and_pd(B.mask, phi));
      const __m256d tx = _mm256_mul_pd(s, B.dx), ty = _mm256_mul_pd(s, B.dy),
                    tz = _mm256_mul_pd(s, B.dz);
      // (tx, ty, tz, 0) per lane; f_j += s·(−Y) as 4 doubles (the 4th: the next value + 0)
      __m256d t0, t1, t2, t3;
      transpose(tx, ty, tz, zero, t0, t1, t2, t3);
      fk = _mm256_add_pd(fk, _mm256_add_pd(_mm256_add_pd(t0, t1), _mm256_add_pd(t2, t3)));
      double* f0 = f + 3 * static_cast<std::int64_t>(nb[0]);
      _mm256_storeu_pd(f0, _mm256_add_pd(_mm256_loadu_pd(f0), t0));
      double* f1 = f + 3 * static_cast<std::int64_t>(nb[1]);
      _mm256_storeu_pd(f1, _mm256_add_pd(_mm256_loadu_pd(f1), t1));
      double* f2 = f + 3 * static_cast<std::int64_t>(nb[2]);
      _mm256_storeu_pd(f2, _mm256_add_pd(_mm256_loadu_pd(f2), t2));
      double* f3 = f + 3 * static_cast<std::int64_t>(nb[3]);
      _mm256_storeu_pd(f3, _mm256_add_pd(_mm256_loadu_pd(f3), t3));
    }
    _mm256_storeu_pd(f + 3 * k, _mm256_sub_pd(_mm256_loadu_pd(f + 3 * k), fk));
  }
  return hsum(energy);
}

}  // namespace

void eam_density_avx2(const EamRows& R, const EamHalf& h, std::int64_t k0, std::int64_t k1,
                      const double* y, double* rho) {
  if (R.single)
    density<true>(R, h, k0, k1, y, rho);
  else
    density<false>(R, h, k0, k1, y, rho);
}

double eam_forces_avx2(const EamRows& R, const EamHalf& h, std::int64_t k0, std::int64_t k1,
                       const double* y, const double* fp, double* f) {
  return R.single ? forces<true>(R, h, k0, k1, y, fp, f) : forces<false>(R, h, k0, k1, y, fp, f);
}

#else

bool eam_avx2_available() { return false; }

void eam_density_avx2(const EamRows&, const EamHalf&, std::int64_t, std::int64_t, const double*,
                      double*) {
  throw std::logic_error("eam_density_avx2: not compiled for this target");
}

double eam_forces_avx2(const EamRows&, const EamHalf&, std::int64_t, std::int64_t, const double*,
                       const double*, double*) {
  throw std::logic_error("eam_forces_avx2: not compiled for this target");
}

#endif

}  // namespace pdcg::dynamics::detail
