/// \file
/// Interatomic potentials as peridynamic constitutive models.
///
/// Atom k carries the multibody energy ψ_k(Y⟨ξ_kj⟩, j ∈ family of k) (docs/theory.md §1). Its
/// Fréchet derivative is the force state t_kj = ∂ψ_k/∂Y⟨ξ_kj⟩, and the PD internal force
/// f_k = Σ_j (t_kj − t_jk) equals the MD force −∂U/∂y_k exactly (U = Σ_k ψ_k).
///   pair potential φ(r):  ψ_k = ½ Σ_j φ(r_kj),  t_kj = ½ φ'(r) Y/r
///   EAM:                  ψ_k = F_k(ρ̄_k) + ½ Σ_j φ(r_kj), ρ̄_k = Σ_j f_j(r_kj),
///                         t_kj = (F_k'(ρ̄_k) f_j'(r) + ½ φ'(r)) Y/r
///   molecular bonds:      ψ_k += ½ E_bond(r_kj) for each bonded partner j.
/// Potential::force_state evaluates ψ_k and t_kj for one family; it is the only primitive
/// bodies, dynamics and dispersion need. It must not allocate (it runs inside OpenMP loops).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pdcg/core/units.hpp"

namespace pdcg::atomistic {

/// One pair_coeff / bond_coeff command as written.
struct CoeffLine {
  std::string i, j;  ///< type ranges as written ("1", "*", "2*4"); j empty for bond_coeff
  std::vector<std::string> args;  ///< remaining words
  std::string line;               ///< the full command line, verbatim
  long line_number = 0;           ///< in `source`
};

/// The LAMMPS commands that define an interaction model, as the user wrote them
/// (a potential file or the relevant lines of an input deck).
struct PotentialSpec {
  std::string source;               ///< file the commands came from (for messages)
  UnitStyle units = UnitStyle::lj;  ///< LAMMPS's default when there is no `units` command
  long units_line = 0;              ///< line of the `units` command (0 = none: the lj default)
  /// `boundary` command (https://docs.lammps.org/boundary.html) as periodicity per direction
  /// (p periodic; f, s, m and their lo/hi pairs non-periodic); nullopt = no boundary command.
  std::optional<std::array<bool, 3>> periodic;
  std::string boundary;    ///< the boundary command's arguments as written ("s s s")
  long boundary_line = 0;  ///< its line in `source` (0 = none)
  std::string atom_style = "atomic";
  /// `mass` commands: type_mass[t] for t = 1..ntypes (index 0 unused), NaN if unset.
  std::vector<double> type_mass;
  /// `set type T charge Q` commands (or the data file's charges, take_type_charges):
  /// type_charge[t] for t = 1..ntypes, NaN if unset; empty = none. Used by embedded LAMMPS.
  std::vector<double> type_charge;
  int ntypes = 0;          ///< number of atom types (from masses/coefficients or the data file)
  std::string pair_style;  ///< e.g. "lj/cut", "eam/alloy", "zero", "tersoff"; empty = none
  std::vector<std::string> pair_style_args;
  long pair_style_line = 0;  ///< line of the pair_style command in `source` (0 = none)
  std::vector<CoeffLine> pair_coeff;
  std::vector<std::string>
      pair_modify;         ///< words of `pair_modify` (e.g. "shift", "yes", "mix", "arithmetic")
  std::string bond_style;  ///< e.g. "harmonic", "fene"; empty = none
  std::vector<std::string> bond_style_args;
  long bond_style_line = 0;  ///< line of the bond_style command in `source` (0 = none)
  std::vector<CoeffLine> bond_coeff;
  std::array<double, 3> special_lj{0.0, 0.0,
                                   0.0};  ///< special_bonds lj 1-2, 1-3, 1-4 (LAMMPS default 0 0 0)
  std::array<double, 3> special_coul{0.0, 0.0, 0.0};  ///< special_bonds coul
  /// Every accepted command line verbatim, in order: what an HDF5 model stores and what
  /// embedded LAMMPS replays.
  std::vector<std::string> lines;
};

/// One family as a potential sees it. Pointers are borrowed (non-owning), valid for the call.
struct FamilyState {
  int type = 0;                        ///< LAMMPS type of the centre atom k (1-based)
  std::int64_t size = 0;               ///< number of bonds n
  const int* neighbor_type = nullptr;  ///< n types of the partners j
  const double* bond = nullptr;  ///< 3n deformed bond vectors Y⟨ξ_kj⟩ = y_j − y_k (interleaved xyz)
  const double* pair_factor =
      nullptr;                     ///< n special_bonds factors for the pair term; nullptr = all 1
  const int* bond_type = nullptr;  ///< n molecular bond types (0 = not bonded); nullptr = none
};

/// Read-only view of a native EAM potential's spline tables (PairEAM's internal form: 7
/// coefficients per grid point m, [7m + 0..6] = spline[m][0..6]) for dedicated half-list loops
/// (dynamics). Evaluated with the coefficient formulas of PairEAM::compute, as force_state does.
/// Pointers are owned by the Potential and valid for its lifetime.
struct EamView {
  int ntypes = 0, nr = 0, nrho = 0;
  double rdr = 0, rdrho = 0, rhomax = 0, cutforcesq = 0;
  std::vector<const double*> rhor;  ///< [jt·(ntypes+1) + kt]: density of a jt atom at a kt atom
  std::vector<const double*> z2r;   ///< [kt·(ntypes+1) + jt]: r·φ(r)
  std::vector<const double*> frho;  ///< [kt]: embedding function
};

/// Half families (each pair once: bonds k→j with j > k, or one of the two bonds of a self
/// image) in CSR form, for pair kernels that scatter to both ends. Borrowed pointers.
/// Periodic images are ghost points (as LAMMPS's ghost atoms): the position and force arrays
/// hold the N points followed by ghost copies y_g = y_a + H·n of the points their half bonds
/// reach through a periodic image, so Y = y_j − y_k with no per-bond shift; the caller fills
/// the ghost positions before and adds the ghost forces to their points after the kernel.
struct HalfFamilies {
  const std::int64_t* offset = nullptr;    ///< N+1
  const std::int32_t* neighbor = nullptr;  ///< per half bond: index into points and ghosts
  const int* type = nullptr;               ///< atom types (1-based) of points and ghosts
  const double* factor = nullptr;          ///< per half bond special_bonds factor; nullptr = all 1
  bool energy = true;  ///< false: forces only (LAMMPS's eflag = 0), the kernel returns 0
};

/// Short neighbour lists of a many-body kernel (LAMMPS's full neighbour list): for each point k
/// the partners within the list radius (short_cutoff() + a skin) at the last rebuild, drawn
/// from k's family, as indices into points and ghosts (periodic images, as in HalfFamilies).
/// The list of k is neighbor[offset[k] .. offset[k] + count[k]); its first owned[k] entries are
/// the pairs k owns (each pair owned by one end: its pair term is evaluated once). Borrowed.
struct ShortLists {
  const std::int64_t* offset = nullptr;    ///< N+1 (list capacity of k: its family size)
  const std::int32_t* count = nullptr;     ///< N
  const std::int32_t* owned = nullptr;     ///< N
  const std::int32_t* neighbor = nullptr;  ///< indices into points and ghosts
  const int* type = nullptr;               ///< atom types (1-based) of points and ghosts
  /// Reference positions of points and ghosts (x_a + H n): a triplet's two ends j, l belong
  /// to each other's families iff |x_l − x_j|² < family_cutsq.
  const double* reference = nullptr;
  double family_cutsq = 0.0;
};

class Potential {
 public:
  virtual ~Potential() = default;
  /// LAMMPS style name, e.g. "lj/cut" or "eam/alloy + bond harmonic".
  virtual std::string style() const = 0;
  /// Largest pair distance at which atoms interact: families are built with it. Molecular
  /// bonds are added to families regardless of their length.
  virtual double cutoff() const = 0;
  /// Number of atom types the potential is defined for.
  virtual int ntypes() const = 0;
  /// Returns ψ_k and writes t_kj = ∂ψ_k/∂Y⟨ξ_kj⟩ into t[0 .. 3n). Allocates nothing;
  /// thread-safe (const, called concurrently for different k).
  virtual double force_state(const FamilyState& family, double* t) const = 0;
  /// True when ψ_k = ½ Σ_j φ(r_kj) with no many-body term (bond-based PD).
  virtual bool pairwise() const { return false; }
  /// The EAM tables when ψ_k is exactly F_k(ρ̄_k) + ½ Σ_j φ(r_kj) (native eam styles without
  /// molecular bonds); nullptr otherwise.
  virtual const EamView* eam_view() const { return nullptr; }
  /// True when half_pair_forces is available (native pair styles without molecular bonds).
  virtual bool has_pair_kernel() const { return false; }
  /// Pair forces of the half families of points k0 ≤ k < k1 at positions y (3(N + ghosts)),
  /// added into f (3(N + ghosts)): per pair, with Y = y_j − y_k and s the special factor,
  /// f_k += s φ'(r)/r Y, f_j −= s φ'(r)/r Y; returns Σ s φ(r). Same operations as
  /// force_state (LAMMPS's pair formulas), inlined per pair. Allocates nothing; thread-safe
  /// for disjoint f. Only valid when has_pair_kernel() (std::logic_error otherwise).
  virtual double half_pair_forces(const HalfFamilies& h, std::int64_t k0, std::int64_t k1,
                                  const double* y, double* f) const;

