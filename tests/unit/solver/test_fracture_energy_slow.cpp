// The fracture_energy rule's crack initiation in the fixed-grip strip on finer grids
// (label solver_slow): how G_init/G_c of the energy rule and of the stretch rule move as
// δ/H shrinks at fixed m; initiation and growth in a mode-I K-field against K_c
// (docs/fracture.md §5.3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "fracture_kfield.hpp"
#include "fracture_strip.hpp"
#include "pdcg/solver/rupture.hpp"

using pdcg::solver::test::strip;
using pdcg::solver::test::StripResult;
using namespace pdcg::solver;

TEST(FractureEnergySlow, StripInitiationAsTheHorizonShrinks) {
  for (double m : {3.015, 4.015}) {
    std::vector<StripResult> r;
    // the coarsest and the finest grid of the series in docs/fracture.md §5.3 (16, 24, 32, 48
    // rows there; the two middle ones cost CI minutes and add no assertion the ends lack)
    for (int rows : {16, 48}) {
      r.push_back(strip(m, rows));
      const double stretch =
          std::pow(r.front().stretch_strain_at_unit_G / r.back().stretch_strain_at_unit_G, 2);
      std::printf(
          "m = %.3f, H/δ = %.2f: energy rule G_init/G_c = %.4f (first break at (%.3f, "
          "%.3f)); stretch rule G_init / G_init(16 rows) = %.4f\n",
          m, 1.0 / r.back().delta, r.back().G_first_over_Gc, r.back().where.x(), r.back().where.y(),
          stretch);
      std::fflush(stdout);
    }
    // δ-independence of the energy rule: over H/δ = 4 … 16 its G_init/G_c moves by at most
    // 1.5× without a trend (measured max/min 1.12 at m = 3, 1.42 at m = 4: which bond near the
    // tip breaks first depends on where the grid puts it), finest/coarsest within 30 %
    // (measured 0.95, 0.76); the stretch rule's G_init falls with δ (∝ δ: 1/3 over this range;
    // measured 0.29 and 0.22, below 0.4)
    double lo = INFINITY, hi = 0;
    for (const auto& x : r)
      lo = std::min(lo, x.G_first_over_Gc), hi = std::max(hi, x.G_first_over_Gc);
    EXPECT_LT(hi / lo, 1.5);
    EXPECT_NEAR(r.back().G_first_over_Gc / r.front().G_first_over_Gc, 1.0, 0.3);
    EXPECT_LT(std::pow(r.front().stretch_strain_at_unit_G / r.back().stretch_strain_at_unit_G, 2),
              0.4);
    // but not at G_c: ≈ 2.4 G_c at m = 3, ≈ 0.8 G_c at m = 4 (docs/fracture.md §5.3)
    for (const auto& x : r) {
      EXPECT_GT(x.G_first_over_Gc, 0.5);
      EXPECT_LT(x.G_first_over_Gc, 3.0);
    }
  }
}

