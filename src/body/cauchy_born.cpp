#include "pdcg/body/cauchy_born.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <tuple>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parallel.hpp"

namespace pdcg::body {

namespace {

/// Each atom's weight in the body's energy: w_k = Σ_p w_kp over the homogenisation points p
/// (homogenised body, in the order of the points), else 1.
std::vector<double> atom_weights(const Body& body) {
  std::vector<double> wk(body.size(), 1.0);
  if (!body.homogenisation) return wk;
  const auto& h = *body.homogenisation;
  std::fill(wk.begin(), wk.end(), 0.0);
  for (std::size_t q = 0; q < h.size(); ++q)
    for (auto c = h.offset[q]; c < h.offset[q + 1]; ++c)
      wk[static_cast<std::size_t>(h.atom[static_cast<std::size_t>(c)])] +=
          h.weight[static_cast<std::size_t>(c)];
  return wk;
}

}  // namespace

CauchyBorn::CauchyBorn(const Body& body, IonRelaxation ion, bool per_point)
    : body_(body), per_point_(per_point) {
  static std::atomic<std::uint64_t> next_id{1};
  id_ = next_id.fetch_add(1);
  if (body.statistics)
    throw InputError("Cauchy–Born material of a statistical body is not supported")
        .key("kind")
        .value("statistical")
        .expected("a delta, homogenised or rescaled body")
        .fix(
            "build the Cauchy–Born material from the delta body: rerun `pdcg atoms2pd` without "
            "`--density statistical` (the default `--density delta`)");
  if (!body.potential) throw InputError("body has no potential").fix("rebuild the body file");
  if (body.families.points() != body.size() || body.size() == 0)
    throw InputError("body has no families").fix("rebuild the body with `pdcg atoms2pd`");
  if (!(body.reference_volume() > 0.0))
    throw InputError("body has zero reference volume")
        .key("box")
        .expected("a box whose first `dimension` edges span a positive measure")
        .fix("give the configuration a box (periodic for a perfect crystal)");
  lattice_ = detect_lattice(body);
  if (ion == IonRelaxation::relaxed && !lattice_.perfect && !per_point)
    throw InputError("relaxed-ion Cauchy–Born needs a perfect crystal")
        .key("ion relaxation")
        .value(lattice_.summary)
        .expected(
            "a perfect periodic crystal (every atom one of equally populated environments: no "
            "vacancy, surface, displaced atom or random occupation)")
        .fix(
            "ask for the clamped-ion values (`pdcg elastic --clamped-ion`), or build the body "
            "from a perfect periodic cell (a random alloy: a periodic cell of ≤ 64 atoms is "
            "relaxed as a whole)");
  relax_ = ion != IonRelaxation::clamped && lattice_.perfect && lattice_.basis > 1;
  relaxed_values_ = ion != IonRelaxation::clamped && lattice_.perfect;
  // (per-point sums: the note of the model's bulk crystal, assign_sublattices)
  if (const auto note = cauchy_born_lattice_note(lattice_, ion); !per_point && !note.text.empty()) {
    if (note.warning)
      log::warn("{}", note.text);
    else
      log::info("{}", note.text);
  }
  // Equivalence classes of atoms: same type and the same multiset of (ξ rounded to
  // 1e-10·horizon, partner type, pair factor, bond type). A perfect Bravais crystal has one
  // class, so W, P, A cost one family instead of N.
  const auto& fam = body.families;
  double scale = 0.0;
  for (std::size_t k = 0; k < body.size(); ++k)
    for (auto b = static_cast<std::size_t>(fam.offset[k]);
         b < static_cast<std::size_t>(fam.offset[k + 1]); ++b)
      scale = std::max(scale, atomistic::bond_vector(fam, body.x, k, b).cwiseAbs().maxCoeff());
  const double tol = 1e-10 * std::max(scale, 1e-300);
  using Key = std::vector<std::tuple<long long, long long, long long, int, double, int, int>>;
  std::map<std::pair<int, Key>, std::int32_t> classes;
  representative_.resize(body.size());
  multiplicity_.assign(body.size(), 0);
  for (std::size_t k = 0; k < body.size(); ++k) {
    Key key;
    for (auto b = fam.offset[k]; b < fam.offset[k + 1]; ++b) {
      const auto bb = static_cast<std::size_t>(b);
      const Eigen::Vector3d xi = atomistic::bond_vector(fam, body.x, k, bb);
      key.emplace_back(std::llround(xi[0] / tol), std::llround(xi[1] / tol),
                       std::llround(xi[2] / tol),
                       body.type[static_cast<std::size_t>(fam.neighbor[bb])],
                       fam.pair_factor.empty() ? 1.0 : fam.pair_factor[bb],
                       fam.bond_type.empty() ? 0 : fam.bond_type[bb],
                       relax_ ? lattice_.class_of[static_cast<std::size_t>(fam.neighbor[bb])] : 0);
    }
    std::sort(key.begin(), key.end());
    // relaxing: the atom's own site is part of its class (members move with one shift)
    const int tk = relax_ ? body.type[k] + 1000000 * lattice_.class_of[k] : body.type[k];
    const auto [it, fresh] =
        classes.emplace(std::make_pair(tk, std::move(key)), static_cast<std::int32_t>(k));
    representative_[k] = it->second;
    ++multiplicity_[static_cast<std::size_t>(it->second)];
  }
  classes_ = classes.size();
  // per-class weights of evaluate(): w_k = Σ_p w_kp (homogenised) or 1
  const std::vector<double> wk = atom_weights(body);
  std::map<std::int32_t, std::size_t> slot;
  for (std::size_t k = 0; k < body.size(); ++k) {
    const auto [it, fresh] = slot.emplace(representative_[k], reps_.size());
    if (fresh) {
      reps_.push_back(representative_[k]);
      rep_weight_.push_back(0.0);
    }
    rep_weight_[it->second] += wk[k];
    nmax_ = std::max(nmax_, fam.offset[k + 1] - fam.offset[k]);
  }
  if (relax_) {
    // per class slot: its site, then the site of every family member (Y_b = Fξ_b + s_c(j) − s_c(k))
    rep_sub_offset_.assign(1, 0);
    for (const auto r : reps_) {
      const auto k = static_cast<std::size_t>(r);
      rep_sub_.push_back(lattice_.class_of[k]);
      for (auto b = fam.offset[k]; b < fam.offset[k + 1]; ++b)
        rep_sub_.push_back(
            lattice_.class_of[static_cast<std::size_t>(fam.neighbor[static_cast<std::size_t>(b)])]);
      rep_sub_offset_.push_back(static_cast<std::int64_t>(rep_sub_.size()));
    }
  }
  if (reps_.size() <= 64) {
    rep_xi_offset_.assign(1, 0);
    for (const auto r : reps_) {
      const auto k = static_cast<std::size_t>(r);
      const std::int64_t o = rep_xi_offset_.back();
      rep_xi_offset_.push_back(o + 3 * (fam.offset[k + 1] - fam.offset[k]));
      rep_xi_.resize(static_cast<std::size_t>(rep_xi_offset_.back()));
      atomistic::family_bond_vectors(fam, body.x, k, rep_xi_.data() + o);
    }
  }
  // per-point class lists (point_sum); with per-point relaxation the classes are split by the
  // atom's own sublattice and its partners' (a class's atoms then share their shifts)
  if (per_point_) assign_sublattices(ion);
  std::vector<std::int32_t> pt_representative = representative_;
  if (pt_relax_) {
    using SiteKey = std::vector<std::tuple<long long, long long, long long, int>>;
    std::map<std::tuple<std::int32_t, std::int32_t, SiteKey>, std::int32_t> split;
    for (std::size_t k = 0; k < body.size(); ++k) {
      SiteKey key;
      for (auto b = fam.offset[k]; b < fam.offset[k + 1]; ++b) {
        const auto bb = static_cast<std::size_t>(b);
        const Eigen::Vector3d xi = atomistic::bond_vector(fam, body.x, k, bb);
        key.emplace_back(std::llround(xi[0] / tol), std::llround(xi[1] / tol),
                         std::llround(xi[2] / tol), bond_site_[bb]);
      }
      std::sort(key.begin(), key.end());
      const auto [it, fresh] =
          split.emplace(std::make_tuple(representative_[k], sub_[k], std::move(key)),
                        static_cast<std::int32_t>(k));
      pt_representative[k] = it->second;
    }
  }
  std::map<std::int32_t, double> acc;
  auto flush = [&]() {
    for (const auto& [r, w] : acc) {
      pt_rep_.push_back(r);
      pt_weight_.push_back(w);
    }
    pt_offset_.push_back(static_cast<std::int64_t>(pt_rep_.size()));
    acc.clear();
  };
  if (body.homogenisation) {
    const auto& h = *body.homogenisation;
    for (std::size_t q = 0; q < h.size(); ++q) {
      for (auto c = h.offset[q]; c < h.offset[q + 1]; ++c)
        acc[pt_representative[static_cast<std::size_t>(h.atom[static_cast<std::size_t>(c)])]] +=
            h.weight[static_cast<std::size_t>(c)];
      flush();
    }
  } else {
    for (std::size_t k = 0; k < body.size(); ++k) {
      acc[pt_representative[k]] += 1.0;
      flush();
    }
  }
}

struct CauchyBorn::Scratch {
  std::vector<double> xi, Y, t, K, work, M;
  std::vector<int> nt;
  void size(std::int64_t nmax, bool tangent) {
    const auto n = static_cast<std::size_t>(nmax);
    if (Y.size() < 3 * n) {
      xi.resize(3 * n);
      Y.resize(3 * n);
      t.resize(3 * n);
      nt.resize(n);
    }
    if (tangent && M.size() < 27 * n) {
      K.resize(9 * n * n);
      work.resize(atomistic::Potential::tangent_workspace(nmax));
      M.resize(27 * n);
    }
  }
};

namespace {
/// The family's tangent contracted with its reference bonds, M_b = Σ_c K_bc ξ_c
/// (M[27 b + 3(3i + k) + L] = Σ_c K_bc,ik ξ_c,L, from zero; n²·27), skipping the zero
/// off-diagonal blocks of pair potentials; block(b, c, K_bc) is called after each block used
/// (b outer, c inner).
template <class Block>
void contract_tangent(const double* K, const double* xi, std::int64_t n, double* M, Block&& block) {
  std::fill(M, M + 27 * n, 0.0);
  for (std::int64_t b = 0; b < n; ++b) {
    double* mb = M + 27 * b;
    for (std::int64_t c = 0; c < n; ++c) {
      const double* kb = K + 9 * (b * n + c);
      if (b != c && kb[0] == 0.0 && kb[4] == 0.0 && kb[8] == 0.0 && kb[1] == 0.0 && kb[2] == 0.0 &&
          kb[3] == 0.0 && kb[5] == 0.0 && kb[6] == 0.0 && kb[7] == 0.0)
        continue;  // pair potentials: only diagonal blocks
      const double* xc = xi + 3 * c;
      for (int ik = 0; ik < 9; ++ik)
        for (int L = 0; L < 3; ++L) mb[3 * ik + L] += kb[ik] * xc[L];
      block(b, c, kb);
    }
  }
}
}  // namespace

void CauchyBorn::family(std::int64_t k, const Eigen::Matrix3d& F, bool tangent, Scratch& s,
                        double& psi, double* pk, double* ak) const {
  const auto& fam = body_.families;
  const auto& pot = *body_.potential;
  const std::int64_t b0 = fam.offset[static_cast<std::size_t>(k)];
  const std::int64_t n = fam.offset[static_cast<std::size_t>(k + 1)] - b0;
  const double* xi = s.xi.data();
  const auto slot = std::lower_bound(reps_.begin(), reps_.end(), static_cast<std::int32_t>(k));
  if (!rep_xi_offset_.empty() && slot != reps_.end() && *slot == k)
    xi = rep_xi_.data() + rep_xi_offset_[static_cast<std::size_t>(slot - reps_.begin())];
  else
    atomistic::family_bond_vectors(fam, body_.x, static_cast<std::size_t>(k), s.xi.data());
  for (std::int64_t b = 0; b < n; ++b) {
    const auto bb = static_cast<std::size_t>(b);
    s.nt[bb] = body_.type[static_cast<std::size_t>(fam.neighbor[static_cast<std::size_t>(b0 + b)])];
    for (int i = 0; i < 3; ++i)
      s.Y[3 * bb + static_cast<std::size_t>(i)] =
          F(i, 0) * xi[3 * b] + F(i, 1) * xi[3 * b + 1] + F(i, 2) * xi[3 * b + 2];
  }
  const atomistic::FamilyState f =
      atomistic::family_state(fam, static_cast<std::size_t>(k),
                              body_.type[static_cast<std::size_t>(k)], s.nt.data(), s.Y.data());
  psi = pot.force_state(f, s.t.data());
  std::fill(pk, pk + 9, 0.0);
  for (std::int64_t b = 0; b < n; ++b)
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 3; ++J)
        pk[3 * i + J] += s.t[static_cast<std::size_t>(3 * b + i)] * xi[3 * b + J];
  if (!tangent) return;
  pot.force_state_tangent(f, s.K.data(), s.work.data());
  // M_b,ikL = Σ_c K_bc,ik ξ_c,L, then A_iJkL = Σ_b ξ_b,J M_b,ikL (n·81)
  contract_tangent(s.K.data(), xi, n, s.M.data(), [](std::int64_t, std::int64_t, const double*) {});
  std::fill(ak, ak + 81, 0.0);
  for (std::int64_t b = 0; b < n; ++b) {
    const double* mb = s.M.data() + 27 * b;
    const double* xb = xi + 3 * b;
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 3; ++J)
        for (int kk = 0; kk < 3; ++kk)
          for (int L = 0; L < 3; ++L)
            ak[(3 * i + J) * 9 + 3 * kk + L] += xb[J] * mb[3 * (3 * i + kk) + L];
  }
}

