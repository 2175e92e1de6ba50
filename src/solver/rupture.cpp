#include "pdcg/solver/rupture.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::solver {

namespace {

/// F_S = I + Σ_{m∈S} u_m ⊗ G^m of stencil s (docs/theory.md §6, eq. 6.2; G^m = g_S^m V_m as
/// stored in Stencils::grad), in the first d rows and columns; members in stencil order.
Mat3 stencil_deformation_gradient(const Stencils& S, std::size_t s, const Eigen::VectorXd& u,
                                  int d) {
  Mat3 F = Mat3::Identity();
  for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) {
    const int m = S.index[r];
    const double* g = S.grad.data() + r * d;
    for (int a = 0; a < d; ++a)
      for (int J = 0; J < d; ++J) F(a, J) += u[d * m + a] * g[J];
  }
  return F;
}

/// Adds one Newton solve (a re-equilibration or a polish) to the stagger cost: its assembly
/// and linear-solve time, factorisations and GMRES iterations, and its Newton iterations
/// (those it took to converge, or every iteration of its residual history if it failed).
void add_newton_cost(StaggerCost& cost, const StepReport& rep, bool converged) {
  cost.assembly_seconds += rep.assembly_seconds;
  cost.solve_seconds += rep.solve_seconds;
  cost.factorisations += rep.factorisations;
  cost.krylov_iterations += rep.krylov_iterations;
  cost.newton_iterations +=
      converged ? rep.iterations : static_cast<int>(rep.residual_history.size());
}

}  // namespace

RuptureCriterion parse_rupture_criterion(const std::string& name) {
  if (name == "bond_stretch") return RuptureCriterion::bond_stretch;
  if (name == "principal_stretch") return RuptureCriterion::principal_stretch;
  if (name == "energy_density") return RuptureCriterion::energy_density;
  if (name == "fracture_energy") return RuptureCriterion::fracture_energy;
  throw InputError("unknown rupture criterion")
      .key("rupture.criterion")
      .value(name)
      .expected("one of: bond_stretch, principal_stretch, energy_density, fracture_energy");
}

RuptureSoftening parse_rupture_softening(const std::string& name) {
  if (name == "none") return RuptureSoftening::none;
  if (name == "linear") return RuptureSoftening::linear;
  throw InputError("unknown rupture softening law")
      .key("rupture.softening")
      .value(name)
      .expected("one of: none, linear");
}

std::string to_string(RuptureSoftening s) {
  return s == RuptureSoftening::linear ? "linear" : "none";
}

double linear_softening_damage(double kappa, double psi_c, double elastic_limit) {
  // docs/fracture.md §6.1: linear softening in the equivalent strain e = √κ
  const double e = std::sqrt(std::max(0.0, kappa)), e0 = std::sqrt(elastic_limit * psi_c),
               ef = std::sqrt(psi_c / elastic_limit);
  if (e <= e0) return 0.0;
  if (e >= ef) return 1.0;
  return 1.0 - (e0 / e) * (ef - e) / (ef - e0);
}

double fracture_energy_shape_factor(int dimension) {
  // ⟨|ξ·n|⟩/δ over an interior family weighted by φ̂(r) ∝ overlap of two δ-balls at distance r
  // (docs/fracture.md §5: 3D ∫₀¹s³f/(2∫₀¹s²f), 2D 2∫₀¹s²f/(π∫₀¹s f), f the overlap fraction).
  const double pi = 3.14159265358979323846, r3 = 1.7320508075688772935;
  if (dimension == 3) return 61.0 / 175.0;
  if (dimension == 2)
    return 8.0 * (128.0 + 20.0 * pi - 81.0 * r3) / (45.0 * pi * (4.0 * pi - 3.0 * r3));
  throw Error(
      fmt::format("internal error: fracture_energy_shape_factor of dimension {}", dimension));
}

std::string to_string(RuptureCriterion c) {
  switch (c) {
    case RuptureCriterion::bond_stretch:
      return "bond_stretch";
    case RuptureCriterion::principal_stretch:
      return "principal_stretch";
    case RuptureCriterion::energy_density:
      return "energy_density";
    case RuptureCriterion::fracture_energy:
      return "fracture_energy";
  }
  return "?";
}

