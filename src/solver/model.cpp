#include "pdcg/solver/model.hpp"

#include <fmt/format.h>

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>

#include "packed_tangent.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "residual_avx2.hpp"

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
int team_size() {
#ifdef _OPENMP
  return omp_get_num_threads();
#else
  return 1;
#endif
}

// F_S − I = Σ_{m∈S} u_m ⊗ G_S^m for stencil s, dimension D known at compile time (the
// d×d accumulator stays in registers; members are contiguous: index[r], grad[D r …]).
template <int D>
inline void gradient_sum(const Stencils& S, std::size_t s, const double* u, double (&F)[D][D]) {
  for (int a = 0; a < D; ++a)
    for (int J = 0; J < D; ++J) F[a][J] = 0.0;
  const int* idx = S.index.data();
  const double* grad = S.grad.data();
  for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) {
    const double* um = u + static_cast<std::int64_t>(D) * idx[r];
    const double* g = grad + r * D;
    for (int a = 0; a < D; ++a)
      for (int J = 0; J < D; ++J) F[a][J] += um[a] * g[J];
  }
}
template <int D>
inline Mat3 gradient_of(const Stencils& S, std::size_t s, const double* u) {
  double F[D][D];
  gradient_sum<D>(S, s, u, F);
  Mat3 out = Mat3::Identity();
  for (int a = 0; a < D; ++a)
    for (int J = 0; J < D; ++J) out(a, J) += F[a][J];
  return out;
}

// The fused residual sweep over stencils [s0, s1): gather F_S, P(F_S), scatter
// f_m += w_S P_S G_S^m into f (a thread's private array). Compiled twice (target_clones):
// for the baseline x86-64 and for x86-64-v3 (AVX2 + FMA), picked at load time by the CPU;
// the FMA version rounds differently (contractions), within round-off of the other.
template <int D>
[[gnu::always_inline]] inline bool stencil_sweep(const Stencils& S, std::size_t s0, std::size_t s1,
                                                 const double* u, double* f,
                                                 const Material& material) {
  const int* idx = S.index.data();
  const double* grad = S.grad.data();
  const std::int64_t* off = S.offsets.data();
  const double* weight = S.weight.data();
  const int* center = S.center.data();
  bool ok = true;
  for (std::size_t s = s0; s < s1; ++s) {
    double G[D][D];
    gradient_sum<D>(S, s, u, G);
    Mat3 F = Mat3::Identity(), P;
    for (int a = 0; a < D; ++a)
      for (int J = 0; J < D; ++J) F(a, J) += G[a][J];
    // The stencil's material is its centre's (per-point materials, Material::evaluate_at).
    if (!material.evaluate_at(center[s], F, nullptr, &P, nullptr)) {
      ok = false;
      continue;
    }
    double wP[D][D];
    for (int a = 0; a < D; ++a)
      for (int J = 0; J < D; ++J) wP[a][J] = weight[s] * P(a, J);
    for (auto r = off[s]; r < off[s + 1]; ++r) {
      double* fm = f + static_cast<std::int64_t>(D) * idx[r];
      const double* g = grad + r * D;
      for (int a = 0; a < D; ++a) {
        double v = 0.0;
        for (int J = 0; J < D; ++J) v += wP[a][J] * g[J];
        fm[a] += v;
      }
    }
  }
  return ok;
}
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define PDCG_SWEEP_CLONES __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define PDCG_SWEEP_CLONES
#endif
/// stencil_sweep of dimension d (2 or 3), each instance inlined into each clone.
PDCG_SWEEP_CLONES bool stencil_sweep_portable(int d, const Stencils& S, std::size_t s0,
                                              std::size_t s1, const double* u, double* f,
                                              const Material& m) {
  return d == 2 ? stencil_sweep<2>(S, s0, s1, u, f, m) : stencil_sweep<3>(S, s0, s1, u, f, m);
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
  // Smeared normals b_k = Σ_{S∋k} w_S G_S^k (one pass over the stencils in order: the same
  // summation order per point as a gather over the reverse index) and the weak-form
  // defect e_k = b_k − s_k.
  smeared_.assign(N, Vec3::Zero());
  defect_.assign(N, Vec3::Zero());
  for (std::size_t s = 0; s < S.size(); ++s)
    for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) {
      const double* g = S.grad.data() + r * d_;
      Vec3& b = smeared_[S.index[r]];
      for (int a = 0; a < d_; ++a) b(a) += S.weight[s] * g[a];
    }
  std::vector<char> weak(N, 0);
  const double area = std::pow(body.spacing(), d_ - 1);
  if (opt_.boundary == BoundaryForm::weak)
    for (std::size_t k = 0; k < N; ++k) {
      const Vec3 e = smeared_[k] - body.surface()[k];
      // |e| below round-off of the sums (interior points): no correction row.
      if (e.norm() > 1e-10 * area) {
        defect_[k] = e;
        weak[k] = 1;
      }
    }
  weak_id_.assign(N, -1);
  for (std::size_t k = 0; k < N; ++k)
    if (weak[k]) {
      weak_id_[k] = static_cast<int>(weak_points_.size());
      weak_points_.push_back(static_cast<int>(k));
    }
  weak_points_.shrink_to_fit();
  build_defect_flux();
}