namespace {
std::string matrix_text(const Eigen::Matrix3d& F) {
  std::string t;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) t.append(fmt::format("{}{:.9g}", r + c ? " " : "", F(r, c)));
  return t;
}
}  // namespace

struct CauchyBorn::RelaxSums {
  double E = 0.0;
  double P[9] = {}, A[81] = {};
  std::vector<double> g, Asf, Ass;  ///< 3n_b; 3n_b × 9; 3n_b × 3n_b (row-major)
  void reset(int nsub, bool tangent) {
    const auto m = static_cast<std::size_t>(3 * nsub);
    E = 0.0;
    std::fill(P, P + 9, 0.0);
    std::fill(A, A + 81, 0.0);
    g.assign(m, 0.0);
    Asf.assign(tangent ? 9 * m : 0, 0.0);
    Ass.assign(tangent ? m * m : 0, 0.0);
  }
};

void CauchyBorn::family_shifted(std::size_t slot, const Eigen::Matrix3d& F, const double* shift,
                                bool tangent, Scratch& s, RelaxSums& out) const {
  const std::int32_t* site = rep_sub_.data() + rep_sub_offset_[slot];
  family_sites(reps_[slot], rep_weight_[slot],
               rep_xi_offset_.empty() ? nullptr : rep_xi_.data() + rep_xi_offset_[slot], site[0],
               site + 1, lattice_.basis, F, shift, tangent, s, out);
}