Rupture::Rupture(Discretization& body, Model& model, RuptureOptions options)
    : body_(&body), model_(&model), opt_(options) {
  if (&model.body() != &body) throw Error("internal error: Rupture on a model of another body");
  body.enable_rupture();
  // Anchor stiffness: the small-strain stiffness scale of one point, max|A(I)| V / Δx².
  Tangent A;
  Mat3 P;
  model.material().evaluate(Mat3::Identity(), nullptr, &P, &A);
  anchor_stiffness_ = A.cwiseAbs().maxCoeff() * std::pow(body.spacing(), body.dimension() - 2);
  if (opt_.softening != RuptureSoftening::none) {
    if (opt_.criterion != RuptureCriterion::fracture_energy)
      throw InputError("a softening failure law needs the fracture_energy criterion")
          .key("rupture.softening")
          .value(to_string(opt_.softening))
          .expected("criterion: fracture_energy (its G_c calibrates the softening)");
    if (!(opt_.elastic_limit > 0 && opt_.elastic_limit <= 1))
      throw InputError("the elastic limit of the softening law is e₀/e_f, in (0, 1]")
          .key("rupture.elastic_limit")
          .value(fmt::format("{}", opt_.elastic_limit))
          .expected("0 < elastic_limit ≤ 1, e.g. 0.1");
    if (!(opt_.damage_tolerance > 0 && opt_.damage_tolerance < 1))
      throw InputError("the damage tolerance of the staggered passes must be in (0, 1)")
          .key("rupture.damage_tolerance")
          .value(fmt::format("{}", opt_.damage_tolerance))
          .expected("0 < damage_tolerance < 1, e.g. 1e-3");
    if (!(opt_.max_damage_increment > 0 && opt_.max_damage_increment <= 1))
      throw InputError("the largest damage increment per pass must be in (0, 1]")
          .key("rupture.max_damage_increment")
          .value(fmt::format("{}", opt_.max_damage_increment))
          .expected("0 < max_damage_increment ≤ 1, e.g. 0.1");
  }
  if (opt_.criterion == RuptureCriterion::fracture_energy) {
    if (!(opt_.fracture_energy > 0) || !std::isfinite(opt_.fracture_energy))
      throw InputError(
          "the fracture_energy rupture criterion needs a critical energy release "
          "rate G_c > 0")
          .key("rupture.G_c")
          .value(fmt::format("{}", opt_.fracture_energy))
          .expected("G_c > 0 (or surface_energy γ > 0, G_c = 2γ)");
    opt_.critical = 1.0;  // the criterion value is W_ij / W_c,ij
    psi_c_ =
        opt_.fracture_energy / (fracture_energy_shape_factor(body.dimension()) * body.horizon());
    const Csr& fam = body.families();
    const Stencils& S = body.bond_stencils();
    const std::size_t nb = fam.index.size();
    reverse_.assign(nb, -1);
    work_c_.assign(nb, 0.0);
    work_.assign(nb, 0.0);
    psi_last_.assign(nb, 0.0);
    for (std::size_t i = 0; i < body.size(); ++i) {
      double psi0 = 0;  // Ψ(I) of the material at i (a Cauchy–Born W need not vanish there)
      model.material().evaluate_at(static_cast<int>(i), Mat3::Identity(), &psi0, nullptr, nullptr);
      for (auto q = fam.begin(i); q < fam.end(i); ++q) {
        const auto r = body.bond_index(fam.index[q], static_cast<int>(i));
        if (r < 0) throw Error("internal error: family not symmetric");
        reverse_[q] = r;
        psi_last_[q] = psi0;
        // both directions' reference weights V_iφ̂⁰_ijV_j: the pair's share of Ψ|Ω|
        work_c_[q] = psi_c_ * (S.weight[q] + S.weight[r]);
      }
    }
    if (softening()) {
      // work_ is the history κ, psi_last_ the damage d (both 0: intact, undamaged)
      std::fill(psi_last_.begin(), psi_last_.end(), 0.0);
      energy_last_.assign(nb, 0.0);
      y_pair_.assign(nb, 0.0);
      to_break_.assign(nb, 0);
      psi_ref_.assign(body.size(), 0.0);
      for (std::size_t i = 0; i < body.size(); ++i)
        model.material().evaluate_at(static_cast<int>(i), Mat3::Identity(), &psi_ref_[i], nullptr,
                                     nullptr);
      // allocate the stiffness factors now (all 1: no weight or lens changes)
      if (nb > 0) body.set_bond_stiffness_factor(0, 1.0);
    }
  }
}

void Rupture::restore_work(std::vector<double> work, std::vector<double> last_psi,
                           double dissipated) {
  if (work.size() != work_.size() || last_psi.size() != psi_last_.size())
    throw InputError("checkpoint: the bond work arrays do not match the body")
        .key("rupture/work")
        .value(fmt::format("{} values", work.size()))
        .expected(fmt::format("{} (one per directed bond)", work_.size()));
  work_ = std::move(work);
  psi_last_ = std::move(last_psi);
  dissipated_ = dissipated;
  if (softening())  // the damage of the intact pairs scales their weights again
    for (std::size_t q = 0; q < psi_last_.size(); ++q) {
      if (body_->broken(static_cast<std::int64_t>(q))) continue;
      const double d = psi_last_[q];
      if (!(d >= 0 && d < 1))
        throw InputError("checkpoint: a bond damage outside [0, 1) on an intact bond")
            .key("rupture/work_psi")
            .value(fmt::format("{}", d))
            .expected("the damage d of the softening law, 0 ≤ d < 1");
      body_->set_bond_stiffness_factor(static_cast<std::int64_t>(q), 1.0 - d);
    }
  // the lenses of the damaged pairs' ends take their shares (a pure function of the damage
  // and the broken set, like restore's rebuild)
  if (softening()) body_->rebuild_broken(opt_.min_reciprocal_condition);
}

bool Rupture::break_pair(int i, std::int64_t q) {
  const int j = body_->families().index[q];
  if (!body_->break_bond(i, j)) return false;
  if (softening()) {
    // the energy the damaged pair still stores at the last evaluation ((1 − d) of the
    // undamaged one; 0 at d = 1) is released for good
    const std::int64_t r = reverse_[q];
    const double e = (1.0 - psi_last_[q]) * (energy_last_[q] + energy_last_[r]);
    if (std::isfinite(e)) dissipated_ += e;
    energy_last_[q] = energy_last_[r] = 0.0;
    psi_last_[q] = psi_last_[r] = 1.0;
  } else if (!work_.empty()) {
    dissipated_ += work_[q] + work_[reverse_[q]];
  }
  return true;
}

