// Shared by test_fracture_energy.cpp and test_fracture_energy_slow.cpp: the mode-I K-field
// boundary-layer test of the fracture_energy rule (docs/fracture.md §5.3).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <vector>

#include "pdcg/solver/rupture.hpp"

namespace pdcg::solver::test {

// Plane-strain Neo-Hooke μ = 1, K = 2 at small strain: λ = K − 2μ/3 = 4/3, ν = 2/7,
// κ = 3 − 4ν = 13/7, E' = E/(1 − ν²) = 4μ(λ + μ)/(λ + 2μ) = 2.8.
inline constexpr double kfield_mu = 1.0, kfield_kappa = 13.0 / 7.0, kfield_E_prime = 2.8;

// LEFM mode-I displacement of unit K_I about the tip (a, 0), crack along −x (Williams;
// e.g. Anderson, Fracture Mechanics, Table 2.2):
//   u_x = (K/2μ) √(r/2π) cos(θ/2) (κ − 1 + 2 sin²(θ/2)),
//   u_y = (K/2μ) √(r/2π) sin(θ/2) (κ + 1 − 2 cos²(θ/2)).
inline Vec3 kfield_unit_displacement(const Vec3& x, double a) {
  const double dx = x.x() - a, dy = x.y(), r = std::hypot(dx, dy), th = std::atan2(dy, dx);
  const double c = std::sqrt(r / (2 * M_PI)) / (2 * kfield_mu);
  const double s2 = std::sin(0.5 * th), c2 = std::cos(0.5 * th);
  return Vec3(c * c2 * (kfield_kappa - 1 + 2 * s2 * s2), c * s2 * (kfield_kappa + 1 - 2 * c2 * c2),
              0.0);
}

// The LEFM K-field of K = K_c imposed on every point of the pre-cracked square (no solve):
// G/G_c at which the first pair reaches its critical work, 1 / max W/W_c (W ∝ K²), and
// the pair. The criterion's own reading of the tip field, without the PD solution.
/// The pre-cracked square of the K-field cases: [−L, L]² on a unit grid (L ≈ L_over_delta·δ,
/// δ = m), a straight crack from the left edge to the centre.
struct KfieldSquare {
  double delta, L;
  Discretization body;
};
inline KfieldSquare kfield_square(double m, double L_over_delta) {
  const double dx = 1.0, delta = m * dx;
  const int n = 2 * static_cast<int>(std::lround(L_over_delta * delta / dx));
  const double L = 0.5 * n * dx;
  GridSpec g;
  g.origin = Vec3(-L, -L, -0.5);
  g.size = Vec3(2 * L, 2 * L, 1.0);
  g.spacing = dx;
  g.cracks.push_back({Vec3(-L - 1, 0, 0), Vec3(0, 0, 0)});
  DiscretizationOptions opt;
  opt.horizon_factor = m;
  return {delta, L, Discretization::grid(g, opt)};
}

struct ImposedResult {
  double G_first_over_Gc = 0;
  Vec3 from = Vec3::Zero(), to = Vec3::Zero();
};
inline ImposedResult kfield_imposed(double m, double L_over_delta) {
  KfieldSquare square = kfield_square(m, L_over_delta);
  Discretization& body = square.body;
  auto mat = make_neo_hookean({1.0, 2.0}, Kinematics::plane_strain);
  Model model(body, *mat);
  const double G_c = 1e-6, Kc = std::sqrt(G_c * kfield_E_prime);
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = G_c;
  Rupture rup(body, model, ro);
  const auto& x = body.positions();
  Eigen::VectorXd u(2 * static_cast<Eigen::Index>(body.size()));
  for (std::size_t i = 0; i < body.size(); ++i) {
    const Vec3 uu = Kc * kfield_unit_displacement(x[i], 0.0);
    u[2 * i] = uu.x();
    u[2 * i + 1] = uu.y();
  }
  const auto v = rup.criterion_values(u);
  std::size_t qm = 0;
  for (std::size_t q = 0; q < v.size(); ++q)
    if (v[q] > v[qm]) qm = q;
  const Csr& fam = body.families();
  std::size_t i = 0;
  while (static_cast<std::size_t>(fam.end(i)) <= qm) ++i;
  return {1.0 / v[qm], x[i], x[fam.index[qm]]};
}

/// The crack tip: the largest x at which a broken bond crosses the crack plane y = 0.
inline double kfield_crack_tip(const Discretization& body) {
  const auto& x = body.positions();
  const Csr& fam = body.families();
  double a = 0;
  for (std::size_t i = 0; i < body.size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      const int j = fam.index[q];
      if (!body.broken(q) || !(x[i].y() < 0 && x[j].y() > 0)) continue;
      const double s = -x[i].y() / (x[j].y() - x[i].y());
      a = std::max(a, x[i].x() + s * (x[j].x() - x[i].x()));
    }
  return a;
}

struct KfieldEvent {
  double K_over_Kc = 0;  // applied K / K_c at this event (bonds broke)
  double tip = 0;        // crack tip after it: largest x where a broken bond crosses y = 0
  std::size_t broken = 0;
  double dissipated = 0;     // Rupture::dissipated_energy() after it
  double released = 0;       // Π before the staggered passes − Π after (fixed boundary)
  std::size_t crossing = 0;  // broken bonds (in total) that cross the crack line y = 0
};
struct KfieldResult {
  double delta = 0, L = 0;
  std::vector<KfieldEvent> events;
  // K/K_c at the first break, and the smallest K at which the tip stands beyond a
  double K_init() const { return events.empty() ? NAN : events.front().K_over_Kc; }
  double K_at_advance(double a) const {
    for (const auto& e : events)
      if (e.tip >= a) return e.K_over_Kc;
    return NAN;
  }
};

// Square [−L, L]², Δx = 1, δ = mΔx, crack y = 0 from the left edge to the tip x = 0 (both on
// cell faces). The LEFM K-field of K_I is prescribed on every point within `layer` (in δ)
// of the outer boundary, about the current tip when `follow_tip` (the boundary-layer
// field moves with the crack), else about the origin. K is raised quasi-statically: after
// each equilibrium the largest W/W_c predicts the K of the next break (W ∝ K² at small
// strain), K is set 10⁻⁴ above it and the staggered passes run at that K. Stops when the
// tip has advanced by a_max δ or after max_events breaking events. `boundary`: how the
// pre-crack faces enter (weak: sharp traction-free faces of the weak form; energy: PD
// surfaces, as the faces rupture opens — the prescribed layer removes every other surface).
// `instantaneous`: the energy_density rule Ψ(F_ij) ≥ ψ_c = G_c/(β₂δ) instead of the
// accumulated pair work. `verbose` prints the twelve largest W/W_c before the first break
// and one line per event (with the energy the passes released, Π before − Π after).
inline KfieldResult kfield(double m, double L_over_delta, double a_max_over_delta,
                           bool follow_tip = true, double layer = 1.0, int max_events = 400,
                           bool verbose = false, BoundaryForm boundary = BoundaryForm::weak,
                           bool instantaneous = false) {
  KfieldSquare square = kfield_square(m, L_over_delta);
  const double delta = square.delta, L = square.L;
  Discretization& body = square.body;
  auto mat = make_neo_hookean({1.0, 2.0}, Kinematics::plane_strain);
  ModelOptions mo;
  mo.boundary = boundary;
  Model model(body, *mat, mo);
  const auto& x = body.positions();
  std::vector<int> outer;
  for (std::size_t i = 0; i < body.size(); ++i)
    if (std::max(std::abs(x[i].x()), std::abs(x[i].y())) > L - layer * delta)
      outer.push_back(static_cast<int>(i));
  const double G_c = 1e-6;  // K_c = √(G_c E') ≈ 1.7·10⁻³: strains ≲ 10⁻³, small strain
  const double Kc = std::sqrt(G_c * kfield_E_prime);
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = G_c;
  if (instantaneous) {  // Ψ(F_ij) ≥ ψ_c: the energy-density rule at the calibrated ψ_c
    ro.criterion = RuptureCriterion::energy_density;
    ro.critical = G_c / (fracture_energy_shape_factor(2) * delta);
  }
  ro.max_passes = 100000;
  Rupture rup(body, model, ro);
  double centre = 0;  // the tip the prescribed field is centred on
  std::vector<DisplacementSet> ds;
  // one displacement set per prescribed point (a component is a function of t = K only)
  auto build_sets = [&] {
    ds.assign(outer.size(), DisplacementSet{"K-field", {}, {}});
    for (std::size_t k = 0; k < outer.size(); ++k) {
      const Vec3 uu = kfield_unit_displacement(x[outer[k]], centre);
      ds[k].points = {outer[k]};
      ds[k].component[0] = [ux = uu.x()](double t) { return t * ux; };
      ds[k].component[1] = [uy = uu.y()](double t) { return t * uy; };
    }
  };
  NewtonOptions no;
  no.steps = 1;
  no.tolerance = 1e-10;
  std::unique_ptr<StaticSolver> solver;
  auto solve_at = [&](double K) {
    build_sets();
    solver = std::make_unique<StaticSolver>(model, ds, std::vector<TractionSet>{}, no);
    solver->advance_to(K);
  };
  const Csr& fam = body.families();
  auto tip = [&] { return kfield_crack_tip(body); };
  KfieldResult out;
  out.delta = delta;
  out.L = L;
  double K = 0.5 * Kc;
  for (int ev = 0; ev < max_events; ++ev) {
    solve_at(K);
    double r = 0;
    for (double v : rup.criterion_values(solver->displacement()))
      r = std::max(r, v / rup.options().critical);
    // next break: W ∝ K² (corrected by further solves while the prediction falls short)
    for (int it = 0; it < 5 && r < 1; ++it) {
      K *= std::sqrt(1.0 / r) * (1 + 1e-4);
      solve_at(K);
      r = 0;
      for (double v : rup.criterion_values(solver->displacement()))
        r = std::max(r, v / rup.options().critical);
    }
    if (verbose && out.events.empty()) {  // the bonds about to break first
      const auto v = rup.criterion_values(solver->displacement());
      std::vector<std::size_t> idx(v.size());
      for (std::size_t q = 0; q < v.size(); ++q) idx[q] = q;
      std::partial_sort(idx.begin(), idx.begin() + 12, idx.end(),
                        [&](auto a, auto b) { return v[a] > v[b]; });
      const Stencils& S = body.bond_stencils();
      for (int k = 0; k < 12; ++k) {
        const std::size_t q = idx[k];
        std::size_t i = 0;
        while (static_cast<std::size_t>(fam.end(i)) <= q) ++i;
        const int j = fam.index[q];
        std::printf("  W/Wc %.4f  (%.1f, %.1f)-(%.1f, %.1f)  members %ld weight %.4g\n", v[q],
                    x[i].x(), x[i].y(), x[j].x(), x[j].y(),
                    static_cast<long>(S.offsets[q + 1] - S.offsets[q]), S.weight[q]);
      }
    }
    const double Pi0 = model.energy(solver->displacement());
    const std::size_t nb = rup.stagger(*solver);
    const double Pi1 = model.energy(solver->displacement());
    const double a = tip();
    std::size_t ncross = 0;
    for (std::size_t i = 0; i < body.size(); ++i)
      for (auto q = fam.begin(i); q < fam.end(i); ++q)
        if (body.broken(q) && x[i].y() < 0 && x[fam.index[q]].y() > 0) ++ncross;
    out.events.push_back(
        {K / Kc, a, body.broken_bonds(), rup.dissipated_energy() / G_c, (Pi0 - Pi1) / G_c, ncross});
    if (verbose) {
      std::printf(
          "K/Kc %.4f  tip %.3f (%.3f δ)  broke %zu (total %zu, crossing %zu)  dissipated/G_c "
          "%.3f  released/G_c %.3f\n",
          K / Kc, a, a / delta, nb, body.broken_bonds(), ncross, rup.dissipated_energy() / G_c,
          (Pi0 - Pi1) / G_c);
      std::fflush(stdout);
    }
    if (follow_tip) centre = a;
    if (a >= a_max_over_delta * delta) break;
  }
  return out;
}

// The same square and boundary layer with the softening failure law (docs/fracture.md §6):
// crack faces as PD surfaces (BoundaryForm::energy), the field following the tip. K starts
// where the most loaded pair reaches the elastic limit (the criterion √κ/e_f ∝ K equals ρ)
// and rises by the factor 1 + dK per step; at each K the staggered passes update the damage
// until it stops growing (rupture.damage_tolerance). One event per step (tip: largest x at
// which a broken pair — d = 1 — crosses y = 0); dissipated = Σ Δd · (undamaged pair energy)
// + what broken pairs still stored. Stops when the tip has advanced by a_max δ or after
// max_steps.
inline KfieldResult kfield_softening(double m, double L_over_delta, double a_max_over_delta,
                                     double elastic_limit, double dK = 0.01,
                                     double max_damage_increment = 1.0, int max_steps = 400,
                                     bool verbose = false) {
  KfieldSquare square = kfield_square(m, L_over_delta);
  const double delta = square.delta, L = square.L;
  Discretization& body = square.body;
  auto mat = make_neo_hookean({1.0, 2.0}, Kinematics::plane_strain);
  ModelOptions mo;
  mo.boundary = BoundaryForm::energy;
  Model model(body, *mat, mo);
  const auto& x = body.positions();
  std::vector<int> outer;
  for (std::size_t i = 0; i < body.size(); ++i)
    if (std::max(std::abs(x[i].x()), std::abs(x[i].y())) > L - delta)
      outer.push_back(static_cast<int>(i));
  const double G_c = 1e-6, Kc = std::sqrt(G_c * kfield_E_prime);
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = G_c;
  ro.softening = RuptureSoftening::linear;
  ro.elastic_limit = elastic_limit;
  ro.max_damage_increment = max_damage_increment;
  ro.max_passes = 100000;
  Rupture rup(body, model, ro);
  double centre = 0;
  std::vector<DisplacementSet> ds;
  NewtonOptions no;
  no.steps = 1;
  no.tolerance = 1e-10;
  std::unique_ptr<StaticSolver> solver;
  auto solve_at = [&](double K) {
    ds.assign(outer.size(), DisplacementSet{"K-field", {}, {}});
    for (std::size_t k = 0; k < outer.size(); ++k) {
      const Vec3 uu = kfield_unit_displacement(x[outer[k]], centre);
      ds[k].points = {outer[k]};
      ds[k].component[0] = [ux = uu.x()](double t) { return t * ux; };
      ds[k].component[1] = [uy = uu.y()](double t) { return t * uy; };
    }
    solver = std::make_unique<StaticSolver>(model, ds, std::vector<TractionSet>{}, no);
    solver->advance_to(K);
  };
  const Csr& fam = body.families();
  auto tip = [&] { return kfield_crack_tip(body); };
  auto vmax = [&] {
    double v = 0;
    for (double c : rup.criterion_values(solver->displacement())) v = std::max(v, c);
    return v;
  };
  KfieldResult out;
  out.delta = delta;
  out.L = L;
  double K = 0.5 * Kc;
  solve_at(K);
  K *= elastic_limit / vmax();  // the criterion √κ/e_f is ∝ K before any damage
  for (int step = 0; step < max_steps; ++step) {
    solve_at(K);
    const double Pi0 = model.energy(solver->displacement());
    const std::size_t nb = rup.stagger(*solver);
    const double Pi1 = model.energy(solver->displacement());
    const double a = tip();
    std::size_t ncross = 0;
    for (std::size_t i = 0; i < body.size(); ++i)
      for (auto q = fam.begin(i); q < fam.end(i); ++q)
        if (body.broken(q) && x[i].y() < 0 && x[fam.index[q]].y() > 0) ++ncross;
    if (body.broken_bonds() > 0)
      out.events.push_back({K / Kc, a, body.broken_bonds(), rup.dissipated_energy() / G_c,
                            (Pi0 - Pi1) / G_c, ncross});
    if (verbose) {
      std::printf(
          "K/Kc %.4f  tip %.3f (%.3f δ)  broke %zu (total %zu, crossing %zu)  dissipated/G_c "
          "%.4f  released/G_c %.4f\n",
          K / Kc, a, a / delta, nb, body.broken_bonds(), ncross, rup.dissipated_energy() / G_c,
          (Pi0 - Pi1) / G_c);
      std::fflush(stdout);
    }
    centre = a;
    if (a >= a_max_over_delta * delta) break;
    K *= 1 + dK;
  }
  return out;
}

}  // namespace pdcg::solver::test
