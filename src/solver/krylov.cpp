#include "pdcg/solver/krylov.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "pdcg/core/error.hpp"

namespace pdcg::solver {

Eigen::MatrixXd lattice_element_stiffness(int d, double h, const Tangent& A) {
  const int nc = 1 << d, nd = nc * d;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nd, nd);
  // 2-point Gauss rule per axis on [0, 1]: exact for the (bi/tri)quadratic integrand.
  const double gp[2] = {0.5 - 0.5 / std::sqrt(3.0), 0.5 + 0.5 / std::sqrt(3.0)};
  const int ng = 1 << d;
  const double wg = std::pow(h, d) / ng;  // Gauss weight × cell volume
  Eigen::MatrixXd dN(nc, 3);
  for (int g = 0; g < ng; ++g) {
    double xi[3] = {0.5, 0.5, 0.5};
    for (int a = 0; a < d; ++a) xi[a] = gp[(g >> a) & 1];
    dN.setZero();
    for (int c = 0; c < nc; ++c)
      for (int J = 0; J < d; ++J) {
        double v = ((c >> J) & 1) ? 1.0 / h : -1.0 / h;
        for (int b = 0; b < d; ++b)
          if (b != J) v *= ((c >> b) & 1) ? xi[b] : 1.0 - xi[b];
        dN(c, J) = v;
      }
    for (int i = 0; i < nc; ++i)
      for (int a = 0; a < d; ++a)
        for (int j = 0; j < nc; ++j)
          for (int b = 0; b < d; ++b) {
            double s = 0;
            for (int J = 0; J < d; ++J)
              for (int L = 0; L < d; ++L) s += dN(i, J) * A(flat(a, J), flat(b, L)) * dN(j, L);
            K(i * d + a, j * d + b) += wg * s;
          }
  }
  return K;
}

SparseColLong lattice_stiffness(const Discretization& body, const Material& material,
                                const std::vector<int>& free_index, int nfree) {
  const int d = body.dimension();
  const double h = body.spacing();
  const std::size_t N = body.size();
  const auto& x = body.positions();
  // Integer lattice coordinates.
  Vec3 lo = Vec3::Constant(INFINITY);
  for (const auto& p : x) lo = lo.cwiseMin(p);
  std::array<std::int64_t, 3> ext{1, 1, 1};
  std::vector<std::array<int, 3>> ijk(N);
  for (std::size_t k = 0; k < N; ++k)
    for (int a = 0; a < d; ++a) {
      const double s = (x[k](a) - lo(a)) / h;
      const long i = std::lround(s);
      // positions are generated as origin + (i + ½)Δx: round-off only
      if (std::abs(s - static_cast<double>(i)) > 1e-6)
        throw InputError(fmt::format("linear solver gmres: point {} at ({}) is not on a regular "
                                     "grid of spacing {} (its lattice preconditioner needs one)",
                                     k, fmt::join(x[k].head(d), ", "), h))
            .key("solver.linear")
            .value("gmres")
            .fix("use linear: umfpack");
      ijk[k][a] = static_cast<int>(i);
      ext[a] = std::max<std::int64_t>(ext[a], i + 2);
    }
  const std::int64_t cells = ext[0] * ext[1] * ext[2];
  if (cells > 64 * static_cast<std::int64_t>(N) + (1 << 20))
    throw InputError(
        "linear solver gmres: the points fill too little of their bounding grid "
        "for the lattice preconditioner")
        .key("solver.linear")
        .value("gmres")
        .fix("use linear: umfpack");
  std::vector<int> at(static_cast<std::size_t>(cells), -1);
  auto lin = [&](std::int64_t i, std::int64_t j, std::int64_t l) {
    return (l * ext[1] + j) * ext[0] + i;
  };
  for (std::size_t k = 0; k < N; ++k)
    at[lin(ijk[k][0], ijk[k][1], d == 3 ? ijk[k][2] : 0)] = static_cast<int>(k);
  Tangent A;
  if (!material.evaluate(Mat3::Identity(), nullptr, nullptr, &A))
    throw NumericalError("lattice preconditioner: the material has no tangent at F = I");
  const Eigen::MatrixXd Ke = lattice_element_stiffness(d, h, A);
  const int nc = 1 << d;
  const double delta = body.horizon();
  std::vector<Eigen::Triplet<double, std::int64_t>> trip;
  std::vector<char> covered(N, 0);
  std::vector<int> corner(nc);
  for (std::int64_t l = 0; l < (d == 3 ? ext[2] - 1 : 1); ++l)
    for (std::int64_t j = 0; j < ext[1] - 1; ++j)
      for (std::int64_t i = 0; i < ext[0] - 1; ++i) {
        bool ok = true;
        for (int c = 0; c < nc && ok; ++c) {
          corner[c] = at[lin(i + (c & 1), j + ((c >> 1) & 1), d == 3 ? l + ((c >> 2) & 1) : 0)];
          ok = corner[c] >= 0;
        }
        // every pair of corners within the horizon must be an intact bond (pre-cracks)
        for (int c = 0; c < nc && ok; ++c)
          for (int e = c + 1; e < nc && ok; ++e) {
            if ((x[corner[c]] - x[corner[e]]).norm() > delta) continue;
            const auto q = body.bond_index(corner[c], corner[e]);
            ok = q >= 0 && !(body.rupture_enabled() && body.broken(q));
          }
        if (!ok) continue;
        for (int c = 0; c < nc; ++c) {
          covered[corner[c]] = 1;
          for (int a = 0; a < d; ++a) {
            const int r = free_index[d * corner[c] + a];
            if (r < 0) continue;
            for (int e = 0; e < nc; ++e)
              for (int b = 0; b < d; ++b) {
                const int s = free_index[d * corner[e] + b];
                if (s >= 0) trip.emplace_back(r, s, Ke(c * d + a, e * d + b));
              }
          }
        }
      }
  for (std::size_t k = 0; k < N; ++k)
    if (!covered[k])
      for (int a = 0; a < d; ++a)
        if (free_index[d * k + a] >= 0)
          trip.emplace_back(free_index[d * k + a], free_index[d * k + a], Ke(a, a));
  SparseColLong P(nfree, nfree);
  P.setFromTriplets(trip.begin(), trip.end());
  P.makeCompressed();
  return P;
}

