// Matrix-free tangent of the correspondence model (model.hpp: internal_force_and_operator,
// apply_tangent; docs/solver.md §4 "Matrix-free GMRES").
//
// The tangent K = ∂f/∂u is never assembled. Per Newton iteration one sweep over the energy
// stencils evaluates f and stores w_S A(F_S) packed by major symmetry; each product K v is
// then one fused sweep over the stencils, the same data stream as the residual
// (Model::residual_kernel): members and G_S^m read once, δF_S gathered, δP_S = w_S A_S : δF_S,
// out_m += δP_S G_S^m scattered into a private force array per thread (static schedule,
// contiguous stencil ranges, summed in a fixed order: deterministic for a thread count).
// Flops per stencil member: 4d² (gather + scatter), per stencil d⁴ (the packed product);
// bytes per member: 4 + 8d (index, G), per stencil 8·d²(d²+1)/2 (the packed tangent).
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "packed_tangent.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/solver/model.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pdcg::solver {

namespace {
int mv_max_threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}
int mv_thread_id() {
#ifdef _OPENMP
  return omp_get_thread_num();
#else
  return 0;
#endif
}
int mv_team_size() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

using detail::gather;
using detail::scatter;

// The product sweep over stencils [s0, s1) (Ap: packed w_S A_S, upper triangle row-major).
template <int D>
[[gnu::always_inline]] inline void product_range(const Stencils& S, std::size_t s0, std::size_t s1,
                                                 const double* Ap, const double* v, double* out) {
  constexpr int D2 = D * D, NP = detail::packed_size(D);
  const int* idx = S.index.data();
  const double* grad = S.grad.data();
  const std::int64_t* off = S.offsets.data();
  for (std::size_t s = s0; s < s1; ++s) {
    double dF[D2];
    gather<D>(idx, grad, off[s], off[s + 1], v, dF);
    const double* A = Ap + s * NP;
    double dP[D2] = {};
    int p = 0;
    for (int i = 0; i < D2; ++i) {
      dP[i] += A[p++] * dF[i];
      for (int j = i + 1; j < D2; ++j, ++p) {
        dP[i] += A[p] * dF[j];
        dP[j] += A[p] * dF[i];
      }
    }
    scatter<D>(idx, grad, off[s], off[s + 1], dP, out);
  }
}
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define PDCG_MV_CLONES __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define PDCG_MV_CLONES
#endif
PDCG_MV_CLONES void product_range_2d(const Stencils& S, std::size_t s0, std::size_t s1,
                                     const double* Ap, const double* v, double* out) {
  product_range<2>(S, s0, s1, Ap, v, out);
}
PDCG_MV_CLONES void product_range_3d(const Stencils& S, std::size_t s0, std::size_t s1,
                                     const double* Ap, const double* v, double* out) {
  product_range<3>(S, s0, s1, Ap, v, out);
}

// Products run on one thread below this many stencil members: a product has one parallel
// region, and on a loaded machine a barrier can cost a time slice (docs/performance.md).
constexpr std::size_t kThreadedMembers = 1'000'000;
}  // namespace

