/// \file
/// Surface energy of a crystal plane from the atoms of a periodic delta body, and the Griffith
/// critical energy release rate G_c = 2γ (docs/fracture.md, docs/theory.md §12).
///
/// The body's periodic box spans a lattice L = {H m : m ∈ Z³} of translations that map the
/// crystal onto itself. For a plane normal n (Cartesian, the body's frame), the in-plane
/// translations {H m : n·H m = 0} form a 2-D lattice with a reduced basis a₁, a₂, and a
/// translation a₃₀ of the least positive height d₀ = n·a₃₀ completes a basis of L. The slab
/// cell is [a₁ a₂ a₃] with a₃ = j a₃₀ (height j d₀ ≥ the requested thickness), filled with the
/// N |det M| atoms of the crystal it holds (H_slab = H M, M integer), and rotated so that
/// a₁ ∥ x and n ∥ z (LAMMPS's box convention; energies are objective). The cut lies in the
/// middle of the widest gap between atomic layers along n (for diamond (111): between the
/// widely spaced layers, the shuffle plane). The bulk is this cell periodic in all three
/// directions; the slab is the same atoms with the third direction non-periodic (two free
/// surfaces of area A = |a₁ × a₂| each):
///
///     γ = (E_slab − E_bulk) / (2A),      G_c = 2γ.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "pdcg/body/body.hpp"
#include "pdcg/body/statics.hpp"

namespace pdcg::body {

struct SlabOptions {
  Eigen::Vector3d normal{0.0, 0.0, 1.0};  ///< plane normal, Cartesian (need not be unit)
  /// Least slab height along n, length units; 0: 4 × the potential cutoff.
  double min_thickness = 0.0;
  int search = 8;  ///< integer range |m_i| ≤ search for lattice translations H m
};

struct Slab {
  Body bulk;                 ///< periodic in all three directions
  Body slab;                 ///< same atoms, order and box; third direction free
  Eigen::Matrix3i M;         ///< slab cell = H M (columns a₁ a₂ a₃ in the body's frame)
  Eigen::Matrix3d rotation;  ///< Q: x_slab = Qᵀ (x_body − origin)
  Eigen::Vector3d normal;    ///< unit normal in the body's frame
  double area = 0.0;         ///< |a₁ × a₂|, one surface
  double height = 0.0;       ///< j d₀
  double period = 0.0;       ///< d₀, least periodic height along n
  int layers = 0;            ///< distinct atomic heights along n in the slab
  double cut_gap = 0.0;      ///< width of the gap the cut lies in (length)
};

/// Builds the slab cell of the plane with normal options.normal. Throws InputError when the
/// body is not a periodic 3-D delta body, or when no in-plane lattice translations within the
/// search range exist (the plane is not a lattice plane of the body's box).
Slab make_slab(const Body& body, const SlabOptions& options);

struct SurfaceEnergy {
  double area = 0.0;
  double e_bulk = 0.0, e_slab = 0.0;  ///< unrelaxed (atoms of the perfect crystal)
  double gamma = 0.0;                 ///< unrelaxed γ, energy/length²
  std::optional<double> e_bulk_relaxed, e_slab_relaxed, gamma_relaxed;
  std::optional<StaticsResult> bulk_statics, slab_statics;
};

/// γ unrelaxed, and relaxed by molecular statics when `statics` is given (fixed box; the slab's
/// atoms relax towards the vacuum along n). A relaxation that does not reach its force
/// tolerance throws NumericalError (never a γ from an unconverged minimum).
SurfaceEnergy surface_energy(const Slab& slab, const std::optional<StaticsOptions>& statics);

/// Energy per area of a unit style in J/m² (metal: eV/Å² = 16.02176634 J/m²; real:
/// kcal/mol/Å² = 0.6947695 J/m²; si: 1); NaN for lj and none.
double energy_per_area_to_j_per_m2(UnitStyle style);

}  // namespace pdcg::body