GmresReport Gmres::solve(const Operator& A, const Operator& precondition, const Eigen::VectorXd& b,
                         Eigen::VectorXd& x, double rtol, int max_iterations) {
  const Eigen::Index n = b.size();
  const int m = std::max(1, m_);
  if (V_.rows() != n || V_.cols() != m + 1) {
    V_.resize(n, m + 1);
    w_.resize(n);
    z_.resize(n);
    r_.resize(n);
    v_.resize(n);
  }
  H_.setZero(m + 1, m);
  g_.resize(m + 1);
  cs_.resize(m);
  sn_.resize(m);
  y_.resize(m);
  GmresReport rep;
  x.setZero(n);
  const double bnorm = b.norm();
  if (!(bnorm > 0)) {
    rep.converged = true;
    return rep;
  }
  r_ = b;
  double beta = bnorm;
  rep.relative_residual = 1.0;
  rep.restart_residuals.push_back(1.0);
  while (rep.iterations < max_iterations) {
    V_.col(0) = r_ / beta;
    g_.setZero();
    g_(0) = beta;
    int k = 0;
    for (; k < m && rep.iterations < max_iterations; ++k) {
      v_ = V_.col(k);
      precondition(v_, z_);
      A(z_, w_);
      ++rep.iterations;
      for (int i = 0; i <= k; ++i) {  // modified Gram–Schmidt
        H_(i, k) = V_.col(i).dot(w_);
        w_ -= H_(i, k) * V_.col(i);
      }
      H_(k + 1, k) = w_.norm();
      if (H_(k + 1, k) > 0) V_.col(k + 1) = w_ / H_(k + 1, k);
      for (int i = 0; i < k; ++i) {  // previous rotations
        const double t = cs_(i) * H_(i, k) + sn_(i) * H_(i + 1, k);
        H_(i + 1, k) = -sn_(i) * H_(i, k) + cs_(i) * H_(i + 1, k);
        H_(i, k) = t;
      }
      const double rr = std::hypot(H_(k, k), H_(k + 1, k));
      cs_(k) = rr > 0 ? H_(k, k) / rr : 1.0;
      sn_(k) = rr > 0 ? H_(k + 1, k) / rr : 0.0;
      H_(k, k) = rr;
      H_(k + 1, k) = 0.0;
      g_(k + 1) = -sn_(k) * g_(k);
      g_(k) = cs_(k) * g_(k);
      if (std::abs(g_(k + 1)) <= rtol * bnorm || !(rr > 0)) {
        ++k;
        break;
      }
    }
    // x += M⁻¹ V y,  H(0:k, 0:k) y = g(0:k)
    for (int i = k - 1; i >= 0; --i) {
      double s = g_(i);
      for (int j = i + 1; j < k; ++j) s -= H_(i, j) * y_(j);
      y_(i) = H_(i, i) != 0.0 ? s / H_(i, i) : 0.0;
    }
    v_ = V_.leftCols(k) * y_.head(k);
    precondition(v_, z_);
    x += z_;
    A(x, w_);
    r_ = b - w_;
    beta = r_.norm();
    rep.relative_residual = beta / bnorm;
    rep.restart_residuals.push_back(rep.relative_residual);
    if (beta <= rtol * bnorm) {
      rep.converged = true;
      return rep;
    }
    if (!std::isfinite(beta)) return rep;
  }
  return rep;
}

}  // namespace pdcg::solver
