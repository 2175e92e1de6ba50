/// \file
/// Discretisation of a body for the bond-associated (BA) correspondence solver.
///
/// Points x_i on a regular grid (cell centres, spacing Δx) with volumes
/// V_i = Δx^d (next to a hole: the cut cell, GridSpec::cut_cells), horizon δ = m Δx (default m
/// = 3.015), families
///   H_i = { j ≠ i : |x_j − x_i| ≤ δ, bond (i, j) not crossing a pre-crack }
/// in CSR. Two kinds of gradient stencils are precomputed from the reference
/// configuration (docs/theory.md §6):
///
///  - point stencils (classical correspondence): members {i} ∪ H_i;
///  - bond stencils (BA, Chen 2018; Chen & Spencer 2018): for each bond (i, j),
///    B_ij = {i, j} ∪ (H_i ∩ H_j) (the points within δ of both ends).
///
/// On every stencil S centred at i the first-order PDDO (Madenci, Barut &
/// Dorduncu 2019) with basis p(ξ) = {1, ξ₁, …, ξ_d} gives
///   A_S = Σ_{m∈S} w(|ξ_m|) p(ξ_m) p(ξ_m)ᵀ V_m,   ξ_m = x_m − x_i,
///   g_S^m = w(|ξ_m|) [A_S⁻¹ p(ξ_m)]_{1..d},      G_S^m = g_S^m V_m,
/// and the stencil deformation gradient F_S = I + Σ_{m∈S} u_m ⊗ G_S^m, exact
/// for linear displacement fields (Σ_m G^m = 0 and Σ_m ξ_m ⊗ G^m = I).
/// w(r) = exp(−4 r²/δ²) by default (a parameter).
///
/// BA weights: φ_ij = |H_i ∩ H_j| / |H_i| (volumes, the point itself and the
/// bond partner counted), normalised per point, φ̂_ij = φ_ij / Σ_j φ_ij V_j, so
/// that Σ_j φ̂_ij V_j = 1 and the discrete energy Σ_i V_i Σ_j φ̂_ij Ψ(F_ij) V_j
/// of a homogeneous deformation is exactly Ψ(F) Σ_i V_i.
///
/// Boundary: every point carries its boundary face vector s_k = Σ n_f |f| over
/// the faces of its grid cell that lie on the body surface (outer boundary,
/// hole, or crack face); Σ_k s_k ⊗ … is the discrete ∮ n dS used by the weak
/// form (see model.hpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace pdcg::solver {

using Vec3 = Eigen::Vector3d;

/// Influence function w(r; δ).
using InfluenceFunction = std::function<double(double r, double delta)>;
/// Madenci's Gaussian w(r) = exp(−4 r²/δ²).
InfluenceFunction gaussian_influence();

struct Hole {
  Vec3 center = Vec3::Zero();
  double radius = 0.0;
};
/// A straight pre-crack: the segment from–to in the xy-plane (in 3D: the plane
/// through the segment parallel to z, through the whole thickness). Bonds that
/// cross it are removed.
struct Crack {
  Vec3 from = Vec3::Zero(), to = Vec3::Zero();
};

/// Where the grid points sit.
///  - cell_centres (default): x = origin + (i + ½)Δx, i = 0 … n−1, V = Δx^d; the outermost
///    points are Δx/2 inside the boundary.
///  - vertices: x = origin + iΔx, i = 0 … n, the points of the boundary lie on it; each
///    point owns its dual cell clipped to the box (V = Δx^d, halved per boundary axis:
///    Δx^d/2 on a face, Δx^d/4 at a 2D corner), boundary faces are the dual-cell faces.
///    Displacement sets selected at x = 0 / x = L then act on the true boundary, the gauge
///    a continuum (FEM) solution has.
enum class GridNodes { cell_centres, vertices };

