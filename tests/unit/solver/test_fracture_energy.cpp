// The energy-based (Griffith) rupture rule of the BA solver, `fracture_energy`
// (docs/fracture.md §5, theory.md §12), against closed forms.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "fracture_kfield.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/solver/rupture.hpp"

using namespace pdcg::solver;

namespace {

const double kPi = 3.14159265358979323846;

// Overlap of two unit balls (d = 2: discs) whose centres are s apart, by quadrature of the
// chord lengths max(0, 2√(1 − ρ²) − s) over the cross-section (independent of the closed
// forms in the code): area in 2D, volume in 3D.
double overlap(int d, double s, int n) {
  double a = 0;
  for (int k = 0; k < n; ++k) {
    const double rho = (k + 0.5) / n;  // 2D: |y| ∈ (0, 1), 3D: cylinder radius
    const double chord = std::max(0.0, 2 * std::sqrt(1 - rho * rho) - s);
    a += chord * (d == 2 ? 2.0 : 2 * kPi * rho) / n;
  }
  return a;
}

// β_d = ∫|s·n| f(|s|) ds / ∫ f(|s|) ds over the unit ball, f = overlap / ball volume.
double shape_factor_by_quadrature(int d, int n) {
  double num = 0, den = 0;
  for (int k = 0; k < n; ++k) {
    const double s = (k + 0.5) / n;
    const double f = overlap(d, s, n);
    // shells: 2D ∫|cos θ| dθ = 4, ∫dθ = 2π; 3D ∫|cos θ| dΩ = 2π, ∫dΩ = 4π
    num += (d == 2 ? 4.0 : 2 * kPi) * std::pow(s, d) * f / n;
    den += (d == 2 ? 2 * kPi : 4 * kPi) * std::pow(s, d - 1) * f / n;
  }
  return num / den;
}

}  // namespace

// The closed forms of β_d (docs/fracture.md §5) against a direct quadrature of the
// defining integrals (overlap of two balls by chords, then the φ̂-weighted mean of |ξ·n|).
TEST(FractureEnergy, ShapeFactorsAreTheContinuumIntegrals) {
  // midpoint rule, 2000 × 2000: error O(n^-1.5) from the √ edge of the chords, < 1e-5
  for (int d : {2, 3}) {
    const double q = shape_factor_by_quadrature(d, 2000);
    std::printf("beta_%d: closed form %.9f, quadrature %.9f\n", d, fracture_energy_shape_factor(d),
                q);
    EXPECT_NEAR(fracture_energy_shape_factor(d), q, 1e-5);
  }
  // the 3D value is the interior normalisation of theory.md §6 in disguise: c₃ = 15/32
  EXPECT_DOUBLE_EQ(fracture_energy_shape_factor(3), 61.0 / 175.0);
  EXPECT_THROW(fracture_energy_shape_factor(1), pdcg::Error);
}

namespace {

struct Case {
  Discretization body;
  std::unique_ptr<Material> mat;
  std::unique_ptr<Model> model;
  std::unique_ptr<StaticSolver> solver;
};

// Uniaxial plane-strain state diag(λ, f) of the homogeneous bar (P₂₂ = 0 by bisection).
Mat3 uniaxial(const Material& m, double lambda) {
  double lo = 0.3, hi = 1.0;
  for (int k = 0; k < 200; ++k) {
    const double f = 0.5 * (lo + hi);
    Mat3 F = Mat3::Identity();
    F(0, 0) = lambda;
    F(1, 1) = f;
    Mat3 P;
    m.evaluate(F, nullptr, &P, nullptr);
    (P(1, 1) > 0 ? hi : lo) = f;
  }
  Mat3 F = Mat3::Identity();
  F(0, 0) = lambda;
  F(1, 1) = 0.5 * (lo + hi);
  return F;
}

}  // namespace