double Rupture::evaluate_directed(const Eigen::VectorXd& u) const {
  const Discretization& B = *body_;
  const int d = B.dimension();
  const Csr& fam = B.families();
  const Stencils& S = B.bond_stencils();
  const auto& x = B.positions();
  const std::size_t N = B.size();
  const double ninf = -std::numeric_limits<double>::infinity();
  if (dir_.size() != fam.index.size()) dir_.assign(fam.index.size(), ninf);  // first call only
  double* dir = dir_.data();
  const Material& mat = model_->material();
  double vmax = ninf;
#pragma omp parallel for schedule(dynamic, 32) reduction(max : vmax)
  for (std::size_t i = 0; i < N; ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (B.broken(q)) {
        dir[q] = ninf;
        continue;
      }
      const int j = fam.index[q];
      if (opt_.criterion == RuptureCriterion::bond_stretch) {
        Vec3 y = x[j] - x[i];
        for (int a = 0; a < d; ++a) y(a) += u[d * j + a] - u[d * i + a];
        dir[q] = y.norm() / (x[j] - x[i]).norm();
      } else {
        const Mat3 F = stencil_deformation_gradient(S, q, u, d);
        if (softening()) {
          // the undamaged energy of the direction (the pair's Y follows below)
          double psi = 0;
          if (mat.evaluate_at(static_cast<int>(i), F, &psi, nullptr, nullptr)) {
            energy_last_[q] = B.intact_bond_weight(q) * (psi - psi_ref_[i]);
            dir[q] = 0.0;
          } else {
            dir[q] = std::numeric_limits<double>::infinity();
          }
          continue;
        }
        if (opt_.criterion == RuptureCriterion::fracture_energy) {
          // Hyperelastic: P = ∂Ψ/∂F, so ∫ φ̂ P:dF over the interval since the last check
          // (φ̂ constant in it: the weight changes only at rebuilds) is φ̂ ΔΨ on any path.
          double psi = 0;
          if (mat.evaluate_at(static_cast<int>(i), F, &psi, nullptr, nullptr)) {
            work_[q] += S.weight[q] * (psi - psi_last_[q]);
            psi_last_[q] = psi;
            dir[q] = 0.0;  // the pair ratio follows below
          } else {
            dir[q] = std::numeric_limits<double>::infinity();
          }
          continue;
        }
        if (opt_.criterion == RuptureCriterion::energy_density) {
          double psi = 0;
          // inadmissible F (J ≤ 0) counts as past every criterion
          dir[q] = mat.evaluate_at(static_cast<int>(i), F, &psi, nullptr, nullptr)
                       ? psi
                       : std::numeric_limits<double>::infinity();
        } else {
          const Mat3 Ff = mat.full_deformation_gradient(F);
          Eigen::SelfAdjointEigenSolver<Mat3> es(Ff.transpose() * Ff, Eigen::EigenvaluesOnly);
          dir[q] = std::sqrt(std::max(0.0, es.eigenvalues()(2)));
        }
      }
      // NaN counts as past the criterion (and as the maximum)
      vmax = std::isnan(dir[q]) ? std::numeric_limits<double>::infinity() : std::max(vmax, dir[q]);
    }
  if (opt_.criterion != RuptureCriterion::fracture_energy) return vmax;
  if (softening()) {
    // The pair's energy density Y = (E_ij + E_ji) / (w_ij + w_ji) (undamaged weights; +∞ if
    // a direction is inverted), then the criterion √max(κ, Y) / e_f.
    const double* E = energy_last_.data();
    const std::int64_t* rev = reverse_.data();
    double* Y = y_pair_.data();
    const double inf = std::numeric_limits<double>::infinity();
#pragma omp parallel for schedule(dynamic, 32)
    for (std::size_t i = 0; i < N; ++i)
      for (auto q = fam.begin(i); q < fam.end(i); ++q) {
        if (B.broken(q)) continue;
        const auto r = rev[q];
        const double w = B.intact_bond_weight(q) + B.intact_bond_weight(r);
        Y[q] = (dir[q] == inf || dir[r] == inf) ? inf : (w > 0 ? (E[q] + E[r]) / w : 0.0);
      }
    const double ef = std::sqrt(psi_c_ / opt_.elastic_limit);
    const double* kappa = work_.data();
    vmax = ninf;
#pragma omp parallel for schedule(dynamic, 32) reduction(max : vmax)
    for (std::size_t i = 0; i < N; ++i)
      for (auto q = fam.begin(i); q < fam.end(i); ++q) {
        if (B.broken(q)) continue;
        dir[q] = Y[q] == inf ? inf : std::sqrt(std::max(kappa[q], Y[q])) / ef;
        vmax = std::isnan(dir[q]) ? inf : std::max(vmax, dir[q]);
      }
    return vmax;
  }
  // The pair's work (both directions) against its critical work; an inverted stencil (+∞)
  // or a NaN work stays past the criterion.
  const double* W = work_.data();
  const double* Wc = work_c_.data();
  const std::int64_t* rev = reverse_.data();
  vmax = ninf;
#pragma omp parallel for schedule(dynamic, 32) reduction(max : vmax)
  for (std::size_t i = 0; i < N; ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (B.broken(q) || dir[q] == std::numeric_limits<double>::infinity()) {
        if (!B.broken(q)) vmax = dir[q];
        continue;
      }
      dir[q] = (W[q] + W[rev[q]]) / Wc[q];
      vmax = std::isnan(dir[q]) ? std::numeric_limits<double>::infinity() : std::max(vmax, dir[q]);
    }
  return vmax;
}

std::vector<double> Rupture::criterion_values(const Eigen::VectorXd& u) const {
  evaluate_directed(u);
  const Discretization& B = *body_;
  const Csr& fam = B.families();
  // symmetric value of the pair: the larger direction
  std::vector<double> val(dir_.size(), -std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < B.size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (B.broken(q)) continue;
      const auto r = B.bond_index(fam.index[q], static_cast<int>(i));
      val[q] = std::max(dir_[q], dir_[r]);
    }
  return val;
}

