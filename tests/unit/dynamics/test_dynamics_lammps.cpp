// Fixed-family dynamics of delta bodies against LAMMPS `fix nve` on the same atoms, velocities
// and time step (embedded LAMMPS, the independent reference): FCC LJ (lj/cut 2.5) and FCC Cu
// (eam, Cu_u3), diamond Si (sw, tersoff: the many-body kernel), perturbed, 100 steps. Energy
// conservation of a small crystal over 10⁴ steps; NVE drift of sw/tersoff against LAMMPS's own.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <omp.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "../atomistic/potential_test_util.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/dynamics/dynamics.hpp"
#include "pdcg_test.hpp"

#ifdef PDCG_WITH_LAMMPS
#include <library.h>
#endif

using namespace pdcg;
using atomistic::Atoms;

namespace {

/// FCC (nbasis 4) or diamond (nbasis 8) lattice of n³ cells, coordinates displaced by up to
/// noise·a.
Atoms fcc(int n, double a, double noise, unsigned seed, int nbasis = 4) {
  return test::cubic_lattice(n, n, n, a, nbasis, noise * a, false, seed);
}

struct MdSetup {
  const char* units;
  std::string potential;  // pair commands (LAMMPS syntax, also read by pdcg)
  double a, noise, temperature, dt, family_cutoff, mass;
  int nbasis = 4;  ///< 4: FCC, 8: diamond
};

body::Body make_body(const MdSetup& s, const Atoms& at) {
  const std::string cmds = std::string("units ") + s.units + "\n" + s.potential;
  const auto spec = atomistic::read_potential_commands_from_string(cmds, "test", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  Atoms a = at;
  a.type_mass = {std::numeric_limits<double>::quiet_NaN(), s.mass};
  // Families a skin beyond the cutoff: atoms that come within the cutoff during the run are
  // already in the family (LAMMPS rebuilds its lists; fixed families must hold them).
  return body::make_delta_body(a, pot, spec,
                               {.dimension = 3, .cutoff = s.family_cutoff, .source = "test"});
}

#ifdef PDCG_WITH_LAMMPS
/// LAMMPS fix nve on the body's atoms (box [0, L)³, L = at.box.hi) from velocities v0 with the
/// setup's pair commands, mass and time step: a data file at 17 digits in `dir`, the deck
/// `units … read_data … fix 1 all nve`, neighbour lists checked every step (LAMMPS's
/// `check yes`: rebuilt when an atom moved half the skin), then `tail` (thermo and run).
/// Log to `log` (empty: none). Returns the open handle; the caller gathers, closes and removes
/// `dir`.
void* lammps_nve(const MdSetup& s, const Atoms& at, const body::Body& b,
                 const std::vector<double>& v0, const std::filesystem::path& dir,
                 const std::string& log, const std::string& tail) {
  std::filesystem::create_directories(dir);
  const auto data = (dir / "atoms.data").string();
  {
    std::ofstream d(data);
    d << "crystal\n\n" << b.size() << " atoms\n1 atom types\n\n";
    d << fmt::format("0 {:.17g} xlo xhi\n0 {:.17g} ylo yhi\n0 {:.17g} zlo zhi\n\n", at.box.hi[0],
                     at.box.hi[1], at.box.hi[2]);
    d << fmt::format("Masses\n\n1 {:.17g}\n\nAtoms # atomic\n\n", s.mass);
    for (std::size_t k = 0; k < b.size(); ++k)
      d << fmt::format("{} 1 {:.17g} {:.17g} {:.17g}\n", b.id[k], b.x[3 * k], b.x[3 * k + 1],
                       b.x[3 * k + 2]);
    d << "\nVelocities\n\n";
    for (std::size_t k = 0; k < b.size(); ++k)
      d << fmt::format("{} {:.17g} {:.17g} {:.17g}\n", b.id[k], v0[3 * k], v0[3 * k + 1],
                       v0[3 * k + 2]);
  }
  const int threads = omp_get_max_threads();
  const char* args[] = {"test",    "-log", log.empty() ? "none" : log.c_str(),
                        "-screen", "none", "-nocite"};
  void* lmp = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
  omp_set_num_threads(threads);
  const std::string script = std::string("units ") + s.units +
                             "\natom_style atomic\nboundary p p p\nread_data " + data + "\n" +
                             s.potential + fmt::format("mass 1 {:.17g}\n", s.mass) +
                             "neigh_modify every 1 delay 0 check yes\n" +
                             fmt::format("timestep {:.17g}\n", s.dt) + "fix 1 all nve\n" + tail;
  lammps_commands_string(lmp, script.c_str());
  return lmp;
}

void check_against_lammps(const MdSetup& s, int cells, int steps) {
  const Atoms at = fcc(cells, s.a, s.noise, 17, s.nbasis);
  const body::Body b = make_body(s, at);
  const auto v0 = dynamics::thermal_velocities(b, s.temperature, 5);
  dynamics::VelocityVerlet vv(b, b.x, v0, s.dt);
  vv.run(steps);

  const auto dir =
      std::filesystem::temp_directory_path() / ("pdcg_dyn_lmp_" + std::to_string(::getpid()));
  void* lmp = lammps_nve(s, at, b, v0, dir, "", fmt::format("thermo 0\nrun {}\n", steps));
  const std::size_t n = b.size();
  std::vector<double> x(3 * n), v(3 * n);
  std::vector<int> img(3 * n);
  lammps_gather_atoms(lmp, const_cast<char*>("x"), 1, 3, x.data());
  lammps_gather_atoms(lmp, const_cast<char*>("v"), 1, 3, v.data());
  lammps_gather_atoms(lmp, const_cast<char*>("image"), 0, 3, img.data());
  lammps_close(lmp);
  std::filesystem::remove_all(dir);

  // displacements u = y − x₀ (LAMMPS positions unwrapped with its image flags)
  const double L = at.box.hi[0];
  std::vector<double> u_lmp(3 * n), u_pd(3 * n);
  for (std::size_t i = 0; i < 3 * n; ++i) {
    u_lmp[i] = x[i] + img[i] * L - b.x[i];
    u_pd[i] = vv.positions()[i] - b.x[i];
    // LAMMPS wraps atoms read outside the box once: undo a whole-box offset
    u_lmp[i] -= L * std::round((u_lmp[i] - u_pd[i]) / L);
  }
  const double eu = test::max_norm_relative_error(u_pd, u_lmp);
  const std::vector<double> vpd(vv.velocities().begin(), vv.velocities().end());
  const double ev = test::max_norm_relative_error(vpd, v);
  std::printf("  [%s] %zu atoms, %d steps: displacement error %.2e, velocity error %.2e\n",
              s.potential.c_str(), n, steps, eu, ev);
  // same forces (to round-off, 1e-14) through the same integrator: differences are summation
  // order amplified by the dynamics' sensitivity over 100 steps (required: ~1e-10)
  EXPECT_LT(eu, 1e-10);
  EXPECT_LT(ev, 1e-10);
}

/// Largest |E(t) − E(0)| / |E(0)| over `steps` of NVE from the same atoms and velocities:
/// pdcg's VelocityVerlet (first) and LAMMPS fix nve on the same deck (second, thermo every
/// step, etotal from its log).
std::pair<double, double> energy_drift(const MdSetup& s, int cells, int steps) {
  const Atoms at = fcc(cells, s.a, s.noise, 19, s.nbasis);
  const body::Body b = make_body(s, at);
  const auto v0 = dynamics::thermal_velocities(b, s.temperature, 7);
  dynamics::VelocityVerlet vv(b, b.x, v0, s.dt);
  const double e0 = vv.thermo().total;
  double drift = 0.0;
  for (int i = 0; i < steps; ++i) {
    vv.step();
    drift = std::max(drift, std::abs(vv.thermo().total - e0));
  }
  const auto dir =
      std::filesystem::temp_directory_path() / ("pdcg_drift_lmp_" + std::to_string(::getpid()));
  const auto log = (dir / "log.lammps").string();
  lammps_close(lammps_nve(s, at, b, v0, dir, log,
                          "thermo_style custom step etotal\nthermo_modify format float %.17g\n" +
                              fmt::format("thermo 1\nrun {}\n", steps)));
  std::ifstream in(log);
  std::string line;
  std::vector<double> e;
  bool table = false;
  while (std::getline(in, line)) {
    if (line.rfind("Loop time", 0) == 0) break;
    if (table) {
      std::istringstream w(line);
      long step;
      double et;
      if (w >> step >> et) e.push_back(et);
    }
    if (line.find("Step") != std::string::npos && line.find("TotEng") != std::string::npos)
      table = true;
  }
  std::filesystem::remove_all(dir);
  EXPECT_EQ(e.size(), static_cast<std::size_t>(steps) + 1);
  double lmp_drift = 0.0;
  for (double v : e) lmp_drift = std::max(lmp_drift, std::abs(v - e.front()));
  return {drift / std::abs(e0), e.empty() ? 0.0 : lmp_drift / std::abs(e.front())};
}
#endif

const MdSetup kLJ{
    "lj", "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n", 1.5599, 0.02, 0.3, 0.005, 2.9, 1.0};
const MdSetup kCu{
    "metal", "pair_style eam\npair_coeff 1 1 /usr/share/lammps/potentials/Cu_u3.eam\n",
    3.615,   0.01,
    300.0,   0.001,
    5.95,    63.55};

// Native three-body and bond-order styles (general force-state path, families 2 r_c + skin)
const MdSetup kSiSw{
    "metal", "pair_style sw\npair_coeff * * /usr/share/lammps/potentials/Si.sw Si\n",
    5.431,   0.01,
    300.0,   0.001,
    8.0,     28.0855,
    8};
const MdSetup kSiTersoff{
    "metal", "pair_style tersoff\npair_coeff * * /usr/share/lammps/potentials/Si.tersoff Si\n",
    5.431,   0.01,
    300.0,   0.001,
    6.9,     28.0855,
    8};

}  // namespace

TEST(DynamicsVsLammps, DiamondSiStillingerWeberAndTersoffFixNve) {
#ifdef PDCG_WITH_LAMMPS
  check_against_lammps(kSiSw, 3, 100);
  check_against_lammps(kSiTersoff, 3, 100);
#else
  GTEST_SKIP() << "LAMMPS not enabled";
#endif
}

// NVE energy conservation of the many-body kernels against LAMMPS's own on the same deck:
// 216 Si atoms at 300 K, 1 fs, 1000 steps (1 ps).
TEST(DynamicsVsLammps, DiamondSiManyBodyEnergyDriftAsLammps) {
#ifdef PDCG_WITH_LAMMPS
  for (const MdSetup* s : {&kSiSw, &kSiTersoff}) {
    const auto [pd, lmp] = energy_drift(*s, 3, 1000);
    std::printf("  [%s] max |E − E0| / |E0| over 1000 steps: pdcg %.3e, LAMMPS %.3e\n",
                s->potential.c_str(), pd, lmp);
    // the same integrator and forces (1e-10): the fluctuation of E is the Verlet error of the
    // trajectory, equal while the two runs stay together and of the same size once round-off
    // has separated them (factor 2; measured: equal to 4 digits, 2.5e-6 sw, 2.1e-6 tersoff)
    EXPECT_LT(pd, 2.0 * lmp);
    EXPECT_GT(lmp, 0.0);
  }
#else
  GTEST_SKIP() << "LAMMPS not enabled";
#endif
}

TEST(DynamicsVsLammps, FccLennardJonesFixNve) {
#ifdef PDCG_WITH_LAMMPS
  check_against_lammps(kLJ, 4, 100);
#else
  GTEST_SKIP() << "LAMMPS not enabled";
#endif
}

TEST(DynamicsVsLammps, FccCopperEamFixNve) {
#ifdef PDCG_WITH_LAMMPS
  check_against_lammps(kCu, 3, 100);
#else
  GTEST_SKIP() << "LAMMPS not enabled";
#endif
}

TEST(Dynamics, SmallLennardJonesCrystalConservesEnergy) {
  // 108 atoms, 10⁴ steps of dt = 0.005 at T = 0.1 (well below the stable limit). The energy
  // is shifted to zero at the cutoff (pair_modify shift yes): unshifted lj/cut jumps by φ(r_c)
  // whenever a bond crosses r_c, in LAMMPS as here, which is not integration error.
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);  // 108 atoms: OpenMP barriers would dominate on a loaded machine
  MdSetup shifted = kLJ;
  shifted.potential += "pair_modify shift yes\n";
  const Atoms at = fcc(3, kLJ.a, 0.01, 3);
  const body::Body b = make_body(shifted, at);
  const auto st = dynamics::stable_time_step(b);
  ASSERT_LT(kLJ.dt, st.dt_stable);
  dynamics::VelocityVerlet vv(b, b.x, dynamics::thermal_velocities(b, 0.1, 9), kLJ.dt);
  const double e0 = vv.thermo().total;
  double drift = 0.0;
  for (int i = 0; i < 10000; ++i) {
    vv.step();
    drift = std::max(drift, std::abs(vv.thermo().total - e0));
  }
  std::printf(
      "  LJ 108 atoms: dt_stable %.4g, max |E − E0| / |E0| over 1e4 steps %.2e (KE %.3g, E0 "
      "%.6g)\n",
      st.dt_stable, drift / std::abs(e0), vv.thermo().kinetic, e0);
  // acceptance: total energy drift below 1e-4 relative over 10⁴ steps
  EXPECT_LT(drift / std::abs(e0), 1e-4);
  omp_set_num_threads(saved);
}