void CauchyBorn::family_sites(std::int64_t k, double w, const double* xi_in, int own,
                              const std::int32_t* partner, int nsub, const Eigen::Matrix3d& F,
                              const double* shift, bool tangent, Scratch& s, RelaxSums& out) const {
  const auto& fam = body_.families;
  const auto& pot = *body_.potential;
  const std::int64_t b0 = fam.offset[static_cast<std::size_t>(k)];
  const std::int64_t n = fam.offset[static_cast<std::size_t>(k + 1)] - b0;
  const double* xi = xi_in;
  if (!xi) {
    atomistic::family_bond_vectors(fam, body_.x, static_cast<std::size_t>(k), s.xi.data());
    xi = s.xi.data();
  }
  const int a = own;  // own site; partner[b]: site of bond b's partner
  for (std::int64_t b = 0; b < n; ++b) {
    const auto bb = static_cast<std::size_t>(b);
    s.nt[bb] = body_.type[static_cast<std::size_t>(fam.neighbor[static_cast<std::size_t>(b0 + b)])];
    const int c = partner[b];
    for (int i = 0; i < 3; ++i)
      s.Y[3 * bb + static_cast<std::size_t>(i)] = F(i, 0) * xi[3 * b] + F(i, 1) * xi[3 * b + 1] +
                                                  F(i, 2) * xi[3 * b + 2] + shift[3 * c + i] -
                                                  shift[3 * a + i];
  }
  const atomistic::FamilyState f =
      atomistic::family_state(fam, static_cast<std::size_t>(k),
                              body_.type[static_cast<std::size_t>(k)], s.nt.data(), s.Y.data());
  out.E += w * pot.force_state(f, s.t.data());
  for (std::int64_t b = 0; b < n; ++b) {
    const int c = partner[b];
    for (int i = 0; i < 3; ++i) {
      const double ti = w * s.t[static_cast<std::size_t>(3 * b + i)];
      for (int J = 0; J < 3; ++J) out.P[3 * i + J] += ti * xi[3 * b + J];
      out.g[static_cast<std::size_t>(3 * c + i)] += ti;  // ∂Y_b/∂s_c = +I, ∂Y_b/∂s_a = −I
      out.g[static_cast<std::size_t>(3 * a + i)] -= ti;
    }
  }
  if (!tangent) return;
  pot.force_state_tangent(f, s.K.data(), s.work.data());
  const auto m = static_cast<std::size_t>(3 * nsub);
  // M_b as in family(); with each block K_bc, A_ss += Σ_bc d_b,q d_c,q' K_bc (d_b = +1 at the
  // partner's site, −1 at the own site)
  contract_tangent(
      s.K.data(), xi, n, s.M.data(), [&](std::int64_t b, std::int64_t c, const double* kb) {
        const int cb = partner[b], cc = partner[c];
        if (cb == a && cc == a) return;  // both bonds within one site: no relative shift
        const int rows[2] = {cb, a}, cols[2] = {cc, a};
        for (int ri = 0; ri < 2; ++ri)
          for (int ci = 0; ci < 2; ++ci) {
            const double sg = w * ((ri == ci) ? 1.0 : -1.0);
            for (int i = 0; i < 3; ++i)
              for (int kk = 0; kk < 3; ++kk)
                out.Ass[static_cast<std::size_t>(3 * rows[ri] + i) * m +
                        static_cast<std::size_t>(3 * cols[ci] + kk)] += sg * kb[3 * i + kk];
          }
      });
  for (std::int64_t b = 0; b < n; ++b) {
    const double* mb = s.M.data() + 27 * b;
    const double* xb = xi + 3 * b;
    const int cb = partner[b];
    for (int i = 0; i < 3; ++i)
      for (int kk = 0; kk < 3; ++kk)
        for (int L = 0; L < 3; ++L) {
          const double v = w * mb[3 * (3 * i + kk) + L];
          for (int J = 0; J < 3; ++J) out.A[(3 * i + J) * 9 + 3 * kk + L] += xb[J] * v;
          // A_sF: ∂g_q,i/∂F_kL = Σ_b d_b,q Σ_c K_bc,ik ξ_c,L
          out.Asf[static_cast<std::size_t>(3 * cb + i) * 9 +
                  static_cast<std::size_t>(3 * kk + L)] += v;
          out.Asf[static_cast<std::size_t>(3 * a + i) * 9 + static_cast<std::size_t>(3 * kk + L)] -=
              v;
        }
  }
}

void CauchyBorn::relaxed_sums(bool bulk, const Eigen::Matrix3d& F, const double* shift,
                              bool tangent, Scratch& s, RelaxSums& out) const {
  if (!bulk) {
    out.reset(lattice_.basis, tangent);
    for (std::size_t c = 0; c < reps_.size(); ++c) family_shifted(c, F, shift, tangent, s, out);
    return;
  }
  // the model's bulk crystal: one interior atom per sublattice, weight 1 (energy per primitive
  // cell; s* and S do not depend on the scale)
  out.reset(bulk_basis_, tangent);
  for (const auto k : bulk_rep_)
    family_sites(k, 1.0, nullptr, sub_[static_cast<std::size_t>(k)],
                 bond_site_.data() + body_.families.offset[static_cast<std::size_t>(k)],
                 bulk_basis_, F, shift, tangent, s, out);
}

struct CauchyBorn::Relaxation {
  RelaxSums sums, trial;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es;  ///< of W_ss on the free shifts
  std::vector<double> shift, probe;
  Eigen::MatrixXd H;
  Eigen::VectorXd g, step;
  int nf = 0, d = 3;
  /// position of free unknown f in the 3·n_b shift vector (sites 1 …, components 0 … d−1)
  std::size_t free_index(int f) const { return static_cast<std::size_t>(3 * (1 + f / d) + f % d); }
};

int CauchyBorn::relax(bool bulk, const Eigen::Matrix3d& F, Relaxation& r) const {
  // Newton on the free shifts (sites 1 … n_b−1, components 0 … d−1: site 0 is held, which
  // removes the rigid translation — the null space of W_ss; a 2D body shifts in its plane).
  thread_local Scratch scratch;
  thread_local std::uint64_t warm_id = 0;  // warm start: this thread's last converged shifts
  thread_local std::vector<double> warm;
  scratch.size(nmax_, true);
  const int nsub = bulk ? bulk_basis_ : lattice_.basis;
  r.d = body_.dimension == 2 ? 2 : 3;
  const int nf = r.d * (nsub - 1);
  r.nf = nf;
  const auto m = static_cast<std::size_t>(3 * nsub);
  const std::uint64_t key = 2 * id_ + (bulk ? 1 : 0);  // the body's set and the bulk's apart
  r.shift.assign(m, 0.0);
  r.probe.resize(m);
  const bool warmed = warm_id == key && warm.size() == m;
  if (warmed) r.shift = warm;
  r.H.resize(nf, nf);
  r.g.resize(nf);
  r.step.resize(nf);
  auto& shift = r.shift;
  auto& probe = r.probe;
  auto& sums = r.sums;
  auto& H = r.H;
  auto& g = r.g;
  auto& step = r.step;
  auto& es = r.es;
  const double length = bulk ? bulk_nearest_ : lattice_.nearest;
  constexpr int max_iterations = 100;
  int it = 0;
  double lmin = 0, lmax = 0;
  bool final_step = false;
  for (int attempt = 0;; ++attempt) try {
      it = 0;
      final_step = false;
      for (;; ++it) {
        relaxed_sums(bulk, F, shift.data(), true, scratch, sums);
        for (int i = 0; i < nf; ++i) {
          g(i) = sums.g[r.free_index(i)];
          for (int c = 0; c < nf; ++c) H(i, c) = sums.Ass[r.free_index(i) * m + r.free_index(c)];
        }
        if (!std::isfinite(sums.E) || !g.allFinite() || !H.allFinite())
          throw NumericalError(fmt::format(
              "inner relaxation of the Cauchy–Born material: non-finite energy or force at F = "
              "[{}] "
              "after {} Newton steps (atoms too close or beyond the potential's tables); use a "
              "smaller deformation or the clamped-ion material (`pdcg elastic --clamped-ion`)",
              matrix_text(F), it));
        es.compute(H);
        if (es.eigenvalues().cwiseAbs().maxCoeff() == 0.0)
          throw NumericalError(fmt::format(
              "inner relaxation of the Cauchy–Born material at F = [{}]: the sublattices do not "
              "interact (W_ss = 0: atoms beyond the potential's cutoff); use a smaller "
              "deformation or the clamped-ion material (`pdcg elastic --clamped-ion`)",
              matrix_text(F)));
        lmin = es.eigenvalues()(0);
        lmax = std::max(std::abs(es.eigenvalues()(nf - 1)), 1e-300);
        // Newton step on a positive definite W_ss; otherwise (not a minimum here) the step of the
        // eigenvalues' magnitudes, floored at 1e-8·max (a descent direction), with the line search
        const Eigen::VectorXd lam =
            es.eigenvalues().cwiseAbs().cwiseMax(lmin > 1e-10 * lmax ? 0.0 : 1e-8 * lmax);
        step = -es.eigenvectors() * (es.eigenvectors().transpose() * g).cwiseQuotient(lam);
        // converged: W_ss positive definite and the Newton step ≤ 1e-10 d_nn — it is taken (no line
        // search) and the state evaluated there; quadratic convergence leaves ~(1e-10)² d_nn, far
        // below the round-off floor of the shifts (~1e-15 d_nn)
        if (lmin > 1e-10 * lmax && step.cwiseAbs().maxCoeff() <= 1e-10 * length) {
          if (final_step || step.cwiseAbs().maxCoeff() <= 1e-14 * length) break;  // (round-off)
          final_step = true;
          for (int f = 0; f < nf; ++f) shift[r.free_index(f)] += step(f);
          continue;
        }
        final_step = false;
        if (it >= max_iterations)
          throw NumericalError(fmt::format(
              "inner relaxation of the Cauchy–Born material did not converge at F = [{}]: {} "
              "Newton "
              "steps, last step {:.3g} (nearest-neighbour distance {:.6g}), smallest eigenvalue of "
              "W_ss {:.3g} (largest {:.3g}; ≤ 0: the basis is unstable at this F, the crystal "
              "would "
              "transform). Use a smaller deformation, or the clamped-ion material "
              "(`pdcg elastic --clamped-ion`)",
              matrix_text(F), it, step.cwiseAbs().maxCoeff(), length, lmin, lmax));
        // backtracking line search on the energy (Armijo 1e-4; the 1e-13·|E| allowance is the
        // round-off of the energy sum, reached only in the quadratic regime where the full step
        // is right)
        const double slope = g.dot(step);
        double alpha = 1.0;
        for (int ls = 0; ls < 40; ++ls, alpha *= 0.5) {
          probe = shift;
          for (int f = 0; f < nf; ++f) probe[r.free_index(f)] += alpha * step(f);
          relaxed_sums(bulk, F, probe.data(), false, scratch, r.trial);
          if (std::isfinite(r.trial.E) &&
              r.trial.E <= sums.E + 1e-4 * alpha * slope + 1e-13 * std::abs(sums.E))
            break;
        }
        shift.swap(probe);
      }
      break;
    } catch (const NumericalError&) {
      // a warm start from a distant F may lie where the sublattices no longer interact (W_ss = 0,
      // no step): once more from s = 0 before giving up
      if (!warmed || attempt > 0) throw;
      std::fill(shift.begin(), shift.end(), 0.0);
    }
  warm_id = key;
  warm = shift;
  return it;
}