RupturePass Rupture::break_exceeding(const Eigen::VectorXd& u) {
  if (softening()) return soften(u);
  RupturePass pass;
  // The pair value is the larger of its two directions, so a pair is past the criterion
  // iff one of its directed values is; the largest pair value is the largest directed one.
  pass.max_value = evaluate_directed(u);
  if (pass.max_value <= opt_.critical) {
    all_rebuilt_.clear();
    return pass;
  }
  const Csr& fam = body_->families();
  const double* dir = dir_.data();
  for (std::size_t i = 0; i < body_->size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q)
      // NaN counts as broken (!(v <= critical)); break_bond returns false if already broken
      if (!body_->broken(q) && !(dir[q] <= opt_.critical))
        pass.broken += break_pair(static_cast<int>(i), q) ? 1 : 0;
  finish_breaks(u, pass);
  return pass;
}

RupturePass Rupture::soften(const Eigen::VectorXd& u) {
  // docs/fracture.md §6: the damage update of a staggered pass (d frozen in the solves)
  RupturePass pass;
  pass.max_value = evaluate_directed(u);
  const Discretization& B = *body_;
  const Csr& fam = B.families();
  const std::size_t N = B.size();
  const double psi_c = psi_c_, rho = opt_.elastic_limit, cap = opt_.max_damage_increment,
               tol = opt_.damage_tolerance;
  const double* Y = y_pair_.data();
  const std::int64_t* rev = reverse_.data();
  double* kappa = work_.data();
  double* dmg = psi_last_.data();
  char* act = to_break_.data();  // 1: damage grew, 2: the pair breaks (d = 1 or inverted)
  double dmax = 0.0;
  std::size_t damaged = 0, changed = 0;
  // each pair is updated by its lower end i < j (it owns both directions q and r)
#pragma omp parallel for schedule(dynamic, 32) reduction(+ : damaged, changed) reduction(max : dmax)
  for (std::size_t i = 0; i < N; ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      act[q] = 0;
      if (static_cast<std::size_t>(fam.index[q]) < i || B.broken(q)) continue;
      const auto r = rev[q];
      if (!(Y[q] < std::numeric_limits<double>::infinity())) {  // inverted stencil, or NaN
        act[q] = 2;
        ++changed;
        continue;
      }
      const double k = std::max(kappa[q], Y[q]);
      kappa[q] = kappa[r] = k;
      const double d0 = dmg[q], d = std::min(linear_softening_damage(k, psi_c, rho), d0 + cap);
      if (!(d > d0)) continue;
      dmax = std::max(dmax, d - d0);
      if (d - d0 > tol) ++damaged;
      dmg[q] = dmg[r] = std::min(d, 1.0);
      act[q] = d >= 1.0 ? 2 : 1;
      ++changed;
    }
  pass.damaged = damaged;
  pass.max_damage_increment = dmax;
  if (changed == 0) {
    all_rebuilt_.clear();
    return pass;
  }
  // Dissipation: the energy the update releases at fixed u (the weights fall by Δd and the
  // lenses lose the softened members' shares), Σ_s w_s (Ψ(F_s) − Ψ(I)) before − after.
  const double before = stored_energy(u), dissipated_before = dissipated_;
  std::size_t softened = 0;
  for (std::size_t i = 0; i < N; ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (act[q] == 1) {
        body_->set_bond_stiffness_factor(q, 1.0 - dmg[q]);
        body_->set_bond_stiffness_factor(rev[q], 1.0 - dmg[q]);
        ++softened;
      } else if (act[q] == 2) {
        pass.broken += break_pair(static_cast<int>(i), q) ? 1 : 0;
      }
    }
  finish_breaks(u, pass, softened > 0);
  const double after = stored_energy(u);
  if (std::isfinite(before) && std::isfinite(after))
    dissipated_ = dissipated_before + (before - after);
  return pass;
}

double Rupture::stored_energy(const Eigen::VectorXd& u) const {
  const Discretization& B = *body_;
  const Stencils& S = B.bond_stencils();
  const int d = B.dimension();
  const Material& mat = model_->material();
  double e = 0.0;
  bool ok = true;
#pragma omp parallel for schedule(static) reduction(+ : e) reduction(&& : ok)
  for (std::size_t s = 0; s < S.size(); ++s) {
    if (!(S.weight[s] > 0)) continue;
    const Mat3 F = stencil_deformation_gradient(S, s, u, d);
    double psi = 0;
    if (!mat.evaluate_at(S.center[s], F, &psi, nullptr, nullptr)) ok = false;
    e += S.weight[s] * (psi - psi_ref_[S.center[s]]);
  }
  return ok ? e : std::numeric_limits<double>::quiet_NaN();
}

void Rupture::finish_breaks(const Eigen::VectorXd& u, RupturePass& pass, bool softened) {
  // centres rebuilt over all rounds of this pass (for a local re-estimate of the stable step)
  std::vector<int> centres;
  if (pass.broken > 0 || softened) {
    pass.rebuilt = commit(u);
    centres = body_->last_rebuilt_centres();
    // A rebuilt (thinned, one-sided) BA stencil can map the current displacement to an
    // inverted F (J ≤ 0) although its bond is below the criterion; the material cannot be
    // evaluated there and the re-equilibrium could not even start. Such a bond counts as past
    // every criterion (as energy_density already treats J ≤ 0) and breaks too; repeat until
    // every intact stencil is admissible at u (bounded: each round breaks at least one bond).
    break_inverted_rounds(u, false, pass, centres);
  }
  if (pass.inverted > 0) {
    std::sort(centres.begin(), centres.end());
    centres.erase(std::unique(centres.begin(), centres.end()), centres.end());
  }
  all_rebuilt_ = std::move(centres);
  pass.anchored = model_->anchors().size();
}

