#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "pdcg/dispersion/closed_form.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::dispersion;

// Reference values (μ = M = h = 1): √(2(1 − cos 1)) = 0.958851…, 2 at κ = π.
TEST(ClosedForm, NearestNeighbourChain) {
  const std::vector<double> mu{1.0};
  EXPECT_NEAR(chain_omega(1.0, 1.0, 1.0, mu), 0.958851077208406, 1e-14);  // 15-digit reference
  EXPECT_NEAR(chain_omega(std::numbers::pi, 1.0, 1.0, mu), 2.0, 1e-14);
  // ε = 2: ω(2κ)/2 = 0.841471 at κ = 1 (= sin 1), 1 at κ = π/2
  auto w = [&](double k) { return chain_omega(k, 1.0, 1.0, mu); };
  EXPECT_NEAR(rescaled_omega(w, 1.0, 2.0), std::sin(1.0), 1e-14);
  EXPECT_NEAR(rescaled_omega(w, std::numbers::pi / 2, 2.0), 1.0, 1e-14);
}

TEST(ClosedForm, NextNearestChainAndLongWaveLimit) {
  const std::vector<double> mu{1.0, 0.25};
  for (double k : {0.1, 0.7, 2.0, 3.0}) {
    const double expect = std::sqrt(2 * (1 - std::cos(k)) + 2 * 0.25 * (1 - std::cos(2 * k)));
    EXPECT_NEAR(chain_omega(k, 1.0, 1.0, mu), expect, 1e-14);
  }
  // ω/κ → h √(Σ μ_n n²/M) = √(1 + 0.25·4) = √2 as κ → 0 (error O(κ²))
  EXPECT_NEAR(chain_omega(1e-4, 1.0, 1.0, mu) / 1e-4, chain_long_wave_speed(1.0, 1.0, mu), 1e-8);
  EXPECT_NEAR(chain_long_wave_speed(1.0, 1.0, mu), std::sqrt(2.0), 1e-15);
}

TEST(ClosedForm, ConstantMicromodulusBar) {
  // Long waves: ρω² → C κ² δ³/3 (the local limit E = C δ³/3 of Silling 2000)
  const double rho = 2.0, c = 3.0, delta = 0.5;
  const double k = 1e-4;
  EXPECT_NEAR(constant_micromodulus_omega(k, rho, c, delta),
              k * std::sqrt(c * delta * delta * delta / 3 / rho), 1e-12);
  // A κ where the direct formula holds: 2C(δ − sin κδ / κ)
  const double k2 = 7.0;
  EXPECT_NEAR(constant_micromodulus_omega(k2, rho, c, delta),
              std::sqrt(2 * c * (delta - std::sin(k2 * delta) / k2) / rho), 1e-14);
  // Short waves saturate: ω² → 2Cδ/ρ
  EXPECT_NEAR(constant_micromodulus_omega(1e7, rho, c, delta), std::sqrt(2 * c * delta / rho),
              1e-6);
}
