// The many-body kernel of VelocityVerlet (native sw and tersoff: short lists, each pair and
// triplet once, Newton's third law; Potential::manybody_forces) against embedded LAMMPS `run 0`
// (forces and energy, the independent reference) and against the general body::Evaluator
// (the PD form), on perturbed, triclinic, free-surface, small periodic and two-element cells,
// on 1 and 2 threads, at the reference and at deformed positions with families of exactly
// 2 r_c (triplets whose ends are not family partners: the fixed-family weights); and its
// hand-over to the general path when atoms move beyond what the families hold.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "../atomistic/potential_test_util.hpp"
#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/dynamics/dynamics.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;
using atomistic::Atoms;
using test::diamond;
using test::slab;

namespace {

const std::string kPot = "/usr/share/lammps/potentials/";

body::Body make_body(const std::string& commands, Atoms at, double family_margin = 1.0) {
  const int ntypes = *std::max_element(at.type.begin(), at.type.end());
  const auto spec = atomistic::read_potential_commands_from_string(commands, "test", ntypes);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  at.type_mass.assign(static_cast<std::size_t>(ntypes) + 1, 28.0855);
  return body::make_delta_body(
      at, pot, spec, {.dimension = 3, .cutoff = family_margin * pot->cutoff(), .source = "test"});
}

/// Forces and energy of the kernel at the body's reference positions against LAMMPS and the
/// general path, and at deformed positions against the general path.
void check(const std::string& commands, const Atoms& at, int threads = 1) {
  const body::Body b = make_body(commands, at);
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  dynamics::VelocityVerlet vv(b, b.x, {}, 0.001);
  dynamics::VelocityVerlet gen(b, b.x, {}, 0.001, dynamics::Kernels::general);
  EXPECT_TRUE(vv.manybody_kernel()) << commands;
  EXPECT_FALSE(gen.manybody_kernel());
  const std::vector<double> f(vv.forces().begin(), vv.forces().end());
  const std::vector<double> fg(gen.forces().begin(), gen.forces().end());
  const double e = vv.thermo().potential, eg = gen.thermo().potential;
  const double err_gen = test::max_norm_relative_error(f, fg);
  // same formulas, summation order: round-off
  EXPECT_LT(err_gen, 1e-12) << commands;
  EXPECT_NEAR(e, eg, 1e-12 * std::abs(eg)) << commands;
  // deformed positions (not the reference): the kernel's lists and the families' bonds
  std::vector<double> y = b.x;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.08, 0.08);
  for (auto& v : y) v += u(rng);
  dynamics::VelocityVerlet vvd(b, y, {}, 0.001);
  dynamics::VelocityVerlet gend(b, y, {}, 0.001, dynamics::Kernels::general);
  const std::vector<double> fd(vvd.forces().begin(), vvd.forces().end());
  const std::vector<double> fgd(gend.forces().begin(), gend.forces().end());
  const double err_def = test::max_norm_relative_error(fd, fgd);
  EXPECT_LT(err_def, 1e-12) << commands;  // round-off, as above
  EXPECT_NEAR(vvd.thermo().potential, gend.thermo().potential,
              1e-12 * std::abs(gend.thermo().potential));
  EXPECT_TRUE(vvd.manybody_kernel());
  omp_set_num_threads(saved);
#if PDCG_WITH_LAMMPS
  const int ntypes = *std::max_element(at.type.begin(), at.type.end());
  const auto spec = atomistic::read_potential_commands_from_string(commands, "test", ntypes);
  const atomistic::LammpsResult ref = atomistic::LammpsEngine(spec).evaluate(at);
  const double err_lmp = test::max_norm_relative_error(f, ref.force);
  std::printf(
      "  %zu atoms, %d thread(s): kernel vs LAMMPS %.2e, vs general %.2e (deformed %.2e), "
      "energy %.12g vs %.12g\n",
      b.size(), threads, err_lmp, err_gen, err_def, e, ref.total_energy);
  // same double-precision formulas as PairSW / PairTersoff, other summation order: round-off
  EXPECT_LT(err_lmp, 1e-10) << commands;
  EXPECT_NEAR(e, ref.total_energy, 1e-10 * std::abs(ref.total_energy)) << commands;
#endif
}

const std::string kSw = "units metal\npair_style sw\npair_coeff * * " + kPot + "Si.sw Si\n";
const std::string kTersoff =
    "units metal\npair_style tersoff\npair_coeff * * " + kPot + "Si.tersoff Si\n";
const std::string kSiC =
    "units metal\npair_style tersoff\npair_coeff * * " + kPot + "SiC.tersoff Si C\n";

}  // namespace

TEST(ManybodyKernel, StillingerWeberMatchesLammpsAndGeneralPath) {
  check(kSw, diamond(3, 5.431, 0.1, false, 1));
  Atoms tri = diamond(3, 5.431, 0.1, false, 2);
  test::make_triclinic(tri, 2.1, -1.4, 1.2);
  check(kSw, tri);
  check(kSw, slab(diamond(3, 5.431, 0.1, false, 3)));
  check(kSw, test::cluster(diamond(4, 5.431, 0.1, false, 4), 7.0));
  check(kSw, diamond(2, 5.431, 0.1, false, 5));  // families hold several images of an atom
  check(kSw, diamond(3, 5.0, 0.15, false, 6));   // compressed: more partners within r_c
  check("units metal\npair_style sw\npair_coeff * * " + kPot + "GaN.sw Ga N\n",
        diamond(3, 4.5, 0.1, true, 7));  // two elements, cutoffs per pair
}