void Rupture::break_inverted_rounds(const Eigen::VectorXd& u, bool check_all_first,
                                    RupturePass& pass, std::vector<int>& centres) {
  for (int round = 0; round < 100; ++round) {
    const std::vector<int> last = body_->last_rebuilt_centres();
    const std::size_t inv = break_inverted(u, &pass.point_stencils_off,
                                           round == 0 && check_all_first ? nullptr : &last);
    if (inv == 0) break;
    pass.broken += inv;
    pass.inverted += inv;
    pass.rebuilt += commit(u);
    const auto& c = body_->last_rebuilt_centres();
    centres.insert(centres.end(), c.begin(), c.end());
  }
}

RupturePass Rupture::break_inadmissible(const Eigen::VectorXd& u) {
  RupturePass pass;
  std::vector<int> centres;
  break_inverted_rounds(u, true, pass, centres);
  std::sort(centres.begin(), centres.end());
  centres.erase(std::unique(centres.begin(), centres.end()), centres.end());
  all_rebuilt_ = std::move(centres);
  pass.anchored = model_->anchors().size();
  return pass;
}

std::vector<std::int64_t> Rupture::broken_pairs() const {
  const Csr& fam = body_->families();
  std::vector<std::int64_t> out;
  for (std::size_t i = 0; i < body_->size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q)
      if (static_cast<std::size_t>(fam.index[q]) > i && body_->broken(q)) {
        out.push_back(static_cast<std::int64_t>(i));
        out.push_back(fam.index[q]);
      }
  return out;
}

void Rupture::restore(const std::vector<std::int64_t>& pairs, std::vector<int> anchor_points,
                      std::vector<double> anchor_targets,
                      const std::vector<std::int64_t>& point_stencils_off) {
  if (pairs.size() % 2 != 0) throw Error("internal error: odd broken-pair list");
  for (auto k : point_stencils_off) body_->suppress_point_stencil(static_cast<int>(k));
  for (std::size_t k = 0; k < pairs.size(); k += 2)
    body_->break_bond(static_cast<int>(pairs[k]), static_cast<int>(pairs[k + 1]));
  body_->rebuild_broken(opt_.min_reciprocal_condition);
  model_->set_anchors(std::move(anchor_points), std::move(anchor_targets), anchor_stiffness_);
}

std::size_t Rupture::break_inverted(const Eigen::VectorXd& u, std::size_t* points_off,
                                    const std::vector<int>* centres) {
  const Discretization& B = *body_;
  const int d = B.dimension();
  const Csr& fam = B.families();
  const Stencils& S = B.bond_stencils();
  const Material& mat = model_->material();
  std::vector<char> bad(fam.index.size(), 0);
  const std::size_t nc = centres ? centres->size() : B.size();
#pragma omp parallel for schedule(dynamic, 32)
  for (std::size_t ci = 0; ci < nc; ++ci) {
    const std::size_t i = centres ? static_cast<std::size_t>((*centres)[ci]) : ci;
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (B.broken(q) || !(S.weight[q] > 0)) continue;
      const Mat3 F = stencil_deformation_gradient(S, q, u, d);
      Mat3 P;
      if (!mat.evaluate_at(static_cast<int>(i), F, nullptr, &P, nullptr)) bad[q] = 1;
    }
  }
  std::size_t n = 0;
  for (std::size_t ci = 0; ci < nc; ++ci) {
    const std::size_t i = centres ? static_cast<std::size_t>((*centres)[ci]) : ci;
    for (auto q = fam.begin(i); q < fam.end(i); ++q)
      if (bad[q]) n += break_pair(static_cast<int>(i), q) ? 1 : 0;
  }
  // Weak-form rows evaluate P(F̄_k) on the point stencil {k} ∪ intact H_k: at a crack it
  // can invert too (measured in dynamic fracture: a thinned one-sided family folds). Its
  // correction P(F̄_k) e_k is dropped for good (point stencil off: F̄_k = I, P = 0).
  if (n == 0) {
    const Stencils& Pst = B.point_stencils();
    const auto& e = model_->boundary_defect();
    for (std::size_t ci = 0; ci < nc; ++ci) {
      const std::size_t k = centres ? static_cast<std::size_t>((*centres)[ci]) : ci;
      if (e[k].isZero() || B.point_stencil_suppressed(static_cast<int>(k))) continue;
      const Mat3 F = stencil_deformation_gradient(Pst, k, u, d);
      Mat3 P;
      if (!mat.evaluate_at(static_cast<int>(k), F, nullptr, &P, nullptr) &&
          body_->suppress_point_stencil(static_cast<int>(k)) && points_off)
        ++*points_off;
    }
  }
  return n;
}