// Homogeneous bar (the bar of Rupture.BarBreaksAtTheAnalyticCriticalLoad): every F_ij is
// diag(λ, f) and no weight changes before the first break, so the work on every pair is
// (V_iφ̂_ijV_j + V_jφ̂_jiV_i) Ψ(F) and the rule is Ψ(F) > ψ_c = G_c / (β₂ δ) for every bond,
// at the surfaces too (the critical work scales with the bond's own φ̂⁰).
TEST(FractureEnergy, HomogeneousBarBreaksAtTheCalibratedEnergyDensity) {
  auto c = std::make_unique<Case>();
  GridSpec g;
  g.size = Vec3(2.0, 1.0, 1.0);
  g.spacing = 1.0 / 8;
  c->body = Discretization::grid(g);
  c->mat = make_neo_hookean({1.0, 10.0}, Kinematics::plane_strain);
  c->model = std::make_unique<Model>(c->body, *c->mat);
  std::vector<int> left, right, pin;
  for (std::size_t i = 0; i < c->body.size(); ++i) {
    const Vec3& x = c->body.positions()[i];
    if (x.x() < 0.1) left.push_back(static_cast<int>(i));
    if (x.x() > 1.9) right.push_back(static_cast<int>(i));
    if (x.x() < 0.1 && x.y() < 0.1) pin.push_back(static_cast<int>(i));
  }
  std::vector<DisplacementSet> ds(3);
  ds[0] = {"left", left, {}};
  ds[0].component[0] = [](double) { return 0.0; };
  ds[1] = {"pin", pin, {}};
  ds[1].component[1] = [](double) { return 0.0; };
  const double xl = c->body.positions()[left[0]].x(), xr = c->body.positions()[right[0]].x();
  ds[2] = {"right", right, {}};
  ds[2].component[0] = [=](double t) { return 0.5 * t * (xr - xl); };
  NewtonOptions no;
  no.steps = 5;
  c->solver = std::make_unique<StaticSolver>(*c->model, ds, std::vector<TractionSet>{}, no);

  double psi3 = 0, psi4 = 0;
  c->mat->evaluate(uniaxial(*c->mat, 1.3), &psi3, nullptr, nullptr);
  c->mat->evaluate(uniaxial(*c->mat, 1.4), &psi4, nullptr, nullptr);
  const double psi_c = 0.5 * (psi3 + psi4);  // between the steps λ = 1.3 and 1.4
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = psi_c * fracture_energy_shape_factor(2) * c->body.horizon();
  Rupture rup(c->body, *c->model, ro);
  EXPECT_NEAR(rup.critical_energy_density() / psi_c, 1.0, 1e-14);
  double before = 0, lambda_break = NAN;
  for (int s = 1; s <= 5; ++s) {
    c->solver->advance_to(s / 5.0);
    const auto vals = rup.criterion_values(c->solver->displacement());
    double vmin = INFINITY, vmax = -INFINITY;
    for (double v : vals)
      if (std::isfinite(v)) vmin = std::min(vmin, v), vmax = std::max(vmax, v);
    if (rup.break_exceeding(c->solver->displacement()).broken > 0) {
      lambda_break = 1.0 + 0.5 * s / 5.0;
      break;
    }
    before = vmax;
    // one value for all bonds: Ψ(F)/ψ_c, interior and surface alike (Newton tolerance 1e-8)
    EXPECT_NEAR(vmin / vmax, 1.0, 1e-6);
  }
  EXPECT_DOUBLE_EQ(lambda_break, 1.4);
  EXPECT_NEAR(before, psi3 / psi_c, 1e-6);  // W/W_c = Ψ(diag(1.3, f))/ψ_c
}

namespace {

// Σ over the pairs crossing the plane x = 8 of a 2D body [0, 16] × [0, ny] (Δx = 1) of their
// critical work W_c,ij: what the rule dissipates when a straight crack separates the body
// along the plane and every crossing pair breaks at its critical work.
double crossing_critical_work(double m, int ny, double* G_c) {
  GridSpec g;
  g.size = Vec3(16.0, ny, 1.0);
  g.spacing = 1.0;
  DiscretizationOptions opt;
  opt.horizon_factor = m;
  Discretization body = Discretization::grid(g, opt);
  auto mat = make_neo_hookean({1.0, 2.0}, Kinematics::plane_strain);
  Model model(body, *mat);
  RuptureOptions ro;
  ro.criterion = RuptureCriterion::fracture_energy;
  ro.fracture_energy = *G_c = 0.37;
  Rupture rup(body, model, ro);
  const auto& x = body.positions();
  const Csr& fam = body.families();
  double sum = 0;
  for (std::size_t i = 0; i < body.size(); ++i)
    for (auto q = fam.begin(i); q < fam.end(i); ++q)
      if (x[i].x() < 8 && x[fam.index[q]].x() > 8) sum += rup.critical_work()[q];
  return sum;
}

}  // namespace

