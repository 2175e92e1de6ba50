#include "pdcg/solver/model.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include "pdcg/core/error.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pdcg::solver {

namespace {
int max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}
int thread_id() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}
}  // namespace

Model::Model(const Discretization& body, const Material& material, ModelOptions options)
    : body_(&body), material_(material.clone()), opt_(options), d_(body.dimension()) {
  if (material_->dimension() != d_)
    throw Error("internal error: material dimension does not match the body");
  energy_ = opt_.correspondence == Correspondence::bond_associated ? &body.bond_stencils()
                                                                   : &body.point_stencils();
  const Stencils& S = *energy_;
  const std::size_t N = body.size();
  // Reverse index point -> (stencil, position).
  member_of_.offsets.assign(N + 1, 0);
  for (int m : S.index) ++member_of_.offsets[m + 1];
  for (std::size_t k = 0; k < N; ++k) member_of_.offsets[k + 1] += member_of_.offsets[k];
  member_of_.index.resize(S.index.size());
  member_pos_.resize(S.index.size());
  {
    std::vector<std::int64_t> fill(member_of_.offsets.begin(), member_of_.offsets.end() - 1);
    for (std::size_t s = 0; s < S.size(); ++s)
      for (auto q = S.offsets[s]; q < S.offsets[s + 1]; ++q) {
        const auto slot = fill[S.index[q]]++;
        member_of_.index[slot] = static_cast<int>(s);
        member_pos_[slot] = static_cast<int>(q - S.offsets[s]);
      }
  }
  // Smeared normals b_k and the weak-form defect e_k = b_k − s_k.
  smeared_.assign(N, Vec3::Zero());
  defect_.assign(N, Vec3::Zero());
  weak_row_.assign(N, 0);
  const double area = std::pow(body.spacing(), d_ - 1);
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < N; ++k) {
    Vec3 b = Vec3::Zero();
    for (auto q = member_of_.offsets[k]; q < member_of_.offsets[k + 1]; ++q) {
      const int s = member_of_.index[q];
      const double* g = S.grad.data() + (S.offsets[s] + member_pos_[q]) * d_;
      for (int a = 0; a < d_; ++a) b(a) += S.weight[s] * g[a];
    }
    smeared_[k] = b;
    if (opt_.boundary == BoundaryForm::weak) {
      const Vec3 e = b - body.surface()[k];
      // |e| below round-off of the sums (interior points): no correction row.
      if (e.norm() > 1e-10 * area) {
        defect_[k] = e;
        weak_row_[k] = 1;
      }
    }
  }
  // Matrix pattern: pairs of points sharing an energy stencil, plus weak rows.
  const Stencils& Pst = body.point_stencils();
  std::vector<std::vector<int>> adj(N);
#pragma omp parallel
  {
    // Per-thread marker: each neighbour is collected once, then the short list is sorted.
    std::vector<std::size_t> mark(N, static_cast<std::size_t>(-1));
#pragma omp for schedule(dynamic, 32)
    for (std::size_t k = 0; k < N; ++k) {
      auto& a = adj[k];
      auto add = [&](int n) {
        if (mark[n] != k) {
          mark[n] = k;
          a.push_back(n);
        }
      };
      for (auto q = member_of_.offsets[k]; q < member_of_.offsets[k + 1]; ++q) {
        const int s = member_of_.index[q];
        for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) add(S.index[r]);
      }
      if (weak_row_[k])
        for (auto r = Pst.offsets[k]; r < Pst.offsets[k + 1]; ++r) add(Pst.index[r]);
      std::sort(a.begin(), a.end());
    }
  }
  adjacency_.offsets.assign(N + 1, 0);
  for (std::size_t k = 0; k < N; ++k)
    adjacency_.offsets[k + 1] = adjacency_.offsets[k] + adj[k].size();
  adjacency_.index.reserve(adjacency_.offsets[N]);
  for (auto& a : adj) adjacency_.index.insert(adjacency_.index.end(), a.begin(), a.end());
  adj.clear();
  // The matrix pattern is not stored here: fill_pattern() writes it into the caller's K
  // from the point adjacency (a stored copy cost 12 bytes per nonzero, ≈ 97 kB per point
  // in 3D).
  pattern_nnz_ = static_cast<std::int64_t>(d_) * d_ * adjacency_.offsets[N];
  slot_.assign(static_cast<std::size_t>(max_threads()), std::vector<int>(N, -1));
}

