#include "pdcg/dynamics/dynamics.hpp"

#include <fmt/format.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <unordered_map>

#include "eam_kernel.hpp"
#include "pdcg/atomistic/eam_spline.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace pdcg::dynamics {

using std::size_t;

void check_masses(const body::Body& body, const std::string& source) {
  if (body.size() == 0) throw InputError("the body has no points").source(source);
  if (body.mass.size() != body.size())
    throw InputError("the body has no masses")
        .source(source)
        .expected("one mass per point")
        .fix(
            "give masses (`mass` commands or a Masses section) when building the body with "
            "atoms2pd");
  for (size_t k = 0; k < body.size(); ++k)
    if (!(std::isfinite(body.mass[k]) && body.mass[k] > 0.0))
      throw InputError("missing or non-positive mass")
          .source(source)
          .key(fmt::format("atom id {}", body.id[k]))
          .value(fmt::format("{}", body.mass[k]))
          .expected("a finite positive mass for every point")
          .fix(
              "set the masses of all types when building the body (`mass` commands or a Masses "
              "section)");
}

namespace {

/// Gershgorin row sums of one EAM family's Hessian in O(n) instead of O(n²): with the analytic
/// tangent of the native EAM (EamModel::force_state_tangent)
///   A_jm = δ_jm D_j + F''_k u_j u_mᵀ,   u_j = ρ'_{j→k}(r_j) Y_j/r_j,
///   D_j = T_j/r I + (T_j'/r − T_j/r²)/r Y_j⊗Y_j,  T_j = F'_k ρ'_j + ½φ'_j,
/// the sums of the general loop are closed forms: Σ_j A_jm = D_m + F'' U u_mᵀ (U = Σ_j u_j),
/// Σ_m A_jm = D_j + F'' u_j Uᵀ, Σ_jm A_jm = Σ_j D_j + F'' U Uᵀ, and the off-diagonal part of
/// row a of neighbour j is |F''| |u_ja| (Σ_m Σ_b |u_mb| − Σ_b |u_jb|). Same spline formulas
/// as the tangent, so the bound equals the general one to round-off. D: 9n, u: 3n doubles.
void eam_family_rows(const atomistic::EamView& E, const body::Body& body, const double* bonds,
                     std::int64_t k, double* D, double* u, double* local) {
  const auto& fam = body.families;
  const auto b0 = fam.offset[static_cast<size_t>(k)];
  const auto n = fam.offset[static_cast<size_t>(k) + 1] - b0;
  const double* fac = fam.pair_factor.empty() ? nullptr : fam.pair_factor.data() + b0;
  const int n1 = E.ntypes + 1;
  const int kt = body.type[static_cast<size_t>(k)];
  using atomistic::eam::locate;
  auto jtype = [&](std::int64_t b) {
    return body.type[static_cast<size_t>(fam.neighbor[static_cast<size_t>(b0 + b)])];
  };
  double rho = 0.0;
  for (std::int64_t b = 0; b < n; ++b) {
    if (fac && fac[b] == 0.0) continue;
    const double* y = bonds + 3 * (b0 + b);
    const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
    if (rsq < E.cutforcesq) {
      int m;
      bool cl;
      const double p = locate(std::sqrt(rsq), E.rdr, E.nr, m, cl);
      const double* c = E.rhor[static_cast<size_t>(jtype(b) * n1 + kt)] + 7 * m;
      rho += ((c[3] * p + c[4]) * p + c[5]) * p + c[6];
    }
  }
  const atomistic::eam::Embedding emb =
      atomistic::eam::embedding(E.frho[static_cast<size_t>(kt)], rho, E.rdrho, E.nrho, E.rhomax);
  const double fp = emb.first, fpp = emb.second;
  double U[3] = {0, 0, 0}, S1 = 0.0, Dsum[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (std::int64_t b = 0; b < n; ++b) {
    const double* y = bonds + 3 * (b0 + b);
    double* d = D + 9 * b;
    double* ub = u + 3 * b;
    std::fill(d, d + 9, 0.0);
    ub[0] = ub[1] = ub[2] = 0.0;
    const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
    if (!(rsq < E.cutforcesq) || (fac && fac[b] == 0.0)) continue;
    const int jt = jtype(b);
    const double r = std::sqrt(rsq);
    int mm;
    bool cl;
    const double q = locate(r, E.rdr, E.nr, mm, cl);
    const double* c1 = E.rhor[static_cast<size_t>(jt * n1 + kt)] + 7 * mm;
    const double* c2 = E.z2r[static_cast<size_t>(kt * n1 + jt)] + 7 * mm;
    const atomistic::eam::PairTerms pt = atomistic::eam::pair_terms(c1, c2, q, cl, r, E.rdr);
    const double g = pt.g, recip = 1.0 / r;
    const double T = fp * g + 0.5 * pt.phip;
    const double Tp = fp * pt.gp + 0.5 * pt.phipp;
    const double sI = T * recip, cY = (Tp * recip - T * recip * recip) * recip;
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 3; ++c) d[3 * a + c] += cY * y[a] * y[c] + (a == c ? sI : 0.0);
    for (int a = 0; a < 3; ++a) {
      ub[a] = g * y[a] * recip;
      U[a] += ub[a];
      S1 += std::abs(ub[a]);
    }
    for (int c = 0; c < 9; ++c) Dsum[c] += d[c];
  }
  double rowk[3] = {0, 0, 0};
  for (std::int64_t b = 0; b < n; ++b) {
    const double* d = D + 9 * b;
    const double* ub = u + 3 * b;
    const double uj1 = std::abs(ub[0]) + std::abs(ub[1]) + std::abs(ub[2]);
    const size_t dof = 3 * static_cast<size_t>(fam.neighbor[static_cast<size_t>(b0 + b)]);
    for (int a = 0; a < 3; ++a) {
      double s = std::abs(fpp) * std::abs(ub[a]) * (S1 - uj1);  // blocks m ≠ j
      for (int c = 0; c < 3; ++c) {
        s += std::abs(d[3 * a + c] + fpp * ub[a] * ub[c]);       // block m = j
        s += std::abs(d[3 * a + c] + fpp * ub[a] * U[c]);        // |H_jk| = |Σ_m A_jm|
        rowk[a] += std::abs(d[3 * a + c] + fpp * U[a] * ub[c]);  // |H_km| = |Σ_j A_jm|
      }
      local[dof + static_cast<size_t>(a)] += s;
    }
  }
  for (int a = 0; a < 3; ++a) {
    double s = rowk[a];
    for (int c = 0; c < 3; ++c) s += std::abs(Dsum[3 * a + c] + fpp * U[a] * U[c]);  // |H_kk|
    local[3 * static_cast<size_t>(k) + static_cast<size_t>(a)] += s;
  }
}

}  // namespace