/// A regular grid body: rectangle (2D) or box (3D) with holes and cracks.
struct GridSpec {
  GridNodes nodes = GridNodes::cell_centres;
  int dimension = 2;
  Vec3 origin = Vec3::Zero();
  Vec3 size = Vec3::Ones();
  double spacing = 0.025;
  std::vector<Hole> holes;
  std::vector<Crack> cracks;
  /// Cut-cell volumes at the holes (docs/solver.md §2, "Cut-cell volumes"): a point whose
  /// cell a hole cuts carries |cell ∩ body| instead of the whole cell, and the part of the
  /// body in a cell whose centre lies in a hole (no point there) goes to the nearest points
  /// of the neighbouring cells, so Σ V_i is the body's exact measure. Holes whose surface
  /// vectors come from the true circle / sphere only (inside the box, disjoint from the
  /// other holes); false: whole cells (the staircase volume).
  bool cut_cells = true;
};

/// Compressed sparse rows of integers (families).
struct Csr {
  std::vector<std::int64_t> offsets{0};
  std::vector<int> index;
  std::int64_t begin(std::size_t row) const { return offsets[row]; }
  std::int64_t end(std::size_t row) const { return offsets[row + 1]; }
  std::size_t rows() const { return offsets.size() - 1; }
};

/// Gradient stencils: stencil s has centre center[s], weight weight[s] (its
/// share of the energy sum), members index[offsets[s] .. offsets[s+1]) and,
/// per member, G^m (dimension doubles each, in `grad`, same order).
struct Stencils {
  std::vector<std::int64_t> offsets{0};
  std::vector<int> index;
  std::vector<double> grad;
  std::vector<int> center;
  std::vector<double> weight;
  std::size_t size() const { return center.size(); }
};

struct DiscretizationOptions {
  double horizon_factor = 3.015;  ///< δ = factor · Δx (ignored if horizon > 0)
  double horizon = 0.0;           ///< absolute δ (> 0 overrides the factor)
  InfluenceFunction influence = gaussian_influence();
  /// A stencil whose scaled moment matrix has a reciprocal condition number
  /// below this is ill-posed (error naming the point).
  double min_reciprocal_condition = 1e-10;
};

class Discretization {
 public:
  /// Builds a regular-grid body. Throws InputError for bad geometry (spacing
  /// ≤ 0, horizon < spacing, no points) and NumericalError naming the position
  /// of a point whose (BA) family is too small for a well-posed g.
  static Discretization grid(const GridSpec& spec, const DiscretizationOptions& opt = {});

  /// Builds from given points (volumes, boundary face vectors), e.g. a model file.
  static Discretization from_points(int dimension, std::vector<Vec3> x, std::vector<double> volume,
                                    std::vector<Vec3> surface, double spacing,
                                    std::vector<Crack> cracks, const DiscretizationOptions& opt);

  int dimension() const { return dim_; }
  std::size_t size() const { return x_.size(); }
  double spacing() const { return dx_; }
  double horizon() const { return delta_; }
  const std::vector<Vec3>& positions() const { return x_; }
  const std::vector<double>& volumes() const { return vol_; }
  /// s_k: area-weighted outward normal of the body surface owned by point k.
  const std::vector<Vec3>& surface() const { return surface_; }
  const Csr& families() const { return families_; }
  /// Classical (point) stencils, one per point, centre = point, weight V_i.
  const Stencils& point_stencils() const { return point_; }
  /// BA stencils, one per bond (i, j) in CSR order of families(),
  /// weight V_i φ̂_ij V_j.
  const Stencils& bond_stencils() const { return bond_; }
  /// φ̂_ij per bond, in CSR order of families().
  const std::vector<double>& bond_weights() const { return phi_hat_; }

  // ---- rupture (docs/effects.md) -------------------------------------------
  // Nothing below is allocated or touched unless enable_rupture() is called: a
  // body without rupture carries no broken-bond flags, and the stencil data the
  // model kernels read are exactly those of the intact body.