// The boundary correction as a bond flux (docs/solver.md §3, "Force balance"): an
// antisymmetric h_kl on the short bonds between weak points, |ξ| ≤ min(δ, 1.75Δx), with
// Σ_l h_kl = e_k: the minimum-norm one, h_kl = φ_k − φ_l with the graph Laplacian
// L φ = e solved per connected component (one point grounded, φ = 0, in each). The
// correction of row k is then −Σ_l ½(P(F̄_k) + P(F̄_l)) h_kl, stored as the coefficients
// c_kk = ½ Σ_l h_kl, c_kl = ½ h_kl of the stresses P(F̄_k), P(F̄_l).
void Model::build_defect_flux() {
  const std::size_t nw = weak_points_.size();
  corr_.offsets.assign(nw + 1, 0);
  corr_.index.clear();
  corr_coef_.clear();
  corr_base_.clear();
  if (nw == 0) return;
  const Discretization& body = *body_;
  const auto& fam = body.families();
  const auto& x = body.positions();
  const double rf = std::min(body.horizon(), 1.75 * body.spacing()) * (1 + 1e-9);
  std::vector<std::vector<int>> nb(nw);
  for (std::size_t w = 0; w < nw; ++w) {
    const int k = weak_points_[w];
    for (auto q = fam.begin(k); q < fam.end(k); ++q) {
      const int l = fam.index[q];
      if (weak_id_[l] >= 0 && (x[l] - x[k]).norm() <= rf) nb[w].push_back(weak_id_[l]);
    }
  }
  for (std::size_t w = 0; w < nw; ++w)  // symmetric graph (families are; kept safe)
    for (int v : nb[w])
      if (std::find(nb[v].begin(), nb[v].end(), static_cast<int>(w)) == nb[v].end())
        nb[v].push_back(static_cast<int>(w));
  for (auto& a : nb) {
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
  }
  // Connected components; the first point of each is grounded.
  std::vector<int> comp(nw, -1), reduced(nw, -1), stack;
  std::vector<Vec3> comp_sum;
  std::vector<double> comp_abs;
  int nr = 0;
  for (std::size_t w0 = 0; w0 < nw; ++w0) {
    if (comp[w0] >= 0) continue;
    const int c = static_cast<int>(comp_sum.size());
    comp_sum.push_back(Vec3::Zero());
    comp_abs.push_back(0.0);
    comp[w0] = c;
    stack.assign(1, static_cast<int>(w0));
    while (!stack.empty()) {
      const int w = stack.back();
      stack.pop_back();
      comp_sum[c] += defect_[weak_points_[w]];
      comp_abs[c] += defect_[weak_points_[w]].norm();
      if (w != static_cast<int>(w0)) reduced[w] = nr++;
      for (int v : nb[w])
        if (comp[v] < 0) {
          comp[v] = c;
          stack.push_back(v);
        }
    }
  }
  for (std::size_t c = 0; c < comp_sum.size(); ++c)
    if (comp_sum[c].norm() > 1e-9 * comp_abs[c])
      log::warn(
          "weak form: the boundary defect of a surface layer does not sum to zero ({:.3e} of "
          "Σ|e| = {:.3e}); the homogeneous patch test is not exact there",
          comp_sum[c].norm() / comp_abs[c], comp_abs[c]);
  std::vector<Eigen::Triplet<double>> trip;
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(nr, d_);
  for (std::size_t w = 0; w < nw; ++w) {
    const int r = reduced[w];
    if (r < 0) continue;
    trip.emplace_back(r, r, static_cast<double>(nb[w].size()));
    for (int v : nb[w])
      if (reduced[v] >= 0) trip.emplace_back(r, reduced[v], -1.0);
    for (int a = 0; a < d_; ++a) rhs(r, a) = defect_[weak_points_[w]](a);
  }
  Eigen::MatrixXd phi = Eigen::MatrixXd::Zero(nr, d_);
  if (nr > 0) {
    Eigen::SparseMatrix<double> L(nr, nr);
    L.setFromTriplets(trip.begin(), trip.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(L);
    if (ldlt.info() != Eigen::Success)
      throw NumericalError("weak form: the graph Laplacian of the boundary layer is singular");
    phi = ldlt.solve(rhs);
  }
  auto phi_of = [&](int w) {
    Vec3 p = Vec3::Zero();
    if (reduced[w] >= 0)
      for (int a = 0; a < d_; ++a) p(a) = phi(reduced[w], a);
    return p;
  };
  corr_.index.reserve(nw);
  for (std::size_t w = 0; w < nw; ++w) {
    const Vec3 pw = phi_of(static_cast<int>(w));
    Vec3 self = Vec3::Zero();
    const std::size_t at = corr_coef_.size();
    corr_.index.push_back(static_cast<int>(w));
    corr_coef_.push_back(Vec3::Zero());
    for (int v : nb[w]) {
      const Vec3 h = pw - phi_of(v);
      self += 0.5 * h;
      corr_.index.push_back(v);
      corr_coef_.push_back(0.5 * h);
    }
    corr_coef_[at] = self;
    corr_.offsets[w + 1] = static_cast<std::int64_t>(corr_.index.size());
  }
  corr_base_ = corr_coef_;
}

// Pieces (docs/solver.md §3, "Pieces"): a weak-form pair term −½(P(F̄_k) + P(F̄_l)) h_kl
// between two points that no chain of live stencils connects any more would still act across
// the cut: it pulls one piece with the other's stress. Where a side is anchored (rupture parks
// a point no stencil couples on a spring, and pins a piece held in some directions only), its
// springs — no reaction of any set — hold that pull and Σ reactions + Σ tractions ≠ 0; where
// both sides are held by grips, each grip carries a share of the other piece's load. So the
// pairs between different pieces are dropped, whatever holds them (from both rows: each row
// pair stays antisymmetric, Σ_k f_k = 0 is kept). Pieces: union–find over the members with
// nonzero G of every energy stencil of nonzero weight (the coupling Rupture::update_anchors
// uses). The pattern stays (zero coefficients), so the tangent, the matrix-free product and
// the row sums, which read these coefficients, follow.
void Model::cut_flux_between_pieces() {
  if (corr_base_.empty()) return;
  corr_coef_ = corr_base_;
  const std::size_t N = body_->size();
  std::vector<int> parent(N);
  for (std::size_t k = 0; k < N; ++k) parent[k] = static_cast<int>(k);
  auto find = [&](int k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];
    return k;
  };
  // every stencil of the body, not only the evaluated ones (restrict_evaluation): the pieces
  // are a property of the whole body, and every process must find the same ones
  const Stencils& S = opt_.correspondence == Correspondence::bond_associated
                          ? body_->bond_stencils()
                          : body_->point_stencils();
  for (std::size_t s = 0; s < S.size(); ++s) {
    if (!(S.weight[s] > 0)) continue;
    int first = -1;
    for (auto q = S.offsets[s]; q < S.offsets[s + 1]; ++q) {
      bool live = false;
      for (int a = 0; a < d_; ++a) live = live || S.grad[static_cast<std::size_t>(q) * d_ + a] != 0;
      if (!live) continue;
      const int r = find(S.index[q]);
      if (first < 0)
        first = r;
      else if (r != first)
        parent[r] = first;
    }
  }
  for (std::size_t w = 0; w < weak_points_.size(); ++w) {
    const int pk = find(weak_points_[w]);
    const auto b = corr_.begin(w);  // the row's own entry, then its flux neighbours
    for (auto c = b + 1; c < corr_.end(w); ++c) {
      const int pl = find(weak_points_[corr_.index[c]]);
      if (pk != pl) {
        corr_coef_[b] -= corr_coef_[c];
        corr_coef_[c] = Vec3::Zero();
      }
    }
  }
}