void Model::fill_pattern(SparseRow& K) const {
  // Compressed row storage filled directly (row d·k+a: columns d·n+b, n ∈ adjacency(k)).
  const std::size_t N = body_->size();
  const int n = static_cast<int>(dofs());
  K = SparseRow(n, n);  // releases any previous storage
  K.makeCompressed();
  K.resizeNonZeros(pattern_nnz_);
  int* outer = K.outerIndexPtr();
  int* inner = K.innerIndexPtr();
  std::int64_t pos = 0;
  for (std::size_t k = 0; k < N; ++k)
    for (int a = 0; a < d_; ++a) {
      outer[d_ * k + a] = static_cast<int>(pos);
      for (auto q = adjacency_.begin(k); q < adjacency_.end(k); ++q)
        for (int b = 0; b < d_; ++b) inner[pos++] = d_ * adjacency_.index[q] + b;
    }
  outer[n] = static_cast<int>(pos);
  std::fill(K.valuePtr(), K.valuePtr() + pattern_nnz_, 0.0);
}

Mat3 Model::stencil_gradient(const Stencils& S, std::size_t s, const Eigen::VectorXd& u) const {
  Mat3 F = Mat3::Identity();
  for (auto q = S.offsets[s]; q < S.offsets[s + 1]; ++q) {
    const int m = S.index[q];
    const double* g = S.grad.data() + q * d_;
    for (int a = 0; a < d_; ++a)
      for (int J = 0; J < d_; ++J) F(a, J) += u[d_ * m + a] * g[J];
  }
  return F;
}

bool Model::evaluate_stencils(const Eigen::VectorXd& u, bool tangent) const {
  const Stencils& S = *energy_;
  const std::size_t ns = S.size(), N = body_->size();
  const int d = d_, d2 = d * d, d4 = d2 * d2;
  Ps_.resize(ns);
  if (tangent) Ac_.resize(ns * static_cast<std::size_t>(d4));
  std::atomic<bool> ok{true};
#pragma omp parallel for schedule(static)
  for (std::size_t s = 0; s < ns; ++s) {
    const Mat3 F = stencil_gradient(S, s, u);
    if (!tangent) {
      if (!material_->evaluate(F, nullptr, &Ps_[s], nullptr)) ok = false;
      continue;
    }
    Tangent A;
    if (!material_->evaluate(F, nullptr, &Ps_[s], &A)) ok = false;
    // Compact d²×d² copy (2D: 16 of the 81 entries), contiguous per stencil: the
    // row gather reads it once per member row, so its size is the memory traffic.
    double* c = Ac_.data() + s * static_cast<std::size_t>(d4);
    for (int a = 0; a < d; ++a)
      for (int J = 0; J < d; ++J)
        for (int b = 0; b < d; ++b)
          for (int L = 0; L < d; ++L) c[(a * d + J) * d2 + b * d + L] = A(flat(a, J), flat(b, L));
  }
  if (opt_.boundary == BoundaryForm::weak) {
    Pbar_.resize(N);
    if (tangent) Abar_.resize(N);
    const Stencils& Pst = body_->point_stencils();
#pragma omp parallel for schedule(static)
    for (std::size_t k = 0; k < N; ++k) {
      if (!weak_row_[k]) continue;
      const Mat3 F = stencil_gradient(Pst, k, u);
      if (!material_->evaluate(F, nullptr, &Pbar_[k], tangent ? &Abar_[k] : nullptr)) ok = false;
    }
  }
  return ok;
}

double Model::energy(const Eigen::VectorXd& u) const {
  const Stencils& S = *energy_;
  double e = 0.0;
  bool ok = true;
#pragma omp parallel for schedule(static) reduction(+ : e) reduction(&& : ok)
  for (std::size_t s = 0; s < S.size(); ++s) {
    double psi = 0;
    if (!material_->evaluate(stencil_gradient(S, s, u), &psi, nullptr, nullptr)) ok = false;
    e += S.weight[s] * psi;
  }
  for (std::size_t a = 0; a < anchor_points_.size(); ++a)
    for (int c = 0; c < d_; ++c) {
      const double du = u[d_ * anchor_points_[a] + c] - anchor_u_[d_ * a + c];
      e += 0.5 * anchor_k_ * du * du;
    }
  return ok ? e : std::numeric_limits<double>::quiet_NaN();
}

