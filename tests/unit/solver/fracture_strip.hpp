// Shared by test_fracture_energy.cpp and test_fracture_energy_slow.cpp: the mode-I strip
// under a fixed grip of the fracture_energy rule's δ-independence check.
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include "pdcg/solver/rupture.hpp"

namespace pdcg::solver::test {

struct StripCase {
  Discretization body;
  std::unique_ptr<Material> mat;
  std::unique_ptr<Model> model;
  std::unique_ptr<StaticSolver> solver;
};

// Mode-I strip under a fixed grip: [0, 3H] × [0, H], H = 1, an edge crack along y = H/2 from
// x = 0 to x = 1.5H, the bottom and top rows of points gripped (u_x = 0, u_y = ∓D/2). Far
// ahead of the tip F = diag(1, 1 + D/H_g) at every point (H_g the grip-row distance; the
// weak form reproduces linear fields exactly), far behind the two halves are rigid, so an
// advance da releases G = H Ψ(diag(1, 1 + D/H_g)) da (H = rows × Δx, every row's volume).
struct StripResult {
  double G_first_over_Gc = 0;  // energy rule: G at the first break beyond the pre-crack / G_c
  double stretch_strain_at_unit_G = 0;  // (s_max − 1) / √G: the stretch rule's first break
  double delta = 0;
  Vec3 where = Vec3::Zero();
};
inline StripResult strip(double m, int rows) {
  const double H = 1.0, L = 3.0, dx = H / rows;
  GridSpec g;
  g.size = Vec3(L, H, 1.0);
  g.spacing = dx;
  g.cracks.push_back({Vec3(-0.1, 0.5 * H, 0), Vec3(1.5 * H, 0.5 * H, 0)});
  DiscretizationOptions opt;
  opt.horizon_factor = m;
  auto c = std::make_unique<StripCase>();
  c->body = Discretization::grid(g, opt);
  c->mat = make_neo_hookean({1.0, 2.0}, Kinematics::plane_strain);
  c->model = std::make_unique<Model>(c->body, *c->mat);
  const auto& x = c->body.positions();
  std::vector<int> bottom, top;
  for (std::size_t i = 0; i < c->body.size(); ++i) {
    if (x[i].y() < dx) bottom.push_back(static_cast<int>(i));
    if (x[i].y() > H - dx) top.push_back(static_cast<int>(i));
  }
  const double Hg = x[top[0]].y() - x[bottom[0]].y();
  auto G_of = [&](double D) {
    Mat3 F = Mat3::Identity();
    F(1, 1) = 1 + D / Hg;
    double psi = 0;
    c->mat->evaluate(F, &psi, nullptr, nullptr);
    return H * psi;
  };
  const double G_c = 1e-5;  // crack growth at a grip strain ≈ 0.3 %: small strain
  double D = 0;             // current grip opening, set by load()
  std::vector<DisplacementSet> ds(2);
  ds[0] = {"bottom", bottom, {}};
  ds[0].component[0] = [](double) { return 0.0; };
  ds[0].component[1] = [&D](double t) { return -0.5 * t * D; };
  ds[1] = {"top", top, {}};
  ds[1].component[0] = [](double) { return 0.0; };
  ds[1].component[1] = [&D](double t) { return 0.5 * t * D; };
  NewtonOptions no;
  no.steps = 1;
  no.tolerance = 1e-10;
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = G_c;
  Rupture rup(c->body, *c->model, ro);
  StripResult out;
  out.delta = c->body.horizon();
  auto solve_ratio = [&](double D_new) {
    D = D_new;
    c->solver = std::make_unique<StaticSolver>(*c->model, ds, std::vector<TractionSet>{}, no);
    c->solver->advance_to(1.0);
    const auto v = rup.criterion_values(c->solver->displacement());
    std::size_t qmax = 0;
    for (std::size_t q = 0; q < v.size(); ++q)
      if (v[q] > v[qmax]) qmax = q;
    const Csr& fam = c->body.families();
    std::size_t i = 0;
    while (static_cast<std::size_t>(fam.end(i)) <= qmax) ++i;
    out.where = 0.5 * (x[i] + x[fam.index[qmax]]);
    return v[qmax];
  };
  // D with G(D) = G_c (bisection on the closed form), then the opening at which the largest
  // W/W_c is 1 (W ∝ D² at small strain; one correction step)
  double lo = 0, hi = 0.1;
  for (int k = 0; k < 100; ++k) (G_of(0.5 * (lo + hi)) < G_c ? lo : hi) = 0.5 * (lo + hi);
  double D1 = 0.5 * (lo + hi);
  const double r0 = solve_ratio(D1);
  D1 /= std::sqrt(r0);
  const double r1 = solve_ratio(D1);
  out.G_first_over_Gc = G_of(D1) / r1 / G_c;
  // the stretch rule at the same state: largest bond strain per √G (s − 1 ∝ D ∝ √G)
  const Csr& fam = c->body.families();
  const auto& u = c->solver->displacement();
  double smax = 0;
  for (std::size_t i = 0; i < c->body.size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q) {
      const int j = fam.index[q];
      const Vec3 xi = x[j] - x[i];
      Vec3 y = xi;
      for (int a = 0; a < 2; ++a) y(a) += u[2 * j + a] - u[2 * i + a];
      smax = std::max(smax, y.norm() / xi.norm());
    }
  out.stretch_strain_at_unit_G = (smax - 1) / std::sqrt(G_of(D1));
  return out;
}

}  // namespace pdcg::solver::test
