// Internal: expected energies and force states of statistical bodies (docs/theory.md §2).
#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "pdcg/body/body.hpp"

namespace pdcg::body::detail {

struct Scratch {
  int order = -1, dim = -1;
  std::vector<double> nodes;    ///< tensor-product Gauss–Hermite nodes, dim per node
  std::vector<double> weights;  ///< their weights (sum 1)
  std::vector<double> factor;  ///< 9 per atom: 3×d factor A_k with A_k A_kᵀ = Σ_k (col-major 3×3)
  std::vector<double> ys;      ///< sample positions (bond vectors and t: per-thread, per family)
  std::vector<double> xs;      ///< the sample's reference positions (∂U/∂G of sampling)
  std::vector<int> ntype;
};

/// Fills psi_out (N) and t_out (3 per bond) with expected values and returns Σ_k E[ψ_k].
/// y, h_y: mean deformed positions and box; G maps the reference fluctuations to the deformed
/// ones (identity for given positions, F for a homogeneous deformation).
/// With du_dg: ∂U/∂G = E[Σ_b t_b ⊗ ξ_b^s], ξ_b^s the bond of the sample in the reference (the
/// mean bond plus the reference fluctuation, which G maps): for G = F and y = F x̄ this is
/// V₀ ∂W/∂F of the conforming deformation (first Piola–Kirchhoff stress times V₀).
double statistical_force_states(const Body& body, const Statistics& s, std::span<const double> y,
                                const Eigen::Matrix3d& h_y, const Eigen::Matrix3d& G,
                                std::span<double> psi_out, std::span<double> t_out,
                                Scratch& scratch, Eigen::Matrix3d* du_dg = nullptr);

}  // namespace pdcg::body::detail