CauchyBornState CauchyBorn::evaluate_relaxed(const Eigen::Matrix3d& F, bool tangent) const {
  thread_local Relaxation r;
  const int it = relax(false, F, r);
  const auto& sums = r.sums;
  const int nf = r.nf;
  CauchyBornState st;
  const double V = body_.reference_volume();
  st.W = sums.E / V;
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J) st.P(i, J) = sums.P[3 * i + J] / V;
  st.shift = r.shift;
  st.iterations = it;
  if (!tangent) return st;
  // A = A_FF − A_Fs A_ss⁻¹ A_sF on the free shifts (W_ss positive definite at the minimum)
  Eigen::MatrixXd B(nf, 9);
  for (int i = 0; i < nf; ++i)
    for (int c = 0; c < 9; ++c)
      B(i, c) = sums.Asf[r.free_index(i) * 9 + static_cast<std::size_t>(c)];
  const Eigen::MatrixXd X = r.es.eigenvectors().transpose() * B;
  Eigen::MatrixXd corr = X.transpose() * r.es.eigenvalues().cwiseInverse().asDiagonal() * X;
  for (int i = 0; i < 9; ++i)
    for (int c = 0; c < 9; ++c) st.A(i, c) = (sums.A[9 * i + c] - corr(i, c)) / V;
  return st;
}

namespace {
/// S = ds*/dF = −W_ss⁻¹ W_sF on the free shifts (nf × 9) from a converged relaxation's
/// eigen-decomposition of W_ss and its W_sF.
template <class Relax>
void shift_sensitivity(const Relax& r, Eigen::MatrixXd& S) {
  Eigen::MatrixXd B(r.nf, 9);
  for (int i = 0; i < r.nf; ++i)
    for (int c = 0; c < 9; ++c)
      B(i, c) = r.sums.Asf[r.free_index(i) * 9 + static_cast<std::size_t>(c)];
  S = -(r.es.eigenvectors() *
        (r.es.eigenvalues().cwiseInverse().asDiagonal() * (r.es.eigenvectors().transpose() * B)));
}
}  // namespace

CauchyBornState CauchyBorn::point_sum_relaxed(std::size_t p, const Eigen::Matrix3d& F,
                                              bool tangent) const {
  // docs/theory.md §11 "per point": E_p(F) = E_p(F, s*(F)) with the bulk crystal's shifts
  thread_local Relaxation bulk, probe;
  thread_local Scratch scratch;
  thread_local RelaxSums pts;
  thread_local Eigen::MatrixXd S;
  const int it = relax(true, F, bulk);
  const int nf = bulk.nf;
  const auto nsub = bulk_basis_;
  scratch.size(nmax_, tangent);
  pts.reset(nsub, tangent);
  const auto& fam = body_.families;
  for (auto c = pt_offset_[p]; c < pt_offset_[p + 1]; ++c) {
    const auto k = pt_rep_[static_cast<std::size_t>(c)];
    const auto kk = static_cast<std::size_t>(k);
    family_sites(k, pt_weight_[static_cast<std::size_t>(c)], nullptr, sub_[kk],
                 bond_site_.data() + fam.offset[kk], nsub, F, bulk.shift.data(), tangent, scratch,
                 pts);
  }
  CauchyBornState st;
  st.W = pts.E;
  st.shift = bulk.shift;
  st.iterations = it;
  shift_sensitivity(bulk, S);
  // P_p = ∂_F E_p + ∂_s E_p · S (the point's own ∂_s E_p ≠ 0: only the bulk cell's sum vanishes)
  for (int r = 0; r < 9; ++r) {
    double v = pts.P[r];
    for (int f = 0; f < nf; ++f) v += pts.g[bulk.free_index(f)] * S(f, r);
    st.P(r / 3, r % 3) = v;
  }
  if (!tangent) return st;
  // A_p = E_FF + E_Fs S + Sᵀ E_sF + Sᵀ E_ss S + ∂_s E_p · dS/dF
  const auto m = static_cast<std::size_t>(3 * nsub);
  Eigen::MatrixXd Esf(nf, 9), Ess(nf, nf);
  for (int f = 0; f < nf; ++f) {
    for (int c = 0; c < 9; ++c)
      Esf(f, c) = pts.Asf[bulk.free_index(f) * 9 + static_cast<std::size_t>(c)];
    for (int e = 0; e < nf; ++e) Ess(f, e) = pts.Ass[bulk.free_index(f) * m + bulk.free_index(e)];
  }
  const Eigen::MatrixXd SE = S.transpose() * Esf;
  const Eigen::MatrixXd corr = SE + SE.transpose() + S.transpose() * Ess * S;
  for (int r = 0; r < 9; ++r)
    for (int c = 0; c < 9; ++c) st.A(r, c) = pts.A[9 * r + c] + corr(r, c);
  // ∂_s E_p · dS/dF (docs/theory.md (11.5)): with λ = −W_ss⁻¹ ∂_s E_p (the bulk's W_ss),
  //   T_rq = Σ_f ∂_s E_p,f ∂S_f,r/∂F_q = W'''[u, v_r, v_q],  u = (0, λ), v_r = (e_r, S e_r),
  // the bulk energy's third derivative along the relaxed path (v) and along λ (u). It is the
  // central difference along u of the bulk's path Hessian M(s) = W_FF + Sᵀ W_sF + W_Fs S +
  // Sᵀ W_ss S (S frozen) at s* ± δλ: two bulk sums with tangents, no Newton, symmetric by
  // construction. Step: |δλ| = kPointShiftStep·d_nn; error O(δ²|λ|²·W⁽⁴⁾) (the third
  // derivatives of the potentials it replaces are not available).
  Eigen::VectorXd gf(nf);
  for (int f = 0; f < nf; ++f) gf(f) = pts.g[bulk.free_index(f)];
  const Eigen::VectorXd lambda =
      -(bulk.es.eigenvectors() * (bulk.es.eigenvalues().cwiseInverse().asDiagonal() *
                                  (bulk.es.eigenvectors().transpose() * gf)));
  const double lmax = lambda.cwiseAbs().maxCoeff();
  if (!(lmax > 0.0)) return st;  // ∂_s E_p = 0 (e.g. an interior atom of diamond): no term
  const double delta = kPointShiftStep * bulk_nearest_ / lmax;
  auto path_hessian = [&](double sign, Matrix9d& M) {
    probe.shift = bulk.shift;
    for (int f = 0; f < nf; ++f) probe.shift[bulk.free_index(f)] += sign * delta * lambda(f);
    relaxed_sums(true, F, probe.shift.data(), true, scratch, probe.sums);
    Eigen::MatrixXd Bs(nf, 9), Hs(nf, nf);
    for (int f = 0; f < nf; ++f) {
      for (int e = 0; e < nf; ++e)
        Hs(f, e) = probe.sums.Ass[bulk.free_index(f) * m + bulk.free_index(e)];
      for (int c = 0; c < 9; ++c)
        Bs(f, c) = probe.sums.Asf[bulk.free_index(f) * 9 + static_cast<std::size_t>(c)];
    }
    const Eigen::MatrixXd SB = S.transpose() * Bs;
    for (int r = 0; r < 9; ++r)
      for (int c = 0; c < 9; ++c) M(r, c) = probe.sums.A[9 * r + c];
    M += SB + SB.transpose() + S.transpose() * Hs * S;
  };
  Matrix9d Mp, Mm;
  path_hessian(+1.0, Mp);
  path_hessian(-1.0, Mm);
  const Matrix9d T = (Mp - Mm) / (2 * delta);
  st.A += 0.5 * (T + T.transpose());  // (symmetric already, to round-off)
  return st;
}