void Model::build_index() const {
  if (indexed_) return;
  const Stencils& S = *energy_;
  const std::size_t N = body_->size();
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
  // Matrix pattern: pairs of points sharing an energy stencil, plus weak rows.
  const Stencils& Pst = body_->point_stencils();
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
      if (const int w = weak_id_[k]; w >= 0 && (weak_row_owned_.empty() || weak_row_owned_[w]))
        for (auto c = corr_.begin(w); c < corr_.end(w); ++c) {
          const int l = weak_points_[corr_.index[c]];
          for (auto r = Pst.offsets[l]; r < Pst.offsets[l + 1]; ++r) add(Pst.index[r]);
        }
      std::sort(a.begin(), a.end());
    }
  }
  adjacency_.offsets.assign(N + 1, 0);
  for (std::size_t k = 0; k < N; ++k)
    adjacency_.offsets[k + 1] = adjacency_.offsets[k] + adj[k].size();
  adjacency_.index.reserve(adjacency_.offsets[N]);
  for (auto& a : adj) adjacency_.index.insert(adjacency_.index.end(), a.begin(), a.end());
  adj.clear();
  adjacency_.index.shrink_to_fit();
  // The matrix pattern is not stored here: fill_pattern() writes it into the caller's K
  // from the point adjacency (a stored copy cost 12 bytes per nonzero, ≈ 97 kB per point
  // in 3D).
  pattern_nnz_ = static_cast<std::int64_t>(d_) * d_ * adjacency_.offsets[N];
  slot_.assign(static_cast<std::size_t>(max_threads()), std::vector<int>(N, -1));
  indexed_ = true;
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
  return d_ == 2 ? gradient_of<2>(S, s, u.data()) : gradient_of<3>(S, s, u.data());
}