// The dedicated half-family EAM path of VelocityVerlet (Potential::eam_view) against the
// general body::Evaluator (both ends of every bond, gather over reverse bonds) and against
// LAMMPS `run 0` forces and energy, for a two-element alloy (CuNi eam/alloy, random types:
// exercises the ρ_{j→k} vs ρ_{k→j} table order) on 1 and 2 threads (2916 atoms: the parallel
// branch with per-thread buffers).
TEST(DynamicsEamHalfPath, SameForcesAsEvaluatorAndLammps) {
  const char* pot =
      "pair_style eam/alloy\npair_coeff * * /usr/share/lammps/potentials/CuNi.eam.alloy Cu Ni\n";
  const int cells = 9;
  const double a = 3.56;
  Atoms at = fcc(cells, a, 0.02, 23);
  std::mt19937 rng(4);
  for (auto& t : at.type) t = 1 + static_cast<int>(rng() % 2);
  at.type_mass = {std::numeric_limits<double>::quiet_NaN(), 63.546, 58.6934};
  const auto spec =
      atomistic::read_potential_commands_from_string(std::string("units metal\n") + pot, "test", 2);
  std::shared_ptr<const atomistic::Potential> p = atomistic::make_potential(spec);
  ASSERT_NE(p->eam_view(), nullptr);
  const body::Body b =
      body::make_delta_body(at, p, spec, {.dimension = 3, .cutoff = 6.9, .source = "test"});
  std::vector<double> y = b.x;  // a configuration away from the reference (bonds deformed)
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (auto& yi : y) yi += u(rng);
  body::Evaluator ev(b);
  const auto e = ev.deformed(y);
  const std::vector<double> f_ev(e.forces.begin(), e.forces.end());
  const int saved = omp_get_max_threads();
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    dynamics::VelocityVerlet vv(b, y, {}, 0.001);
    const std::vector<double> f(vv.forces().begin(), vv.forces().end());
    const double ef = test::max_norm_relative_error(f, f_ev);
    const double ee = std::abs(vv.thermo().potential - e.energy) / std::abs(e.energy);
    std::printf("  CuNi %zu atoms, %d threads: half path vs Evaluator: forces %.2e, energy %.2e\n",
                b.size(), threads, ef, ee);
    // same splines and formulas, different summation order: round-off (1e-13 relative)
    EXPECT_LT(ef, 1e-13);
    EXPECT_LT(ee, 1e-13);
  }
  omp_set_num_threads(saved);