void CauchyBorn::assign_sublattices(IonRelaxation ion) {
  // docs/elastic.md §7.1. Sublattices from the neighbour shells (bonds up to 1.5 d_nn, d_nn the
  // shortest bond): two atoms with equal shells (type, bonds ξ to 1e-6 d_nn, partner types) are one
  // environment; the bulk crystal's sites are the repeated environments with the largest shell
  // (a surface atom misses bonds; a lone displaced atom and its neighbours are environments of
  // one atom). The bulk must be closed: every shell bond of a bulk site ends at a bulk atom
  // somewhere in the model — else there is no interior and no bulk crystal to relax.
  const bool relax_wanted = ion != IonRelaxation::clamped;
  const auto& fam = body_.families;
  const std::size_t N = body_.size();
  double dnn = std::numeric_limits<double>::max();
  for (std::size_t k = 0; k < N; ++k)
    for (auto b = static_cast<std::size_t>(fam.offset[k]);
         b < static_cast<std::size_t>(fam.offset[k + 1]); ++b)
      dnn = std::min(dnn, atomistic::bond_vector(fam, body_.x, k, b).norm());
  bulk_nearest_ = dnn;
  // the shell: bonds up to 1.5 d_nn (first shells of diamond, hcp, honeycomb; first and second
  // of fcc and bcc), within the families' cutoff
  const double rc = std::min(body_.potential->cutoff(), 1.5 * dnn) * (1.0 + 1e-9);
  const double tol = 1e-6 * dnn;
  using Pos = std::tuple<long long, long long, long long>;
  auto pos_key = [&](const Eigen::Vector3d& v) {
    return Pos{std::llround(v[0] / tol), std::llround(v[1] / tol), std::llround(v[2] / tol)};
  };
  auto shell = [&](std::size_t k, auto&& visit) {  // visit(bond index, ξ) for |ξ| ≤ r_c
    for (auto b = static_cast<std::size_t>(fam.offset[k]);
         b < static_cast<std::size_t>(fam.offset[k + 1]); ++b) {
      const Eigen::Vector3d xi = atomistic::bond_vector(fam, body_.x, k, b);
      if (xi.norm() <= rc) visit(b, xi);
    }
  };
  std::map<std::pair<int, std::vector<std::tuple<Pos, int>>>, std::size_t> env;
  std::vector<std::size_t> env_of(N), env_size, env_first, env_count;
  for (std::size_t k = 0; k < N; ++k) {
    std::vector<std::tuple<Pos, int>> key;
    shell(k, [&](std::size_t b, const Eigen::Vector3d& xi) {
      key.emplace_back(pos_key(xi), body_.type[static_cast<std::size_t>(fam.neighbor[b])]);
    });
    std::sort(key.begin(), key.end());
    const std::size_t size = key.size();
    const auto [it, fresh] = env.emplace(std::make_pair(body_.type[k], std::move(key)), env.size());
    if (fresh) {
      env_size.push_back(size);
      env_first.push_back(k);
      env_count.push_back(0);
    }
    env_of[k] = it->second;
    ++env_count[it->second];
  }
  std::size_t full = 0;
  for (std::size_t e = 0; e < env_size.size(); ++e)
    if (env_count[e] >= 2) full = std::max(full, env_size[e]);
  std::vector<std::int32_t> site_of_env(env_size.size(), -1);
  std::vector<std::size_t> site_first;  // first atom of each bulk site
  for (std::size_t k = 0; k < N; ++k) {
    const auto e = env_of[k];
    if (env_count[e] >= 2 && env_size[e] == full && site_of_env[e] < 0) {
      site_of_env[e] = static_cast<std::int32_t>(site_first.size());
      site_first.push_back(k);
    }
  }
  const int nsites = static_cast<int>(site_first.size());
  // the bulk's bond table: (site, ξ) → the partner's site, from bonds between bulk atoms
  auto site_of = [&](std::size_t k) { return site_of_env[env_of[k]]; };
  using Key = std::tuple<std::int32_t, Pos>;
  std::map<Key, std::int32_t> table;
  auto refuse = [&](const std::string& what, std::size_t k) {
    return InputError(
               "per-point inner relaxation: the atoms cannot be assigned to the sublattices of "
               "the model's bulk crystal")
        .key("material.ion_relaxation")
        .value(fmt::format("{}: atom id {} at ({:.6g}, {:.6g}, {:.6g}); bulk crystal: {} "
                           "sublattices (the repeated environments with {} bonds within "
                           "{:.6g})",
                           what, body_.id[k], body_.x[3 * k], body_.x[3 * k + 1],
                           body_.x[3 * k + 2], nsites, full, rc))
        .expected(
            "a model cut from a crystal: every atom at a lattice position of the bulk crystal "
            "found in its interior, and interior atoms farther than the horizon from every "
            "surface, of every sublattice")
        .fix(
            "set `ion_relaxation: clamped` (clamped-ion per-point material: every atom follows "
            "F), or build the model from unrelaxed lattice positions with a deeper interior");
  };
  bool closed = nsites > 0;
  for (std::size_t k = 0; k < N; ++k)
    if (site_of(k) >= 0)
      shell(k, [&](std::size_t b, const Eigen::Vector3d& xi) {
        const auto j = static_cast<std::size_t>(fam.neighbor[b]);
        if (site_of(j) < 0) return;
        const auto [it, fresh] = table.emplace(Key{site_of(k), pos_key(xi)}, site_of(j));
        if (!fresh && it->second != site_of(j))
          throw refuse("two bulk atoms of one site have partners of different sites at one bond",
                       k);
      });
  for (const auto k : site_first)
    shell(k, [&](std::size_t, const Eigen::Vector3d& xi) {
      closed = closed && table.count(Key{site_of(k), pos_key(xi)}) > 0;
    });
  // per site: its shell bonds (ξ, partner site) — the bulk crystal's graph
  std::vector<std::vector<std::pair<Eigen::Vector3d, std::int32_t>>> graph(
      static_cast<std::size_t>(nsites));
  bool centrosymmetric = true;
  for (std::size_t c = 0; c < site_first.size() && closed; ++c) {
    const auto k = site_first[c];
    shell(k, [&](std::size_t, const Eigen::Vector3d& xi) {
      graph[c].emplace_back(xi, table.at(Key{site_of(k), pos_key(xi)}));
    });
    for (const auto& [x, s] : graph[c]) {
      bool found = false;
      for (const auto& [y, t] : graph[c]) found = found || (x + y).norm() <= tol;
      centrosymmetric = centrosymmetric && found;
    }
  }
  // bulk representatives: per site an atom whose family is the complete crystal within the
  // horizon (its size counted on the bulk's graph), so its ψ is the bulk's
  if (closed && nsites > 1) {
    const double horizon = body_.horizon();
    for (std::size_t c = 0; c < site_first.size(); ++c) {
      std::map<Pos, std::int32_t> seen{
          {pos_key(Eigen::Vector3d::Zero()), static_cast<std::int32_t>(c)}};
      std::vector<std::pair<Eigen::Vector3d, std::int32_t>> open{
          {Eigen::Vector3d::Zero(), static_cast<std::int32_t>(c)}};
      std::size_t lo = 0, hi = 0;  // sites within the horizon, strictly / with round-off
      for (std::size_t head = 0; head < open.size(); ++head) {
        const auto [x, s] = open[head];
        for (const auto& [xi, t] : graph[static_cast<std::size_t>(s)]) {
          const Eigen::Vector3d y = x + xi;
          if (y.norm() > horizon + rc) continue;
          if (!seen.emplace(pos_key(y), t).second) continue;
          open.emplace_back(y, t);
          if (y.norm() <= horizon * (1 + 1e-9)) ++hi;
          if (y.norm() < horizon * (1 - 1e-9)) ++lo;
        }
      }
      std::int32_t rep = -1;
      for (std::size_t k = 0; k < N && rep < 0; ++k) {
        const auto size = static_cast<std::size_t>(fam.offset[k + 1] - fam.offset[k]);
        if (site_of(k) == static_cast<std::int32_t>(c) && size >= lo && size <= hi)
          rep = static_cast<std::int32_t>(k);
      }
      if (rep < 0) {
        closed = false;
        break;
      }
      bulk_rep_.push_back(rep);
    }
  }
  if (!closed || nsites == 0) {
    bulk_rep_.clear();
    if (!relax_wanted) return;
    if (ion == IonRelaxation::relaxed)
      throw refuse(
          "no bulk crystal: no interior atoms deeper than the horizon (every bond of a bulk "
          "site must end at a bulk atom, and one atom per site must have the crystal's complete "
          "family)",
          site_first.empty() ? 0 : site_first[0]);
    log::warn(
        "per-point Cauchy–Born: no bulk crystal found in the model (no interior deeper than the "
        "horizon): clamped-ion per-point values, every atom follows F (a model with such an "
        "interior relaxes with the bulk's sublattice shifts, docs/elastic.md §7)");
    return;
  }
  bulk_basis_ = nsites;
  if (nsites == 1) {
    log::info(
        "per-point Cauchy–Born: the model's bulk is a Bravais lattice: no sublattice to relax; "
        "every atom follows F");
    return;
  }
  if (!relax_wanted) {
    if (!centrosymmetric)
      log::warn(
          "per-point Cauchy–Born: clamped-ion values requested for a crystal with a basis ({} "
          "sublattices in the model's bulk, whose sites are not centres of inversion): every atom "
          "follows F, the sublattices are not relaxed, so W_p, P_p and A_p are too stiff (shear "
          "most). The relaxed values: ion_relaxation: automatic (docs/elastic.md §7)",
          nsites);
    return;
  }
  // every atom's site: along the shell bonds from the bulk atoms outwards
  sub_.assign(N, -1);
  std::vector<std::size_t> queue;
  for (std::size_t k = 0; k < N; ++k)
    if (site_of(k) >= 0) {
      sub_[k] = site_of(k);
      queue.push_back(k);
    }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::size_t k = queue[head];
    shell(k, [&](std::size_t b, const Eigen::Vector3d& xi) {
      const auto it = table.find(Key{sub_[k], pos_key(xi)});
      if (it == table.end()) return;  // not a bond of the bulk crystal (displaced atom)
      const auto j = static_cast<std::size_t>(fam.neighbor[b]);
      if (sub_[j] < 0) {
        sub_[j] = it->second;
        queue.push_back(j);
      } else if (sub_[j] != it->second) {
        throw refuse("reached as two different sublattices", j);
      }
    });
  }
  std::size_t unassigned = 0, first = N;
  for (std::size_t k = 0; k < N; ++k)
    if (sub_[k] < 0 && unassigned++ == 0) first = k;
  if (unassigned)
    throw refuse(fmt::format("{} of {} atoms off the bulk lattice, e.g.", unassigned, N), first);
  bond_site_.resize(fam.neighbor.size());
  for (std::size_t b = 0; b < bond_site_.size(); ++b)
    bond_site_[b] = sub_[static_cast<std::size_t>(fam.neighbor[b])];
  pt_relax_ = true;
  log::info(
      "per-point Cauchy–Born: the model's bulk is a crystal with {} sublattices; all {} atoms "
      "assigned; every point uses the bulk's relaxed shifts s*(F) (docs/elastic.md §7: surface "
      "and defect atoms are not relaxed beyond them)",
      nsites, N);
}