StableStep stable_time_step(const body::Body& body, std::span<const double> y) {
  check_masses(body, "body");
  const auto& fam = body.families;
  const size_t n = body.size();
  std::vector<double> bonds(3 * fam.bonds());
  atomistic::deformed_bonds(fam, y.empty() ? std::span<const double>(body.x) : y, fam.h, bonds);
  std::int64_t max_family = 0;
  for (size_t k = 0; k < n; ++k)
    max_family = std::max(max_family, fam.offset[k + 1] - fam.offset[k]);
  const auto& pot = *body.potential;
  // row[i]: Σ_k Σ_l |H⁽ᵏ⁾_il| for the 3N dofs. Families scatter into their neighbours' rows,
  // so each thread accumulates its own copy (computed once per run: memory 3N per thread).
  std::vector<double> row(3 * n, 0.0);
  const atomistic::EamView* eam = body.statistics ? nullptr : pot.eam_view();
  if (eam && std::any_of(body.type.begin(), body.type.end(), [&](int t) {
        return t < 1 || t > eam->ntypes || !eam->frho[static_cast<size_t>(t)];
      }))
    eam = nullptr;  // the general path gives NaN for an uncovered type
#pragma omp parallel
  {
    const size_t nf = static_cast<size_t>(max_family);
    std::vector<double> K(eam ? 9 * nf : 9 * nf * nf),
        work(atomistic::Potential::tangent_workspace(max_family));
    std::vector<double> rowk(3 * (nf + 1)), sumj(9 * nf), summ(9 * nf), local(3 * n, 0.0);
    std::vector<int> ntype(nf);
#pragma omp for schedule(dynamic, 64)
    for (std::int64_t k = 0; k < static_cast<std::int64_t>(n); ++k) {
      const auto b0 = fam.offset[static_cast<size_t>(k)];
      const auto m = fam.offset[static_cast<size_t>(k) + 1] - b0;
      if (m == 0) continue;
      if (eam) {
        eam_family_rows(*eam, body, bonds.data(), k, K.data(), work.data(), local.data());
        continue;
      }
      const size_t nm = static_cast<size_t>(m);
      for (size_t j = 0; j < nm; ++j)
        ntype[j] = body.type[static_cast<size_t>(fam.neighbor[static_cast<size_t>(b0) + j])];
      const atomistic::FamilyState st =
          atomistic::family_state(fam, static_cast<size_t>(k), body.type[static_cast<size_t>(k)],
                                  ntype.data(), bonds.data() + 3 * b0);
      if (pot.pairwise()) {
        // ψ_k = ½ Σ_j φ(r_kj): t_kj depends on Y_kj alone, A_jm = 0 for j ≠ m, and the
        // diagonal block is the tangent of the one-bond family {j} (O(n) instead of O(n²)).
        for (size_t j = 0; j < nm; ++j) {
          atomistic::FamilyState one = st;
          one.size = 1;
          one.neighbor_type = ntype.data() + j;
          one.bond = st.bond + 3 * j;
          if (st.pair_factor) one.pair_factor = st.pair_factor + j;
          if (st.bond_type) one.bond_type = st.bond_type + j;
          pot.force_state_tangent(one, K.data() + (j * nm + j) * 9, work.data());
        }
      } else {
        pot.force_state_tangent(st, K.data(), work.data());
      }
      // sumj[m] = Σ_j A_jm (column sums), summ[j] = Σ_m A_jm (row sums), 3×3 each.
      std::fill(sumj.begin(), sumj.begin() + 9 * static_cast<std::ptrdiff_t>(nm), 0.0);
      std::fill(summ.begin(), summ.begin() + 9 * static_cast<std::ptrdiff_t>(nm), 0.0);
      std::fill(rowk.begin(), rowk.end(), 0.0);
      double kk[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      const bool diagonal = pot.pairwise();  // only blocks j = m were written
      for (size_t j = 0; j < nm; ++j)
        for (size_t mm = diagonal ? j : 0; mm < (diagonal ? j + 1 : nm); ++mm) {
          const double* A = K.data() + (j * nm + mm) * 9;
          for (int c = 0; c < 9; ++c) {
            sumj[mm * 9 + static_cast<size_t>(c)] += A[c];
            summ[j * 9 + static_cast<size_t>(c)] += A[c];
            kk[c] += A[c];
          }
        }
      // Rows of neighbour j: |A_jm| over m, |H_jk| = |Σ_m A_jm|.
      for (size_t j = 0; j < nm; ++j) {
        const size_t dof = 3 * static_cast<size_t>(fam.neighbor[static_cast<size_t>(b0) + j]);
        for (int a = 0; a < 3; ++a) {
          double s = 0.0;
          for (size_t mm = diagonal ? j : 0; mm < (diagonal ? j + 1 : nm); ++mm) {
            const double* A = K.data() + (j * nm + mm) * 9;
            s += std::abs(A[3 * a]) + std::abs(A[3 * a + 1]) + std::abs(A[3 * a + 2]);
          }
          const double* S = summ.data() + j * 9;
          s += std::abs(S[3 * a]) + std::abs(S[3 * a + 1]) + std::abs(S[3 * a + 2]);
          local[dof + static_cast<size_t>(a)] += s;
        }
      }
      // Row of k: |H_km| = |Σ_j A_jm|, |H_kk| = |Σ_jm A_jm|.
      for (int a = 0; a < 3; ++a) {
        double s = std::abs(kk[3 * a]) + std::abs(kk[3 * a + 1]) + std::abs(kk[3 * a + 2]);
        for (size_t mm = 0; mm < nm; ++mm) {
          const double* S = sumj.data() + mm * 9;
          s += std::abs(S[3 * a]) + std::abs(S[3 * a + 1]) + std::abs(S[3 * a + 2]);
        }
        local[3 * static_cast<size_t>(k) + static_cast<size_t>(a)] += s;
      }
    }
#pragma omp critical
    for (size_t i = 0; i < 3 * n; ++i) row[i] += local[i];
  }
  const double c = unit_constants(body.units).ftm2v;
  StableStep out;
  double w2 = 0.0;
  for (size_t i = 0; i < 3 * n; ++i) {
    const double r = c * row[i] / body.mass[i / 3];
    if (r > w2) {
      w2 = r;
      out.critical_id = body.id[i / 3];
    }
  }
  out.omega_bound = std::sqrt(w2);
  out.dt_stable = w2 > 0.0 ? 2.0 / out.omega_bound : std::numeric_limits<double>::infinity();
  return out;
}

void require_stable_time_step(double dt, const StableStep& limit, bool force) {
  if (force || dt <= limit.dt_stable) return;
  throw InputError("time step above the stable limit")
      .key("dt")
      .value(fmt::format("{:.6g}", dt))
      .expected(
          fmt::format("dt <= {:.6g} = 2/ω_bound (Gershgorin bound ω_bound = {:.6g} at atom id {}; "
                      "the requested dt is {:.4g}× the limit)",
                      limit.dt_stable, limit.omega_bound, limit.critical_id, dt / limit.dt_stable))
      .fix("use a smaller time step, or --force-unstable to run anyway");
}

std::vector<double> thermal_velocities(const body::Body& body, double temperature,
                                       std::uint64_t seed) {
  check_masses(body, "body");
  if (!(temperature >= 0.0) || !std::isfinite(temperature))
    throw InputError("bad temperature")
        .key("temperature")
        .value(fmt::format("{}", temperature))
        .expected("T >= 0");
  const size_t n = body.size();
  const int d = std::clamp(body.dimension, 1, 3);
  std::vector<double> v(3 * n, 0.0);
  if (temperature == 0.0 || n < 2) return v;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  double p[3] = {0, 0, 0}, mtot = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double s = 1.0 / std::sqrt(body.mass[k]);
    for (int a = 0; a < d; ++a) {
      v[3 * k + static_cast<size_t>(a)] = s * g(rng);
      p[a] += body.mass[k] * v[3 * k + static_cast<size_t>(a)];
    }
    mtot += body.mass[k];
  }
  double ke2 = 0.0;  // Σ M v²
  for (size_t k = 0; k < n; ++k)
    for (int a = 0; a < d; ++a) {
      double& vi = v[3 * k + static_cast<size_t>(a)];
      vi -= p[a] / mtot;
      ke2 += body.mass[k] * vi * vi;
    }
  const auto uc = unit_constants(body.units);
  const double dof = static_cast<double>(d) * static_cast<double>(n - 1);
  const double t_now = uc.mvv2e * ke2 / (dof * uc.boltz);
  const double f = std::sqrt(temperature / t_now);
  for (auto& vi : v) vi *= f;
  return v;
}