namespace {

// Kinematic separation of a homogeneous 2D body [0, 16Δx] × [0, ny Δx] (Δx = 1) along the
// plane x = 8: the right half is moved rigidly by a (mode I opening), a raised by 0.5 %
// steps (at each a, breaking repeats until nothing breaks), until no intact bond crosses the
// plane. Returns the dissipated energy (the work stored in every broken pair when it broke).
struct Separation {
  double dissipated = 0;
  std::size_t broken = 0, crossing = 0;
  double G_c = 0;
};
Separation separate(double m, int ny) {
  GridSpec g;
  g.size = Vec3(16.0, ny, 1.0);
  g.spacing = 1.0;
  DiscretizationOptions opt;
  opt.horizon_factor = m;
  Discretization body = Discretization::grid(g, opt);
  auto mat = make_neo_hookean({1.0, 2.0}, Kinematics::plane_strain);
  Model model(body, *mat);
  Separation out;
  // G_c so that the separation happens at small strain (a ≈ 0.01 δ)
  out.G_c = 1e-4 * body.horizon();
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = out.G_c;
  Rupture rup(body, model, ro);
  const auto& x = body.positions();
  const Csr& fam = body.families();
  const Stencils& S = body.bond_stencils();
  auto crossing_intact = [&] {
    std::size_t n = 0;
    for (std::size_t i = 0; i < body.size(); ++i)
      for (auto q = fam.begin(i); q < fam.end(i); ++q)
        // intact and carrying stress in one of its directions (an ill-posed stencil has
        // weight 0: its stored work was released when it was switched off)
        if (x[i].x() < 8 && x[fam.index[q]].x() > 8 && !body.broken(q) &&
            (S.weight[q] > 0 || S.weight[body.bond_index(fam.index[q], static_cast<int>(i))] > 0))
          ++n;
    return n;
  };
  out.crossing = crossing_intact();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(2 * static_cast<Eigen::Index>(body.size()));
  auto set = [&](double a) {
    for (std::size_t i = 0; i < body.size(); ++i) u[2 * i] = x[i].x() > 8 ? a : 0.0;
  };
  // first a: the largest ratio W/W_c at a₀ scaled (W ∝ a² at small strain) to 0.9
  double a = 1e-4;
  set(a);
  double r = -INFINITY;
  for (double v : rup.criterion_values(u)) r = std::max(r, v);
  a *= std::sqrt(0.9 / r);
  for (int step = 0; step < 3000 && crossing_intact() > 0; ++step, a *= 1.005) {
    set(a);
    while (rup.break_exceeding(u).broken > 0) {
    }
  }
  out.dissipated = rup.dissipated_energy();
  out.broken = body.broken_bonds();
  return out;
}

}  // namespace

// A straight crack opened kinematically through a homogeneous body: the energy counted bond
// by bond (work stored in each pair when it broke, or in a stencil when it went ill-posed)
// over the new crack area, for m = 3 and 4. The free top and bottom surfaces change the bonds near
// them (one-sided families, renormalised φ̂); the difference of two heights (24 and 40 Δx) cancels
// that edge share and leaves the interior dissipation per unit length.
TEST(FractureEnergySlow, KinematicSeparationDissipation) {
  for (double m : {3.015, 4.015}) {
    const Separation s24 = separate(m, 24), s40 = separate(m, 40);
    const double whole = s40.dissipated / (40 * s40.G_c);
    const double interior = (s40.dissipated - s24.dissipated) / (16 * s40.G_c);
    std::printf(
        "m = %.3f: crossing pairs %zu, broken %zu; dissipated / (G_c · area): whole "
        "section %.4f, interior %.4f\n",
        m, s40.crossing, s40.broken, whole, interior);
    // not G_c to the discretisation error (FractureEnergy.CrossingBondsCriticalWorkIsGc…
    // checks the calibration): the pairs break with more than their critical work (a
    // broken neighbour renormalises φ̂ and changes F at fixed u) — measured 1.10 (m = 3) and
    // 1.33 (m = 4), docs/fracture.md §5
    EXPECT_GT(interior, 1.0);
    EXPECT_LT(interior, 1.5);
  }
}