bool Model::evaluate_weak_rows(const Eigen::VectorXd& u, bool tangent) const {
  const std::size_t nw = weak_points_.size();
  Pbar_.resize(nw);
  if (tangent) Abar_.resize(nw);
  const Stencils& Pst = body_->point_stencils();
  bool ok = true;
  // restrict_evaluation: only the stresses the evaluated weak rows read
  const char* need = weak_needed_.empty() ? nullptr : weak_needed_.data();
#pragma omp parallel for schedule(static) reduction(&& : ok)
  for (std::size_t w = 0; w < nw; ++w) {
    if (need && !need[w]) continue;
    const int k = weak_points_[w];
    const Mat3 F = stencil_gradient(Pst, static_cast<std::size_t>(k), u);
    if (!material_->evaluate_at(k, F, nullptr, &Pbar_[w], tangent ? &Abar_[w] : nullptr))
      ok = false;
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
    if (!material_->evaluate_at(S.center[s], stencil_gradient(S, s, u), &psi, nullptr, nullptr))
      ok = false;
    e += S.weight[s] * psi;
  }
  for (std::size_t a = 0; a < anchor_points_.size(); ++a)
    for (int c = 0; c < d_; ++c) {
      const double du = u[d_ * anchor_points_[a] + c] - anchor_u_[d_ * a + c];
      if (!std::isnan(du)) e += 0.5 * anchor_k_ * du * du;  // NaN target: no spring
    }
  return ok ? e : std::numeric_limits<double>::quiet_NaN();
}