template <int D>
bool Model::operator_sweep(const Eigen::VectorXd& u, Eigen::VectorXd& f, double& asym) const {
  constexpr int D2 = D * D, NP = detail::packed_size(D);
  const Stencils& S = *energy_;
  const std::size_t ns = S.size(), ndof = dofs();
  Apk_.resize(ns * NP);
  const auto nextra = static_cast<std::size_t>(std::max(0, mv_max_threads() - 1));
  if (mvbuf_.size() < nextra) mvbuf_.resize(nextra);
  for (std::size_t t = 0; t < nextra; ++t)
    if (mvbuf_[t].size() != ndof) mvbuf_[t].assign(ndof, 0.0);
  const double* ud = u.data();
  double* fd = f.data();
  const int* idx = S.index.data();
  const double* grad = S.grad.data();
  const std::int64_t* off = S.offsets.data();
  bool ok = true;
  asym = 0.0;  // max |A_ij − A_ji| / max |A| over the stencils
  double amax_asym = 0.0;
#pragma omp parallel reduction(&& : ok) reduction(max : amax_asym)
  {
    const int t = mv_thread_id(), nt = mv_team_size();
    double* ft = t == 0 ? fd : mvbuf_[static_cast<std::size_t>(t - 1)].data();
    if (t > 0) std::fill(ft, ft + ndof, 0.0);
    const std::size_t s0 = ns * t / nt, s1 = ns * (t + 1) / nt;
    Tangent A;
    Mat3 P;
    for (std::size_t s = s0; s < s1; ++s) {
      double G[D2];
      gather<D>(idx, grad, off[s], off[s + 1], ud, G);
      Mat3 F = Mat3::Identity();
      for (int a = 0; a < D; ++a)
        for (int J = 0; J < D; ++J) F(a, J) += G[a * D + J];
      double* Ac = Apk_.data() + s * NP;
      if (!material_->evaluate_at(S.center[s], F, nullptr, &P, &A)) {
        ok = false;
        std::fill(Ac, Ac + NP, 0.0);
        continue;
      }
      const double w = S.weight[s];
      double wP[D2];
      for (int a = 0; a < D; ++a)
        for (int J = 0; J < D; ++J) wP[a * D + J] = w * P(a, J);
      scatter<D>(idx, grad, off[s], off[s + 1], wP, ft);
      amax_asym = std::max(amax_asym, detail::pack_tangent(D, A, w, Ac));
    }
#pragma omp barrier
    if (nt > 1) {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < ndof; ++i) {
        double v = fd[i];
        for (int q = 1; q < nt; ++q) v += mvbuf_[static_cast<std::size_t>(q - 1)][i];
        fd[i] = v;
      }
    }
  }
  asym = amax_asym;
  return ok;
}

bool Model::energy_force_and_tangents(const Eigen::VectorXd& u, Eigen::VectorXd& f) const {
  double asym = 0.0;
  const bool ok = d_ == 2 ? operator_sweep<2>(u, f, asym) : operator_sweep<3>(u, f, asym);
  if (asym > detail::kMaxAsymmetry)
    throw NumericalError(
        "tangent: the material tangent lacks major symmetry (max |A_aJbL − A_bLaJ| / max |A| = " +
        fmt::format("{:.3e}", asym) +
        "); the solver stores the stencil tangents packed by this symmetry (assembled and "
        "matrix-free alike) and needs a hyperelastic material (a stress derived from an "
        "energy)");
  return ok;
}

bool Model::internal_force_and_operator(const Eigen::VectorXd& u, Eigen::VectorXd& f) const {
  if (f.size() != static_cast<Eigen::Index>(dofs())) f.resize(dofs());
  f.setZero();
  if (!energy_force_and_tangents(u, f) || !evaluate_weak_rows(u, true)) return false;
  // Weak rows: f_k −= Σ_l P(F̄_l) c_kl (the bond-flux correction, model.cpp); the products
  // use Ā_l = A(F̄_l), kept by evaluate_weak_rows, and a scratch δP_l per weak point.
  const std::size_t nw = weak_points_.size();
  dPw_.resize(nw * static_cast<std::size_t>(d_ * d_));
#pragma omp parallel for schedule(static)
  for (std::size_t w = 0; w < nw; ++w) subtract_correction(w, f);
  if (!anchor_points_.empty()) add_anchors(u, f, nullptr);
  return true;
}

