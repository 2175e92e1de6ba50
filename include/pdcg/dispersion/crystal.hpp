/// \file
/// Dispersion of a perfect crystal with a basis, per primitive cell: all 3n branches (3
/// acoustic, 3(n − 1) optical) of its n basis atoms along labelled high-symmetry paths
/// (docs/dispersion.md "Crystals with a basis", docs/theory.md §11).
///
/// The crystal is classified by body::detect_lattice (environment classes = basis atoms; the
/// primitive translations). With one representative atom r_c per class c, the linearised force
/// states K_bd = ∂t_b/∂Y_d of its family and a Bloch wave u_j = a_{c(j)} e^{iκ·x_j}, the bond
/// b of r_c deforms by Y_b = a_{c(j_b)} e^{iκ·ξ_b} − a_c =: B_b a, so the energy per primitive
/// cell is ½ aᴴ D a with
///     D(κ) = Σ_c Σ_{b,d ∈ H_{r_c}} B_bᴴ K_bd B_d     (3n × 3n, Hermitian),
/// and ω² = eig(M^{−½} D M^{−½}/mvv2e), M = diag(m_c). For n = 1 this is point_omega's D_p.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/body/body.hpp"
#include "pdcg/body/lattice.hpp"
#include "pdcg/dispersion/model.hpp"

namespace pdcg::dispersion {

/// The Bravais lattice of a perfect crystal's translations, in the body's orientation.
struct CrystalLattice {
  /// "fcc", "bcc", "sc", "hcp" (3D hexagonal), "hex" (2D triangular) or "chain".
  std::string lattice;
  double a = 0.0;  ///< cubic: conventional cube edge; hcp, hex, chain: in-plane spacing
  double c = 0.0;  ///< hcp: the c axis (0 otherwise)
  /// Columns: the standard frame's x, y, z axes in body coordinates (cubic: the cube axes;
  /// hcp/hex: x along a₁, z along c / the sheet normal). Points are R·κ_standard.
  Eigen::Matrix3d frame = Eigen::Matrix3d::Identity();
  std::vector<SymmetryPoint> points;  ///< in body Cartesian coordinates
  int basis = 1;
  std::string summary;  ///< e.g. "fcc lattice, a = 5.431, 2 basis atoms"
};

/// Classifies the translations of a perfect crystal (info.perfect, info.primitive set): fcc
/// (12 shortest translations), bcc (8), sc (6 orthogonal), hcp (a hexagon of translations and
/// c normal to it), 2D hex (dimension 2), chain (dimension 1); the candidate is accepted only
/// when every primitive vector is a translation of it and the cell measures agree (1e-6
/// relative). Throws InputError otherwise (the lattice is named by its shortest translations,
/// the fix: --lattice/--a with one-point curves, or --cell / --direction).
CrystalLattice classify_lattice(const body::LatticeInfo& info, int dimension,
                                const std::string& source = "");

/// Primitive-cell dynamical matrix of a perfect crystal (delta or rescaled body; see above).
class CrystalDispersion {
 public:
  /// Throws InputError when the body is not a perfect crystal (info.summary is the reason) or
  /// is statistical / homogenised (their model has 3 DOF per point: one-point dispersion).
  CrystalDispersion(const body::Body& body, const body::LatticeInfo& info);
  /// Frequencies at κ (body Cartesian, 1/length), ascending, 3n; ω² < 0 as −√|ω²|.
  Eigen::VectorXd omega(const Eigen::Vector3d& kappa) const;
  /// The mass-weighted dynamical matrix M^{−½} D M^{−½}/mvv2e at κ (Hermitian, 3n × 3n).
  Eigen::MatrixXcd dynamical_matrix(const Eigen::Vector3d& kappa) const;
  int basis() const { return static_cast<int>(rep_.size()); }
  /// Representative atom (index into the body) of each basis class.
  const std::vector<std::size_t>& representatives() const { return rep_; }
  std::string description() const { return description_; }

 private:
  const body::Body& body_;
  std::vector<int> class_of_;
  std::vector<std::size_t> rep_;
  std::vector<double> mass_;
  std::unique_ptr<LinearisedFamilies> lin_;
  double mvv2e_ = 1.0;
  std::string description_;
};

}  // namespace pdcg::dispersion