TEST(ManybodyKernel, TersoffMatchesLammpsAndGeneralPath) {
  check(kTersoff, diamond(3, 5.431, 0.1, false, 21));
  Atoms tri = diamond(3, 5.431, 0.1, false, 22);
  test::make_triclinic(tri, 2.1, -1.4, 1.2);
  check(kTersoff, tri);
  check(kTersoff, slab(diamond(3, 5.431, 0.1, false, 23)));
  check(kTersoff, test::cluster(diamond(4, 5.431, 0.1, false, 24), 7.0));
  check(kTersoff, diamond(2, 4.6, 0.15, false, 25));  // compressed, small periodic box
  // SiC.tersoff (two elements, 8 triples, cutoffs per triple), zincblende and triclinic
  check(kSiC, diamond(3, 4.36, 0.1, true, 26));
  Atoms sic = diamond(3, 4.36, 0.1, true, 27);
  test::make_triclinic(sic, 1.1, 0.7, -0.9);
  check(kSiC, sic);
  check(kSiC, slab(diamond(3, 4.36, 0.1, true, 28)));
  check("units metal\npair_style tersoff shift 0.05\npair_coeff * * " + kPot + "Si.tersoff Si\n",
        diamond(3, 5.431, 0.1, false, 29));
}

TEST(ManybodyKernel, TwoThreadsThreadPrivateForces) {
  // 2744 atoms: above the kernel's serial threshold (2048), per-thread force arrays reduced
  check(kSw, diamond(7, 5.431, 0.1, false, 31), 2);
  check(kSiC, diamond(7, 4.36, 0.1, true, 32), 2);
}

TEST(ManybodyKernel, FallsBackWhenAtomsMoveBeyondTheFamilies) {
  // Three Si atoms, families of exactly 2 r_c = 7.54 Å: at the reference the ends j, l are
  // 8.0 Å apart (not partners; i is each one's partner at 4.0 Å). Moved 2.66 Å each, to
  // 2.4 Å from i at 100°: r_c + 2 (2.66 + skin/2) > 7.54, so a pair within r_c might be
  // missing from the families (ψ_k ignores it, short lists drawn from families cannot tell):
  // the kernel hands over to the general path.
  Atoms at;
  at.box.lo = {-20, -20, -20};
  at.box.hi = {20, 20, 20};
  at.box.periodic = {false, false, false};
  at.id = {1, 2, 3};
  at.type = {1, 1, 1};
  at.x = {0, 0, 0, -4.0, 0, 0, 4.0, 0, 0};
  const body::Body b = make_body(kSw, at);
  const double t = 50.0 * std::numbers::pi / 180.0;
  const std::vector<double> y = {
      0, 0, 0, -2.4 * std::sin(t), 2.4 * std::cos(t), 0, 2.4 * std::sin(t), 2.4 * std::cos(t), 0};
  dynamics::VelocityVerlet vv(b, y, {}, 0.001);
  dynamics::VelocityVerlet gen(b, y, {}, 0.001, dynamics::Kernels::general);
  EXPECT_FALSE(vv.manybody_kernel());
  const std::vector<double> f(vv.forces().begin(), vv.forces().end());
  const std::vector<double> fg(gen.forces().begin(), gen.forces().end());
  EXPECT_LT(test::max_norm_relative_error(f, fg), 1e-14);  // the same general evaluation
  // ψ_j, ψ_l lack their thirds of φ3(i; j, l) and φ2(j, l): with families wide enough for the
  // move (1.4 × 7.54 = 10.6 Å, j and l partners) the kernel runs and the forces differ
  body::Body wide = make_body(kSw, at, 1.4);
  dynamics::VelocityVerlet vw(wide, y, {}, 0.001);
  dynamics::VelocityVerlet gw(wide, y, {}, 0.001, dynamics::Kernels::general);
  EXPECT_TRUE(vw.manybody_kernel());
  const std::vector<double> fw(vw.forces().begin(), vw.forces().end());
  const std::vector<double> fgw(gw.forces().begin(), gw.forces().end());
  EXPECT_LT(test::max_norm_relative_error(fw, fgw), 1e-12);  // round-off
  EXPECT_GT(test::max_norm_relative_error(fw, fg), 1e-3);
}

TEST(ManybodyKernel, ShortListsRebuiltAsAtomsMove) {
  // 64 Si atoms at 3000 K for 300 fs: atoms move by more than half the skin (0.19 Å for sw,
  // 0.15 Å for tersoff), so the short lists are rebuilt; families with 1.5 Å of skin keep the
  // kernel on. After the run, forces at the final positions equal the general path's.
  for (const std::string& cmds : {kSw, kTersoff}) {
    const body::Body b = make_body(cmds, diamond(2, 5.431, 0.05, false, 41), 1.0);
    const double fam = b.horizon();
    const body::Body wide = make_body(cmds, diamond(2, 5.431, 0.05, false, 41), (fam + 1.5) / fam);
    dynamics::VelocityVerlet vv(wide, wide.x, dynamics::thermal_velocities(wide, 3000.0, 3), 0.001);
    vv.run(300);
    EXPECT_TRUE(vv.manybody_kernel());
    EXPECT_GT(vv.short_list_builds(), 2);
    const std::vector<double> y(vv.positions().begin(), vv.positions().end());
    dynamics::VelocityVerlet gen(wide, y, {}, 0.001, dynamics::Kernels::general);
    const std::vector<double> f(vv.forces().begin(), vv.forces().end());
    const std::vector<double> fg(gen.forces().begin(), gen.forces().end());
    const double err = test::max_norm_relative_error(f, fg);
    std::printf("  %zu atoms, 300 steps at 3000 K: %lld list builds, forces vs general %.2e\n",
                wide.size(), static_cast<long long>(vv.short_list_builds()), err);
    EXPECT_LT(err, 1e-12);  // round-off, as above
  }
}
