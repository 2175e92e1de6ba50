// Explicit dynamics of PD bodies (docs/dynamics.md): stable time step of a chain (Gershgorin
// bound = the exact zone-edge frequency), refusal/acceptance around it, energy conservation,
// and the measured dispersion of pdcg runs of a delta and a rescaled chain (docs/dispersion.md).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <omp.h>
#include <unistd.h>

#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/dispersion/closed_form.hpp"
#include "pdcg/dispersion/trajectory.hpp"
#include "pdcg/dynamics/dynamics.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;
using atomistic::Atoms;

namespace {

// LAMMPS bond harmonic E = K (r − r0)²: K = μ/2 for springs of stiffness μ = 1 (M = h = 1).
const char* kChain =
    "units lj\natom_style bond\npair_style zero 2.5\npair_coeff * *\nbond_style harmonic\n"
    "bond_coeff 1 0.5 1.0\nspecial_bonds lj/coul 0.0 1.0 1.0\nmass 1 1.0\n";

/// Periodic chain of n atoms at spacing 1 along x, nearest neighbours bonded (1D body).
body::Body chain_body(int n) {
  Atoms a;
  a.box.lo = {0, -0.5, -0.5};
  a.box.hi = {static_cast<double>(n), 0.5, 0.5};
  a.box.periodic = {true, false, false};
  for (int i = 0; i < n; ++i) {
    a.id.push_back(i + 1);
    a.type.push_back(1);
    a.x.insert(a.x.end(), {static_cast<double>(i), 0.0, 0.0});
    a.bonds.push_back({1, i + 1, (i + 1) % n + 1});
  }
  const auto spec = atomistic::read_potential_commands_from_string(kChain, "chain", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  return body::make_delta_body(a, pot, spec, {.dimension = 1, .cutoff = 0.0, .source = "chain"});
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()))).string();
}

/// Small chains run on one thread: on a loaded 2-core machine OpenMP barriers of tiny loops
/// cost milliseconds per step (results do not depend on the thread count).
struct OneThread {
  int saved = omp_get_max_threads();
  OneThread() { omp_set_num_threads(1); }
  ~OneThread() { omp_set_num_threads(saved); }
};

}  // namespace

TEST(StableStep, ChainBoundIsTheZoneEdgeFrequency) {
  // For the nearest-neighbour chain the stiffness rows are (−μ, 2μ, −μ): Gershgorin gives
  // ω_max² ≤ 4μ/M, which IS the zone-edge ω(π)² = 4: the bound is exact here.
  const auto b = chain_body(32);
  const auto s = dynamics::stable_time_step(b);
  // tangent of bond harmonic by the central-difference default: ~1e-10 relative
  EXPECT_NEAR(s.omega_bound, 2.0, 1e-8);
  EXPECT_NEAR(s.dt_stable, 1.0, 1e-8);
}

TEST(StableStep, RefusesAboveAcceptsBelowWithBoundedEnergy) {
  const OneThread one;
  const auto b = chain_body(32);
  const auto s = dynamics::stable_time_step(b);
  try {
    dynamics::require_stable_time_step(1.05 * s.dt_stable, s, false);
    ADD_FAILURE() << "dt = 1.05 × stable accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("stable"), std::string::npos) << what;
    EXPECT_NE(what.find(fmt::format("{:.6g}", s.dt_stable)), std::string::npos) << what;
  }
  EXPECT_NO_THROW(dynamics::require_stable_time_step(0.99 * s.dt_stable, s, false));
  EXPECT_NO_THROW(dynamics::require_stable_time_step(1.05 * s.dt_stable, s, true));

  const auto v = dynamics::thermal_velocities(b, 0.01, 7);
  // 0.99 × stable: every mode, including the zone edge at ω dt = 1.98, stays bounded.
  dynamics::VelocityVerlet ok(b, b.x, v, 0.99 * s.dt_stable);
  const double e0 = ok.thermo().total;
  double first = 0.0, second = 0.0;
  for (int i = 0; i < 20000; ++i) {
    ok.step();
    const double e = std::abs(ok.thermo().total);
    (i < 10000 ? first : second) = std::max(i < 10000 ? first : second, e);
  }
  // bounded: the second half never exceeds the first half's peak by more than 10 %
  // (Verlet's synchronous energy oscillates near the limit but does not grow)
  EXPECT_LT(second, 1.1 * first);
  EXPECT_LT(first, 1e3 * e0);
  // 1.05 × stable (forced): the zone-edge mode grows by |λ| ≈ 1.4 per step.
  dynamics::VelocityVerlet bad(b, b.x, v, 1.05 * s.dt_stable);
  bad.run(200);
  EXPECT_GT(std::abs(bad.thermo().total), 1e6 * e0);
}

