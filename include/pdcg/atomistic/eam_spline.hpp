#pragma once
/// Table lookups of LAMMPS's PairEAM (pair_eam.cpp, `compute` and `file2array`/`array2spline`),
/// shared by the native EAM styles (atomistic) and the half-family EAM path of the dynamics.
/// Each table row m holds 7 coefficients: [0..2] the derivative's quadratic, [3..6] the
/// value's cubic in the fraction p ∈ [0, 1] of the grid cell, as LAMMPS stores them.
#include <algorithm>
#include <limits>

namespace pdcg::atomistic::eam {

/// Row index min(max((int) q, lo), hi) as LAMMPS's MAX(lo, MIN((int) q, hi)), without converting
/// a q outside the int range (a fuzzed table, a negative or huge density) to int: that
/// conversion is undefined behaviour. NaN gives hi.
inline int cell(double q, int lo, int hi) {
  if (!(q < static_cast<double>(hi))) return hi;
  return q >= static_cast<double>(lo) ? static_cast<int>(q) : lo;
}

/// Grid cell of a radial argument x (r with rdx = 1/dr) as LAMMPS computes it: row m ≤ nmax−1
/// and the returned fraction p ≤ 1; `clamped` when p hit its upper bound (x past the table:
/// the second derivative is taken as 0 there).
inline double locate(double x, double rdx, int nmax, int& m, bool& clamped) {
  double q = x * rdx + 1.0;
  m = cell(q, std::numeric_limits<int>::min(), nmax - 1);
  q -= m;
  clamped = q > 1.0;
  return std::min(q, 1.0);
}

/// Embedding function at ρ̄: F, F′ and F″ (Daw & Baskes 1984; LAMMPS splines). Beyond the
/// table (ρ̄ > ρ_max) F is continued linearly, F(ρ̄) = F(ρ_max) + F′(ρ_max)(ρ̄ − ρ_max), as
/// LAMMPS does, and F″ = 0.
struct Embedding {
  double value, first, second;
};

/// `row0` points at the 7-coefficient rows of one embedding table (row m at row0 + 7m).
inline Embedding embedding(const double* row0, double rho, double rdrho, int nrho, double rhomax) {
  double p = rho * rdrho + 1.0;
  const int m = cell(p, 1, nrho - 1);
  p -= m;
  const bool clamped = p > 1.0;
  p = std::min(p, 1.0);
  const double* c = row0 + 7 * m;
  Embedding e;
  e.first = (c[0] * p + c[1]) * p + c[2];
  e.value = ((c[3] * p + c[4]) * p + c[5]) * p + c[6];
  if (rho > rhomax) e.value += e.first * (rho - rhomax);
  e.second = clamped ? 0.0 : (2.0 * c[0] * p + c[1]) * rdrho;
  return e;
}

/// A bond's terms of the EAM tangent at length r: the density derivative g = ρ′(r) and its
/// derivative g′, and the pair potential φ = (rφ)/r with φ′ and φ″, from the density row
/// `rho_row` and the r·φ row `z2r_row` of the grid cell located at r (fraction p, `clamped`
/// as locate() gives them; rdr = 1/dr). Past the table (clamped) the second derivatives g′
/// and (rφ)″ are 0, as in LAMMPS.
struct PairTerms {
  double g, gp, phi, phip, phipp;
};

inline PairTerms pair_terms(const double* rho_row, const double* z2r_row, double p, bool clamped,
                            double r, double rdr) {
  const double* c1 = rho_row;
  const double* c2 = z2r_row;
  PairTerms t;
  t.g = (c1[0] * p + c1[1]) * p + c1[2];
  t.gp = clamped ? 0.0 : (2.0 * c1[0] * p + c1[1]) * rdr;
  const double z2 = ((c2[3] * p + c2[4]) * p + c2[5]) * p + c2[6];
  const double z2p = (c2[0] * p + c2[1]) * p + c2[2];
  const double z2pp = clamped ? 0.0 : (2.0 * c2[0] * p + c2[1]) * rdr;
  const double recip = 1.0 / r;
  t.phi = z2 * recip;
  t.phip = z2p * recip - t.phi * recip;
  t.phipp = (z2pp - 2.0 * t.phip) * recip;  // (rφ)'' = rφ'' + 2φ'
  return t;
}

}  // namespace pdcg::atomistic::eam