void CauchyBorn::require_clamped(const char* what) const {
  if (relax_)
    throw InputError(fmt::format("{} of the Cauchy–Born material is clamped-ion only", what))
        .key("ion relaxation")
        .value(fmt::format("relaxed ({})", lattice_.summary))
        .expected("a material constructed for per-point sums, or IonRelaxation::clamped")
        .fix(
            "use the body-level material (relaxed), or construct it per point (CauchyBorn(body, "
            "ion, true): the bulk's relaxed shifts) or clamped-ion");
}

void CauchyBorn::per_atom(const Eigen::Matrix3d& F, bool tangent, std::vector<double>& psi,
                          std::vector<double>& p, std::vector<double>& a) const {
  const auto N = static_cast<std::int64_t>(body_.size());
  psi.assign(static_cast<std::size_t>(N), 0.0);
  p.assign(static_cast<std::size_t>(9 * N), 0.0);
  a.assign(tangent ? static_cast<std::size_t>(81 * N) : 0, 0.0);
  ParallelExceptions errors;  // a potential may refuse a strained configuration
#pragma omp parallel
  {
    Scratch scratch;  // per thread, sized once for the largest family
    scratch.size(nmax_, tangent);
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t k = 0; k < N; ++k)
      errors.capture([&] {
        if (representative_[static_cast<std::size_t>(k)] != k) return;
        family(k, F, tangent, scratch, psi[static_cast<std::size_t>(k)], p.data() + 9 * k,
               tangent ? a.data() + 81 * k : nullptr);
      });
  }
  errors.rethrow();
  // copy the representatives' results to the other members of their class
  for (std::int64_t k = 0; k < N; ++k) {
    const auto r = static_cast<std::size_t>(representative_[static_cast<std::size_t>(k)]);
    const auto kk = static_cast<std::size_t>(k);
    if (r == kk) continue;
    psi[kk] = psi[r];
    std::copy(p.begin() + static_cast<std::ptrdiff_t>(9 * r),
              p.begin() + static_cast<std::ptrdiff_t>(9 * r + 9),
              p.begin() + static_cast<std::ptrdiff_t>(9 * kk));
    if (tangent)
      std::copy(a.begin() + static_cast<std::ptrdiff_t>(81 * r),
                a.begin() + static_cast<std::ptrdiff_t>(81 * r + 81),
                a.begin() + static_cast<std::ptrdiff_t>(81 * kk));
  }
}

namespace {
/// s += w·(ψ, P, A) of one family, P as 9 row-major values (3i + J), A as 81 ((9r + q));
/// `a81 == nullptr`: no tangent.
void accumulate(CauchyBornState& s, double w, double psi, const double* p9, const double* a81) {
  s.W += w * psi;
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J) s.P(i, J) += w * p9[3 * i + J];
  if (a81)
    for (int r = 0; r < 9; ++r)
      for (int q = 0; q < 9; ++q) s.A(r, q) += w * a81[9 * r + q];
}
}  // namespace

