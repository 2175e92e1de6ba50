// EAM tables in LAMMPS's internal form (PairEAM: file2array + array2spline). Private header.
#pragma once

#include <vector>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic {

struct EamTables {
  int ntypes = 0;
  int nr = 0, nrho = 0;
  double dr = 0, drho = 0, rdr = 0, rdrho = 0, rhomax = 0, cutmax = 0, cutforcesq = 0;
  /// Spline coefficients, 7 per grid point m = 1..n: [7m + 0..6] as PairEAM's spline[m][0..6].
  std::vector<std::vector<double>> frho_spline, rhor_spline, z2r_spline;
  std::vector<int> type2frho;            ///< ntypes+1
  std::vector<int> type2rhor, type2z2r;  ///< (ntypes+1)², [i*(ntypes+1)+j]
  std::vector<double> type_mass;         ///< ntypes+1, from the files
};

/// Reads the files named by spec.pair_coeff (eam, eam/alloy, eam/fs) as LAMMPS does and
/// builds the tables. Throws InputError with file and line on malformed files.
EamTables build_eam_tables(const PotentialSpec& spec);

/// The read-only view of `tables` for dedicated kernels (Potential::eam_view): its grid
/// constants, and per type (pair) the spline that type2rhor/type2z2r/type2frho pick (nullptr
/// where none). The pointers point into `tables`, valid while it lives and is not moved.
EamView make_eam_view(const EamTables& tables);

/// PairEAM::interpolate: f[1..n] → 7 coefficients per point.
void eam_interpolate(int n, double delta, const std::vector<double>& f,
                     std::vector<double>& spline);

}  // namespace pdcg::atomistic