  /// True when manybody_forces is available (native sw and tersoff).
  virtual bool has_manybody_kernel() const { return false; }
  /// Largest distance at which two atoms interact directly (the short list's cutoff): the
  /// largest r_c of sw and tersoff (cutoff() is 2 r_c, the reach of ψ_k); cutoff() otherwise.
  virtual double short_cutoff() const { return cutoff(); }
  /// Forces and energy of the LAMMPS form of a many-body style for the points k0 ≤ k < k1 as
  /// centres (PairSW / PairTersoff::compute: each pair term once, by its owner; each triplet
  /// once, at its centre, forces to all three atoms), added into f (3 per point and ghost);
  /// returns the energy of those terms. A term's share in the ψ of an atom whose family lacks
  /// one of its atoms is left out, as force_state does (ShortLists::reference), so that summed
  /// over all centres this is U = Σ_k ψ_k and f = −∂U/∂y of the fixed families, provided
  /// every atom within short_cutoff() of a centre is in its family and in its list (the
  /// caller's lists and skin guarantee it). A point with more than 512 partners within the
  /// cutoff sets `applicable` to false (the caller then uses the general path). Allocates
  /// nothing; thread-safe for disjoint f. Only valid when has_manybody_kernel()
  /// (std::logic_error otherwise).
  virtual double manybody_forces(const ShortLists& lists, std::int64_t k0, std::int64_t k1,
                                 const double* y, double* f, bool& applicable) const;