CauchyBornState CauchyBorn::evaluate(const Eigen::Matrix3d& F, bool tangent) const {
  if (relax_) return evaluate_relaxed(F, tangent);
  if (reps_.size() <= 64) {
    // Few distinct environments (perfect crystals, their coarse models): one family per class,
    // weighted by Σ w_k over the class; serial and allocation-free after the first call of the
    // thread (the BA solver calls this once per bond stencil, from its own OpenMP loop).
    thread_local Scratch scratch;
    scratch.size(nmax_, tangent);
    CauchyBornState s;
    double psi = 0, p9[9], a81[81];
    for (std::size_t c = 0; c < reps_.size(); ++c) {
      family(reps_[c], F, tangent, scratch, psi, p9, a81);
      const double w = rep_weight_[c];
      accumulate(s, w, psi, p9, tangent ? a81 : nullptr);
    }
    const double V = body_.reference_volume();
    s.W /= V;
    s.P /= V;
    s.A /= V;
    return s;
  }
  std::vector<double> psi, p, a;
  per_atom(F, tangent, psi, p, a);
  CauchyBornState s;
  const std::size_t N = body_.size();
  // Homogenised bodies: W = Σ_p E_p / V₀ = Σ_k (Σ_p w_kp) ψ_k / V₀ (the point energies add
  // up to the body's energy; V₀ is the body's volume, not Σ_p V_p, which differs from it on a
  // grid incommensurate with a periodic box).
  const std::vector<double> wk = atom_weights(body_);
  const double V = body_.reference_volume();
  for (std::size_t k = 0; k < N; ++k) {
    accumulate(s, wk[k], psi[k], p.data() + 9 * k, tangent ? a.data() + 81 * k : nullptr);
  }
  s.W /= V;
  s.P /= V;
  s.A /= V;
  return s;
}

CauchyBornState CauchyBorn::point_sum(std::size_t p, const Eigen::Matrix3d& F, bool tangent) const {
  if (pt_relax_) return point_sum_relaxed(p, F, tangent);
  if (relax_ && !per_point_) require_clamped("the per-point sum");
  thread_local Scratch scratch;
  scratch.size(nmax_, tangent);
  CauchyBornState s;
  double psi = 0, p9[9], a81[81];
  for (auto c = pt_offset_[p]; c < pt_offset_[p + 1]; ++c) {
    const auto cc = static_cast<std::size_t>(c);
    family(pt_rep_[cc], F, tangent, scratch, psi, p9, a81);
    const double w = pt_weight_[cc];
    accumulate(s, w, psi, p9, tangent ? a81 : nullptr);
  }
  return s;
}

std::vector<CauchyBornState> CauchyBorn::points(const Eigen::Matrix3d& F, bool tangent) const {
  if (!body_.homogenisation)
    throw InputError("per-point Cauchy–Born material needs a homogenised body")
        .key("kind")
        .value(std::string(to_string(body_.kind)))
        .fix("run `pdcg homogenize` first, or use the body-level material");
  require_clamped("the per-point form");
  std::vector<double> psi, p, a;
  per_atom(F, tangent, psi, p, a);
  const auto& h = *body_.homogenisation;
  std::vector<CauchyBornState> out(h.size());
  for (std::size_t q = 0; q < h.size(); ++q) {
    auto& s = out[q];
    for (auto c = h.offset[q]; c < h.offset[q + 1]; ++c) {
      const auto k = static_cast<std::size_t>(h.atom[static_cast<std::size_t>(c)]);
      const double w = h.weight[static_cast<std::size_t>(c)];
      s.W += w * psi[k];
      for (int r = 0; r < 9; ++r) s.P(r / 3, r % 3) += w * p[9 * k + static_cast<std::size_t>(r)];
      if (tangent)
        for (int r = 0; r < 9; ++r)
          for (int cc = 0; cc < 9; ++cc)
            s.A(r, cc) += w * a[81 * k + static_cast<std::size_t>(9 * r + cc)];
    }
    const double inv = 1.0 / h.volume[q];
    s.W *= inv;
    s.P *= inv;
    s.A *= inv;
  }
  return out;
}

Matrix6d voigt_elastic_constants(const Eigen::Matrix3d& F, const CauchyBornState& st) {
  const Eigen::Matrix3d Fi = F.inverse();
  const Eigen::Matrix3d S = Fi * st.P;
  // B_iJkL = A_iJkL − δ_ik S_JL; C_MJNL = F⁻¹_Mi F⁻¹_Nk B_iJkL
  double C[3][3][3][3] = {};
  for (int M = 0; M < 3; ++M)
    for (int J = 0; J < 3; ++J)
      for (int N = 0; N < 3; ++N)
        for (int L = 0; L < 3; ++L) {
          double v = 0.0;
          for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) {
              const double B = st.A(3 * i + J, 3 * k + L) - (i == k ? S(J, L) : 0.0);
              v += Fi(M, i) * Fi(N, k) * B;
            }
          C[M][J][N][L] = v;
        }
  constexpr int vi[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};
  Matrix6d out;
  for (int I = 0; I < 6; ++I)
    for (int K = 0; K < 6; ++K) {
      // symmetrised over the minor pairs (exact symmetry of ∂²W/∂E∂E)
      const int a = vi[I][0], b = vi[I][1], c = vi[K][0], d = vi[K][1];
      out(I, K) = 0.25 * (C[a][b][c][d] + C[b][a][c][d] + C[a][b][d][c] + C[b][a][d][c]);
    }
  return out;
}

Moduli moduli(const Matrix6d& C, int dimension) {
  Moduli m;
  if (dimension == 2) {
    Eigen::Matrix3d c2;
    const int id[3] = {0, 1, 5};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c2(i, j) = C(id[i], id[j]);
    m.bulk_voigt = (c2(0, 0) + c2(1, 1) + 2 * c2(0, 1)) / 4;
    m.shear_voigt = (c2(0, 0) + c2(1, 1) - 2 * c2(0, 1) + 4 * c2(2, 2)) / 8;
    const Eigen::Matrix3d s = c2.inverse();
    m.bulk_reuss = 1.0 / (s(0, 0) + s(1, 1) + 2 * s(0, 1));
    m.shear_reuss = 2.0 / (s(0, 0) + s(1, 1) - 2 * s(0, 1) + s(2, 2));
    return m;
  }
  m.bulk_voigt = (C(0, 0) + C(1, 1) + C(2, 2) + 2 * (C(0, 1) + C(0, 2) + C(1, 2))) / 9;
  m.shear_voigt = (C(0, 0) + C(1, 1) + C(2, 2) - (C(0, 1) + C(0, 2) + C(1, 2)) +
                   3 * (C(3, 3) + C(4, 4) + C(5, 5))) /
                  15;
  const Matrix6d s = C.inverse();
  m.bulk_reuss = 1.0 / (s(0, 0) + s(1, 1) + s(2, 2) + 2 * (s(0, 1) + s(0, 2) + s(1, 2)));
  m.shear_reuss = 15.0 / (4 * (s(0, 0) + s(1, 1) + s(2, 2)) - 4 * (s(0, 1) + s(0, 2) + s(1, 2)) +
                          3 * (s(3, 3) + s(4, 4) + s(5, 5)));
  return m;
}

std::vector<Eigen::Matrix3d> fit_deformations(int dimension, double max_stretch, int steps) {
  if (!(max_stretch > 1.0) || steps < 1)
    throw InputError("fit range invalid")
        .key("max-stretch")
        .value(std::to_string(max_stretch))
        .expected("a stretch > 1 and at least one step");
  const int nd = dimension == 2 ? 2 : 3;
  std::vector<Eigen::Matrix3d> set;
  for (int s = 1; s <= steps; ++s) {
    const double lam = 1.0 + (max_stretch - 1.0) * s / steps;
    for (double l : {lam, 1.0 / lam}) {
      for (int d = 0; d < nd; ++d) {  // uniaxial (lateral F = 1)
        Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
        F(d, d) = l;
        set.push_back(F);
      }
      Eigen::Matrix3d B = Eigen::Matrix3d::Identity();  // equi-biaxial in xy
      B(0, 0) = B(1, 1) = l;
      set.push_back(B);
    }
    const double g = lam - 1.0;  // simple shear
    for (int d = 0; d < nd; ++d)
      for (int e = 0; e < nd; ++e)
        if (d != e) {
          Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
          F(d, e) = g;
          set.push_back(F);
        }
  }
  return set;
}

