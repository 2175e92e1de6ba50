// Vector (AVX2 + FMA) kernels of the half-family EAM passes of VelocityVerlet (private header).
//
// The two pair passes of evaluate_eam (host densities ρ̄, then forces) 4 half bonds at a time:
// the neighbours' positions as 4 rows (x, y, z, ·) of the point + ghost array transposed into
// lanes, the distance, LAMMPS's table cell (m, p) computed exactly as the scalar loop does
// (r·rdr + 1 without FMA, truncation, the same clamps), the spline rows of the 4 lanes loaded
// and transposed likewise from fused tables (EamRows: the coefficients one bond needs in one or
// two 32-byte rows), bonds beyond the cutoff and the padding lanes of a family's last block
// masked out branch-free, and a scalar scatter to the neighbours (f_j −= t as one 4-double
// read-modify-write per bond: the position and force arrays carry one padding double). No
// gather instructions: on the benchmark machine (AMD EPYC, family 26) vgatherdpd takes ≈ 3 ns
// per 4 doubles against ≈ 0.4–1 ns for 4 loads and a 4×4 transpose (measured), which made a
// gather variant slower than the scalar loop. Same formulas as the scalar loop, except that
// (r·φ)' comes from the value coefficients; the results differ by round-off only (FMA
// contraction, summation order; the unit test asserts 1e-13 relative).
//
// Compiled with target("avx2,fma") in the portable build and chosen at run time
// (eam_avx2_available(); the scalar loop otherwise), as the LJ kernel in atomistic/potentials.
#pragma once

#include <cstdint>
#include <vector>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::dynamics::detail {

/// EAM spline rows in the layout of the vector passes, one row per type pair (kt, jt) and knot m
/// (m = 0..nr, LAMMPS's row m of its 7-coefficient tables: [0..2] derivative, [3..6] value):
///   dens  (density pass): ρ_{j→k} value [3..6], then (several types) ρ_{k→j} value [3..6];
///   force (force pass):   ρ_{j→k} derivative [0..2], (several types) ρ_{k→j} derivative
///                         [0..2], then z2 = r·φ value [3..6] (its derivative row [0..2] is
///                         3 z3/dr, 2 z4/dr, z5/dr: recomputed from the value row);
/// with ρ_{j→k} = rhor[jt·(n+1) + kt] and z2 = z2r[kt·(n+1) + jt] of EamView. One type: ρ_{j→k}
/// = ρ_{k→j}, rows of 4 and 8 doubles (7 used); several: 8 and 12 (10 used).
struct EamRows {
  int ntypes = 0, nr = 0;
  bool single = false;
  int dens_stride = 0, force_stride = 0;
  double rdr = 0.0, cutsq = 0.0;
  std::vector<double> dens, force;
  std::vector<std::int32_t> pair_knot;  ///< [kt·(ntypes+1) + jt]: index of the pair's knot 0
};

EamRows make_eam_rows(const atomistic::EamView& E);

/// The vector kernels are compiled in (x86-64, GCC/Clang) and the CPU has AVX2 and FMA.
bool eam_avx2_available();

/// Half families (CSR) as the kernels read them. neighbor and neighbor_type are read in blocks
/// of 4 and must be readable 3 entries past the last bond (padding: any valid point index).
struct EamHalf {
  const std::int64_t* offset = nullptr;
  const std::int32_t* neighbor = nullptr;
  const int* neighbor_type = nullptr;  ///< per half bond (only read with several types)
  const int* type = nullptr;           ///< per point
};

/// rho[k] += Σ_j ρ_{j→k}(r_kj), rho[j] += ρ_{k→j}(r_kj) over the half bonds of k0 ≤ k < k1
/// (rho over points and ghosts). y: positions of points and ghosts.
void eam_density_avx2(const EamRows& R, const EamHalf& h, std::int64_t k0, std::int64_t k1,
                      const double* y, double* rho);

/// f_k += s Y, f_j −= s Y, s = (F'_k ρ'_{j→k} + F'_j ρ'_{k→j} + φ')/r over the half bonds of
/// k0 ≤ k < k1; returns Σ φ. f: 3(points + ghosts) + 1 doubles (the last one padding, left
/// unchanged); fp: F'(ρ̄) of points and ghosts.
/// Both passes read y as 3(points + ghosts) + 1 doubles (the last one padding).
double eam_forces_avx2(const EamRows& R, const EamHalf& h, std::int64_t k0, std::int64_t k1,
                       const double* y, const double* fp, double* f);

}  // namespace pdcg::dynamics::detail