#ifdef PDCG_WITH_LAMMPS
  const auto dir =
      std::filesystem::temp_directory_path() / ("pdcg_eam_half_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto data = (dir / "atoms.data").string();
  {
    std::ofstream d(data);
    d << "alloy\n\n" << b.size() << " atoms\n2 atom types\n\n";
    const double L = cells * a;
    d << fmt::format("0 {:.17g} xlo xhi\n0 {:.17g} ylo yhi\n0 {:.17g} zlo zhi\n\n", L, L, L);
    d << "Atoms # atomic\n\n";
    for (std::size_t k = 0; k < b.size(); ++k)
      d << fmt::format("{} {} {:.17g} {:.17g} {:.17g}\n", b.id[k], b.type[k], y[3 * k],
                       y[3 * k + 1], y[3 * k + 2]);
  }
  const char* args[] = {"test", "-log", "none", "-screen", "none", "-nocite"};
  void* lmp = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
  omp_set_num_threads(saved);
  const std::string script = "units metal\natom_style atomic\nboundary p p p\nread_data " + data +
                             "\n" + pot + "thermo_style custom pe\nrun 0\n";
  lammps_commands_string(lmp, script.c_str());
  const std::size_t n = b.size();
  std::vector<double> fl(3 * n);
  lammps_gather_atoms(lmp, const_cast<char*>("f"), 1, 3, fl.data());
  const double pe = lammps_get_thermo(lmp, const_cast<char*>("pe"));
  lammps_close(lmp);
  std::filesystem::remove_all(dir);
  // both kernels: the vector one where the CPU has AVX2/FMA, and the scalar loops
  for (auto kernels : {dynamics::Kernels::automatic, dynamics::Kernels::scalar}) {
    dynamics::VelocityVerlet vv(b, y, {}, 0.001, kernels);
    const std::vector<double> f(vv.forces().begin(), vv.forces().end());
    const double ef = test::max_norm_relative_error(f, fl);
    const double ee = std::abs(vv.thermo().potential - pe) / std::abs(pe);
    std::printf("  CuNi %zu atoms: half path (%s) vs LAMMPS: forces %.2e, energy %.2e\n", n,
                vv.vector_eam() ? "vector kernel" : "scalar loops", ef, ee);
    // same tables and formulas as PairEAM, summation order differs: round-off
    EXPECT_LT(ef, 1e-13);
    EXPECT_LT(ee, 1e-13);
  }
#endif
}

