/// \file
/// A PD body as LAMMPS input (docs/dynamics.md, "Running a coarse model in LAMMPS"): its points
/// as atoms (data file with masses, box, periodicity and initial velocities) and its
/// interaction as LAMMPS pair commands, so the explicit dynamics of `pdcg md` can run in LAMMPS
/// itself (MPI, GPU, KOKKOS) at any scale.
///
/// Which bodies can be exported (docs/theory.md §1, §4):
///  - pairwise potentials (ψ_k = ½Σ_j φ(r_kj)), delta or rescaled: the rescaled pair potential
///    φ_ε(r) = ε^d φ(r/ε) (from ψ_ε,k(Y') = ε^d ψ_k(ε⁻¹Y'), (4.6)) is tabulated for
///    `pair_style table` (spline or linear), with a number of points chosen so that the
///    interpolation error of forces and energies, as LAMMPS interpolates them, is below a
///    stated tolerance, or (lj/cut, morse) as the style itself with rescaled coefficients;
///  - native EAM (eam, eam/alloy, eam/fs), delta or rescaled: the rescaled body is again an
///    EAM model, F_ε(ρ̄) = ε^d F(ρ̄), ρ_ε(r) = ρ(r/ε), φ_ε(r) = ε^d φ(r/ε), written as a setfl
///    file on the grid dr' = ε dr (`pair_style eam/alloy`, or `eam/fs` when a density depends
///    on the receiving type), exact up to round-off.
/// Refused with an InputError naming what cannot be exported and why: statistical bodies
/// (expected energies are not functions of the distance), many-body potentials other than
/// EAM (angle and bond-order terms: no pair table, and the rescaled parameters of a
/// three-body style are not a LAMMPS style), molecular bonds and special factors (not
/// implemented), pair styles evaluated through embedded LAMMPS (not implemented), long-range
/// k-space terms, unit style `none`.
///
/// Fixed families vs neighbour lists: LAMMPS rebuilds its neighbour lists, a PD body keeps the
/// families of its reference configuration. The two agree as long as every pair that comes
/// within the cutoff during the run is in the families (small amplitudes, or families built
/// with a skin: `atoms2pd --family-cutoff`); a pair outside the families that enters the
/// cutoff interacts in LAMMPS only.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "pdcg/body/body.hpp"

namespace pdcg::dynamics {

enum class TableStyle { spline, linear };
/// How a pair potential is written: as a table of φ_ε (any pairwise native style), or as its own
/// LAMMPS style with rescaled coefficients (lj/cut: ε_LJ·ε^d, σ·ε, cutoffs·ε; morse: D0·ε^d,
/// α/ε, r0·ε, cutoffs·ε; exact, mixing rules and `pair_modify shift` commute with the scaling).
enum class PairForm { table, native };

struct LammpsExportOptions {
  PairForm pair_form = PairForm::table;
  /// LAMMPS's interpolation: `spline` (cubic splines in r² of E and F/r) or `linear` (linear
  /// in r² of the file's values, LAMMPS uses them without re-splining).
  TableStyle table_style = TableStyle::spline;
  /// Bound on the interpolation error at every distance r of the table:
  /// |F_table(r) − F(r)| ≤ tol · max(|F(r)|, F_scale) and the same for E, with F_scale and
  /// E_scale the largest |F| and |E| at distances r ≥ the closest reference pair.
  double table_tolerance = 1e-10;
  /// Inner end of the tables (LAMMPS stops with "Pair distance < table inner cutoff" below
  /// it); 0 = table_inner_fraction × the closest pair distance of the reference configuration.
  double table_inner = 0.0;
  double table_inner_fraction = 0.6;
  /// Largest number of table points tried (refused when the tolerance needs more).
  std::int64_t max_table_points = std::int64_t{1} << 21;
  /// Time step and steps written into the input script (run with -var dt … -var steps …).
  double dt = 0.0;
  std::int64_t steps = 0;
  std::string prefix = "model";  ///< file names: <prefix>.data, .table/.eam.*, .pair, in.<prefix>
  std::string command_line;      ///< recorded in the files' header comments
};

/// One tabulated type pair.
struct PairTable {
  int type_i = 0, type_j = 0;  ///< the body's atom types (i ≤ j)
  std::string keyword;         ///< section name in the table file
  double r_lo = 0.0, r_cut = 0.0;
  std::int64_t points = 0;
  double force_error = 0.0;   ///< max |ΔF| / max(|F|, F_scale) over the test points
  double energy_error = 0.0;  ///< max |ΔE| / max(|E|, E_scale)
  double force_scale = 0.0, energy_scale = 0.0;
};

struct LammpsExport {
  std::string pair_style;  ///< "table spline N", "lj/cut 5", "morse 7", "eam/alloy", "eam/fs"
  std::vector<PairTable> tables;
  /// LAMMPS atom types: one per (body type, point mass); lammps_type_of_body_type[t] lists
  /// the LAMMPS types of body type t.
  std::vector<int> body_type_of_lammps_type;  ///< index 1.., [0] unused
  std::vector<double> lammps_type_mass;       ///< index 1.., [0] unused
  std::vector<std::filesystem::path> files;   ///< written, in order
  double closest_pair = 0.0;                  ///< closest reference pair distance
};

/// Throws InputError when the body cannot be represented in LAMMPS (names what and why).
void check_exportable(const body::Body& body, std::string_view source);

/// Writes <dir>/<prefix>.data, the pair file(s) and <dir>/in.<prefix> (atomically: temporary
/// files renamed into place). `velocities`: 3N in body order (empty = zero). Throws
/// InputError (not exportable, tolerance not reachable, bad options).
LammpsExport export_lammps(const body::Body& body, std::span<const double> velocities,
                           const std::filesystem::path& dir, const LammpsExportOptions& options,
                           std::string_view source);

/// The interpolation LAMMPS's `pair_style table` performs on a table of n points uniform in r²
/// from r_lo to r_cut (pair_table.cpp, compute_table + compute; the end derivatives of the
/// spline as LAMMPS computes them), for measuring the tabulation error. Exposed for tests.
struct TableInterpolant {
  TableStyle style = TableStyle::spline;
  double rsq_lo = 0.0, delta = 0.0;
  std::vector<double> e, f, e2, f2;  ///< knot values (f stored as F/r) and second derivatives
  /// E and F at r (r_lo ≤ r < r_cut).
  void eval(double r, double& energy, double& force) const;
};

/// LAMMPS's internal table (PairTable::compute_table) from a table file's n knots uniform in r²
/// from r_lo to r_cut: energies e, forces f (F, not F/r) and the FPRIME slopes dF/dr at both ends.
TableInterpolant table_interpolant(TableStyle style, double r_lo, double r_cut,
                                   std::span<const double> e, std::span<const double> f,
                                   double fplo, double fphi);

}  // namespace pdcg::dynamics