bool Model::internal_force(const Eigen::VectorXd& u, Eigen::VectorXd& f) const {
  if (!evaluate_stencils(u, false)) return false;
  const Stencils& S = *energy_;
  const std::size_t N = body_->size();
  f.setZero(dofs());
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < N; ++k) {
    for (auto q = member_of_.offsets[k]; q < member_of_.offsets[k + 1]; ++q) {
      const int s = member_of_.index[q];
      const double* g = S.grad.data() + (S.offsets[s] + member_pos_[q]) * d_;
      const Mat3& P = Ps_[s];
      for (int a = 0; a < d_; ++a) {
        double v = 0;
        for (int J = 0; J < d_; ++J) v += P(a, J) * g[J];
        f[d_ * k + a] += S.weight[s] * v;
      }
    }
    if (weak_row_[k])
      for (int a = 0; a < d_; ++a)
        for (int J = 0; J < d_; ++J) f[d_ * k + a] -= Pbar_[k](a, J) * defect_[k](J);
  }
  if (!anchor_points_.empty()) add_anchors(u, f, nullptr);
  return true;
}

void Model::set_anchors(std::vector<int> points, std::vector<double> targets, double stiffness) {
  anchor_points_ = std::move(points);
  anchor_u_ = std::move(targets);
  anchor_k_ = stiffness;
}

void Model::add_anchors(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseRow* K) const {
  for (std::size_t a = 0; a < anchor_points_.size(); ++a) {
    const int k = anchor_points_[a];
    for (int c = 0; c < d_; ++c) {
      f[d_ * k + c] += anchor_k_ * (u[d_ * k + c] - anchor_u_[d_ * a + c]);
      if (K) K->coeffRef(d_ * k + c, d_ * k + c) += anchor_k_;  // diagonal is in the pattern
    }
  }
}

