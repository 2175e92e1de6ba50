// The softening failure law of fracture_energy at scale (docs/fracture.md §6.3): a crack
// opened kinematically, and initiation and growth in the mode-I K-field. Label `slow`
// (minutes each on the loaded 2-core machine; the K-field case runs ~60 staggered load steps
// of Newton solves with stencil rebuilds), left out of the sanitizer run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fracture_kfield.hpp"
#include "pdcg/solver/rupture.hpp"

using namespace pdcg::solver;

namespace {
// The right half of a 16 × ny plane-strain body (x > 8) moved rigidly along x by a, raised in
// 2 % steps; at each a the damage updates run to convergence (no solve: u is imposed). When
// every pair crossing x = 8 is separated the halves are rigid and store nothing, so the
// dissipated energy is all the work that opened the crack.
struct SoftSeparation {
  double dissipated = 0, G_c = 0;
  std::size_t broken = 0, crossing = 0;
};
SoftSeparation soft_separate(double m, int ny, double rho) {
  GridSpec g;
  g.size = Vec3(16.0, ny, 1.0);
  g.spacing = 1.0;
  DiscretizationOptions opt;
  opt.horizon_factor = m;
  Discretization body = Discretization::grid(g, opt);
  auto mat = make_neo_hookean({1.0, 2.0}, Kinematics::plane_strain);
  Model model(body, *mat);
  SoftSeparation out;
  out.G_c = 1e-4 * body.horizon();  // separation at small strain (a ≈ 0.01–0.1 δ)
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = out.G_c;
  ro.softening = RuptureSoftening::linear;
  ro.elastic_limit = rho;
  Rupture rup(body, model, ro);
  const auto& x = body.positions();
  const Csr& fam = body.families();
  auto crossing_intact = [&] {
    std::size_t n = 0;
    for (std::size_t i = 0; i < body.size(); ++i)
      for (auto q = fam.begin(i); q < fam.end(i); ++q)
        if (x[i].x() < 8 && x[fam.index[q]].x() > 8 && !body.broken(q)) ++n;
    return n;
  };
  out.crossing = crossing_intact();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(body.size()));
  auto set = [&](double a) {
    for (std::size_t i = 0; i < body.size(); ++i) u[2 * i] = x[i].x() > 8 ? a : 0.0;
  };
  double a = 1e-4;
  set(a);
  double r = 0;  // the criterion √κ/e_f is ∝ a before any damage: start at 0.9 ρ
  for (double v : rup.criterion_values(u)) r = std::max(r, v);
  a *= 0.9 * rho / r;
  for (int step = 0; step < 2000 && crossing_intact() > 0; ++step, a *= 1.02) {
    set(a);
    for (int pass = 0; pass < 1000; ++pass) {
      const RupturePass p = rup.break_exceeding(u);
      if (p.broken == 0 && p.damaged == 0) break;
    }
  }
  out.dissipated = rup.dissipated_energy();
  out.broken = body.broken_bonds();
  return out;
}
}  // namespace

// A straight crack opened kinematically with the softening law (the counterpart of
// FractureEnergySlow.KinematicSeparationDissipation, where the brittle rule dissipates 1.10 G_c at
// m = 3): the interior dissipation per unit length (difference of ny = 40 and 24, which cancels the
// free top and bottom) against G_c = ψ_c β₂δ of the calibration (§5.2: the lattice sum of the
// crossing pairs' ψ_c(w_ij + w_ji) is 1.032 G_c at m = 3).
TEST(FractureSofteningSlow, DISABLED_KinematicSeparationSpreadsDamage) {
  // ρ = 0.5 only (ρ = 0.1: 78.9 G_c, 2546 broken, 6 min more)
  const double rho = 0.5;
  const SoftSeparation s24 = soft_separate(3.015, 24, rho), s40 = soft_separate(3.015, 40, rho);
  const double interior = (s40.dissipated - s24.dissipated) / (16 * s40.G_c);
  std::printf("rho = %.2f: crossing pairs %zu, broken %zu; interior dissipation %.4f G_c\n", rho,
              s40.crossing, s40.broken, interior);
  // Not G_c: measured 12.63 G_c with 3029 pairs broken for 702 crossing (docs/fracture.md
  // §6.3): under an imposed jump every pair whose lens straddles the plane damages and
  // breaks. Asserted as the measured defect (band ±15 %: the 2 % steps of a), so that a
  // change of the law that fixes it shows here.
  EXPECT_NEAR(interior, 12.63, 0.15 * 12.63);
  EXPECT_GT(s40.broken, 3 * s40.crossing);
}

// The softening law in the K-field (docs/fracture.md §6.3): m = 3, L = 4δ, ρ = 0.1, K raised
// by 1 % steps; against K_c = √(G_c E') and the brittle rule's 1.849 / 1.917 K_c (§5.3).
TEST(FractureSofteningSlow, DISABLED_KFieldGrowthBelowTheBrittleLoad) {
  const auto r = pdcg::solver::test::kfield_softening(3.015, 4.0, 0.45, 0.1);
  ASSERT_GE(r.events.size(), 2u);
  const auto& e1 = r.events.back();
  std::printf("K_init/K_c = %.4f, K at a = %.2f δ: %.4f K_c\n", r.K_init(), e1.tip / r.delta,
              e1.K_over_Kc);
  // measured 1.335 (first pair separated, crossing y = 0 at x = 0.5) and 1.403 (tip 0.5δ):
  // ±3 % (the 1 % K steps and the order of the staggered updates)
  EXPECT_NEAR(r.K_init(), 1.335, 0.03 * 1.335);
  EXPECT_NEAR(e1.K_over_Kc, 1.403, 0.03 * 1.403);
  // below the brittle rule's growth (1.917 K_c) and above K_c: the target (growth
  // within 10 % of K_c) is not met
  EXPECT_LT(e1.K_over_Kc, 1.6);
  EXPECT_GT(e1.K_over_Kc, 1.1);
}