std::vector<double> velocities_from_atoms(const body::Body& body, const atomistic::Atoms& atoms,
                                          const std::string& source) {
  if (atoms.v.size() != 3 * atoms.size())
    throw InputError("no velocities in the file")
        .source(source)
        .expected("columns vx vy vz (LAMMPS dump custom … vx vy vz)")
        .fix("dump velocities, or use --temperature or no velocity option (zero)");
  if (atoms.size() != body.size())
    throw InputError("the velocity file has a different number of atoms than the body")
        .source(source)
        .value(std::to_string(atoms.size()))
        .expected(fmt::format("{} atoms with the body's ids", body.size()));
  // both sorted by id
  std::vector<size_t> order(atoms.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return atoms.id[a] < atoms.id[b]; });
  std::vector<double> v(3 * body.size());
  for (size_t k = 0; k < body.size(); ++k) {
    const size_t i = order[k];
    if (atoms.id[i] != body.id[k])
      throw InputError("atom ids of the velocity file differ from the body's")
          .source(source)
          .key("id")
          .value(std::to_string(atoms.id[i]))
          .expected(fmt::format("id {}", body.id[k]));
    for (int a = 0; a < 3; ++a)
      v[3 * k + static_cast<size_t>(a)] = atoms.v[3 * i + static_cast<size_t>(a)];
  }
  return v;
}

bool eam_vector_kernel_available() { return detail::eam_avx2_available(); }

VelocityVerlet::VelocityVerlet(const body::Body& body, std::vector<double> y0,
                               std::vector<double> v0, double dt, Kernels kernels)
    : body_(body), ev_(body), y_(std::move(y0)), v_(std::move(v0)), dt_(dt) {
  check_masses(body, "body");
  if (!(dt > 0.0) || !std::isfinite(dt))
    throw InputError("bad time step")
        .key("dt")
        .value(fmt::format("{}", dt))
        .expected("a positive number");
  const size_t n = body.size();
  if (y_.empty()) y_ = body.x;
  if (v_.empty()) v_.assign(3 * n, 0.0);
  if (y_.size() != 3 * n || v_.size() != 3 * n)
    throw InputError("positions/velocities do not match the body")
        .expected(fmt::format("3×{} values", n));
  const auto uc = unit_constants(body.units);
  ftm2v_ = uc.ftm2v;
  mvv2e_ = uc.mvv2e;
  boltz_ = uc.boltz;
  inv_mass_.resize(n);
  for (size_t k = 0; k < n; ++k) inv_mass_[k] = 1.0 / body.mass[k];
  f_.resize(3 * n);
  const bool general = kernels == Kernels::general;
  half_ = !general && body.potential->pairwise() && !body.statistics;
  if (!general && !body.statistics) eam_ = body.potential->eam_view();
  if (eam_ && (eam_->ntypes < 1 || std::any_of(body.type.begin(), body.type.end(), [&](int t) {
                 return t < 1 || t > eam_->ntypes || !eam_->frho[static_cast<size_t>(t)];
               })))
    eam_ = nullptr;  // the general path reports the bad type (NaN force states)
  if (half_ || eam_) setup_half();
  // the many-body kernel (sw, tersoff): delta bodies without molecular bonds or special factors
  const auto& pot = *body.potential;
  manybody_ = !general && !half_ && !eam_ && !body.statistics &&
              body.kind == body::BodyKind::delta && pot.has_manybody_kernel() &&
              body.families.pair_factor.empty() && body.families.bond_type.empty() &&
              body.horizon() > 0.0 && std::all_of(body.type.begin(), body.type.end(), [&](int t) {
                return t >= 1 && t <= pot.ntypes();
              });
  if (manybody_) setup_manybody();
  // the vector EAM passes (no special factors)
  if (eam_ && kernels == Kernels::automatic && half_factor_.empty() && detail::eam_avx2_available())
    eam_rows_ = std::make_shared<const detail::EamRows>(detail::make_eam_rows(*eam_));
  evaluate();
}

