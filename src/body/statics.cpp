// Molecular statics of delta bodies (include/pdcg/body/statics.hpp, docs/fracture.md §2).
#include "pdcg/body/statics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "pdcg/atomistic/families.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::body {

MinStyle parse_min_style(std::string_view name, std::string_view where) {
  if (name == "cg") return MinStyle::cg;
  if (name == "fire") return MinStyle::fire;
  throw InputError("unknown minimiser")
      .key(std::string(where.empty() ? "min_style" : where))
      .value(std::string(name))
      .expected("cg or fire");
}

namespace {

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

/// Largest per-atom norm of a 3N vector.
double max_atom_norm(const std::vector<double>& v) {
  double m = 0.0;
  for (std::size_t i = 0; i + 2 < v.size(); i += 3)
    m = std::max(m, v[i] * v[i] + v[i + 1] * v[i + 1] + v[i + 2] * v[i + 2]);
  return std::sqrt(m);
}

/// U and −∂U/∂y of a working copy of the body whose families are rebuilt whenever an atom has
/// moved more than skin/2 since the last build.
class Problem {
 public:
  Problem(const Body& body, double radius, double skin, std::span<const double> y)
      : work_(body), radius_(radius), skin_(skin) {
    rebuild(y);
    rebuilds_ = 0;  // the first build is not a rebuild
  }

  double evaluate(std::span<const double> y, std::vector<double>& f) {
    if (moved_beyond_margin(y)) {
      rebuild(y);
      log::debug("statics: families rebuilt (an atom moved more than skin/2 = {:.6g})",
                 0.5 * skin_);
    }
    const Evaluation e = ev_->deformed(y);
    ++evaluations_;
    std::copy(e.forces.begin(), e.forces.end(), f.begin());
    if (!std::isfinite(e.energy))
      throw NumericalError(
          fmt::format("molecular statics: the energy is not finite ({}) after {} evaluations: "
                      "atoms overlap; reduce the step (max_step) or check the configuration",
                      e.energy, evaluations_));
    return e.energy;
  }

  int rebuilds() const { return rebuilds_; }
  std::int64_t evaluations() const { return evaluations_; }
  double shortest_bond(std::span<const double> y) const {
    double m = std::numeric_limits<double>::infinity();
    const auto& fam = work_.families;
    for (std::size_t k = 0; k < work_.size(); ++k)
      for (auto b = static_cast<std::size_t>(fam.offset[k]);
           b < static_cast<std::size_t>(fam.offset[k + 1]); ++b)
        m = std::min(m, atomistic::bond_vector(fam, y, fam.h, k, b).norm());
    return m;
  }

 private:
  bool moved_beyond_margin(std::span<const double> y) const {
    const double lim2 = 0.25 * skin_ * skin_;
    for (std::size_t i = 0; i + 2 < y.size(); i += 3) {
      const double dx = y[i] - ybuild_[i], dy = y[i + 1] - ybuild_[i + 1],
                   dz = y[i + 2] - ybuild_[i + 2];
      if (dx * dx + dy * dy + dz * dz > lim2) return true;
    }
    return false;
  }
  void rebuild(std::span<const double> y) {
    atomistic::Atoms a;
    a.box = work_.box;
    a.id = work_.id;
    a.type = work_.type;
    a.x.assign(y.begin(), y.end());
    if (work_.dimension == 2) a.box.periodic[2] = false;  // as make_delta_body: no images along z
    atomistic::FamilyOptions fo;
    fo.cutoff = radius_;
    ev_.reset();
    work_.families = atomistic::build_families(a, fo);
    work_.x.assign(y.begin(), y.end());
    ybuild_.assign(y.begin(), y.end());
    ev_ = std::make_unique<Evaluator>(work_);
    ++rebuilds_;
  }