// Residual, fused per stencil (docs/performance.md "BA kernels"): one pass
// over the BA stencils reads each stencil's members and G once, gathers F_S, evaluates
// P(F_S) and scatters f_m += w_S P_S G_S^m while the stencil is in L1. Threads own
// contiguous stencil ranges (static schedule) and accumulate into private force arrays
// (thread 0 into f), summed in a fixed order afterwards: no atomics, no false sharing,
// deterministic for a given thread count. The stencil data stream from memory exactly once
// (4 + 8d bytes per term), the minimum; no per-stencil stress is stored.
// 3D with the AVX2 sweep: every thread (thread 0 too) scatters into its own force array padded
// to 4 doubles per point and aligned to 32 bytes (one 32-byte add per member instead of a
// 16 + 8-byte pair); 32 B per point and thread, summed into f in a fixed order.
template <int D>
bool Model::residual_kernel(const Eigen::VectorXd& u, Eigen::VectorXd& f) const {
  const Stencils& S = *energy_;
  const std::size_t ns = S.size(), ndof = dofs(), N = body_->size();
#ifdef PDCG_SOLVER_AVX2
  const bool simd = detail::cpu_has_avx2_fma();
#else
  const bool simd = false;
#endif
  const bool pad = D == 3 && simd;
  const auto mt = static_cast<std::size_t>(std::max(1, max_threads()));
  const std::size_t nbuf = pad ? mt : mt - 1, len = pad ? 4 * N + 4 : ndof;
  if (fbuf_.size() < nbuf) fbuf_.resize(nbuf);
  for (std::size_t t = 0; t < nbuf; ++t)
    if (fbuf_[t].size() != len) fbuf_[t].assign(len, 0.0);
  auto padded = [this](std::size_t q) {  // 32-byte aligned start of thread q's padded array
    double* p = fbuf_[q].data();
    return p + (32 - reinterpret_cast<std::uintptr_t>(p) % 32) % 32 / sizeof(double);
  };
  const double* ud = u.data();
  double* fd = f.data();
  bool ok = true;
#pragma omp parallel reduction(&& : ok)
  {
    const int t = thread_id(), nt = team_size();
    const auto tq = static_cast<std::size_t>(t);
    double* ft = pad ? padded(tq) : t == 0 ? fd : fbuf_[tq - 1].data();
    if (pad)
      std::fill(ft, ft + 4 * N, 0.0);
    else if (t > 0)
      std::fill(ft, ft + ndof, 0.0);
    // Contiguous stencil range per thread (a static schedule).
    const std::size_t s0 = ns * t / nt, s1 = ns * (t + 1) / nt;
#ifdef PDCG_SOLVER_AVX2
    // AVX2 + FMA sweep (residual_avx2.cpp) when the CPU has it, else the portable one.
    if (simd) {
      if (!detail::stencil_sweep_avx2(D, S, s0, s1, ud, ft, *material_)) ok = false;
    } else
#endif
        if (!stencil_sweep_portable(D, S, s0, s1, ud, ft, *material_))
      ok = false;
#pragma omp barrier
    if (pad) {
#pragma omp for schedule(static)
      for (std::size_t k = 0; k < N; ++k)
        for (int a = 0; a < 3; ++a) {
          double v = fd[3 * k + a];
          for (int q = 0; q < nt; ++q) v += padded(static_cast<std::size_t>(q))[4 * k + a];
          fd[3 * k + a] = v;
        }
    } else if (nt > 1) {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < ndof; ++i) {
        double v = fd[i];
        for (int q = 1; q < nt; ++q) v += fbuf_[static_cast<std::size_t>(q - 1)][i];
        fd[i] = v;
      }
    }
  }
  return ok;
}

bool Model::internal_force(const Eigen::VectorXd& u, Eigen::VectorXd& f) const {
  f.setZero(dofs());
  const bool ok = d_ == 2 ? residual_kernel<2>(u, f) : residual_kernel<3>(u, f);
  if (!ok || !evaluate_weak_rows(u, false)) return false;
  const std::size_t nw = weak_points_.size();
  const char* own = weak_row_owned_.empty() ? nullptr : weak_row_owned_.data();
#pragma omp parallel for schedule(static)
  for (std::size_t w = 0; w < nw; ++w)
    if (!own || own[w]) subtract_correction(w, f);
  if (!anchor_points_.empty()) add_anchors(u, f, nullptr);
  return true;
}

