/// \file
/// Iterative linear solve of the Newton systems for bodies whose LU does not fit in
/// memory (large 3D): restarted GMRES (Saad & Schultz 1986; right preconditioning,
/// modified Gram–Schmidt, Givens rotations) on the reduced weak-form tangent K_ff, with
/// the Cholesky factor (CHOLMOD) of a cheap symmetric positive definite operator on the
/// same points as the preconditioner:
///
///   the lattice stiffness P — trilinear (Q1, 3D) or bilinear (2D) finite elements whose
///   nodes are the grid points (one element per grid cell whose 2^d corner points all exist
///   and are mutually bonded, so holes and pre-cracks are respected), with the material's
///   small-strain tangent A = ∂P/∂F at F = I, 2^d Gauss points per element:
///     P_{ia,jb} = Σ_e Σ_g w_g Σ_JL ∂N_i/∂X_J A_aJbL ∂N_j/∂X_L.
///
/// P and the BA tangent discretise the same continuum operator −∇·(A:∇u) at long
/// wavelengths; P has 27 (3D) or 9 (2D) point neighbours per row instead of the BA
/// tangent's ≈ 900 (3D) or ≈ 110 (2D), so its factor is cheap. They differ at
/// wavelengths of a few spacings (the nonlocal tangent is softer there), which is what
/// GMRES has to resolve (iteration counts in docs/performance.md).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <functional>
#include <vector>

#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/material.hpp"

namespace pdcg::solver {

/// Column-major sparse matrix with 64-bit indices (SuiteSparse's *_l / *_dl interfaces).
using SparseColLong = Eigen::SparseMatrix<double, Eigen::ColMajor, std::int64_t>;

/// The lattice stiffness P restricted to the free dofs (free_index[dof] = free index or
/// −1; nfree free dofs). A free dof that belongs to no element gets the diagonal entry of
/// an element's stiffness, so P_ff stays nonsingular. Throws InputError if the points do
/// not lie on a regular grid of the body's spacing.
SparseColLong lattice_stiffness(const Discretization& body, const Material& material,
                                const std::vector<int>& free_index, int nfree);

/// Element stiffness of one grid cell of side h (d = 2 or 3): (2^d·d)², corner c at
/// offsets ((c >> a) & 1)·h, dof c·d + a. Exposed for the tests.
Eigen::MatrixXd lattice_element_stiffness(int dimension, double h, const Tangent& A);

struct GmresReport {
  bool converged = false;
  int iterations = 0;                     ///< Krylov iterations (operator products)
  double relative_residual = 0.0;         ///< ‖b − A x‖ / ‖b‖ at exit (true residual)
  std::vector<double> restart_residuals;  ///< true relative residual at each restart
};

/// Restarted GMRES(m) with right preconditioning. Workspace is kept between solves
/// (no allocation after the first solve of a given size, apart from what the operator and
/// the preconditioner do).
class Gmres {
 public:
  using Operator = std::function<void(const Eigen::VectorXd& in, Eigen::VectorXd& out)>;
  explicit Gmres(int restart = 50) : m_(restart) {}
  /// Solves A x = b to ‖b − A x‖ ≤ rtol ‖b‖ from x = 0, with at most max_iterations
  /// products by A. precondition(v, z) sets z = M⁻¹ v.
  GmresReport solve(const Operator& A, const Operator& precondition, const Eigen::VectorXd& b,
                    Eigen::VectorXd& x, double rtol, int max_iterations);
  int restart() const { return m_; }

 private:
  int m_;
  Eigen::MatrixXd V_, H_;
  Eigen::VectorXd g_, cs_, sn_, y_, w_, z_, r_, v_;
};

}  // namespace pdcg::solver
