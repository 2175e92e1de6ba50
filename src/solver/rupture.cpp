#include "pdcg/solver/rupture.hpp"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::solver {

RuptureCriterion parse_rupture_criterion(const std::string& name) {
  if (name == "bond_stretch") return RuptureCriterion::bond_stretch;
  if (name == "principal_stretch") return RuptureCriterion::principal_stretch;
  if (name == "energy_density") return RuptureCriterion::energy_density;
  throw InputError("unknown rupture criterion")
      .key("rupture.criterion")
      .value(name)
      .expected("one of: bond_stretch, principal_stretch, energy_density");
}

std::string to_string(RuptureCriterion c) {
  switch (c) {
    case RuptureCriterion::bond_stretch:
      return "bond_stretch";
    case RuptureCriterion::principal_stretch:
      return "principal_stretch";
    case RuptureCriterion::energy_density:
      return "energy_density";
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
}

std::vector<double> Rupture::criterion_values(const Eigen::VectorXd& u) const {
  const Discretization& B = *body_;
  const int d = B.dimension();
  const Csr& fam = B.families();
  const Stencils& S = B.bond_stencils();
  const auto& x = B.positions();
  const std::size_t N = B.size();
  const double ninf = -std::numeric_limits<double>::infinity();
  std::vector<double> dir(fam.index.size(), ninf);
  const Material& mat = model_->material();
#pragma omp parallel for schedule(dynamic, 32)
  for (std::size_t i = 0; i < N; ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (B.broken(q)) continue;
      const int j = fam.index[q];
      if (opt_.criterion == RuptureCriterion::bond_stretch) {
        Vec3 y = x[j] - x[i];
        for (int a = 0; a < d; ++a) y(a) += u[d * j + a] - u[d * i + a];
        dir[q] = y.norm() / (x[j] - x[i]).norm();
        continue;
      }
      Mat3 F = Mat3::Identity();
      for (auto r = S.offsets[q]; r < S.offsets[q + 1]; ++r) {
        const int m = S.index[r];
        const double* g = S.grad.data() + r * d;
        for (int a = 0; a < d; ++a)
          for (int J = 0; J < d; ++J) F(a, J) += u[d * m + a] * g[J];
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
  // symmetric value of the pair: the larger direction
  std::vector<double> val(dir.size(), ninf);
#pragma omp parallel for schedule(dynamic, 32)
  for (std::size_t i = 0; i < N; ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (B.broken(q)) continue;
      const auto r = B.bond_index(fam.index[q], static_cast<int>(i));
      val[q] = std::max(dir[q], dir[r]);
    }
  return val;
}

RupturePass Rupture::break_exceeding(const Eigen::VectorXd& u) {
  RupturePass pass;
  const auto val = criterion_values(u);
  const Csr& fam = body_->families();
  pass.max_value = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < body_->size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      const int j = fam.index[q];
      if (!body_->broken(q)) pass.max_value = std::max(pass.max_value, val[q]);
      // each pair once (i < j); NaN counts as broken (!(v <= critical))
      if (j > static_cast<int>(i) && !body_->broken(q) && !(val[q] <= opt_.critical))
        pass.broken += body_->break_bond(static_cast<int>(i), j) ? 1 : 0;
    }
  if (pass.broken > 0) pass.rebuilt = commit(u);
  // A rebuilt (thinned, one-sided) BA stencil can map the current displacement to an
  // inverted F (J ≤ 0) although its bond is below the criterion; the material cannot be
  // evaluated there and the re-equilibrium could not even start. Such a bond counts as past
  // every criterion (as energy_density already treats J ≤ 0) and breaks too; repeat until
  // every intact stencil is admissible at u (bounded: each round breaks at least one bond).
  for (int round = 0; pass.broken > 0 && round < 100; ++round) {
    const std::size_t inv = break_inverted(u);
    if (inv == 0) break;
    pass.broken += inv;
    pass.inverted += inv;
    pass.rebuilt += commit(u);
  }
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
                      std::vector<double> anchor_targets) {
  if (pairs.size() % 2 != 0) throw Error("internal error: odd broken-pair list");
  for (std::size_t k = 0; k < pairs.size(); k += 2)
    body_->break_bond(static_cast<int>(pairs[k]), static_cast<int>(pairs[k + 1]));
  body_->rebuild_broken(opt_.min_reciprocal_condition);
  model_->set_anchors(std::move(anchor_points), std::move(anchor_targets), anchor_stiffness_);
}

std::size_t Rupture::break_inverted(const Eigen::VectorXd& u) {
  const Discretization& B = *body_;
  const int d = B.dimension();
  const Csr& fam = B.families();
  const Stencils& S = B.bond_stencils();
  const Material& mat = model_->material();
  std::vector<char> bad(fam.index.size(), 0);
#pragma omp parallel for schedule(dynamic, 32)
  for (std::size_t i = 0; i < B.size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      if (B.broken(q) || !(S.weight[q] > 0)) continue;
      Mat3 F = Mat3::Identity();
      for (auto r = S.offsets[q]; r < S.offsets[q + 1]; ++r) {
        const int m = S.index[r];
        const double* g = S.grad.data() + r * d;
        for (int a = 0; a < d; ++a)
          for (int J = 0; J < d; ++J) F(a, J) += u[d * m + a] * g[J];
      }
      Mat3 P;
      if (!mat.evaluate_at(static_cast<int>(i), F, nullptr, &P, nullptr)) bad[q] = 1;
    }
  std::size_t n = 0;
  for (std::size_t i = 0; i < B.size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q)
      if (bad[q]) n += body_->break_bond(static_cast<int>(i), fam.index[q]) ? 1 : 0;
  return n;
}

std::size_t Rupture::commit(const Eigen::VectorXd& u) {
  const std::size_t n = body_->rebuild_broken(opt_.min_reciprocal_condition);
  if (n > 0) update_anchors(u);
  return n;
}

void Rupture::update_anchors(const Eigen::VectorXd& u) {
  // A point is coupled if some stencil of nonzero weight has a nonzero G at it.
  const Discretization& B = *body_;
  const Stencils& S = B.bond_stencils();
  const int d = B.dimension();
  std::vector<char> coupled(B.size(), 0);
  for (std::size_t s = 0; s < S.size(); ++s) {
    if (!(S.weight[s] > 0)) continue;
    for (auto r = S.offsets[s]; r < S.offsets[s + 1]; ++r) {
      const double* g = S.grad.data() + r * d;
      bool nz = false;
      for (int a = 0; a < d; ++a) nz = nz || g[a] != 0.0;
      if (nz) coupled[S.index[r]] = 1;
    }
  }
  // parked at their current displacement (no force on anyone else)
  std::vector<int> pts;
  std::vector<double> tgt;
  for (std::size_t k = 0; k < B.size(); ++k) {
    if (coupled[k]) continue;
    pts.push_back(static_cast<int>(k));
    for (int a = 0; a < d; ++a) tgt.push_back(u[d * k + a]);
  }
  model_->set_anchors(std::move(pts), std::move(tgt), anchor_stiffness_);
}

std::size_t Rupture::stagger(StaticSolver& solver) {
  std::size_t total = 0;
  for (int pass_no = 1;; ++pass_no) {
    const RupturePass p = break_exceeding(solver.displacement());
    if (p.broken == 0) {
      if (pass_no > 1)
        log::info("rupture at t = {:.6g}: no further bond past {} {} after {} passes (max {:.4g})",
                  solver.load_factor(), to_string(opt_.criterion), opt_.critical, pass_no - 1,
                  p.max_value);
      return total;
    }
    total += p.broken;
    if (pass_no > opt_.max_passes)
      throw NumericalError(fmt::format(
          "rupture at load factor {:.6g}: bonds still breaking after {} staggered passes ({} "
          "broken in total); the crack runs unstably at fixed load — use more load steps or a "
          "larger rupture.max_passes",
          solver.load_factor(), opt_.max_passes, body_->broken_bonds()));
    StepReport rep;
    const bool ok = solver.reequilibrate(rep);
    log::info(
        "rupture pass {} at t = {:.6g}: {} bonds broke ({} broken in total, max {} {:.4g} > {}; "
        "{} of them with an inverted rebuilt stencil), "
        "{} stencils rebuilt, {} ill-posed stencils off, {} detached points; re-equilibrium: {} "
        "({} Newton iterations, residual {:.3e})",
        pass_no, solver.load_factor(), p.broken, body_->broken_bonds(), to_string(opt_.criterion),
        p.max_value, opt_.critical, p.inverted, p.rebuilt, body_->suppressed_stencils(), p.anchored,
        ok ? "converged" : "FAILED", rep.iterations,
        rep.residual_history.empty() ? NAN : rep.residual_history.back());
    if (!ok) {
      log::warn(
          "rupture pass {} at t = {:.6g}: Newton cannot re-equilibrate after {} bonds broke "
          "(residual history {:.2e}) — the crack grows unstably at fixed load; falling back to "
          "adaptive dynamic relaxation",
          pass_no, solver.load_factor(), p.broken, fmt::join(rep.residual_history, " "));
      StepReport adr;
      const bool relaxed = solver.relax(opt_.relaxation_tolerance, opt_.relaxation_iterations, adr);
      StepReport polish;
      const bool polished = relaxed && solver.reequilibrate(polish);
      log::info(
          "adaptive dynamic relaxation: {} after {} iterations (residual {:.3e}); Newton polish: "
          "{} ({} iterations, residual {:.3e})",
          relaxed ? "converged" : "FAILED", adr.iterations, adr.residual,
          polished ? "converged" : (relaxed ? "FAILED" : "skipped"), polish.iterations,
          polish.residual_history.empty() ? NAN : polish.residual_history.back());
      if (!polished)
        throw NumericalError(fmt::format(
            "rupture at load factor {:.6g}: neither Newton nor adaptive dynamic relaxation "
            "({} iterations, residual {:.3e}) re-equilibrated the body after {} bonds broke "
            "(pass {}); the body may have fallen apart (a free fragment has rigid motions) — "
            "check the damage field of the last output",
            solver.load_factor(), adr.iterations, adr.residual, p.broken, pass_no));
    }
  }
}

}  // namespace pdcg::solver