NeoHookeanFit fit_neo_hookean(const CauchyBorn& cb, const std::vector<Eigen::Matrix3d>& set) {
  const CauchyBornState s0 = cb.evaluate(Eigen::Matrix3d::Identity(), false);
  const double W0 = s0.W;
  const Eigen::Matrix3d S0 = s0.P;  // at F = I the second PK stress equals P
  Eigen::MatrixXd G(static_cast<Eigen::Index>(set.size()), 2);
  Eigen::VectorXd w(static_cast<Eigen::Index>(set.size()));
  for (std::size_t s = 0; s < set.size(); ++s) {
    const Eigen::Matrix3d& F = set[s];
    const double J = F.determinant();
    const double I1b = std::pow(J, -2.0 / 3.0) * (F.transpose() * F).trace();
    const auto r = static_cast<Eigen::Index>(s);
    G(r, 0) = 0.5 * (I1b - 3.0);
    G(r, 1) = 0.125 * (J - 1.0 / J) * (J - 1.0 / J);
    const Eigen::Matrix3d E = 0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity());
    w(r) = cb.energy(F) - W0 - (S0.array() * E.array()).sum();
  }
  const Eigen::Vector2d c = G.colPivHouseholderQr().solve(w);
  NeoHookeanFit fit;
  fit.mu = c(0);
  fit.bulk = c(1);
  fit.samples = static_cast<int>(set.size());
  fit.reference_stress = S0;
  const double n = static_cast<double>(set.size());
  fit.rms_error = std::sqrt((G * c - w).squaredNorm() / n);
  fit.relative_error = fit.rms_error / std::sqrt(w.squaredNorm() / n);
  return fit;
}

namespace {
/// Axial quantities of a one-bond family of length r along x: t_x = ½φ'(r), K_xx = ½φ''(r).
void one_bond(const atomistic::Potential& pot, int ti, int tj, double r, double& tx, double& kxx) {
  const double y[3] = {r, 0.0, 0.0};
  double t[3], K[9], work[9];
  atomistic::FamilyState f;
  f.type = ti;
  f.size = 1;
  f.neighbor_type = &tj;
  f.bond = y;
  pot.force_state(f, t);
  pot.force_state_tangent(f, K, work);
  tx = t[0];
  kxx = K[0];
}
}  // namespace

double pair_inflection_stretch(const atomistic::Potential& pot, int ti, int tj) {
  if (!pot.pairwise())
    throw InputError("bond inflection rule needs a pair potential")
        .key("pair_style")
        .value(pot.style())
        .expected("lj/cut, morse (bond-based)")
        .fix("use uniaxial_peak_stretch (Cauchy–Born peak stress) for many-body potentials");
  const double rc = pot.cutoff();
  const int n = 4000;
  double r0 = 0.0, rinf = 0.0, tprev = 0.0, kprev = 0.0;
  for (int s = 1; s <= n; ++s) {
    const double r = rc * s / n;
    double tx, kxx;
    one_bond(pot, ti, tj, r, tx, kxx);
    if (s > 1 && r0 == 0.0 && tprev < 0.0 && tx >= 0.0) {
      // minimum: t changes sign; refine by bisection
      double lo = r - rc / n, hi = r;
      for (int it = 0; it < 100; ++it) {
        const double mid = 0.5 * (lo + hi);
        double tm, km;
        one_bond(pot, ti, tj, mid, tm, km);
        (tm < 0.0 ? lo : hi) = mid;
      }
      r0 = 0.5 * (lo + hi);
    } else if (r0 > 0.0 && kprev > 0.0 && kxx <= 0.0) {
      double lo = r - rc / n, hi = r;
      for (int it = 0; it < 100; ++it) {
        const double mid = 0.5 * (lo + hi);
        double tm, km;
        one_bond(pot, ti, tj, mid, tm, km);
        (km > 0.0 ? lo : hi) = mid;
      }
      rinf = 0.5 * (lo + hi);
      break;
    }
    tprev = tx;
    kprev = kxx;
  }
  if (r0 == 0.0 || rinf == 0.0)
    throw InputError("pair energy has no minimum and inflection within the cutoff")
        .key("types")
        .value(std::to_string(ti) + " " + std::to_string(tj))
        .expected("a bonding pair interaction (φ with a minimum inside the cutoff)");
  return rinf / r0;
}

double uniaxial_peak_stretch(const CauchyBorn& cb, const Eigen::Vector3d& direction,
                             double max_stretch, int steps) {
  const Eigen::Vector3d nvec = direction.normalized();
  auto F_of = [&](double lam) {
    return Eigen::Matrix3d(Eigen::Matrix3d::Identity() + (lam - 1.0) * nvec * nvec.transpose());
  };
  // dP_nn/dλ = n_i n_J A_iJkL n_k n_L
  auto slope = [&](double lam) {
    const CauchyBornState s = cb.evaluate(F_of(lam), true);
    double v = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 3; ++J)
        for (int k = 0; k < 3; ++k)
          for (int L = 0; L < 3; ++L)
            v += nvec[i] * nvec[J] * nvec[k] * nvec[L] * s.A(3 * i + J, 3 * k + L);
    return v;
  };
  double prev = 1.0, sprev = slope(1.0);
  for (int s = 1; s <= steps; ++s) {
    const double lam = 1.0 + (max_stretch - 1.0) * s / steps;
    const double sl = slope(lam);
    if (sprev > 0.0 && sl <= 0.0) {
      double lo = prev, hi = lam;
      for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi);
        (slope(mid) > 0.0 ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi);
    }
    prev = lam;
    sprev = sl;
  }
  return 0.0;
}

LatticeNote cauchy_born_lattice_note(const LatticeInfo& lattice, IonRelaxation ion) {
  if (ion != IonRelaxation::clamped && lattice.perfect) return {};
  if (ion == IonRelaxation::clamped && lattice.perfect && !lattice.bravais() &&
      !lattice.centrosymmetric)
    return {fmt::format(
                "Cauchy–Born: {}, whose sites are not centres of inversion (as in diamond, hcp, "
                "honeycomb): clamped-ion (unrelaxed) values requested — every atom follows F, "
                "the basis is not relaxed, so W, P and the elastic constants are too stiff "
                "(shear constants such as C44 most). The relaxed-ion values: `pdcg elastic` "
                "without --clamped-ion, the body-level `model: cauchy-born` material",
                lattice.summary),
            true};
  if (lattice.perfect) return {};
  return {fmt::format("Cauchy–Born: {}: inner relaxation unavailable (it needs a perfect "
                      "crystal): W, P and C are those of the atoms held at the affinely deformed "
                      "positions — clamped-ion, no relaxation of basis, defect, surface or "
                      "displaced atoms",
                      lattice.summary),
          true};
}

LatticeNote cauchy_born_lattice_note(const LatticeInfo& lattice) {
  if (lattice.bravais()) return {};
  if (lattice.perfect && lattice.centrosymmetric) return {};
  if (lattice.perfect)
    return {fmt::format(
                "Cauchy–Born: {}, whose sites are not centres of inversion (as in diamond, hcp, "
                "honeycomb): every atom follows F, the basis is not relaxed, so W, P and the "
                "elastic constants are the clamped-ion (unrelaxed) values — too stiff, shear "
                "constants such as C44 most. The relaxed-ion values: the default material "
                "(IonRelaxation::automatic or relaxed), `pdcg elastic` without --clamped-ion",
                lattice.summary),
            true};
  return {fmt::format("Cauchy–Born: {}: W, P and C are those of the atoms held at the affinely "
                      "deformed positions (no relaxation of defect, surface or displaced atoms)",
                      lattice.summary),
          false};
}

}  // namespace pdcg::body