void VelocityVerlet::setup_half() {
  const auto& fam = body_.families;
  const size_t n = body_.size();
  half_offset_.assign(n + 1, 0);
  type_ext_.assign(body_.type.begin(), body_.type.end());
  // one ghost per distinct (point, image n): key j·2^32 + packed n (10 bits per component)
  std::unordered_map<std::uint64_t, std::int32_t> ghost_of;
  std::int64_t widest = 0;
  for (size_t k = 0; k < n; ++k) {
    for (auto b = fam.offset[k]; b < fam.offset[k + 1]; ++b) {
      const auto ub = static_cast<size_t>(b);
      const auto j = static_cast<size_t>(fam.neighbor[ub]);
      if (!(j > k || (j == k && fam.reverse[ub] > b))) continue;  // the other half holds it
      const int img[3] = {fam.shift[3 * ub], fam.shift[3 * ub + 1], fam.shift[3 * ub + 2]};
      std::int32_t target = fam.neighbor[ub];
      if (img[0] != 0 || img[1] != 0 || img[2] != 0) {
        std::uint64_t key = static_cast<std::uint64_t>(j) << 32;
        for (int a = 0; a < 3; ++a) {
          if (img[a] < -511 || img[a] > 511)
            throw std::logic_error("setup_half: periodic image beyond ±511 boxes");
          key |= static_cast<std::uint64_t>(img[a] + 512) << (10 * a);
        }
        const auto [it, added] =
            ghost_of.emplace(key, static_cast<std::int32_t>(n + ghost_atom_.size()));
        if (added) {
          const Eigen::Vector3d s = fam.h * Eigen::Vector3d(img[0], img[1], img[2]);
          ghost_atom_.push_back(fam.neighbor[ub]);
          ghost_shift_.insert(ghost_shift_.end(), {s[0], s[1], s[2]});
          type_ext_.push_back(body_.type[j]);
        }
        target = it->second;
      }
      half_neighbor_.push_back(target);
      half_type_.push_back(body_.type[j]);
      if (!fam.pair_factor.empty()) half_factor_.push_back(fam.pair_factor[ub]);
      if (!fam.bond_type.empty()) half_bond_type_.push_back(fam.bond_type[ub]);
    }
    half_offset_[k + 1] = static_cast<std::int64_t>(half_neighbor_.size());
    widest = std::max(widest, half_offset_[k + 1] - half_offset_[k]);
  }
  // padding: the vector EAM passes read the neighbours (and their types) in blocks of 4
  half_neighbor_.insert(half_neighbor_.end(), 3, 0);
  half_type_.insert(half_type_.end(), 3, 1);
  if (n + ghost_atom_.size() > static_cast<size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::length_error("setup_half: more than 2^31 points and ghosts");
  const size_t next = n + ghost_atom_.size();
  // + 1: the vector EAM passes read and update 4 doubles per point
  y_.resize(3 * next + 1);
  f_.resize(3 * next + 1);
  update_ghosts();
  const int threads = omp_get_max_threads();
  thread_f_.assign(static_cast<size_t>(threads), std::vector<double>(3 * next + 1));
  thread_y_.assign(static_cast<size_t>(threads),
                   std::vector<double>(3 * static_cast<size_t>(widest) + 3));
  thread_t_.assign(static_cast<size_t>(threads),
                   std::vector<double>(3 * static_cast<size_t>(widest) + 3));
  if (eam_) {
    thread_rho_.assign(static_cast<size_t>(threads), std::vector<double>(next));
    rho_.assign(next, 0.0);
    fp_.assign(next, 0.0);
  }
}

/// Ghosts for every (point, image) a family bond reaches, the bonds' point/ghost indices with
/// each family's owned bonds first (the half rule of setup_half), and the list arrays (a list
/// holds at most its family: no reallocation when rebuilt).
void VelocityVerlet::setup_manybody() {
  const auto& fam = body_.families;
  const size_t n = body_.size();
  type_ext_.assign(body_.type.begin(), body_.type.end());
  mb_reference_.assign(body_.x.begin(), body_.x.end());
  std::unordered_map<std::uint64_t, std::int32_t> ghost_of;
  mb_bond_ext_.resize(fam.bonds());
  mb_bond_owned_.assign(n, 0);
  for (size_t k = 0; k < n; ++k) {
    auto pos = static_cast<size_t>(fam.offset[k]);
    for (int pass = 0; pass < 2; ++pass)
      for (auto b = fam.offset[k]; b < fam.offset[k + 1]; ++b) {
        const auto ub = static_cast<size_t>(b);
        const auto j = static_cast<size_t>(fam.neighbor[ub]);
        const bool owned = j > k || (j == k && fam.reverse[ub] > b);
        if (owned != (pass == 0)) continue;
        const int img[3] = {fam.shift[3 * ub], fam.shift[3 * ub + 1], fam.shift[3 * ub + 2]};
        std::int32_t target = fam.neighbor[ub];
        if (img[0] != 0 || img[1] != 0 || img[2] != 0) {
          std::uint64_t key = static_cast<std::uint64_t>(j) << 32;
          for (int a = 0; a < 3; ++a) key |= static_cast<std::uint64_t>(img[a] + 512) << (10 * a);
          const auto [it, added] =
              ghost_of.emplace(key, static_cast<std::int32_t>(n + ghost_atom_.size()));
          if (added) {
            const Eigen::Vector3d sh = fam.h * Eigen::Vector3d(img[0], img[1], img[2]);
            ghost_atom_.push_back(fam.neighbor[ub]);
            ghost_shift_.insert(ghost_shift_.end(), {sh[0], sh[1], sh[2]});
            type_ext_.push_back(body_.type[j]);
            for (int a = 0; a < 3; ++a)
              mb_reference_.push_back(body_.x[3 * j + static_cast<size_t>(a)] + sh[a]);
          }
          target = it->second;
        }
        mb_bond_ext_[pos++] = target;
        if (owned) ++mb_bond_owned_[k];
      }
  }
  if (n + ghost_atom_.size() > static_cast<size_t>(std::numeric_limits<std::int32_t>::max()))
    throw std::length_error("setup_manybody: more than 2^31 points and ghosts");
  const size_t next = n + ghost_atom_.size();
  y_.resize(3 * next);
  f_.resize(3 * next);
  update_ghosts();
  thread_f_.assign(static_cast<size_t>(omp_get_max_threads()), std::vector<double>(3 * next));
  mb_neighbor_.resize(fam.bonds());
  mb_count_.assign(n, 0);
  mb_owned_.assign(n, 0);
  mb_built_y_.assign(3 * n, 0.0);
  // list radius r_c + skin, skin = 0.1 r_c (Si sw: 0.38 Å; LAMMPS's metal default is 2 Å, but
  // PairSW/PairTersoff then filter that list every step as the kernels here filter theirs)
  const double rc = body_.potential->short_cutoff();
  const double skin = 0.1 * rc;
  mb_list_sq_ = (rc + skin) * (rc + skin);
  mb_short_cutoff_ = rc;
  mb_half_skin_sq_ = 0.25 * skin * skin;
  mb_family_sq_ = body_.horizon() * body_.horizon();
}

/// Short lists at the current positions (ghosts up to date): the family bonds of each point
/// shorter than the list radius, owned ones first.
void VelocityVerlet::build_short_lists() {
  const auto& fam = body_.families;
  const std::int64_t n = static_cast<std::int64_t>(body_.size());
  const double* y = y_.data();
  const double listsq = mb_list_sq_;
  double worst = 0.0;
#pragma omp parallel for schedule(static) reduction(max : worst) if (n > 2048)
  for (std::int64_t k = 0; k < n; ++k) {
    const auto b0 = fam.offset[static_cast<size_t>(k)];
    const auto b1 = fam.offset[static_cast<size_t>(k) + 1];
    const auto bown = b0 + mb_bond_owned_[static_cast<size_t>(k)];
    const double* yk = y + 3 * k;
    std::int32_t* out = mb_neighbor_.data() + b0;
    std::int32_t c = 0, owned = 0;
    for (auto b = b0; b < b1; ++b) {
      const std::int32_t e = mb_bond_ext_[static_cast<size_t>(b)];
      const double* ye = y + 3 * static_cast<std::int64_t>(e);
      const double dx = ye[0] - yk[0], dy = ye[1] - yk[1], dz = ye[2] - yk[2];
      if (dx * dx + dy * dy + dz * dz < listsq) {
        out[c++] = e;
        if (b < bown) ++owned;
      }
    }
    double d2 = 0.0;  // displacement from the reference
    for (int a = 0; a < 3; ++a) {
      const double d = yk[a] - body_.x[3 * static_cast<size_t>(k) + static_cast<size_t>(a)];
      d2 += d * d;
    }
    worst = std::max(worst, d2);
    mb_count_[static_cast<size_t>(k)] = c;
    mb_owned_[static_cast<size_t>(k)] = owned;
    for (int a = 0; a < 3; ++a)
      mb_built_y_[3 * static_cast<size_t>(k) + static_cast<size_t>(a)] = yk[a];
  }
  mb_built_ = true;
  mb_displacement_ = std::sqrt(worst);
  ++mb_builds_;
}

/// Forces and energy through the many-body kernel; false (nothing written) when the kernel
/// met a configuration it does not reproduce (Potential::manybody_forces), after which the
/// general path is used for the rest of the run.
bool VelocityVerlet::evaluate_manybody() {
  const std::int64_t n = static_cast<std::int64_t>(body_.size());
  const std::int64_t next = n + static_cast<std::int64_t>(ghost_atom_.size());
  update_ghosts();
  // rebuild when a point has moved by more than half the skin (Neighbor::decide)
  if (!mb_built_) {
    build_short_lists();
  } else {
    double worst = 0.0;
    const double* y = y_.data();
    const double* yb = mb_built_y_.data();
#pragma omp parallel for schedule(static) reduction(max : worst) if (n > 2048)
    for (std::int64_t i = 0; i < 3 * n; i += 3) {
      const double dx = y[i] - yb[i], dy = y[i + 1] - yb[i + 1], dz = y[i + 2] - yb[i + 2];
      worst = std::max(worst, dx * dx + dy * dy + dz * dz);
    }
    if (worst > mb_half_skin_sq_) build_short_lists();
  }
  // Until the next build no point is farther than D + skin/2 from its reference (D: at the
  // build), so two points within r_c are within r_c + 2(D + skin/2) at the reference: in each
  // other's family while that is below the family cutoff. Beyond it a partner within r_c may
  // be missing from a family, which ψ_k ignores and the short lists cannot see: hand over.
  if (!(mb_short_cutoff_ + 2.0 * (mb_displacement_ + std::sqrt(mb_half_skin_sq_)) <
        body_.horizon()))
    return false;
  const auto& pot = *body_.potential;
  atomistic::ShortLists lists;
  lists.offset = body_.families.offset.data();
  lists.count = mb_count_.data();
  lists.owned = mb_owned_.data();
  lists.neighbor = mb_neighbor_.data();
  lists.type = type_ext_.data();
  lists.reference = mb_reference_.data();
  lists.family_cutsq = mb_family_sq_;
  const int nthreads = std::min<int>(omp_get_max_threads(), static_cast<int>(thread_f_.size()));
  const double* y = y_.data();
  double energy = 0.0;
  bool ok = true;
#pragma omp parallel num_threads(nthreads) reduction(+ : energy) reduction(&& : ok) if (n > 2048)
  {
    const auto tid = static_cast<size_t>(omp_get_thread_num());
    const int used = omp_get_num_threads();
    double* f = used == 1 ? f_.data() : thread_f_[tid].data();
    std::fill(f, f + 3 * next, 0.0);
    const std::int64_t k0 = n * static_cast<std::int64_t>(tid) / used;
    const std::int64_t k1 = n * (static_cast<std::int64_t>(tid) + 1) / used;
    bool applicable = true;
    energy += pot.manybody_forces(lists, k0, k1, y, f, applicable);
    ok = ok && applicable;
    reduce_thread_forces(f, used);  // the last work of the region
  }
  if (!ok) return false;
  potential_ = energy;
  return true;
}

/// Ghost positions y_g = y_a + H·n (called inside or outside a parallel region).
void VelocityVerlet::update_ghosts() {
  const std::int64_t ng = static_cast<std::int64_t>(ghost_atom_.size());
  double* y = y_.data();
  double* yg = y + 3 * body_.size();
  const std::int32_t* a = ghost_atom_.data();
  const double* s = ghost_shift_.data();
#pragma omp for schedule(static)
  for (std::int64_t g = 0; g < ng; ++g)
    for (int c = 0; c < 3; ++c) yg[3 * g + c] = y[3 * a[g] + c] + s[3 * g + c];
}

/// Inside a parallel region of `used` threads, the last work of every thread: folds the ghost
/// entries of this thread's force copy f, then (several threads) sums the copies thread_f_
/// into f_, each thread a static slice of the 3n values, in thread order. No barrier at the
/// end: the region's end is one.
void VelocityVerlet::reduce_thread_forces(double* f, int used) {
  fold_ghosts(f, 3);
  if (used == 1) return;
  const std::int64_t n3 = 3 * static_cast<std::int64_t>(body_.size());
#pragma omp barrier
#pragma omp for schedule(static) nowait
  for (std::int64_t i = 0; i < n3; ++i) {
    double s = 0.0;
    for (int th = 0; th < used; ++th)
      s += thread_f_[static_cast<size_t>(th)][static_cast<size_t>(i)];
    f_[static_cast<size_t>(i)] = s;
  }
}

/// Adds the ghost entries of one array (stride values per point) to their points (serial: a
/// point can have several ghosts; each thread folds its own copy).
void VelocityVerlet::fold_ghosts(double* f, size_t stride) const {
  const double* fg = f + stride * body_.size();
  const std::int32_t* a = ghost_atom_.data();
  const size_t ng = ghost_atom_.size();
  if (stride == 3) {
    for (size_t g = 0; g < ng; ++g) {
      double* fa = f + 3 * static_cast<size_t>(a[g]);
      fa[0] += fg[3 * g];
      fa[1] += fg[3 * g + 1];
      fa[2] += fg[3 * g + 2];
    }
    return;
  }
  for (size_t g = 0; g < ng; ++g)
    for (size_t c = 0; c < stride; ++c)
      f[stride * static_cast<size_t>(a[g]) + c] += fg[stride * g + c];
}

void VelocityVerlet::evaluate_eam() {
  const std::int64_t n = static_cast<std::int64_t>(body_.size());
  const atomistic::EamView& E = *eam_;
  const int n1 = E.ntypes + 1;
  const int nr1 = E.nr - 1, nrho = E.nrho;
  const double rdr = E.rdr, rdrho = E.rdrho, rhomax = E.rhomax, cutsq = E.cutforcesq;
  const double* const* rhor = E.rhor.data();
  const double* const* z2r = E.z2r.data();
  const double* const* frho = E.frho.data();
  const int nthreads = std::min<int>(omp_get_max_threads(), static_cast<int>(thread_f_.size()));
  const double* y = y_.data();
  const int* type = body_.type.data();
  const std::int64_t* off = half_offset_.data();
  const std::int32_t* nb = half_neighbor_.data();
  const int* nbt = half_type_.data();
  const std::int64_t next = n + static_cast<std::int64_t>(ghost_atom_.size());
  const std::int32_t* ga = ghost_atom_.data();
  const double* fac = half_factor_.empty() ? nullptr : half_factor_.data();
  double* rho = rho_.data();
  double* fp = fp_.data();
  const detail::EamRows* rows = eam_rows_.get();
  detail::EamHalf hf;
  hf.offset = off;
  hf.neighbor = nb;
  hf.neighbor_type = nbt;
  hf.type = type;
  double energy = 0.0;
#pragma omp parallel num_threads(nthreads) reduction(+ : energy) if (n > 2048)
  {
    const auto tid = static_cast<size_t>(omp_get_thread_num());
    const int used = omp_get_num_threads();  // 1 when the `if` clause keeps it serial
    double* trho = used == 1 ? rho : thread_rho_[tid].data();
    double* f = used == 1 ? f_.data() : thread_f_[tid].data();
    update_ghosts();
    std::fill(trho, trho + next, 0.0);
    std::fill(f, f + 3 * next, 0.0);
    // this thread's static block of points in the two pair passes
    const std::int64_t k0 = n * static_cast<std::int64_t>(tid) / used;
    const std::int64_t k1 = n * (static_cast<std::int64_t>(tid) + 1) / used;
    // pass 1: ρ̄ (PairEAM::compute, density of j at k and of k at j from one distance)
    if (rows) detail::eam_density_avx2(*rows, hf, k0, k1, y, trho);
    for (std::int64_t k = rows ? k1 : k0; k < k1; ++k) {
      const double xk = y[3 * k], yk = y[3 * k + 1], zk = y[3 * k + 2];
      const int kt = type[k];
      double rk = 0.0;
      for (std::int64_t b = off[k]; b < off[k + 1]; ++b) {
        if (fac && fac[b] == 0.0) continue;  // LAMMPS excludes these pairs
        const std::int64_t j = nb[b];
        const double dx = y[3 * j] - xk, dy = y[3 * j + 1] - yk, dz = y[3 * j + 2] - zk;
        const double rsq = dx * dx + dy * dy + dz * dz;
        if (rsq < cutsq) {
          const int jt = nbt[b];
          double p = std::sqrt(rsq) * rdr + 1.0;
          int m = static_cast<int>(p);
          m = std::min(m, nr1);
          p -= m;
          p = std::min(p, 1.0);
          const double* c = rhor[jt * n1 + kt] + 7 * m;
          rk += ((c[3] * p + c[4]) * p + c[5]) * p + c[6];
          const double* d = rhor[kt * n1 + jt] + 7 * m;
          trho[j] += ((d[3] * p + d[4]) * p + d[5]) * p + d[6];
        }
      }
      trho[k] += rk;
    }
    fold_ghosts(trho, 1);  // this thread's copy
#pragma omp barrier
    // pass 2: ρ̄ summed over the thread copies, F(ρ̄) and F'(ρ̄) (linear beyond ρ_max), and F'
    // of the ghosts (LAMMPS's forward communication of fp): copied on one thread; with several,
    // evaluated from the same sum of the copies in the same loop (the same value, one barrier
    // fewer per step)
    if (used == 1) {
      for (std::int64_t k = 0; k < n; ++k) {
        const atomistic::eam::Embedding emb =
            atomistic::eam::embedding(frho[type[k]], rho[k], rdrho, nrho, rhomax);
        fp[k] = emb.first;
        energy += emb.value;
      }
      for (std::int64_t g = n; g < next; ++g) fp[g] = fp[ga[g - n]];
    } else {
#pragma omp for schedule(static)
      for (std::int64_t k = 0; k < next; ++k) {
        const std::int64_t a = k < n ? k : ga[k - n];
        double r = 0.0;
        for (int th = 0; th < used; ++th)
          r += thread_rho_[static_cast<size_t>(th)][static_cast<size_t>(a)];
        const atomistic::eam::Embedding emb =
            atomistic::eam::embedding(frho[type[a]], r, rdrho, nrho, rhomax);
        fp[k] = emb.first;
        if (k < n) {
          rho[k] = r;
          energy += emb.value;
        }
      }
    }
    // pass 3: pair forces and energies
    if (rows) energy += detail::eam_forces_avx2(*rows, hf, k0, k1, y, fp, f);
    for (std::int64_t k = rows ? k1 : k0; k < k1; ++k) {
      const double xk = y[3 * k], yk = y[3 * k + 1], zk = y[3 * k + 2];
      const int kt = type[k];
      const double fpk = fp[k];
      double fx = 0.0, fy = 0.0, fz = 0.0, e = 0.0;
      for (std::int64_t b = off[k]; b < off[k + 1]; ++b) {
        if (fac && fac[b] == 0.0) continue;
        const std::int64_t j = nb[b];
        const double dx = y[3 * j] - xk, dy = y[3 * j + 1] - yk, dz = y[3 * j + 2] - zk;
        const double rsq = dx * dx + dy * dy + dz * dz;
        if (rsq < cutsq) {
          const int jt = nbt[b];
          const double r = std::sqrt(rsq);
          double p = r * rdr + 1.0;
          int m = static_cast<int>(p);
          m = std::min(m, nr1);
          p -= m;
          p = std::min(p, 1.0);
          const double* c1 = rhor[jt * n1 + kt] + 7 * m;
          const double rhojp = (c1[0] * p + c1[1]) * p + c1[2];
          const double* c2 = rhor[kt * n1 + jt] + 7 * m;
          const double rhokp = (c2[0] * p + c2[1]) * p + c2[2];
          const double* c3 = z2r[kt * n1 + jt] + 7 * m;
          const double z2p = (c3[0] * p + c3[1]) * p + c3[2];
          const double z2 = ((c3[3] * p + c3[4]) * p + c3[5]) * p + c3[6];
          const double recip = 1.0 / r;
          const double phi = z2 * recip;
          const double phip = z2p * recip - phi * recip;
          const double s = (fpk * rhojp + fp[j] * rhokp + phip) * recip;
          e += phi;
          fx += s * dx;
          fy += s * dy;
          fz += s * dz;
          f[3 * j] -= s * dx;
          f[3 * j + 1] -= s * dy;
          f[3 * j + 2] -= s * dz;
        }
      }
      f[3 * k] += fx;
      f[3 * k + 1] += fy;
      f[3 * k + 2] += fz;
      energy += e;
    }
    reduce_thread_forces(f, used);  // the last work of the region
  }
  potential_ = energy;
}

void VelocityVerlet::evaluate_pairwise(bool with_energy) {
  const std::int64_t n = static_cast<std::int64_t>(body_.size());
  const auto& pot = *body_.potential;
  const int nthreads = std::min<int>(omp_get_max_threads(), static_cast<int>(thread_f_.size()));
  double energy = 0.0;
  const std::int64_t next = n + static_cast<std::int64_t>(ghost_atom_.size());
  const double* y = y_.data();
  const bool kernel = pot.has_pair_kernel();
  atomistic::HalfFamilies h;
  h.offset = half_offset_.data();
  h.neighbor = half_neighbor_.data();
  h.type = type_ext_.data();
  h.factor = half_factor_.empty() ? nullptr : half_factor_.data();
  h.energy = with_energy || !kernel;
#pragma omp parallel num_threads(nthreads) reduction(+ : energy) if (n > 2048)
  {
    const auto tid = static_cast<size_t>(omp_get_thread_num());
    const int used = omp_get_num_threads();  // 1 when the `if` clause keeps it serial
    double* f = used == 1 ? f_.data() : thread_f_[tid].data();
    double* Y = thread_y_[tid].data();
    double* t = thread_t_[tid].data();
    update_ghosts();
    std::fill(f, f + 3 * next, 0.0);
    if (kernel) {
      // the potential's inlined pair loop over this thread's static block of points
      const std::int64_t k0 = n * static_cast<std::int64_t>(tid) / used;
      const std::int64_t k1 = n * (static_cast<std::int64_t>(tid) + 1) / used;
      energy += pot.half_pair_forces(h, k0, k1, y, f);
    } else {
#pragma omp for schedule(static) nowait
      for (std::int64_t k = 0; k < n; ++k) {
        const auto b0 = half_offset_[static_cast<size_t>(k)];
        const auto m = half_offset_[static_cast<size_t>(k) + 1] - b0;
        if (m == 0) continue;
        const double* yk = y + 3 * k;
        for (std::int64_t q = 0; q < m; ++q) {
          const auto b = static_cast<size_t>(b0 + q);
          const double* yj = y + 3 * static_cast<std::int64_t>(half_neighbor_[b]);
          for (int a = 0; a < 3; ++a) Y[3 * q + a] = yj[a] - yk[a];
        }
        atomistic::FamilyState st;
        st.type = body_.type[static_cast<size_t>(k)];
        st.size = m;
        st.neighbor_type = half_type_.data() + b0;
        st.bond = Y;
        st.pair_factor = half_factor_.empty() ? nullptr : half_factor_.data() + b0;
        st.bond_type = half_bond_type_.empty() ? nullptr : half_bond_type_.data() + b0;
        energy += 2.0 * pot.force_state(st, t);
        double fk[3] = {0.0, 0.0, 0.0};
        for (std::int64_t q = 0; q < m; ++q) {
          double* fj =
              f + 3 * static_cast<std::int64_t>(half_neighbor_[static_cast<size_t>(b0 + q)]);
          for (int a = 0; a < 3; ++a) {
            fk[a] += 2.0 * t[3 * q + a];
            fj[a] -= 2.0 * t[3 * q + a];
          }
        }
        for (int a = 0; a < 3; ++a) f[3 * k + a] += fk[a];
      }
    }
    reduce_thread_forces(f, used);  // the last work of the region
  }
  potential_ = energy;
  potential_current_ = h.energy;
}

/// Σφ at the current positions through the pair kernel (serial, forces into scratch), for
/// thermo() after a forces-only step.
double VelocityVerlet::pair_energy() const {
  atomistic::HalfFamilies h;
  h.offset = half_offset_.data();
  h.neighbor = half_neighbor_.data();
  h.type = type_ext_.data();
  h.factor = half_factor_.empty() ? nullptr : half_factor_.data();
  auto& scratch = thread_f_[0];
  std::fill(scratch.begin(), scratch.end(), 0.0);
  return body_.potential->half_pair_forces(h, 0, static_cast<std::int64_t>(body_.size()), y_.data(),
                                           scratch.data());
}

void VelocityVerlet::evaluate(bool energy) {
  potential_current_ = true;
  if (eam_) {
    evaluate_eam();  // F(ρ̄) and φ are needed for the forces anyway
    return;
  }
  if (half_) {
    evaluate_pairwise(energy);
    return;
  }
  if (manybody_ && !mb_fallback_) {
    if (evaluate_manybody()) return;
    mb_fallback_ = true;
    log::warn(
        "md: at step {} an atom is {:.3g} from its reference position: with the short-list "
        "skin, two atoms within the cutoff {:.6g} may now be beyond the family cutoff {:.6g} "
        "at the reference (or an atom has more than 512 partners within the cutoff), which "
        "the many-body kernel cannot represent; continuing with the general evaluation of the "
        "fixed families (slower). A larger --family-cutoff (atoms2pd) keeps the kernel",
        step_, mb_displacement_, mb_short_cutoff_, body_.horizon());
  }
  const auto e = ev_.deformed(std::span<const double>(y_.data(), 3 * body_.size()));
  potential_ = e.energy;
  std::copy(e.forces.begin(), e.forces.end(), f_.begin());
}

void VelocityVerlet::step(bool energy) {
  const std::int64_t n = static_cast<std::int64_t>(body_.size());
  const double dtf = 0.5 * dt_ * ftm2v_, dtv = dt_;
  double* y = y_.data();
  double* v = v_.data();
  const double* f = f_.data();
  const double* im = inv_mass_.data();
#pragma omp parallel for schedule(static) if (n > 2048)
  for (std::int64_t k = 0; k < n; ++k) {
    const double s = dtf * im[k];
    for (std::int64_t a = 3 * k; a < 3 * k + 3; ++a) {
      v[a] += s * f[a];
      y[a] += dtv * v[a];
    }
  }
  // forces at the new positions (no allocation after the first call)
  evaluate(energy);
  const double* fn = f_.data();
#pragma omp parallel for schedule(static) if (n > 2048)
  for (std::int64_t k = 0; k < n; ++k) {
    const double s = dtf * im[k];
    for (std::int64_t a = 3 * k; a < 3 * k + 3; ++a) v[a] += s * fn[a];
  }
  ++step_;
}

Thermo VelocityVerlet::thermo() const {
  Thermo t;
  t.step = step_;
  t.time = static_cast<double>(step_) * dt_;
  const std::int64_t n = static_cast<std::int64_t>(body_.size());
  double ke2 = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : ke2) if (n > 2048)
  for (std::int64_t k = 0; k < n; ++k) {
    const double* vk = v_.data() + 3 * k;
    ke2 += body_.mass[static_cast<size_t>(k)] * (vk[0] * vk[0] + vk[1] * vk[1] + vk[2] * vk[2]);
  }
  t.kinetic = 0.5 * mvv2e_ * ke2;
  t.potential = potential_current_ ? potential_ : pair_energy();
  t.total = t.kinetic + t.potential;
  const double dof =
      std::clamp(body_.dimension, 1, 3) * static_cast<double>(std::max<std::int64_t>(n - 1, 1));
  t.temperature = 2.0 * t.kinetic / (dof * boltz_);
  return t;
}