  Body work_;
  double radius_, skin_;
  std::vector<double> ybuild_;
  std::unique_ptr<Evaluator> ev_;
  int rebuilds_ = 0;
  std::int64_t evaluations_ = 0;
};

struct LineSearch {
  bool ok = false;
  double alpha = 0.0, energy = 0.0;
};

/// Minimises φ(α) = U(y + α h) over 0 < α ≤ amax by secant steps on φ'(α) = −f(y + αh)·h
/// inside a bracket. Accepts when |φ'(α)| ≤ 0.1 |φ'(0)| (curvature condition) and the energy
/// has not risen beyond its round-off, or at α = amax while still descending. On success y, f
/// hold the new point.
LineSearch line_search(Problem& p, std::vector<double>& y, std::vector<double>& f,
                       const std::vector<double>& h, double E0, double d0, double amax,
                       double alpha0, std::vector<double>& yt, std::vector<double>& ft) {
  // energy round-off of a sum of N terms, generous (a decrease smaller than this cannot be seen)
  const double eps_e = 1e-12 * std::max(std::abs(E0), 1e-300);
  double a_lo = 0.0, p_lo = d0, a_hi = 0.0, p_hi = 0.0;
  bool have_hi = false;
  double alpha = std::min(alpha0, amax);
  LineSearch out;
  auto trial = [&](double a) {
    for (std::size_t i = 0; i < y.size(); ++i) yt[i] = y[i] + a * h[i];
    const double e = p.evaluate(yt, ft);
    return e;
  };
  for (int it = 0; it < 60; ++it) {
    const double Et = trial(alpha);
    const double pt = -dot(ft, h);
    const bool lower = Et <= E0 + eps_e;
    if (lower && std::abs(pt) <= 0.1 * std::abs(d0)) {
      out = {true, alpha, Et};
      break;
    }
    double next;
    if (lower && pt < 0.0) {
      a_lo = alpha;
      p_lo = pt;
      if (!have_hi) {
        if (alpha >= amax * (1.0 - 1e-12)) {
          out = {true, alpha, Et};  // step-limited, still descending
          break;
        }
        // secant extrapolation from (0, d0) and (α, φ'(α)), between 1.5α and min(4α, amax)
        const double sec = (pt > d0) ? alpha * d0 / (d0 - pt) : 4.0 * alpha;
        next = std::min(amax, std::clamp(sec, 1.5 * alpha, 4.0 * alpha));
        alpha = next;
        continue;
      }
    } else {
      a_hi = alpha;
      p_hi = lower ? pt : std::max(pt, std::abs(d0));  // energy rose: minimum lies before α
      have_hi = true;
    }
    const double w = a_hi - a_lo;
    if (w <= 1e-14 * a_hi) break;
    next = a_lo - p_lo * w / (p_hi - p_lo);
    if (!(next > a_lo + 0.01 * w && next < a_hi - 0.01 * w)) next = a_lo + 0.5 * w;
    alpha = next;
  }
  if (!out.ok && a_lo > 0.0) {
    // bracket collapsed: the last point that still descended
    const double Et = trial(a_lo);
    if (Et <= E0 + eps_e) out = {true, a_lo, Et};
  }
  if (out.ok) {  // yt, ft hold the accepted point (the last trial)
    y.swap(yt);
    f.swap(ft);
  }
  return out;
}

}  // namespace

