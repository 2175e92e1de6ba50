// Hard case (label `stability`, docs/validation.md §2): explicit dynamics at the edge of the stable step.
//
// Safeguard: ExplicitSolver refuses a time step above the Gershgorin bound
// Δt_G = 2/√(max_k Σ_n |K_kn|/M_k) (InputError) unless allow_unstable. Without it a user
// step a few percent above the true limit 2/ω_max makes the highest mode grow by a factor
// |λ| > 1 every step (for ωΔt = 2.1: λ = −1.88) and the run explodes within tens of steps.
// The tests: 0.99 Δt_G for 10⁵ steps keeps the energy bounded; 1.05 Δt_G is refused; forced,
// 1.05 Δt_G runs because the Gershgorin bound is conservative (the true limit, from the
// largest eigenvalue of M⁻¹K, is reported), and 1.05 × the true limit blows up.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "pdcg/core/error.hpp"
#include "pdcg/solver/explicit.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

using namespace pdcg::solver;

namespace {

// 6×4 points (Δx = 1/8), plane strain μ = 1, K = 10, ρ = 1, energy form (symmetric K, so
// ω² = eigenvalues of M⁻¹K are real); the left column is fixed.
struct Block {
  Discretization body;
  std::unique_ptr<Material> mat;
  std::unique_ptr<Model> model;
  std::vector<DisplacementSet> ds;
};

std::unique_ptr<Block> make_block() {
#ifdef _OPENMP
  omp_set_num_threads(1);  // 24 points
#endif
  auto b = std::make_unique<Block>();
  GridSpec g;
  g.size = Vec3(0.75, 0.5, 1.0);
  g.spacing = 0.125;
  b->body = Discretization::grid(g);
  b->mat = make_neo_hookean({1.0, 10.0}, Kinematics::plane_strain);
  ModelOptions mo;
  mo.boundary = BoundaryForm::energy;
  b->model = std::make_unique<Model>(b->body, *b->mat, mo);
  std::vector<int> left;
  for (std::size_t i = 0; i < b->body.size(); ++i)
    if (b->body.positions()[i].x() < 0.1) left.push_back(static_cast<int>(i));
  b->ds.resize(1);
  b->ds[0] = {"left", left, {}};
  b->ds[0].component[0] = [](double) { return 0.0; };
  b->ds[0].component[1] = [](double) { return 0.0; };
  return b;
}

// Small random velocities (fixed seed): every mode, including the highest, is excited.
Eigen::VectorXd random_velocity(const Block& b, double amplitude) {
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  Eigen::VectorXd v(b.model->dofs());
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = amplitude * U(rng);
  for (int p : b.ds[0].points) v[2 * p] = v[2 * p + 1] = 0.0;
  return v;
}

// True stable limit 2/ω_max from the largest eigenvalue of M⁻¹K on the free dofs.
double true_limit(const Block& b, const ExplicitSolver& s) {
  Eigen::VectorXd f;
  SparseRow K;
  b.model->internal_force_and_tangent(Eigen::VectorXd::Zero(b.model->dofs()), f, K);
  std::vector<int> free;
  std::vector<char> fixed(b.model->dofs(), 0);
  for (int p : b.ds[0].points) fixed[2 * p] = fixed[2 * p + 1] = 1;
  for (std::size_t i = 0; i < fixed.size(); ++i)
    if (!fixed[i]) free.push_back(static_cast<int>(i));
  const Eigen::MatrixXd Kd = Eigen::MatrixXd(K);
  const int n = static_cast<int>(free.size());
  Eigen::MatrixXd A(n, n);  // M^{-1/2} K M^{-1/2}, symmetric
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      A(r, c) = Kd(free[r], free[c]) / std::sqrt(s.mass()[free[r]] * s.mass()[free[c]]);
  const double wmax2 = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(A).eigenvalues().maxCoeff();
  return 2.0 / std::sqrt(wmax2);
}

double energy(const Block& b, const ExplicitSolver& s) {
  return s.modified_kinetic_energy() + b.model->energy(s.displacement());
}

}  // namespace

TEST(ExplicitStability, BoundedEnergyAt099OfTheStableStepFor1e5Steps) {
  auto b = make_block();
  ExplicitOptions o;
  o.safety = 0.99;
  ExplicitSolver s(*b->model, b->ds, o);
  s.set_velocity(random_velocity(*b, 1e-4));
  const double E0 = energy(*b, s);
  double first_half = 0, second_half = 0;
  const int n = 100000;
  for (int k = 1; k <= n; ++k) {
    s.step();
    if (k % 100) continue;
    const double E = energy(*b, s);
    ASSERT_TRUE(std::isfinite(E)) << "step " << k;
    (k <= n / 2 ? first_half : second_half) = std::max(k <= n / 2 ? first_half : second_half, E);
  }
  std::printf("0.99 Δt_G (Δt = %.5g), 1e5 steps: E0 %.4e, max E first half %.4e, second %.4e\n",
              s.time_step(), E0, first_half, second_half);
  // bounded: the Verlet energy is conserved up to the (small) nonlinearity; a growing mode
  // would make the second half's peak exceed the first half's
  EXPECT_LT(second_half, 1.1 * first_half);
  EXPECT_LT(first_half, 1.5 * E0);
}

TEST(ExplicitStability, AboveTheStableStepIsRefusedUnlessForced) {
  auto b = make_block();
  ExplicitOptions o;
  ExplicitSolver ref(*b->model, b->ds, o);
  const double dtG = ref.stable_limit();
  const double dtT = true_limit(*b, ref);
  std::printf("Gershgorin limit %.6g, true limit 2/ω_max %.6g (ratio %.4f)\n", dtG, dtT, dtT / dtG);
  EXPECT_LE(dtG, dtT * (1 + 1e-12));  // Gershgorin never exceeds the true limit
  o.time_step = 1.05 * dtG;
  EXPECT_THROW(ExplicitSolver(*b->model, b->ds, o), pdcg::InputError);
  // forced: 1.05 Δt_G, and 1.05 × the true limit
  auto run = [&](double dt, int steps) -> std::pair<int, double> {
    ExplicitOptions f;
    f.time_step = dt;
    f.allow_unstable = true;
    ExplicitSolver s(*b->model, b->ds, f);
    s.set_velocity(random_velocity(*b, 1e-4));
    const double E0 = energy(*b, s);
    double Emax = E0;
    try {
      for (int k = 1; k <= steps; ++k) {
        s.step();
        const double E = energy(*b, s);
        if (!std::isfinite(E) || E > 1e6 * E0) return std::make_pair(k, HUGE_VAL);
        Emax = std::max(Emax, E);
      }
    } catch (const pdcg::NumericalError&) {  // J ≤ 0: blown up
      return std::make_pair(steps, HUGE_VAL);
    }
    return std::make_pair(steps, Emax / E0);
  };
  const auto at_G = run(1.05 * dtG, 20000);
  const auto at_T = run(1.05 * dtT, 2000);
  std::printf(
      "forced 1.05 Δt_G: %d steps, max E/E0 %.4g; forced 1.05 × true limit: blew up "
      "after %d steps (E/E0 %g)\n",
      at_G.first, at_G.second, at_T.first, at_T.second);
  if (1.05 * dtG < dtT) {
    EXPECT_LT(at_G.second, 1.5);  // below the true limit: still stable, as the bound says
  } else {
    EXPECT_TRUE(std::isinf(at_G.second));
  }
  EXPECT_TRUE(std::isinf(at_T.second)) << "1.05 × the true limit must blow up";
  EXPECT_LT(at_T.first, 2000);
}