// The inlined pair kernel (Potential::half_pair_forces) against the general Evaluator, LJ
// with two types (mixed coefficients) on 1 and 2 threads (2916 atoms: parallel branch).
TEST(DynamicsPairKernel, SameForcesAsEvaluator) {
  MdSetup two = kLJ;
  two.potential =
      "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\npair_coeff 2 2 0.8 1.1 2.7\nmass 2 2.0\n";
  Atoms at = fcc(9, kLJ.a, 0.02, 29);
  std::mt19937 rng(6);
  for (auto& t : at.type) t = 1 + static_cast<int>(rng() % 2);
  const std::string cmds = std::string("units lj\n") + two.potential;
  const auto spec = atomistic::read_potential_commands_from_string(cmds, "test", 2);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  ASSERT_TRUE(pot->has_pair_kernel());
  at.type_mass = {std::numeric_limits<double>::quiet_NaN(), 1.0, 2.0};
  const body::Body b =
      body::make_delta_body(at, pot, spec, {.dimension = 3, .cutoff = 3.2, .source = "test"});
  std::vector<double> y = b.x;
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  for (auto& yi : y) yi += u(rng);
  body::Evaluator ev(b);
  const auto e = ev.deformed(y);
  const std::vector<double> f_ev(e.forces.begin(), e.forces.end());
  const int saved = omp_get_max_threads();
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    dynamics::VelocityVerlet vv(b, y, {}, 0.001);
    const std::vector<double> f(vv.forces().begin(), vv.forces().end());
    const double ef = test::max_norm_relative_error(f, f_ev);
    const double ee = std::abs(vv.thermo().potential - e.energy) / std::abs(e.energy);
    std::printf(
        "  LJ 2 types %zu atoms, %d threads: pair kernel vs Evaluator: forces %.2e, energy %.2e\n",
        b.size(), threads, ef, ee);
    // same formulas, summation order differs: round-off (1e-13 relative)
    EXPECT_LT(ef, 1e-13);
    EXPECT_LT(ee, 1e-13);
    // a forces-only step (no Σφ in the kernel) moves the same way; thermo() computes the
    // potential energy on demand (serially: per-thread partial sums differ in order only)
    dynamics::VelocityVerlet with(b, y, {}, 0.001), without(b, y, {}, 0.001);
    with.step(true);
    without.step(false);
    for (size_t i = 0; i < 3 * b.size(); ++i)
      ASSERT_EQ(with.positions()[i], without.positions()[i]);
    const double pw = with.thermo().potential;
    EXPECT_LT(std::abs(without.thermo().potential - pw), 1e-14 * std::abs(pw));
  }
  omp_set_num_threads(saved);
}