StaticsResult relax(const Body& body, std::vector<double>& y, const StaticsOptions& o) {
  if (body.kind != BodyKind::delta || body.statistics || body.homogenisation || body.epsilon != 1.0)
    throw InputError("molecular statics needs a delta body")
        .key("body kind")
        .value(std::string(to_string(body.kind)))
        .expected("a delta body (pdcg atoms2pd --density delta)")
        .fix("relax the atoms, not a coarse-grained or statistical model");
  if (!body.families.bond_type.empty() || !body.families.pair_factor.empty())
    throw InputError("molecular statics of a body with molecular bonds or special_bonds")
        .key("families")
        .value("molecular bonds / special_bonds factors")
        .expected("atoms interacting through the pair or many-body potential only")
        .fix("relax the molecular system in LAMMPS (minimize), then build the body");
  if (y.size() != 3 * body.size())
    throw InputError("positions do not match the body")
        .key("positions")
        .value(std::to_string(y.size() / 3))
        .expected(std::to_string(body.size()) + " atoms");
  if (!(o.force_tolerance >= 0.0) || !std::isfinite(o.force_tolerance))
    throw InputError("bad force tolerance")
        .key("force tolerance")
        .value(fmt::format("{}", o.force_tolerance))
        .expected("a number >= 0");
  if (o.max_iterations < 0)
    throw InputError("bad iteration limit")
        .key("max iterations")
        .value(std::to_string(o.max_iterations))
        .expected(">= 0");
  if (!(o.max_step >= 0.0) || !std::isfinite(o.max_step))
    throw InputError("bad max step")
        .key("max step")
        .value(fmt::format("{}", o.max_step))
        .expected("a length >= 0 (0: 0.1 × shortest bond)");
  const double rc = body.potential->cutoff();
  const double skin = o.skin < 0.0 ? 0.1 * rc : o.skin;
  if (!(skin > 0.0) || !std::isfinite(skin))
    throw InputError("bad family margin (skin)")
        .key("skin")
        .value(fmt::format("{}", skin))
        .expected("a length > 0: families are rebuilt when an atom moves more than skin/2");
  const double radius = rc + skin;

  Problem p(body, radius, skin, y);
  const std::size_t n3 = y.size();
  std::vector<double> f(n3), h(n3), fold(n3), yt(n3), ft(n3), v(n3);
  StaticsResult r;
  r.family_radius = radius;
  double E = p.evaluate(y, f);
  r.energy0 = E;
  const double dmax = o.max_step > 0.0 ? o.max_step : 0.1 * p.shortest_bond(y);
  if (!(dmax > 0.0) || !std::isfinite(dmax))
    throw InputError("cannot choose a step for molecular statics")
        .key("max step")
        .value(fmt::format("{}", dmax))
        .expected("a body with bonds, or an explicit max step");
  double fn2 = dot(f, f);
  // the stopping tests at the top of every iteration (both styles): sets r.stop (and
  // r.converged) when one holds
  auto stopped = [&] {
    if (std::sqrt(fn2) <= o.force_tolerance) {
      r.converged = true;
      r.stop = "force tolerance";
      return true;
    }
    if (r.iterations >= o.max_iterations) {
      r.stop = "max iterations";
      return true;
    }
    return false;
  };

  if (o.style == MinStyle::cg) {
    h = f;
    double alpha_prev = std::numeric_limits<double>::infinity();
    bool steepest = true;
    while (!stopped()) {
      double d0 = -dot(f, h);
      if (!(d0 < 0.0)) {
        h = f;
        d0 = -fn2;
        steepest = true;
      }
      const double hmax = max_atom_norm(h);
      const double amax = dmax / hmax;
      fold = f;
      const LineSearch ls =
          line_search(p, y, f, h, E, d0, amax, std::min(alpha_prev, amax), yt, ft);
      ++r.iterations;
      if (!ls.ok) {
        if (steepest) {
          r.stop = "line search found no lower energy along the force (round-off floor)";
          break;
        }
        h = f;  // restart along the force
        steepest = true;
        continue;
      }
      E = ls.energy;
      alpha_prev = ls.alpha;
      const double fn2_new = dot(f, f);
      // Polak–Ribière+: β = max(0, f·(f − f_old)/|f_old|²)
      const double beta = std::max(0.0, (fn2_new - dot(f, fold)) / fn2);
      fn2 = fn2_new;
      for (std::size_t i = 0; i < n3; ++i) h[i] = f[i] + beta * h[i];
      steepest = beta == 0.0;
    }
  } else {
    // FIRE: unit masses; dt_max = 1/ω_max (half the stability limit of the symplectic Euler
    // step), ω_max² estimated by power iteration with finite-difference Hessian products.
    const double eps = 1e-6 * dmax;
    for (std::size_t i = 0; i < n3; ++i) v[i] = std::sin(1.0 + 0.7 * static_cast<double>(i));
    double lambda = 0.0;
    for (int it = 0; it < 12; ++it) {
      const double vn = std::sqrt(dot(v, v));
      for (std::size_t i = 0; i < n3; ++i) yt[i] = y[i] + eps * v[i] / vn;
      (void)p.evaluate(yt, ft);
      for (std::size_t i = 0; i < n3; ++i) v[i] = -(ft[i] - f[i]) / eps;
      lambda = std::sqrt(dot(v, v));
    }
    if (!(lambda > 0.0) || !std::isfinite(lambda))
      throw NumericalError("FIRE: could not estimate the stiffness (Hessian power iteration)");
    const double dt_max = 1.0 / std::sqrt(lambda);
    double dt = 0.1 * dt_max, a = 0.1;
    int npos = 0;
    std::fill(v.begin(), v.end(), 0.0);
    while (!stopped()) {
      const double P = dot(f, v);
      if (P > 0.0) {
        const double vn = std::sqrt(dot(v, v)), fn = std::sqrt(fn2);
        for (std::size_t i = 0; i < n3; ++i) v[i] = (1.0 - a) * v[i] + a * vn * f[i] / fn;
        if (npos > 5) {
          dt = std::min(1.1 * dt, dt_max);
          a *= 0.99;
        }
        ++npos;
      } else {
        std::fill(v.begin(), v.end(), 0.0);
        dt *= 0.5;
        a = 0.1;
        npos = 0;
      }
      for (std::size_t i = 0; i < n3; ++i) v[i] += dt * f[i];
      const double vmax = max_atom_norm(v) * dt;
      const double scale = vmax > dmax ? dmax / vmax : 1.0;
      for (std::size_t i = 0; i < n3; ++i) y[i] += scale * dt * v[i];
      E = p.evaluate(y, f);
      fn2 = dot(f, f);
      ++r.iterations;
    }
  }
  r.energy = E;
  r.force_norm = std::sqrt(fn2);
  r.force_max = max_atom_norm(f);
  r.evaluations = p.evaluations();
  r.rebuilds = p.rebuilds();
  return r;
}

}  // namespace pdcg::body