struct DumpWriter::Impl {
  explicit Impl(const std::string& p) : file(p) {}
  io::AtomicTextFile file;
  std::string buffer;
};

DumpWriter::DumpWriter(const std::string& path) : impl_(new Impl(path)) {}
DumpWriter::~DumpWriter() { delete impl_; }

void DumpWriter::write(const body::Body& body, std::int64_t step, std::span<const double> y,
                       std::span<const double> v) {
  const auto& b = body.box;
  auto& s = impl_->file.stream();
  const size_t n = body.size();
  const char* pf[3];
  for (int a = 0; a < 3; ++a) pf[a] = b.periodic[static_cast<size_t>(a)] ? "pp" : "ff";
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{}\n", step,
                 n);
  if (b.triclinic()) {
    const double xlo = b.lo[0] + std::min({0.0, b.xy, b.xz, b.xy + b.xz});
    const double xhi = b.hi[0] + std::max({0.0, b.xy, b.xz, b.xy + b.xz});
    const double ylo = b.lo[1] + std::min(0.0, b.yz), yhi = b.hi[1] + std::max(0.0, b.yz);
    fmt::format_to(std::back_inserter(out),
                   "ITEM: BOX BOUNDS xy xz yz {} {} {}\n{:.17g} {:.17g} {:.17g}\n{:.17g} {:.17g} "
                   "{:.17g}\n{:.17g} {:.17g} {:.17g}\n",
                   pf[0], pf[1], pf[2], xlo, xhi, b.xy, ylo, yhi, b.xz, b.lo[2], b.hi[2], b.yz);
  } else {
    fmt::format_to(std::back_inserter(out),
                   "ITEM: BOX BOUNDS {} {} {}\n{:.17g} {:.17g}\n{:.17g} {:.17g}\n{:.17g} {:.17g}\n",
                   pf[0], pf[1], pf[2], b.lo[0], b.hi[0], b.lo[1], b.hi[1], b.lo[2], b.hi[2]);
  }
  fmt::format_to(std::back_inserter(out), "ITEM: ATOMS id type x y z ix iy iz vx vy vz\n");
  for (size_t k = 0; k < n; ++k) {
    Eigen::Vector3i img(0, 0, 0);
    const Eigen::Vector3d w = b.wrap(Eigen::Vector3d(y[3 * k], y[3 * k + 1], y[3 * k + 2]), img);
    fmt::format_to(std::back_inserter(out),
                   "{} {} {:.17g} {:.17g} {:.17g} {} {} {} {:.17g} {:.17g} {:.17g}\n", body.id[k],
                   body.type[k], w[0], w[1], w[2], img[0], img[1], img[2], v[3 * k], v[3 * k + 1],
                   v[3 * k + 2]);
  }
  s.write(out.data(), static_cast<std::streamsize>(out.size()));
}

void DumpWriter::commit() { impl_->file.commit(); }

}  // namespace pdcg::dynamics