void Model::restrict_evaluation(const std::vector<char>& owned) {
  const Stencils& all = opt_.correspondence == Correspondence::bond_associated
                            ? body_->bond_stencils()
                            : body_->point_stencils();
  if (owned.empty()) {
    energy_ = &all;
    owned_stencils_ = Stencils{};
    weak_row_owned_.clear();
    weak_needed_.clear();
  } else {
    if (owned.size() != body_->size())
      throw Error("internal error: restrict_evaluation needs one flag per point");
    Stencils& S = owned_stencils_;
    S = Stencils{};
    for (std::size_t s = 0; s < all.size(); ++s) {
      if (!owned[static_cast<std::size_t>(all.center[s])]) continue;
      S.center.push_back(all.center[s]);
      S.weight.push_back(all.weight[s]);
      S.index.insert(S.index.end(), all.index.begin() + all.offsets[s],
                     all.index.begin() + all.offsets[s + 1]);
      S.grad.insert(S.grad.end(), all.grad.begin() + all.offsets[s] * d_,
                    all.grad.begin() + all.offsets[s + 1] * d_);
      S.offsets.push_back(static_cast<std::int64_t>(S.index.size()));
    }
    energy_ = &owned_stencils_;
    weak_row_owned_.assign(weak_points_.size(), 0);
    weak_needed_.assign(weak_points_.size(), 0);
    for (std::size_t w = 0; w < weak_points_.size(); ++w) {
      weak_row_owned_[w] = owned[static_cast<std::size_t>(weak_points_[w])];
      if (weak_row_owned_[w])
        for (auto c = corr_.begin(w); c < corr_.end(w); ++c) weak_needed_[corr_.index[c]] = 1;
    }
  }
  // The reverse index, the adjacency and the packed tangents follow the evaluated stencils.
  indexed_ = false;
  member_of_ = Csr{};
  member_pos_.clear();
  adjacency_ = Csr{};
  Apk_.clear();
}

void Model::subtract_correction(std::size_t w, Eigen::VectorXd& f) const {
  const auto k = static_cast<std::size_t>(weak_points_[w]);
  for (auto c = corr_.begin(w); c < corr_.end(w); ++c) {
    const Mat3& P = Pbar_[corr_.index[c]];
    const Vec3& h = corr_coef_[c];
    for (int a = 0; a < d_; ++a)
      for (int J = 0; J < d_; ++J) f[d_ * k + a] -= P(a, J) * h(J);
  }
}

void Model::set_anchors(std::vector<int> points, std::vector<double> targets, double stiffness) {
  anchor_points_ = std::move(points);
  anchor_u_ = std::move(targets);
  anchor_k_ = stiffness;
  cut_flux_between_pieces();
}

void Model::add_anchors(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseRow* K) const {
  for (std::size_t a = 0; a < anchor_points_.size(); ++a) {
    const int k = anchor_points_[a];
    for (int c = 0; c < d_; ++c) {
      if (std::isnan(anchor_u_[d_ * a + c])) continue;  // no spring in this component
      f[d_ * k + c] += anchor_k_ * (u[d_ * k + c] - anchor_u_[d_ * a + c]);
      if (K) K->coeffRef(d_ * k + c, d_ * k + c) += anchor_k_;  // diagonal is in the pattern
    }
  }
}