std::size_t Rupture::commit(const Eigen::VectorXd& u) {
  const std::size_t n = body_->rebuild_broken(opt_.min_reciprocal_condition);
  if (softening()) {
    // as below: an ill-posed rebuilt stencil releases what its direction still stores
    const Csr& fam = body_->families();
    const Stencils& S = body_->bond_stencils();
    for (int c : body_->last_rebuilt_centres())
      for (auto q = fam.begin(c); q < fam.end(c); ++q)
        if (!body_->broken(q) && !(S.weight[q] > 0) && energy_last_[q] != 0) {
          if (std::isfinite(energy_last_[q])) dissipated_ += (1.0 - psi_last_[q]) * energy_last_[q];
          energy_last_[q] = 0;
        }
  } else if (!work_.empty()) {
    // An intact bond whose rebuilt stencil is ill-posed carries no stress any more (weight
    // 0): the work stored in it is released for good and counted as dissipated.
    const Csr& fam = body_->families();
    const Stencils& S = body_->bond_stencils();
    for (int c : body_->last_rebuilt_centres())
      for (auto q = fam.begin(c); q < fam.end(c); ++q)
        if (!body_->broken(q) && !(S.weight[q] > 0) && work_[q] != 0) {
          dissipated_ += work_[q];
          work_[q] = 0;
        }
  }
  if (n > 0) {
    if (opt_.anchor_detached)
      update_anchors(u);  // and the flux between pieces (Model::set_anchors)
    else
      model_->cut_flux_between_pieces();  // no force across a complete cut (docs/solver.md §3)
  }
  return n;
}

void Rupture::update_anchors(const Eigen::VectorXd& u) {
  // A point is coupled if some stencil of nonzero weight has a nonzero G at it. The members
  // of such a stencil are coupled to each other: union-find over the points gives the
  // pieces the body has broken into (anchor_fragments).
  const Discretization& B = *body_;
  const Stencils& S = B.bond_stencils();
  const int d = B.dimension();
  const std::size_t N = B.size();
  // pieces: the union-find runs when the held dofs are known (free fragments are parked,
  // or pieces held in only some directions pinned)
  const bool pieces = held_.size() == static_cast<std::size_t>(d) * N;
  const bool fragments = pieces && opt_.anchor_fragments;
  const bool pins = pieces && opt_.pin_partly_held;
  std::vector<char> coupled(N, 0);
  std::vector<int>& parent = fragment_parent_;
  if (pieces) {
    parent.resize(N);
    for (std::size_t k = 0; k < N; ++k) parent[k] = static_cast<int>(k);
  }
  const auto root = [&parent](int k) {
    while (parent[k] != k) k = parent[k] = parent[parent[k]];  // path halving
    return k;
  };
  for (std::size_t s = 0; s < S.size(); ++s) {
    if (!(S.weight[s] > 0)) continue;
    int first = -1;
    for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) {
      const double* g = S.grad.data() + r * d;
      bool nz = false;
      for (int a = 0; a < d; ++a) nz = nz || g[a] != 0.0;
      if (!nz) continue;
      const int m = S.index[r];
      coupled[m] = 1;
      if (!pieces) continue;
      if (first < 0) {
        first = root(m);
      } else {
        const int rm = root(m);
        if (rm != first) parent[rm] = first;
      }
    }
  }
  // A piece is held if one of its points has a prescribed component; a piece with none is a
  // free fragment: it carries no load, and its rigid motions are null modes of K. A piece
  // held in some directions only (no point of it prescribed in direction a: e.g. the upper
  // half of a separated sheet on a grip that slides in x) has its translation along a as a
  // null mode: its lowest-numbered point is pinned by the spring in those directions only.
  // No external force acts on the piece along a, so at equilibrium the pin carries none.
  std::vector<char> held_piece, held_dir;
  std::vector<int> pin_of;
  if (pieces) {
    held_piece.assign(N, 0);
    held_dir.assign(static_cast<std::size_t>(d) * N, 0);
    for (std::size_t k = 0; k < N; ++k)
      for (int a = 0; a < d; ++a)
        if (held_[d * k + a]) {
          const auto r = static_cast<std::size_t>(root(static_cast<int>(k)));
          held_piece[r] = 1;
          held_dir[d * r + a] = 1;
        }
    if (pins) {
      pin_of.assign(N, -1);
      for (std::size_t k = 0; k < N; ++k) {
        if (!coupled[k]) continue;
        const auto r = static_cast<std::size_t>(root(static_cast<int>(k)));
        if (pin_of[r] < 0) pin_of[r] = static_cast<int>(k);
      }
    }
  }
  const auto partly_held = [&](std::size_t r) {
    if (!held_piece[r]) return false;
    for (int a = 0; a < d; ++a)
      if (!held_dir[d * r + a]) return true;
    return false;
  };
  // parked at their current displacement (no force on anyone else)
  std::vector<int> pts;
  std::vector<double> tgt;
  std::size_t in_fragments = 0, roots = 0, pinned = 0;
  // a fragment point parked before keeps its target (the fragment does not creep pass by pass)
  std::vector<int> before;
  if (pieces) {
    before.assign(N, -1);
    const std::vector<int>& a = model_->anchors();
    for (std::size_t q = 0; q < a.size(); ++q) before[a[q]] = static_cast<int>(q);
  }
  const std::vector<double>& old_targets = model_->anchor_targets();
  for (std::size_t k = 0; k < N; ++k) {
    const bool free_piece = fragments && coupled[k] && !held_piece[root(static_cast<int>(k))];
    if (fragments && coupled[k] && static_cast<std::size_t>(root(static_cast<int>(k))) == k &&
        free_piece)
      ++roots;
    const std::size_t r = pieces ? static_cast<std::size_t>(root(static_cast<int>(k))) : k;
    const bool pin = pins && coupled[k] && pin_of[r] == static_cast<int>(k) && partly_held(r);
    if (coupled[k] && !free_piece && !pin) continue;
    pts.push_back(static_cast<int>(k));
    if (free_piece) ++in_fragments;
    if (pin) ++pinned;
    for (int a = 0; a < d; ++a) {
      if (pin && held_dir[d * r + a]) {  // held along a: no spring
        tgt.push_back(NAN);
        continue;
      }
      // parked or pinned before: the same target (the piece does not creep pass by pass)
      const double old =
          (free_piece || pin) && before[k] >= 0 ? old_targets[d * before[k] + a] : NAN;
      tgt.push_back(std::isnan(old) ? u[d * k + a] : old);
    }
  }
  fragment_points_ = in_fragments;
  free_fragments_ = roots;
  pinned_pieces_ = pinned;
  model_->set_anchors(std::move(pts), std::move(tgt), anchor_stiffness_);
}

