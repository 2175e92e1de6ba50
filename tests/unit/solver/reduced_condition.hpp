/// \file
/// Test helper: condition number κ(K_ff) of the reduced tangent at u (the rows and columns
/// of the dofs no displacement set fixes), from a dense SVD. Two Newton solutions that both
/// satisfy ‖R_f‖ ≤ tol ‖f‖ differ by at most ≈ κ(K_ff) · tol · ‖u‖: the bound the GMRES and
/// matrix-free tests compare a Krylov solution with the direct one by. Small bodies only.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <vector>

#include "pdcg/solver/model.hpp"
#include "pdcg/solver/newton.hpp"

namespace pdcg::solver::test_support {

inline double reduced_condition_number(const Model& M, const std::vector<DisplacementSet>& sets,
                                       const Eigen::VectorXd& u) {
  const int dim = M.dimension();
  Eigen::VectorXd f;
  SparseRow K;
  EXPECT_TRUE(M.internal_force_and_tangent(u, f, K));
  std::vector<char> fixed(M.dofs(), 0);
  for (const auto& set : sets)
    for (int p : set.points)
      for (int a = 0; a < dim; ++a)
        if (set.component[a]) fixed[dim * p + a] = 1;
  std::vector<int> fr;
  for (std::size_t i = 0; i < M.dofs(); ++i)
    if (!fixed[i]) fr.push_back(static_cast<int>(i));
  const Eigen::MatrixXd Kd(K);
  Eigen::MatrixXd Kff(fr.size(), fr.size());
  for (std::size_t i = 0; i < fr.size(); ++i)
    for (std::size_t j = 0; j < fr.size(); ++j) Kff(i, j) = Kd(fr[i], fr[j]);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Kff);
  return svd.singularValues()(0) / svd.singularValues().tail(1)(0);
}

}  // namespace pdcg::solver::test_support