// The K-field boundary-layer table of docs/fracture.md §5.3: K at the first break and at
// growth (the tip 0.6δ past the pre-crack, steady from there) over K_c = √(G_c E'), for
// m = 3 with two δ (L = 4δ and 6δ: on one square, δ and ⅔δ) and m = 4, crack faces as PD
// surfaces (BoundaryForm::energy); and the weak form's sharp pre-crack faces at m = 4, where
// the first pair to break is normal to the crack, on one side of it: no crossing pair.
TEST(FractureEnergySlow, KFieldGrowthAgainstKc) {
  using pdcg::solver::test::kfield;
  struct Row {
    double m, L;
  };
  std::vector<std::pair<Row, pdcg::solver::test::KfieldResult>> rows;
  for (Row row : {Row{3.015, 4.0}, Row{3.015, 6.0}, Row{4.015, 4.0}}) {
    rows.push_back({row, kfield(row.m, row.L, 0.6, true, 1.0, 80, false, BoundaryForm::energy)});
    const auto& r = rows.back().second;
    std::printf("m = %.3f, L/δ = %.0f: K_init/K_c = %.4f, K_growth/K_c = %.4f (tip %.2f δ)\n",
                row.m, row.L, r.K_init(), r.K_at_advance(0.6 * r.delta),
                r.events.back().tip / r.delta);
    std::fflush(stdout);
  }
  for (const auto& [row, r] : rows) {
    // measured K_init / K_growth: 1.849 / 1.917 (m = 3, L = 4δ), 1.826 / 1.890 (m = 3, 6δ),
    // 1.684 / 1.911 (m = 4, 4δ): G = 2.8–3.7 G_c; bands 1.6–2.0 and 1.75–2.1 K_c
    EXPECT_GT(r.K_init(), 1.6);
    EXPECT_LT(r.K_init(), 2.0);
    EXPECT_GT(r.K_at_advance(0.6 * r.delta), 1.75);
    EXPECT_LT(r.K_at_advance(0.6 * r.delta), 2.1);
  }
  // δ-independence at fixed m: the two squares differ by the O(δ/L) boundary layer only
  // (measured 1.2 % and 1.4 %; 1.809 / 1.860 at L = 10δ), tolerance 3 %
  EXPECT_NEAR(rows[1].second.K_init() / rows[0].second.K_init(), 1.0, 0.03);
  EXPECT_NEAR(rows[1].second.K_at_advance(0.6 * rows[1].second.delta) /
                  rows[0].second.K_at_advance(0.6 * rows[0].second.delta),
              1.0, 0.03);
  // the weak form's sharp pre-crack faces: at m = 4 a pair along the face, one row off the
  // crack line, breaks first (measured K = 0.98 K_c) — a pair that does not cross the
  // crack, so its break blunts the tip instead of advancing it
  const auto w = kfield(4.015, 4.0, 0.01, true, 1.0, 1, false, BoundaryForm::weak);
  ASSERT_EQ(w.events.size(), 1u);
  std::printf("weak form, m = 4: K_init/K_c = %.4f, tip after it %.3f\n", w.K_init(),
              w.events[0].tip);
  EXPECT_LT(w.K_init(), 1.2);
  EXPECT_EQ(w.events[0].crossing, 0u);
}

// The tip calibration of the brittle lj15 sheet (docs/fracture.md §7.6b; the workflow's
// `run.sh -f 2.3`): G/G_c at which the m = 3 rule first breaks the pair across a sharp
// pre-crack tip with the weak form's faces (the sheet's notch is such a face) in the Williams
// K-field, extrapolated linearly in δ/L from L = 6δ and 8δ to δ/L → 0. Measured K_init/K_c =
// 1.6380, 1.6104, 1.5946, 1.5760 at L/δ = 4, 5, 6, 8 (falling as the O(δ/L) boundary layer
// shrinks); extrapolated 1.5202, G = 2.311 G_c. Checks that the workflow's factor is this
// measurement: 2.3 ± 0.05 (the extrapolation's own spread: the L = 5–6δ pair gives a slope
// 7 % steeper, 0.02 in G). 5 s of CPU in Release.
TEST(FractureEnergySlow, TipCalibrationFactorIsTheKFieldInitiationAtWeakFaces) {
  using pdcg::solver::test::kfield;
  const auto at6 = kfield(3.015, 6.0, 0.01, true, 1.0, 1, false, BoundaryForm::weak);
  const auto at8 = kfield(3.015, 8.0, 0.01, true, 1.0, 1, false, BoundaryForm::weak);
  ASSERT_FALSE(at6.events.empty());
  ASSERT_FALSE(at8.events.empty());
  // the first pair to break crosses the crack line at the tip: a tip advance, not a blunting
  EXPECT_GT(at6.events[0].crossing, 0u);
  EXPECT_GT(at8.events[0].crossing, 0u);
  const double s6 = at6.delta / at6.L;
  const double s8 = at8.delta / at8.L;
  EXPECT_LT(at8.K_init(), at6.K_init());  // the boundary layer's share falls with δ/L
  const double K_inf = at8.K_init() - (at6.K_init() - at8.K_init()) / (s6 - s8) * s8;
  std::printf("weak faces, m = 3: K_init/K_c = %.4f (L = 6δ), %.4f (8δ); δ/L → 0: %.4f, "
              "G = %.3f G_c\n",
              at6.K_init(), at8.K_init(), K_inf, K_inf * K_inf);
  EXPECT_NEAR(K_inf * K_inf, 2.3, 0.05);
}