std::size_t Rupture::stagger(StaticSolver& solver) {
  std::size_t total = 0;
  const auto t_start = std::chrono::steady_clock::now();
  last_cost_ = StaggerCost{};
  StaggerCost& cost = last_cost_;
  struct Account {  // adds the cost of this call to the total however it ends
    Rupture& r;
    std::chrono::steady_clock::time_point t0;
    ~Account() {
      StaggerCost& c = r.last_cost_;
      c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      StaggerCost& T = r.total_cost_;
      T.passes += c.passes;
      T.newton_iterations += c.newton_iterations;
      T.failed_newton_iterations += c.failed_newton_iterations;
      T.continuation_iterations += c.continuation_iterations;
      T.relaxation_iterations += c.relaxation_iterations;
      T.continuation_passes += c.continuation_passes;
      T.relaxation_passes += c.relaxation_passes;
      T.seconds += c.seconds;
      T.assembly_seconds += c.assembly_seconds;
      T.solve_seconds += c.solve_seconds;
      T.factorisations += c.factorisations;
      T.krylov_iterations += c.krylov_iterations;
    }
  } account{*this, t_start};
  // Stencils that invert (J ≤ 0) during the re-equilibrium (Newton's accepted states, ADR
  // iterates) break there and the solve goes on (docs/effects.md §2).
  std::size_t during = 0, during_points = 0;
  solver.set_inadmissible_handler([&](const Eigen::VectorXd& u) {
    const RupturePass p = break_inadmissible(u);
    during += p.broken;
    during_points += p.point_stencils_off;
    if (p.broken + p.point_stencils_off > 0)
      log::debug("re-equilibrium: {} bonds with an inverted stencil broke, {} point stencils off",
                 p.broken, p.point_stencils_off);
    return p.broken + p.point_stencils_off > 0;
  });
  // ADR guard: far from equilibrium (relative residual above relaxation_break_residual) an
  // iterate that inverts a stencil is rejected instead (docs/effects.md §2).
  solver.set_relaxation_break_residual(opt_.relaxation_break_residual);
  struct Reset {
    StaticSolver& s;
    int reuse;
    ~Reset() {
      s.set_inadmissible_handler({});
      s.set_relaxation_break_residual(INFINITY);
      s.set_factor_reuse(reuse);
    }
  } reset{solver, solver.factor_reuse()};
  if (opt_.factor_reuse > 0) solver.set_factor_reuse(opt_.factor_reuse);
  // Residual scale: once the crack has separated the body, the internal force is round-off
  // and the relative residual stays O(1) at the equilibrium; 1e-4 of the largest force of a
  // converged state (a load the body no longer carries) keeps the criterion meaningful and
  // changes nothing while the body carries more than that (docs/effects.md §2).
  peak_force_ = std::max(peak_force_, solver.internal_force().norm());
  // Free fragments (pieces with no prescribed dof) are parked: their rigid motions would
  // make K singular (docs/effects.md §2, "Free fragments").
  if ((opt_.anchor_fragments || opt_.pin_partly_held) && opt_.anchor_detached && held_.empty()) {
    const int d = body_->dimension();
    std::vector<char> held(static_cast<std::size_t>(d) * body_->size(), 0);
    for (const DisplacementSet& set : solver.displacement_sets())
      for (int p : set.points)
        for (int a = 0; a < d; ++a)
          if (set.component[a]) held[static_cast<std::size_t>(d) * p + a] = 1;
    held_ = std::move(held);
  }
  solver.set_force_floor(std::max(solver.force_floor(), 1e-4 * peak_force_));
  for (int pass_no = 1;; ++pass_no) {
    const RupturePass p = break_exceeding(solver.displacement());
    if (p.broken == 0 && p.damaged == 0) {  // damaged: softening pairs still moving
      if (pass_no > 1)
        log::info(
            "rupture at t = {:.6g}: no further bond past {} {} after {} passes (max {:.4g}); "
            "{} Newton iterations ({} in failed solves), {} pseudo-transient and {} ADR "
            "iterations, {:.2f} s (assembly {:.2f} s, linear solves {:.2f} s; {} Newton "
            "factorisations, {} GMRES iterations)",
            solver.load_factor(), to_string(opt_.criterion), opt_.critical, pass_no - 1,
            p.max_value, cost.newton_iterations, cost.failed_newton_iterations,
            cost.continuation_iterations, cost.relaxation_iterations,
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count(),
            cost.assembly_seconds, cost.solve_seconds, cost.factorisations, cost.krylov_iterations);
      return total;
    }
    total += p.broken;
    if (pass_no > opt_.max_passes)
      throw NumericalError(fmt::format(
          "rupture at load factor {:.6g}: bonds still breaking after {} staggered passes ({} "
          "broken in total); the crack runs unstably at fixed load — use more load steps or a "
          "larger rupture.max_passes",
          solver.load_factor(), opt_.max_passes, body_->broken_bonds()));
    ++cost.passes;
    const auto t_pass = std::chrono::steady_clock::now();
    StepReport rep;
    during = during_points = 0;
    const bool ok = solver.reequilibrate(rep);
    add_newton_cost(cost, rep, ok);
    if (!ok) cost.failed_newton_iterations += static_cast<int>(rep.residual_history.size());
    if (softening())
      log::debug("rupture pass {}: damage grew in {} pairs by more than {} (largest {:.3g})",
                 pass_no, p.damaged, opt_.damage_tolerance, p.max_damage_increment);
    log::info(
        "rupture pass {} at t = {:.6g}: {} bonds broke ({} broken in total, max {} {:.4g} > {}; "
        "{} of them with an inverted rebuilt stencil), "
        "{} stencils rebuilt, {} ill-posed stencils off, {} detached points ({} in {} free "
        "fragments, {} pins of partly held pieces); re-equilibrium: {} "
        "({} Newton iterations, residual {:.3e}, force balance {:.2e} of the load; {} bonds "
        "broke and {} point stencils went off when their stencils inverted during it; {:.2f} s)",
        pass_no, solver.load_factor(), p.broken, body_->broken_bonds(), to_string(opt_.criterion),
        p.max_value, opt_.critical, p.inverted, p.rebuilt, body_->suppressed_stencils(), p.anchored,
        fragment_points_, free_fragments_, pinned_pieces_,
        ok ? (rep.roundoff_floor ? "converged at the round-off floor" : "converged") : "FAILED",
        rep.iterations, rep.residual_history.empty() ? NAN : rep.residual_history.back(),
        ok ? solver.force_balance() : NAN, during, during_points,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_pass).count());
    if (ok) continue;
    if (opt_.pseudo_transient) {
      log::info(
          "rupture pass {} at t = {:.6g}: Newton cannot re-equilibrate after {} bonds broke "
          "(residual history {:.2e}) — the crack grows unstably at fixed load; pseudo-transient "
          "continuation",
          pass_no, solver.load_factor(), p.broken, fmt::join(rep.residual_history, " "));
      const auto t_ptc = std::chrono::steady_clock::now();
      StepReport ptc;
      during = during_points = 0;
      const bool continued =
          solver.pseudo_transient(opt_.relaxation_tolerance, opt_.continuation_iterations, ptc);
      cost.continuation_iterations += ptc.iterations;
      StepReport polish;
      const bool polished = continued && solver.reequilibrate(polish);
      cost.assembly_seconds += ptc.assembly_seconds;
      cost.solve_seconds += ptc.solve_seconds;
      add_newton_cost(cost, polish, polished);
      log::info(
          "pseudo-transient continuation: {} after {} factorisations ({} steps rejected, "
          "residual {:.3e}; {} bonds broke and {} point stencils went off when their stencils "
          "inverted); Newton polish: {} ({} iterations, residual {:.3e}); {:.2f} s",
          continued ? "converged" : (ptc.stalled ? "FAILED (stalled)" : "FAILED"), ptc.iterations,
          ptc.cutbacks, ptc.residual, during, during_points,
          polished ? "converged" : (continued ? "FAILED" : "skipped"), polish.iterations,
          polish.residual_history.empty() ? NAN : polish.residual_history.back(),
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t_ptc).count());
      if (polished) {
        ++cost.continuation_passes;
        continue;
      }
      log::warn(
          "rupture pass {} at t = {:.6g}: pseudo-transient continuation did not re-equilibrate "
          "(residual history {:.2e}); falling back to adaptive dynamic relaxation",
          pass_no, solver.load_factor(), fmt::join(ptc.residual_history, " "));
    } else {
      log::warn(
          "rupture pass {} at t = {:.6g}: Newton cannot re-equilibrate after {} bonds broke "
          "(residual history {:.2e}) — the crack grows unstably at fixed load; falling back to "
          "adaptive dynamic relaxation",
          pass_no, solver.load_factor(), p.broken, fmt::join(rep.residual_history, " "));
    }
    ++cost.relaxation_passes;
    const auto t_adr = std::chrono::steady_clock::now();
    StepReport adr;
    during = during_points = 0;
    const bool relaxed = solver.relax(opt_.relaxation_tolerance, opt_.relaxation_iterations, adr);
    cost.relaxation_iterations += adr.iterations;
    StepReport polish;
    const bool polished = relaxed && solver.reequilibrate(polish);
    add_newton_cost(cost, polish, polished);
    log::info(
        "adaptive dynamic relaxation: {} after {} iterations (residual {:.3e}; {} bonds broke "
        "and {} point stencils went off when their stencils inverted; {} steps rejected on "
        "J ≤ 0 far from equilibrium); Newton polish: {} ({} iterations, residual {:.3e}); "
        "{:.2f} s",
        relaxed ? "converged" : "FAILED", adr.iterations, adr.residual, during, during_points,
        adr.cutbacks, polished ? "converged" : (relaxed ? "FAILED" : "skipped"), polish.iterations,
        polish.residual_history.empty() ? NAN : polish.residual_history.back(),
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t_adr).count());
    if (!polished)
      throw NumericalError(fmt::format(
          "rupture at load factor {:.6g}: neither Newton{} nor adaptive dynamic relaxation "
          "({} iterations, residual {:.3e}) re-equilibrated the body after {} bonds broke "
          "(pass {}); the body may have fallen apart (a free fragment has rigid motions) — "
          "check the damage field of the last output",
          solver.load_factor(), opt_.pseudo_transient ? ", pseudo-transient continuation" : "",
          adr.iterations, adr.residual, p.broken, pass_no));
  }
}

}  // namespace pdcg::solver