TEST(Dynamics, BadInputIsExplained) {
  auto b = chain_body(8);
  EXPECT_THROW(dynamics::VelocityVerlet(b, {}, {}, 0.0), InputError);
  EXPECT_THROW(dynamics::VelocityVerlet(b, {}, {}, -1.0), InputError);
  EXPECT_THROW(dynamics::thermal_velocities(b, -1.0, 1), InputError);
  Atoms no_v;
  EXPECT_THROW(dynamics::velocities_from_atoms(b, no_v, "x.dump"), InputError);
  b.mass[3] = std::numeric_limits<double>::quiet_NaN();
  try {
    dynamics::check_masses(b, "b.h5");
    ADD_FAILURE() << "missing mass accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("atom id 4"), std::string::npos) << e.what();
  }
}

TEST(Dynamics, ThermalVelocitiesHaveTheTemperatureAndNoMomentum) {
  const auto b = chain_body(64);
  const auto v = dynamics::thermal_velocities(b, 0.37, 11);
  dynamics::VelocityVerlet vv(b, b.x, v, 0.1);
  // exact rescaling: round-off
  EXPECT_NEAR(vv.thermo().temperature, 0.37, 1e-12);
  double p = 0.0;
  for (std::size_t k = 0; k < b.size(); ++k) {
    p += b.mass[k] * v[3 * k];
    EXPECT_EQ(v[3 * k + 1], 0.0);  // 1D body: motion along x only
  }
  EXPECT_NEAR(p, 0.0, 1e-12);
  EXPECT_EQ(dynamics::thermal_velocities(b, 0.37, 11), v);  // reproducible
}

// Measured dispersion: a pdcg dynamic run (written as a LAMMPS dump by DumpWriter, read back by the
// dump reader) of the delta chain and of the chain rescaled by ε = 2, measured with the dispersion
// code: ridge frequencies within one frequency bin of ω(κ) and ω_ε(κ) = ω(εκ)/ε.
TEST(MeasuredDispersion, DeltaAndRescaledChainRunsFollowOmegaEps) {
  const OneThread one;
  for (double eps : {1.0, 2.0}) {
    const auto delta = chain_body(32);
    const body::Body b = eps == 1.0 ? delta : coarsen::rescale(delta, eps);
    const auto v = dynamics::thermal_velocities(b, 0.01, 4928459);
    const double dt = 0.01 * eps;
    const int every = 10;
    const std::size_t frames = 1024;
    const auto path = temp_path("pdcg_dyn_chain.dump");
    {
      dynamics::VelocityVerlet vv(b, b.x, v, dt);
      dynamics::DumpWriter dump(path);
      dump.write(b, 0, vv.positions(), vv.velocities());
      for (std::size_t f = 1; f < frames; ++f) {
        vv.run(every);
        dump.write(b, vv.steps_done(), vv.positions(), vv.velocities());
      }
      dump.commit();
    }
    const atomistic::DumpReader reader(path);
    ASSERT_EQ(reader.nframes(), frames);
    std::vector<Atoms> fr;
    for (std::size_t f = 0; f < frames; ++f) fr.push_back(reader.frame(f));
    std::filesystem::remove(path);
    dispersion::TrajectoryOptions opt;
    opt.axis = 0;
    opt.component = 0;
    opt.frame_interval = dt * every;
    const auto r = dispersion::ridge(dispersion::measure(fr, opt));
    ASSERT_FALSE(r.empty());
    const std::vector<double> mu{1.0};
    auto w = [&](double k) { return dispersion::chain_omega(k, 1.0, 1.0, mu); };
    for (const auto& p : r)
      // one frequency bin: the resolution of a finite record (Hann window, peak at the nearest bin)
      EXPECT_LE(std::abs(p.omega - dispersion::rescaled_omega(w, p.kappa, eps)), p.resolution)
          << "ε = " << eps << ", κ = " << p.kappa;
    std::printf("  ε = %g: %zu ridge points, resolution %.4g\n", eps, r.size(), r.front().resolution);
  }
}