  /// Allocates the per-bond broken flags (all intact).
  void enable_rupture();
  bool rupture_enabled() const { return !broken_.empty(); }
  /// CSR position of the bond (i, j) in families(), or −1.
  std::int64_t bond_index(int i, int j) const;
  /// Marks the bond (i, j) broken in both directions (no stencil rebuilt yet).
  /// Returns false if it was already broken.
  bool break_bond(int i, int j);
  bool broken(std::int64_t q) const { return broken_[q] != 0; }
  /// Rebuilds, after break_bond calls, every stencil that a broken bond touches:
  /// the point stencils and all BA stencils centred at the ends of the broken
  /// bonds and at their (reference) family members. A member m leaves B_ij when
  /// bond (i, m) or (j, m) is broken (its G becomes 0); φ_ij is recomputed from
  /// the intact families and renormalised; a broken bond's stencil gets weight 0;
  /// a stencil whose moment matrix is ill-posed (reciprocal condition below
  /// min_reciprocal_condition) gets G = 0 and weight 0: it carries no stress.
  /// Returns the number of stencils rebuilt.
  /// min_reciprocal_condition > 0 replaces the build option for the rebuilt stencils.
  std::size_t rebuild_broken(double min_reciprocal_condition = 0.0);
  /// Centres whose stencils the last rebuild_broken call rebuilt (sorted).
  const std::vector<int>& last_rebuilt_centres() const { return rebuilt_centres_; }
  /// Switches the point stencil of k off for good (G = 0, also through later rebuilds):
  /// its F̄_k became inadmissible (J ≤ 0) at a crack, so the weak-form correction
  /// P(F̄_k) e_k of that point is dropped (P(I) = 0). Returns false if it already was.
  bool suppress_point_stencil(int k);
  bool point_stencil_suppressed(int k) const { return !point_off_.empty() && point_off_[k]; }
  /// Points whose point stencil is off (checkpoints).
  std::vector<int> suppressed_point_stencils() const;
  /// Broken fraction of the reference family of each point, in [0, 1].
  std::vector<double> damage() const;
  /// Number of broken (undirected) bonds.
  std::size_t broken_bonds() const { return n_broken_; }
  /// Stencils switched off because their family became ill-posed.
  std::size_t suppressed_stencils() const { return n_suppressed_; }
  /// Stiffness factor of the bond q (CSR order), in [0, 1]: the (1 − d) of a softening
  /// failure law (docs/fracture.md §6). Its BA stencil's weight becomes V_iφ̂_ijV_j · factor
  /// at once; at the next rebuild_broken (the ends are marked like those of a broken bond)
  /// the member j of the stencils of i (and i of j's) counts with this share — in the
  /// moment matrix, the lens volume |B| and the family volume — and each family is
  /// renormalised to Σ_j φ̂_ijV_j·factor_ij = 1: factor 0 is a broken bond, continuously.
  /// All 1 (and nothing allocated) until first set.
  void set_bond_stiffness_factor(std::int64_t q, double factor);
  double bond_stiffness_factor(std::int64_t q) const {
    return bond_factor_.empty() ? 1.0 : bond_factor_[q];
  }
  /// Weight of the BA stencil q without its stiffness factor: V_iφ̂_ijV_j.
  double intact_bond_weight(std::int64_t q) const {
    return vol_[bond_.center[q]] * phi_hat_[q] * vol_[families_.index[q]];
  }

 private:
  void build(const DiscretizationOptions& opt);
  int dim_ = 2;
  double dx_ = 0, delta_ = 0;
  std::vector<Vec3> x_;
  std::vector<double> vol_;
  std::vector<Vec3> surface_;
  std::vector<Crack> cracks_;
  Csr families_;
  Stencils point_, bond_;
  std::vector<double> phi_hat_;
  // rupture state (empty unless enabled)
  DiscretizationOptions opt_;
  std::vector<char> broken_;         // per directed bond
  std::vector<char> suppressed_;     // per bond stencil: ill-posed, weight 0
  std::vector<char> point_off_;      // per point: point stencil switched off (inverted)
  std::vector<double> bond_factor_;  // per bond stencil: stiffness factor (empty: all 1)
  std::vector<int> dirty_;           // points whose stencils need a rebuild
  std::vector<int> rebuilt_centres_;
  std::size_t n_broken_ = 0, n_suppressed_ = 0;
};

/// True if the segment a–b crosses the crack (xy-projection).
bool crosses(const Crack& c, const Vec3& a, const Vec3& b);

}  // namespace pdcg::solver