template <int D>
void Model::assemble_rows(Eigen::VectorXd& f, SparseRow& K) const {
  constexpr int D2 = D * D, D4 = D2 * D2;
  const Stencils& S = *energy_;
  const Stencils& Pst = body_->point_stencils();
  const std::size_t N = body_->size();
  double* vals = K.valuePtr();
  const int* outer = K.outerIndexPtr();
  const double* grad = S.grad.data();
  const int* sidx = S.index.data();
  // Row gather: row k of K is Σ_{S∋k} w_S Σ_{n∈S} (G_S^k)ᵀ A_S G_S^n, each stencil read
  // once per member row; no atomics, deterministic. The per-thread slot array
  // (slot[n] = position of n in row k's adjacency) is allocated at construction.
#pragma omp parallel
  {
    int* slot = slot_[static_cast<std::size_t>(thread_id())].data();
#pragma omp for schedule(dynamic, 16)
    for (std::size_t k = 0; k < N; ++k) {
      const int* adj_b = adjacency_.index.data() + adjacency_.begin(k);
      const int* adj_e = adjacency_.index.data() + adjacency_.end(k);
      for (const int* p = adj_b; p != adj_e; ++p) slot[*p] = static_cast<int>(p - adj_b);
      const std::int64_t row_len = D * (adj_e - adj_b);
      double* rows[D];
      for (int a = 0; a < D; ++a) {
        rows[a] = vals + outer[D * k + a];
        std::fill(rows[a], rows[a] + row_len, 0.0);
      }
      double fk[D] = {};
      double B[D][D2];  // B[a][b*D+L] = w Σ_J A_aJbL G^k_J
      for (auto q = member_of_.offsets[k]; q < member_of_.offsets[k + 1]; ++q) {
        const int s = member_of_.index[q];
        const double w = S.weight[s];
        const double* gk = grad + (S.offsets[s] + member_pos_[q]) * D;
        const Mat3& P = Ps_[s];
        const double* A = Ac_.data() + static_cast<std::size_t>(s) * D4;
        for (int a = 0; a < D; ++a) {
          double v = 0;
          for (int J = 0; J < D; ++J) v += P(a, J) * gk[J];
          fk[a] += w * v;
          for (int bL = 0; bL < D2; ++bL) {
            double t = 0;
            for (int J = 0; J < D; ++J) t += A[(a * D + J) * D2 + bL] * gk[J];
            B[a][bL] = w * t;
          }
        }
        const auto r0 = S.offsets[s], r1 = S.offsets[s + 1];
        for (auto r = r0; r < r1; ++r) {
          const double* gn = grad + r * D;
          const std::int64_t c0 = static_cast<std::int64_t>(D) * slot[sidx[r]];
          for (int a = 0; a < D; ++a)
            for (int b = 0; b < D; ++b) {
              double t = 0;
              for (int L = 0; L < D; ++L) t += B[a][b * D + L] * gn[L];
              rows[a][c0 + b] += t;
            }
        }
      }
      for (int a = 0; a < D; ++a) f[D * k + a] = fk[a];
      if (weak_row_[k]) {
        const Vec3& e = defect_[k];
        const Tangent& A = Abar_[k];
        for (int a = 0; a < D; ++a) {
          for (int J = 0; J < D; ++J) f[D * k + a] -= Pbar_[k](a, J) * e(J);
          for (int b = 0; b < D; ++b)
            for (int L = 0; L < D; ++L) {
              double t = 0;
              for (int J = 0; J < D; ++J) t += A(flat(a, J), flat(b, L)) * e(J);
              B[a][b * D + L] = t;
            }
        }
        for (auto r = Pst.offsets[k]; r < Pst.offsets[k + 1]; ++r) {
          const int n = Pst.index[r];
          const double* gn = Pst.grad.data() + r * D;
          const std::int64_t c0 = static_cast<std::int64_t>(D) * slot[n];
          for (int a = 0; a < D; ++a)
            for (int b = 0; b < D; ++b) {
              double t = 0;
              for (int L = 0; L < D; ++L) t += B[a][b * D + L] * gn[L];
              rows[a][c0 + b] -= t;
            }
        }
      }
    }
  }  // omp parallel
}

bool Model::internal_force_and_tangent(const Eigen::VectorXd& u, Eigen::VectorXd& f,
                                       SparseRow& K) const {
  if (!evaluate_stencils(u, true)) return false;
  if (K.rows() != static_cast<Eigen::Index>(dofs()) || K.nonZeros() != pattern_nnz_)
    fill_pattern(K);
  if (f.size() != static_cast<Eigen::Index>(dofs())) f.resize(dofs());
  // More threads than at construction (omp_set_num_threads raised): one slot array each.
  if (slot_.size() < static_cast<std::size_t>(max_threads()))
    slot_.resize(static_cast<std::size_t>(max_threads()), std::vector<int>(body_->size(), -1));
  if (d_ == 2)
    assemble_rows<2>(f, K);
  else
    assemble_rows<3>(f, K);
  if (!anchor_points_.empty()) add_anchors(u, f, &K);
  return true;
}

std::vector<Mat3> Model::point_deformation_gradients(const Eigen::VectorXd& u) const {
  const Stencils& S = *energy_;
  const std::size_t N = body_->size();
  std::vector<Mat3> F(N, Mat3::Zero());
  std::vector<double> wsum(N, 0.0);
  // Stencils of one centre are contiguous (bond stencils in CSR order of families).
  for (std::size_t s = 0; s < S.size(); ++s) {
    const int c = S.center[s];
    F[c] += S.weight[s] * stencil_gradient(S, s, u);
    wsum[c] += S.weight[s];
  }
  for (std::size_t k = 0; k < N; ++k) {
    F[k] /= wsum[k];
    if (d_ == 2) F[k](2, 2) = 1.0;
  }
  return F;
}

std::vector<Mat3> Model::point_family_gradients(const Eigen::VectorXd& u) const {
  const std::size_t N = body_->size();
  std::vector<Mat3> F(N);
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < N; ++k) F[k] = stencil_gradient(body_->point_stencils(), k, u);
  return F;
}

}  // namespace pdcg::solver