/// Forwards everything but eam_view: the same potential through the general paths.
class HideEamView final : public atomistic::Potential {
 public:
  explicit HideEamView(std::shared_ptr<const atomistic::Potential> b) : b_(std::move(b)) {}
  std::string style() const override { return b_->style(); }
  double cutoff() const override { return b_->cutoff(); }
  int ntypes() const override { return b_->ntypes(); }
  double force_state(const atomistic::FamilyState& f, double* t) const override {
    return b_->force_state(f, t);
  }
  void force_state_tangent(const atomistic::FamilyState& f, double* K, double* w) const override {
    b_->force_state_tangent(f, K, w);
  }

 private:
  std::shared_ptr<const atomistic::Potential> b_;
};

// O(n) Gershgorin rows of EAM families (closed forms of the rank-one embedding term) against
// the general O(n²) loop over the analytic tangent (the same potential behind a wrapper that
// hides eam_view), at a perturbed
// configuration of the CuNi alloy.
TEST(DynamicsEamHalfPath, StableStepEqualsGeneralTangentBound) {
  const char* pot =
      "pair_style eam/alloy\npair_coeff * * /usr/share/lammps/potentials/CuNi.eam.alloy Cu Ni\n";
  Atoms at = fcc(4, 3.56, 0.02, 31);
  std::mt19937 rng(8);
  for (auto& t : at.type) t = 1 + static_cast<int>(rng() % 2);
  at.type_mass = {std::numeric_limits<double>::quiet_NaN(), 63.546, 58.6934};
  const auto spec =
      atomistic::read_potential_commands_from_string(std::string("units metal\n") + pot, "test", 2);
  std::shared_ptr<const atomistic::Potential> p = atomistic::make_potential(spec);
  const body::Body b =
      body::make_delta_body(at, p, spec, {.dimension = 3, .cutoff = 6.9, .source = "test"});
  body::Body general = b;
  general.potential = std::make_shared<HideEamView>(b.potential);
  ASSERT_EQ(general.potential->eam_view(), nullptr);
  std::vector<double> y = b.x;
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (auto& yi : y) yi += u(rng);
  const auto fast = dynamics::stable_time_step(b, y);
  const auto ref = dynamics::stable_time_step(general, y);
  std::printf("  CuNi 256 atoms: ω_bound O(n) %.17g, general %.17g (atoms %lld, %lld)\n",
              fast.omega_bound, ref.omega_bound, static_cast<long long>(fast.critical_id),
              static_cast<long long>(ref.critical_id));
  // closed-form sums instead of explicit ones: round-off (1e-12 relative)
  EXPECT_LT(std::abs(fast.omega_bound - ref.omega_bound), 1e-12 * ref.omega_bound);
  EXPECT_EQ(fast.critical_id, ref.critical_id);
}