// (a) The calibration: the critical works of the pairs crossing a straight crack through a
// homogeneous body add up to G_c per unit crack area, to the discretisation error of the
// lattice sum Σ_j |ξ·n| φ̂_ij V_j against its continuum value β₂δ. The free top and bottom
// surfaces change the bonds near them (one-sided families, renormalised φ̂); the difference
// of two heights (24 and 40 Δx) cancels that share and leaves the interior value.
TEST(FractureEnergy, CrossingBondsCriticalWorkIsGcPerUnitArea) {
  for (double m : {3.015, 4.015, 5.015}) {
    double G_c = 0;
    const double w24 = crossing_critical_work(m, 24, &G_c),
                 w40 = crossing_critical_work(m, 40, &G_c);
    const double whole = w40 / (40 * G_c), interior = (w40 - w24) / (16 * G_c);
    std::printf(
        "m = %.3f: crossing critical work / (G_c · area): whole section %.5f, interior "
        "%.5f\n",
        m, whole, interior);
    // lattice sum vs the continuum integral at m = 3 … 5: measured within 4 % (the overlap
    // volumes |B_ij| are counted in whole cells of a grid only 3–5 cells per horizon)
    EXPECT_NEAR(interior, 1.0, 0.04);
    EXPECT_NEAR(whole, 1.0, 0.06);  // plus the two surface layers
  }
}

namespace {

// The first-order PDDO fit (basis {1, x, y}, weight exp(−4r²/δ²)) of the LEFM mode-I field
// over the lens of the bond across the tip, in the continuum limit: the disc of radius δ
// about the tip without the two sectors |θ| > 3π/4 that the crack hides from one end (a
// member m behind the tip is seen from the end on the other side of the crack iff
// |x_m| < |y_m|, for ends at (Δx/2, ∓Δx/2) and the tip at a cell corner). Returns G/G_c at
// which the small-strain Ψ of the fitted F reaches ψ_c = G_c/(β₂δ). Midpoint rule on an
// n × n grid over [−δ, δ]², the K-field from its closed form (independent of the solver's
// stencils).
double lefm_tip_lens_G_over_Gc(int n) {
  using pdcg::solver::test::kfield_E_prime;
  const double delta = 1.0, h = 2 * delta / n, lam = 4.0 / 3.0, mu = 1.0;
  const double K = std::sqrt(kfield_E_prime);  // G = K²/E' = 1
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  Eigen::Vector3d bx = Eigen::Vector3d::Zero(), by = Eigen::Vector3d::Zero();
  for (int a = 0; a < n; ++a)
    for (int b = 0; b < n; ++b) {
      const double x = -delta + (a + 0.5) * h, y = -delta + (b + 0.5) * h;
      const double r = std::hypot(x, y);
      if (r >= delta || std::abs(std::atan2(y, x)) > 0.75 * kPi) continue;
      const double w = std::exp(-4 * r * r / (delta * delta));
      const Eigen::Vector3d p(1.0, x, y);
      const Vec3 u = K * pdcg::solver::test::kfield_unit_displacement(Vec3(x, y, 0), 0.0);
      M += w * p * p.transpose();
      bx += w * u.x() * p;
      by += w * u.y() * p;
    }
  const Eigen::Vector3d cx = M.ldlt().solve(bx), cy = M.ldlt().solve(by);
  const double exx = cx(1), eyy = cy(2), exy = 0.5 * (cx(2) + cy(1));
  const double psi =
      0.5 * lam * (exx + eyy) * (exx + eyy) + mu * (exx * exx + eyy * eyy + 2 * exy * exy);
  return 1.0 / (fracture_energy_shape_factor(2) * delta * psi);
}

}  // namespace