template <int D>
void Model::assemble_rows(Eigen::VectorXd& f, SparseRow& K) const {
  constexpr int D2 = D * D, NP = detail::packed_size(D);
  const Stencils& S = *energy_;
  const Stencils& Pst = body_->point_stencils();
  const std::size_t N = body_->size();
  double* vals = K.valuePtr();
  const int* outer = K.outerIndexPtr();
  const double* grad = S.grad.data();
  const int* sidx = S.index.data();
  // Row gather: row k of K is Σ_{S∋k} w_S Σ_{n∈S} (G_S^k)ᵀ A_S G_S^n, each stencil's packed
  // w_S A_S (Apk_, energy_force_and_tangents) read once per member row; no atomics,
  // deterministic. The per-thread slot array (slot[n] = position of n in row k's
  // adjacency) is allocated with the index. f holds the energy part on entry (scattered by
  // the stencil sweep); the rows add the weak-form correction.
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
      double B[D][D2];  // B[a][b*D+L] = w Σ_J A_aJbL G^k_J
      for (auto q = member_of_.offsets[k]; q < member_of_.offsets[k + 1]; ++q) {
        const int s = member_of_.index[q];
        const double* gk = grad + (S.offsets[s] + member_pos_[q]) * D;
        const double* A = Apk_.data() + static_cast<std::size_t>(s) * NP;
        detail::contract_packed<D>(A, gk, B);
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
      if (const int w = weak_id_[k]; w >= 0 && (weak_row_owned_.empty() || weak_row_owned_[w])) {
        subtract_correction(static_cast<std::size_t>(w), f);
        // −Σ_l A(F̄_l) : (c_kl ⊗ Ḡ_l^n) over the correction's stresses l and their families
        for (auto c = corr_.begin(w); c < corr_.end(w); ++c) {
          const int wl = corr_.index[c], l = weak_points_[wl];
          const Vec3& e = corr_coef_[c];
          const Tangent& A = Abar_[wl];
          for (int a = 0; a < D; ++a)
            for (int b = 0; b < D; ++b)
              for (int L = 0; L < D; ++L) {
                double t = 0;
                for (int J = 0; J < D; ++J) t += A(flat(a, J), flat(b, L)) * e(J);
                B[a][b * D + L] = t;
              }
          for (auto r = Pst.offsets[l]; r < Pst.offsets[l + 1]; ++r) {
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
    }
  }  // omp parallel
}

bool Model::internal_force_and_tangent(const Eigen::VectorXd& u, Eigen::VectorXd& f,
                                       SparseRow& K) const {
  build_index();
  if (f.size() != static_cast<Eigen::Index>(dofs())) f.resize(dofs());
  f.setZero();
  if (!energy_force_and_tangents(u, f) || !evaluate_weak_rows(u, true)) return false;
  if (K.rows() != static_cast<Eigen::Index>(dofs()) || K.nonZeros() != pattern_nnz_)
    fill_pattern(K);
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

bool Model::tangent_row_abs_sums(const Eigen::VectorXd& u, const std::vector<int>& points,
                                 const std::vector<char>& skip_column,
                                 std::vector<double>& sums) const {
  // The packed w_S A_S of every stencil these rows meet, once (into a local array, a few
  // stencils per row), then the rows gathered as in assemble_rows.
  build_index();
  const Stencils& S = *energy_;
  const Stencils& Pst = body_->point_stencils();
  const int d = d_, d2 = d * d, np = detail::packed_size(d);
  std::vector<int> where(S.size(), -1);  // stencil -> its position in need
  std::vector<int> need;
  for (int k : points)
    for (auto q = member_of_.offsets[k]; q < member_of_.offsets[k + 1]; ++q)
      if (where[member_of_.index[q]] < 0) {
        where[member_of_.index[q]] = static_cast<int>(need.size());
        need.push_back(member_of_.index[q]);
      }
  std::vector<double> Ap(need.size() * static_cast<std::size_t>(np));
  if (Abar_.size() < weak_points_.size()) Abar_.resize(weak_points_.size());
  bool ok = true;
  double asym = 0.0;
#pragma omp parallel for schedule(static) reduction(&& : ok) reduction(max : asym)
  for (std::size_t i = 0; i < need.size(); ++i) {
    const int s = need[i];
    Tangent A;
    Mat3 P;
    if (!material_->evaluate_at(S.center[s], stencil_gradient(S, s, u), nullptr, &P, &A)) {
      ok = false;
      continue;
    }
    asym = std::max(asym, detail::pack_tangent(d, A, S.weight[s], Ap.data() + i * np));
  }
  if (asym > detail::kMaxAsymmetry)
    throw NumericalError(
        "tangent row sums: the material tangent lacks major symmetry (max "
        "|A_aJbL − A_bLaJ| / max |A| = " +
        std::to_string(asym) + "); a hyperelastic material is needed");
  {
    std::vector<char> done(weak_points_.size(), 0);
    for (int k : points)
      if (const int w = weak_id_[k]; w >= 0)
        for (auto c = corr_.begin(w); c < corr_.end(w); ++c) {
          const int wl = corr_.index[c], l = weak_points_[wl];
          if (done[wl]) continue;
          done[wl] = 1;
          Mat3 P;
          if (!material_->evaluate_at(l, stencil_gradient(Pst, l, u), nullptr, &P, &Abar_[wl]))
            ok = false;
        }
  }
  if (!ok) return false;
  sums.assign(points.size() * static_cast<std::size_t>(d), 0.0);
#pragma omp parallel
  {
    std::vector<int> slot(body_->size(), -1);
    std::vector<double> row;
#pragma omp for schedule(dynamic, 4)
    for (std::size_t pi = 0; pi < points.size(); ++pi) {
      const int k = points[pi];
      const auto a0 = adjacency_.begin(k), a1 = adjacency_.end(k);
      for (auto p = a0; p < a1; ++p) slot[adjacency_.index[p]] = static_cast<int>(p - a0);
      const std::size_t len = static_cast<std::size_t>(d) * (a1 - a0);
      row.assign(d * len, 0.0);  // row a at a·len, column slot·d + b
      double B[3][9];
      for (auto q = member_of_.offsets[k]; q < member_of_.offsets[k + 1]; ++q) {
        const int s = member_of_.index[q];
        const double w = S.weight[s];
        if (!(w != 0.0)) continue;
        const double* gk = S.grad.data() + (S.offsets[s] + member_pos_[q]) * d;
        const double* A = Ap.data() + static_cast<std::size_t>(where[s]) * np;
        for (int a = 0; a < d; ++a)
          for (int bL = 0; bL < d2; ++bL) {
            double t = 0;
            for (int J = 0; J < d; ++J) t += A[detail::packed_at(d2, a * d + J, bL)] * gk[J];
            B[a][bL] = t;
          }
        for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) {
          const double* gn = S.grad.data() + r * d;
          const std::size_t c0 = static_cast<std::size_t>(d) * slot[S.index[r]];
          for (int a = 0; a < d; ++a)
            for (int b = 0; b < d; ++b) {
              double t = 0;
              for (int L = 0; L < d; ++L) t += B[a][b * d + L] * gn[L];
              row[a * len + c0 + b] += t;
            }
        }
      }
      if (const int w = weak_id_[k]; w >= 0)
        for (auto c = corr_.begin(w); c < corr_.end(w); ++c) {
          const int wl = corr_.index[c], l = weak_points_[wl];
          const Tangent& A = Abar_[wl];
          const Vec3& e = corr_coef_[c];
          for (int a = 0; a < d; ++a)
            for (int b = 0; b < d; ++b)
              for (int L = 0; L < d; ++L) {
                double t = 0;
                for (int J = 0; J < d; ++J) t += A(flat(a, J), flat(b, L)) * e(J);
                B[a][b * d + L] = t;
              }
          for (auto r = Pst.offsets[l]; r < Pst.offsets[l + 1]; ++r) {
            const double* gn = Pst.grad.data() + r * d;
            const std::size_t c0 = static_cast<std::size_t>(d) * slot[Pst.index[r]];
            for (int a = 0; a < d; ++a)
              for (int b = 0; b < d; ++b) {
                double t = 0;
                for (int L = 0; L < d; ++L) t += B[a][b * d + L] * gn[L];
                row[a * len + c0 + b] -= t;
              }
          }
        }
      for (int a = 0; a < d; ++a) {
        double sum = 0;
        for (auto p = a0; p < a1; ++p)
          for (int b = 0; b < d; ++b) {
            const int col = d * adjacency_.index[p] + b;
            if (!skip_column.empty() && skip_column[col]) continue;
            sum += std::abs(row[a * len + static_cast<std::size_t>(p - a0) * d + b]);
          }
        sums[static_cast<std::size_t>(d) * pi + a] = sum;
      }
    }
  }
  // anchored points: the spring on the diagonal
  for (std::size_t a = 0; a < anchor_points_.size(); ++a)
    for (std::size_t pi = 0; pi < points.size(); ++pi)
      if (points[pi] == anchor_points_[a])
        for (int c = 0; c < d; ++c)
          if (!std::isnan(anchor_u_[static_cast<std::size_t>(d) * a + c]))
            sums[static_cast<std::size_t>(d) * pi + c] += anchor_k_;
  return true;
}

std::vector<Mat3> Model::point_deformation_gradients(const Eigen::VectorXd& u) const {
  // every stencil, also after restrict_evaluation (the output fields of a distributed run)
  const Stencils& S = opt_.correspondence == Correspondence::bond_associated
                          ? body_->bond_stencils()
                          : body_->point_stencils();
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
    // a point whose stencils all broke (rupture) carries no stress: F = I, not 0/0
    F[k] = wsum[k] > 0 ? Mat3(F[k] / wsum[k]) : Mat3::Identity();
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