template <int D>
void Model::product_sweep(const Eigen::VectorXd& v, Eigen::VectorXd& out) const {
  constexpr int D2 = D * D;
  const Stencils& S = *energy_;
  const Stencils& Pst = body_->point_stencils();
  const std::size_t ns = S.size(), ndof = dofs(), nw = weak_points_.size();
  const bool threaded = S.index.size() > kThreadedMembers;
  const auto nextra = static_cast<std::size_t>(std::max(0, mv_max_threads() - 1));
  if (threaded) {
    if (mvbuf_.size() < nextra) mvbuf_.resize(nextra);
    for (std::size_t t = 0; t < nextra; ++t)
      if (mvbuf_[t].size() != ndof) mvbuf_[t].assign(ndof, 0.0);
  }
  const double* vd = v.data();
  double* od = out.data();
  const double* Ap = Apk_.data();
#pragma omp parallel if (threaded)
  {
    const int t = mv_thread_id(), nt = mv_team_size();
    double* ot = t == 0 ? od : mvbuf_[static_cast<std::size_t>(t - 1)].data();
    std::fill(ot, ot + ndof, 0.0);
    const std::size_t s0 = ns * t / nt, s1 = ns * (t + 1) / nt;
    if (D == 2)
      product_range_2d(S, s0, s1, Ap, vd, ot);
    else
      product_range_3d(S, s0, s1, Ap, vd, ot);
#pragma omp barrier
    if (nt > 1) {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < ndof; ++i) {
        double x = od[i];
        for (int q = 1; q < nt; ++q) x += mvbuf_[static_cast<std::size_t>(q - 1)][i];
        od[i] = x;
      }
    }
    // Weak rows: δP_l = Ā_l : δF̄_l, δF̄_l = Σ_{m∈H̄_l} v_m ⊗ Ḡ_l^m, per weak point, then
    // out_k −= Σ_l δP_l c_kl (each row written by one thread; after the barriers).
    double* dP = dPw_.data();
#pragma omp for schedule(static)
    for (std::size_t w = 0; w < nw; ++w) {
      const int k = weak_points_[w];
      double dF[D2];
      gather<D>(Pst.index.data(), Pst.grad.data(), Pst.offsets[k], Pst.offsets[k + 1], vd, dF);
      const Tangent& A = Abar_[w];
      for (int a = 0; a < D; ++a)
        for (int J = 0; J < D; ++J) {
          double x = 0.0;
          for (int b = 0; b < D; ++b)
            for (int L = 0; L < D; ++L) x += A(flat(a, J), flat(b, L)) * dF[b * D + L];
          dP[w * D2 + a * D + J] = x;
        }
    }
#pragma omp for schedule(static)
    for (std::size_t w = 0; w < nw; ++w) {
      const int k = weak_points_[w];
      for (auto c = corr_.begin(w); c < corr_.end(w); ++c) {
        const double* p = dP + static_cast<std::size_t>(corr_.index[c]) * D2;
        const Vec3& h = corr_coef_[c];
        for (int a = 0; a < D; ++a) {
          double x = 0.0;
          for (int J = 0; J < D; ++J) x += p[a * D + J] * h(J);
          od[static_cast<std::size_t>(D) * k + a] -= x;
        }
      }
    }
  }
  for (std::size_t a = 0; a < anchor_points_.size(); ++a)
    for (int c = 0; c < D; ++c) {
      const auto i = static_cast<std::size_t>(D) * anchor_points_[a] + c;
      if (!std::isnan(anchor_u_[static_cast<std::size_t>(D) * a + c])) od[i] += anchor_k_ * vd[i];
    }
}

void Model::apply_tangent(const Eigen::VectorXd& v, Eigen::VectorXd& out) const {
  if (out.size() != static_cast<Eigen::Index>(dofs())) out.resize(dofs());
  if (d_ == 2)
    product_sweep<2>(v, out);
  else
    product_sweep<3>(v, out);
}

std::size_t Model::operator_bytes() const {
  std::size_t b =
      (Apk_.capacity() + dPw_.capacity()) * sizeof(double) + Abar_.capacity() * sizeof(Tangent);
  for (const auto& x : mvbuf_) b += x.capacity() * sizeof(double);
  return b;
}

}  // namespace pdcg::solver