  /// Doubles of scratch force_state_tangent needs for a family of n bonds.
  static std::size_t tangent_workspace(std::int64_t n) { return 9 * static_cast<std::size_t>(n); }
  /// Second Fréchet derivative of ψ_k (the linearised force state, for dispersion and
  /// Cauchy–Born tangents):
  ///   K[(j·n + m)·9 + 3a + b] = ∂t_kj,a / ∂Y⟨ξ_km⟩_b   (n² blocks of 3×3, row-major).
  /// Pairwise potentials have only the blocks j = m:
  ///   ½[φ''(r) e⊗e + φ'(r)/r (I − e⊗e)],  e = Y/r.
  /// The default differentiates force_state by central differences (step s = 6e-6·max(1,|Y|):
  /// truncation O(s²) and round-off O(ε/s) both ≈ 1e-11 relative); native styles override it
  /// analytically. `workspace` holds tangent_workspace(n) doubles. Allocates nothing.
  virtual void force_state_tangent(const FamilyState& family, double* K, double* workspace) const;
  /// Masses the potential itself sets per atom type (EAM files carry them; LAMMPS's
  /// pair_coeff sets them): index t = 1..ntypes, NaN where unset; empty if none.
  virtual std::vector<double> type_masses() const { return {}; }
};

}  // namespace pdcg::atomistic