// The criterion's reading of a crack-tip field (docs/fracture.md §5.3): the exact LEFM
// mode-I field imposed on every point of a pre-cracked square (no solve) breaks first the
// bond across the tip, at G = 4.18 G_c — the lens-averaged energy density of the K-field,
// a constant of the influence function and of the lens, not 1. Checked against the
// continuum lens fit by direct quadrature (lefm_tip_lens_G_over_Gc), which the lattice
// stencils approach as m grows (measured m = 3…8: 4.715, 4.475, 4.342, 4.267, 4.203).
TEST(FractureEnergy, ImposedKFieldBreaksTheTipBondAtTheLensAverage) {
  const double q800 = lefm_tip_lens_G_over_Gc(800), q1600 = lefm_tip_lens_G_over_Gc(1600);
  std::printf("continuum lens fit: G/G_c = %.5f (800²), %.5f (1600²)\n", q800, q1600);
  // midpoint rule on the disc's and sectors' edges: O(h), 800² vs 1600² differ by 1e-3
  EXPECT_NEAR(q800, q1600, 3e-3 * q1600);
  EXPECT_GT(q1600, 4.1);  // far from the calibration's 1: the criterion is local
  for (double m : {4.015, 6.015}) {
    const auto r = pdcg::solver::test::kfield_imposed(m, 2.2);
    std::printf("m = %.3f: G_first/G_c = %.4f at the pair (%.1f, %.1f)-(%.1f, %.1f)\n", m,
                r.G_first_over_Gc, r.from.x(), r.from.y(), r.to.x(), r.to.y());
    // the bond across the tip breaks first
    EXPECT_NEAR(std::abs(r.from.x() - 0.5) + std::abs(r.to.x() - 0.5), 0.0, 1e-12);
    EXPECT_NEAR(r.from.y() + r.to.y(), 0.0, 1e-12);
    EXPECT_NEAR(std::abs(r.from.y()), 0.5, 1e-12);
    // the lattice lens of m points per δ against its continuum limit: +7.0 % at m = 4,
    // +2.0 % at m = 6 measured, falling ∝ 1/m (whole cells in the lens); tolerance 1.5 × that
    const double tol = m < 5 ? 0.105 : 0.03;
    EXPECT_NEAR(r.G_first_over_Gc / q1600, 1.0, tol);
    EXPECT_GT(r.G_first_over_Gc, q1600);
  }
}

// Mode-I K-field boundary-layer test (docs/fracture.md §5.3): the LEFM field of K_I
// prescribed on the outer δ-layer of a pre-cracked square (L = 4δ, m = 3, the field
// following the tip, crack faces as PD surfaces: BoundaryForm::energy, like the faces
// rupture opens), K raised quasi-statically. Against the closed form K_c = √(G_c E'):
// the crack does not start or grow at K_c but at ≈ 1.85 and 1.92 K_c (G ≈ 3.4–3.7 G_c),
// while the bond work it dissipates per unit of new crack is G_c (the calibration).
TEST(FractureEnergy, KFieldCrackGrowsAboveKcButDissipatesGc) {
  using pdcg::solver::test::kfield;
  const auto r = kfield(3.015, 4.0, 0.6, true, 1.0, 50, false, BoundaryForm::energy);
  ASSERT_GE(r.events.size(), 3u);
  const auto& e0 = r.events.front();
  const auto& e1 = r.events.back();
  std::printf(
      "K_init/K_c = %.4f, K at a = %.2f δ: %.4f K_c; bond work over the advance %.3f: "
      "%.4f G_c per unit length\n",
      r.K_init(), e1.tip / r.delta, e1.K_over_Kc, e1.tip - e0.tip,
      (e1.dissipated - e0.dissipated) / (e1.tip - e0.tip));
  // measured 1.849 and 1.917 (L = 4δ; 1.809 and 1.875 at L = 10δ: the finite square's
  // O(δ/L) share); the band is 1.7–2.1 K_c, i.e. G/G_c 2.9–4.4, nowhere near 1
  EXPECT_GT(r.K_init(), 1.7);
  EXPECT_LT(r.K_init(), 2.0);
  EXPECT_GT(e1.K_over_Kc, 1.75);
  EXPECT_LT(e1.K_over_Kc, 2.1);
  EXPECT_GE(e1.K_over_Kc, r.K_init());
  // energy: the bond work dissipated per unit advance is about the calibration's G_c
  // (measured 1.07 over this 1.5Δx; 1.29–1.30 in steady growth over 1.7–2.5δ at L = 6δ and
  // 10δ; > 0.9: every pair crossing the new crack breaks with ≥ W_c, their lattice sum is G_c
  // to 3.2 %, and the granular tip position leaves a few long crossing pairs intact) and
  // below the G = K²/E' the advance releases (3.67 G_c: the rest is the snap-back of
  // abruptly broken pairs, docs/fracture.md §5.3)
  const double per_length = (e1.dissipated - e0.dissipated) / (e1.tip - e0.tip);
  EXPECT_GT(per_length, 0.9);
  EXPECT_LT(per_length, e1.K_over_Kc * e1.K_over_Kc);
}
