/// \file
/// Dispersion of a PD model linearised about its reference configuration (docs/theory.md §5).
///
/// A plane wave u(x) = a e^{iκ·x} deforms bond b of atom k by Y_b = a_{j_b} e^{iκ·ξ_b} − a_k
/// (times e^{iκ·x_k}). With K_bc = ∂t_b/∂Y_c (Potential::force_state_tangent) the energy of the
/// wave is ½ Σ_k Σ_bc Y_b* K_bc Y_c, so
///
/// * at one point of a Bravais-lattice body, where every atom moves with the same a
///   (delta body of a perfect lattice; its homogenised and rescaled bodies, point by point):
///     D_p(κ) = Σ_k w_k Σ_{b,c∈H_k} (e^{iκ·ξ_b} − 1)* K_bc (e^{iκ·ξ_c} − 1),  M_p = Σ_k w_k M_k,
///     ω²(κ) = eig(D_p / M_p)  (3 branches);
/// * for a periodic cell with a basis (all atoms of a periodic body, any κ; folded bands),
///     D(κ) = Σ_k Σ_bc B_b^H K_bc B_c,  B_b a = a_{j_b} e^{iκ·ξ_b} − a_k,
///     ω² = eig(M^{−½} D M^{−½})  (3N branches).
/// For a 1D chain with springs μ_n this gives ω² = (2/M) Σ μ_n (1 − cos nκh) exactly, and for a
/// body rescaled by ε it gives ω_ε(κ) = ω(εκ)/ε (docs/theory.md §4) because K_ε = ε⁻² K on bonds
/// εξ. Refs: Born & Huang, Dynamical Theory of Crystal Lattices (1954), ch. V; Silling, J. Mech.
/// Phys. Solids 48 (2000) 175 (PD dispersion).
#pragma once

#include <Eigen/Core>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potential.hpp"

namespace pdcg::dispersion {

/// Linearised families of a set of atoms, evaluated once at the reference bonds.
class LinearisedFamilies {
 public:
  /// x: the 3N reference positions the families were built from; atoms: indices into the
  /// families to linearise (all atoms if empty).
  LinearisedFamilies(const atomistic::Potential& potential, const atomistic::Families& families,
                     std::span<const double> x, std::span<const int> type,
                     std::span<const std::int32_t> atoms = {});
  const atomistic::Families& families() const { return *families_; }
  /// K blocks of atom k (n_k² · 9 doubles), or an empty span if k was not linearised.
  std::span<const double> tangent(std::size_t k) const;
  /// Reference bonds ξ of atom k's family (3 n_k doubles; empty if k was not linearised). Kept
  /// for the linearised atoms only (3 n_k next to the 9 n_k² of K).
  std::span<const double> bonds(std::size_t k) const;

  /// One linearised atom: its n bonds, the tangent blocks and the reference bonds.
  struct Atom {
    std::int64_t n = 0;          ///< bonds of the family
    const double* K = nullptr;   ///< n² blocks of 9 (row-major), block (b, c) at 9(b n + c)
    const double* xi = nullptr;  ///< 3n reference bonds ξ_b
    const double* block(std::int64_t b, std::int64_t c) const { return K + (b * n + c) * 9; }
    /// Block (b, c) is exactly zero (bonds b and c do not interact).
    bool zero_block(std::int64_t b, std::int64_t c) const {
      const double* p = block(b, c);
      for (int i = 0; i < 9; ++i)
        if (p[i] != 0.0) return false;
      return true;
    }
  };
  /// Atom k's linearisation; throws Error(not_linearised) if k was not linearised.
  Atom atom(std::size_t k, const char* not_linearised) const;

 private:
  const atomistic::Families* families_;
  std::vector<std::int64_t> start_;       ///< per atom: start in k_ (−1 if absent)
  std::vector<std::int64_t> bond_start_;  ///< per atom: start in xi_ (−1 if absent)
  std::vector<double> k_, xi_;
};

/// ω(κ) at one point made of weighted atoms (Bravais lattice assumption, see above).
/// Returns the 3 frequencies in ascending order; a negative ω² (unstable mode) is returned as
/// −√|ω²|. mvv2e converts mass·velocity² to energy (LAMMPS force->mvv2e: 1 in lj/si, 1.0364269e-4
/// in metal): ω² = eig(D)/(M·mvv2e), so ω is in inverse time units of the unit style.
Eigen::Vector3d point_omega(const LinearisedFamilies& lin,
                            std::span<const std::pair<std::int32_t, double>> atoms,
                            std::span<const double> mass, const Eigen::Vector3d& kappa,
                            double mvv2e = 1.0);

/// ω(κ) of a periodic cell with a basis: all 3N branches, ascending (same sign convention).
Eigen::VectorXd cell_omega(const LinearisedFamilies& lin, std::span<const double> mass,
                           const Eigen::Vector3d& kappa, double mvv2e = 1.0);

/// A named high-symmetry point, in Cartesian reciprocal coordinates (units 1/length).
struct SymmetryPoint {
  std::string label;
  Eigen::Vector3d kappa;
};

/// High-symmetry points of a lattice in its standard orientation ("fcc", "bcc", "sc", "hcp"
/// (3D hexagonal, a₁ = a(1,0,0), a₂ = a(½,√3/2,0), a₃ = c(0,0,1); needs c > 0), "hex" (2D
/// triangular, same a₁, a₂, in the xy plane), "chain" (along x)) with lattice constant a (cubic:
/// conventional cube edge; hcp, hex and chain: in-plane spacing). Labels and coordinates
/// follow Setyawan & Curtarolo, Comput. Mater. Sci. 49 (2010) 299 (docs/dispersion.md).
/// Throws InputError for an unknown lattice.
std::vector<SymmetryPoint> symmetry_points(const std::string& lattice, double a, double c = 0.0);

/// The default path of a lattice (`--path auto`): Setyawan–Curtarolo's, with '|' for a jump
/// (fcc G-X-W-K-G-L-U-W-L-K|U-X, bcc G-H-N-G-P-H|P-N, sc G-X-M-G-R-X|M-R, hcp
/// G-M-K-G-A-L-H-A|L-M|K-H, hex G-M-K-G, chain G-X).
std::string default_path(const std::string& lattice);

/// One κ of a path: cumulative length s (a jump '|' does not advance it), κ, and the label
/// when κ is a corner of the path ("" between corners; "X|U" at a jump).
struct PathPoint {
  double s = 0.0;
  Eigen::Vector3d kappa;
  std::string label;
};

/// Points along a path "G-X-W|U-X" (labels of `points`, G = Γ; '|' a jump), nk per segment.
/// Throws InputError naming an unknown label and listing the valid ones for `lattice` (the
/// name used in the message).
std::vector<PathPoint> labelled_path(const std::vector<SymmetryPoint>& points,
                                     const std::string& lattice, const std::string& labels,
                                     int nk_per_segment);

/// Points along a path "G-X-K-G-L" (labels as in symmetry_points; G = Γ), nk per segment.
/// Returns κ and the cumulative path length. Throws InputError naming an unknown label and
/// listing the valid ones.
std::vector<std::pair<double, Eigen::Vector3d>> path(const std::string& lattice, double a,
                                                     const std::string& labels, int nk_per_segment);

}  // namespace pdcg::dispersion
