// The vector (AVX2 + FMA) EAM kernel of VelocityVerlet (src/dynamics/eam_kernel.*) against the
// scalar loops it replaces (which are tested against LAMMPS and the general Evaluator in
// test_dynamics_lammps.cpp): forces and potential energy on perturbed crystals — one type (Cu,
// eam), two types (CuNi eam/alloy, random types: the ρ_{j→k} vs ρ_{k→j} rows), a 3-cell periodic
// box (several images of one atom: ghosts) and a free cluster (families of every length: the
// masked last block) — on 1 and 2 threads. Skipped (GTEST_SKIP) only on a CPU without AVX2 and
// FMA, where VelocityVerlet runs the scalar loops anyway.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/dynamics/dynamics.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;

namespace {

struct Case {
  const char* name;
  std::string potential;  // LAMMPS pair commands
  int ntypes, cells;
  double a, family_cutoff;
  bool periodic;
};

body::Body make(const Case& c, std::vector<double>& y) {
  atomistic::Atoms at;
  const double L = c.cells * c.a;
  at.box.hi = {L, L, L};
  if (!c.periodic) {
    at.box.lo = {-L, -L, -L};
    at.box.hi = {2 * L, 2 * L, 2 * L};
    at.box.periodic = {false, false, false};
  }
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::int64_t id = 0;
  for (int i = 0; i < c.cells; ++i)
    for (int j = 0; j < c.cells; ++j)
      for (int k = 0; k < c.cells; ++k)
        for (const auto& b : basis) {
          at.id.push_back(++id);
          at.type.push_back(1 + static_cast<int>(rng() % static_cast<unsigned>(c.ntypes)));
          for (int d = 0; d < 3; ++d)
            at.x.push_back(((d == 0 ? i : d == 1 ? j : k) + b[d]) * c.a + 0.02 * c.a * u(rng));
        }
  at.type_mass = {std::numeric_limits<double>::quiet_NaN(), 63.546, 58.6934};
  at.type_mass.resize(static_cast<std::size_t>(c.ntypes) + 1);
  const auto spec = atomistic::read_potential_commands_from_string(
      std::string("units metal\n") + c.potential, "test", c.ntypes);
  std::shared_ptr<const atomistic::Potential> p = atomistic::make_potential(spec);
  body::Body b = body::make_delta_body(
      at, p, spec, {.dimension = 3, .cutoff = c.family_cutoff, .source = "test"});
  // a configuration away from the reference: bonds deformed, some skin bonds within the cutoff
  y = b.x;
  std::uniform_real_distribution<double> w(-0.05, 0.05);
  for (auto& yi : y) yi += w(rng);
  return b;
}

}  // namespace

TEST(DynamicsEamVector, SameForcesAndEnergyAsScalarLoops) {
  if (!dynamics::eam_vector_kernel_available())
    GTEST_SKIP() << "this CPU has no AVX2/FMA: VelocityVerlet runs the scalar EAM loops only";
  const std::string cu = "pair_style eam\npair_coeff 1 1 /usr/share/lammps/potentials/Cu_u3.eam\n";
  const std::string cuni =
      "pair_style eam/alloy\npair_coeff * * /usr/share/lammps/potentials/CuNi.eam.alloy Cu Ni\n";
  const Case cases[] = {
      {"Cu, 9 cells", cu, 1, 9, 3.615, 5.45, true},
      {"CuNi, 9 cells", cuni, 2, 9, 3.56, 6.9, true},
      {"Cu, 3 cells (images)", cu, 1, 3, 3.615, 5.95, true},
      {"Cu, free cluster", cu, 1, 5, 3.615, 5.45, false},
  };
  const int saved = omp_get_max_threads();
  for (const Case& c : cases) {
    std::vector<double> y;
    const body::Body b = make(c, y);
    for (int threads : {1, 2}) {
      omp_set_num_threads(threads);
      dynamics::VelocityVerlet vec(b, y, {}, 0.001);
      dynamics::VelocityVerlet sca(b, y, {}, 0.001, dynamics::Kernels::scalar);
      ASSERT_TRUE(vec.vector_eam());
      ASSERT_FALSE(sca.vector_eam());
      const std::vector<double> fv(vec.forces().begin(), vec.forces().end());
      const std::vector<double> fs(sca.forces().begin(), sca.forces().end());
      const double ef = test::max_norm_relative_error(fv, fs);
      const double es = sca.thermo().potential;
      const double ee = std::abs(vec.thermo().potential - es) / std::abs(es);
      std::printf("  %s, %zu atoms, %d threads: vector vs scalar: forces %.2e, energy %.2e\n",
                  c.name, b.size(), threads, ef, ee);
      // same tables and formulas; FMA contraction, summation order and (r·φ)' from the value
      // coefficients (3 z3/dr instead of LAMMPS's stored row) differ by round-off (observed
      // ≤ 4e-15); 1e-13 relative to the largest force, as the other kernel tests
      EXPECT_LT(ef, 1e-13);
      EXPECT_LT(ee, 1e-13);
      // and they move alike: 20 steps, displacements relative to the largest (round-off grows
      // with the steps; 1e-11 leaves room for that growth)
      vec.run(20);
      sca.run(20);
      std::vector<double> uv(3 * b.size()), us(3 * b.size());
      for (std::size_t i = 0; i < uv.size(); ++i) {
        uv[i] = vec.positions()[i] - y[i];
        us[i] = sca.positions()[i] - y[i];
      }
      EXPECT_LT(test::max_norm_relative_error(uv, us), 1e-11);
    }
  }
  omp_set_num_threads(saved);
}
