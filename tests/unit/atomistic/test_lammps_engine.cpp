// Fallback styles through embedded LAMMPS, compared with the `lmp` executable run on the same
// configuration (its dump of forces and pe/atom is the reference, parsed here by hand).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/lammps_potential.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"
#include "potential_test_util.hpp"

using namespace pdcg::atomistic;

#if PDCG_WITH_LAMMPS
namespace {

/// Diamond-cubic Si, n³ cells of 8 atoms, coordinates displaced by up to noise·a.
Atoms diamond(int n, double a, double noise, unsigned seed) {
  return pdcg::test::diamond(n, a, noise * a, false, seed);
}

struct Reference {
  std::vector<double> pe, f;
};

/// Runs `lmp` on a data file of `at` with the given potential lines, reads back its dump.
Reference run_lmp(const Atoms& at, const std::string& potential_lines, const std::string& tag) {
  const auto dir = std::filesystem::temp_directory_path() / ("pdcg_lmp_" + tag);
  std::filesystem::create_directories(dir);
  {
    std::ofstream d(dir / "conf.data");
    d.precision(17);
    d << "Si test\n\n"
      << at.size() << " atoms\n1 atom types\n"
      << at.box.lo[0] << ' ' << at.box.hi[0] << " xlo xhi\n"
      << at.box.lo[1] << ' ' << at.box.hi[1] << " ylo yhi\n"
      << at.box.lo[2] << ' ' << at.box.hi[2] << " zlo zhi\n\nMasses\n\n1 28.0855\n\nAtoms\n\n";
    for (std::size_t i = 0; i < at.size(); ++i)
      d << at.id[i] << " 1 " << at.x[3 * i] << ' ' << at.x[3 * i + 1] << ' ' << at.x[3 * i + 2]
        << '\n';
  }
  {
    std::ofstream in(dir / "in.run");
    in << "units metal\natom_style atomic\nboundary p p p\nread_data "
       << (dir / "conf.data").string() << "\n"
       << potential_lines << "compute pe all pe/atom\n"
       << "dump d all custom 1 " << (dir / "out.dump").string() << " id fx fy fz c_pe\n"
       << "dump_modify d format float %.17g sort id\nrun 0\n";
  }
  const std::string cmd =
      "cd " + dir.string() + " && lmp -in in.run -log none -screen none -nocite > lmp.out 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << "lmp failed, see " << dir / "lmp.out";
  Reference r;
  r.pe.assign(at.size(), 0.0);
  r.f.assign(3 * at.size(), 0.0);
  std::ifstream dump(dir / "out.dump");
  std::string line;
  bool atoms = false;
  std::size_t read = 0;
  while (std::getline(dump, line)) {
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      atoms = true;
      continue;
    }
    if (!atoms) continue;
    std::istringstream ss(line);
    long id;
    double fx, fy, fz, pe;
    ss >> id >> fx >> fy >> fz >> pe;
    const auto k = static_cast<std::size_t>(id - 1);
    r.f[3 * k] = fx;
    r.f[3 * k + 1] = fy;
    r.f[3 * k + 2] = fz;
    r.pe[k] = pe;
    ++read;
  }
  EXPECT_EQ(read, at.size());
  if (!::testing::Test::HasFailure())
    std::filesystem::remove_all(dir);  // kept for diagnosis otherwise
  return r;
}

}  // namespace

TEST(LammpsEngine, TersoffFallbackMatchesLmpDump) {
  const std::string lines = "pair_style tersoff\npair_coeff * * Si.tersoff Si\n";
  const Atoms at = diamond(3, 5.431, 0.03, 61);
  const PotentialSpec spec =
      read_potential_commands_from_string("units metal\n" + lines, "si-tersoff.in", 1);
  const LammpsEngine engine(spec);
  const LammpsResult r = engine.evaluate(at);
  // lmp resolves "Si.tersoff" through $LAMMPS_POTENTIALS; give it the resolved path
  const std::string resolved =
      "pair_style tersoff\npair_coeff * * " + *find_potential_file("Si.tersoff") + " Si\n";
  const Reference ref = run_lmp(at, resolved, "tersoff");
  // Same LAMMPS code on the same (17-digit) positions; only the I/O differs: round-off.
  EXPECT_LT(pdcg::test::max_norm_relative_error(r.force, ref.f), 1e-12);
  EXPECT_LT(pdcg::test::max_norm_relative_error(r.energy, ref.pe), 1e-12);
  double fmax = 0;
  for (double v : ref.f) fmax = std::max(fmax, std::abs(v));
  EXPECT_GT(fmax, 0.1);  // perturbed: forces are not trivially zero
}

TEST(LammpsEngine, StillingerWeberFallbackMatchesLmpDump) {
  const std::string lines =
      "pair_style sw\npair_coeff * * " + *find_potential_file("Si.sw") + " Si\n";
  const Atoms at = diamond(3, 5.431, 0.03, 62);
  const LammpsEngine engine(
      read_potential_commands_from_string("units metal\n" + lines, "si-sw.in", 1));
  const LammpsResult r = engine.evaluate(at);
  const Reference ref = run_lmp(at, lines, "sw");
  // Same LAMMPS code on the same positions: round-off.
  EXPECT_LT(pdcg::test::max_norm_relative_error(r.force, ref.f), 1e-12);
  EXPECT_LT(pdcg::test::max_norm_relative_error(r.energy, ref.pe), 1e-12);
}

// Force states of fallback styles from finite differences of LAMMPS per-atom energies
// (docs/theory.md §1: t_kj = ∂ψ_k/∂Y⟨ξ_kj⟩): the PD force Σ_j (t_kj − t_jk) must be the LAMMPS
// force. The reference is the `lmp` executable's dump of the same configuration.
namespace {
struct ForceStateRun {
  Families families;
  std::vector<double> psi, t, f;
  double total = 0.0;
};
ForceStateRun fallback_force_states(const LammpsEngine& engine, const Atoms& at, double cutoff) {
  ForceStateRun r;
  FamilyOptions opt;
  opt.cutoff = cutoff;
  r.families = build_families(at, opt);
  r.psi.resize(at.size());
  r.t.resize(3 * r.families.bonds());
  r.f.resize(3 * at.size());
  r.total = lammps_force_states(engine, at, r.families, r.psi, r.t);
  pd_forces(r.families, r.t, r.f);
  return r;
}
}  // namespace

TEST(LammpsForceStates, TersoffPdForcesEqualLmpForces) {
  const std::string resolved =
      "pair_style tersoff\npair_coeff * * " + *find_potential_file("Si.tersoff") + " Si\n";
  const Atoms at = diamond(3, 5.431, 0.03, 71);  // box 16.3 Å > 2 × horizon
  const LammpsEngine engine(
      read_potential_commands_from_string("units metal\n" + resolved, "si-tersoff.in", 1));
  // Si.tersoff: R = 3.0, D = 0.2 → r_c = R + D = 3.2 Å; bond-order energies reach 2 r_c.
  const ForceStateRun run = fallback_force_states(engine, at, 6.5);
  const Reference ref = run_lmp(at, resolved, "tersoff_fs");
  // Central differences, h = 1e-5 × mean bond (≈ 5e-5 Å): truncation O(h²) ≈ 1e-9 relative,
  // round-off ≈ 1e-16 |ψ|/h per term summed over ~100 bonds: 1e-7 is a safe bound.
  const double err = pdcg::test::max_norm_relative_error(run.f, ref.f);
  std::printf("tersoff: PD force vs lmp, max-norm relative error %.3g\n", err);
  EXPECT_LT(err, 1e-7);
  // ψ_k is LAMMPS's pe/atom of the unperturbed configuration: round-off.
  EXPECT_LT(pdcg::test::max_norm_relative_error(run.psi, ref.pe), 1e-12);
  // Bonds longer than r_c carry force states (three-body terms): the 2 r_c horizon is needed.
  double beyond = 0.0;
  for (std::size_t k = 0; k < run.families.points(); ++k)
    for (auto b = static_cast<std::size_t>(run.families.offset[k]);
         b < static_cast<std::size_t>(run.families.offset[k + 1]); ++b)
      if (bond_vector(run.families, at.x, k, b).norm() > 3.2)
        beyond = std::max(beyond, std::abs(run.t[3 * b]) + std::abs(run.t[3 * b + 1]) +
                                      std::abs(run.t[3 * b + 2]));
  EXPECT_GT(beyond, 1e-3);
}

TEST(LammpsForceStates, StillingerWeberFreeClusterForcesEqualLammpsForces) {
  const std::string lines =
      "pair_style sw\npair_coeff * * " + *find_potential_file("Si.sw") + " Si\n";
  Atoms at = diamond(2, 5.431, 0.03, 72);
  at.box.periodic = {false, false, false};  // free cluster: surfaces everywhere
  const LammpsEngine engine(
      read_potential_commands_from_string("units metal\n" + lines, "sw.in", 1));
  const LammpsResult direct = engine.evaluate(at);
  // Si.sw: r_c = a σ = 3.77 Å; three-body terms reach 2 r_c.
  const ForceStateRun run = fallback_force_states(engine, at, 7.6);
  // Finite differences against LAMMPS's analytic forces (same reasoning as above).
  const double err = pdcg::test::max_norm_relative_error(run.f, direct.force);
  std::printf("sw cluster: PD force vs LAMMPS, max-norm relative error %.3g\n", err);
  EXPECT_LT(err, 1e-7);
  EXPECT_NEAR(run.total, direct.total_energy, 1e-12 * std::abs(direct.total_energy));
}

TEST(LammpsForceStates, HorizonOfOneCutoffIsRejectedForThreeBodyStyles) {
  const std::string lines =
      "pair_style sw\npair_coeff * * " + *find_potential_file("Si.sw") + " Si\n";
  Atoms at = diamond(2, 5.431, 0.03, 73);
  at.box.periodic = {false, false, false};
  const LammpsEngine engine(
      read_potential_commands_from_string("units metal\n" + lines, "sw.in", 1));
  try {
    (void)fallback_force_states(engine, at, 3.8);  // r_c only
    FAIL() << "expected InputError";
  } catch (const pdcg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("horizon too small"), std::string::npos) << e.what();
  }
}

TEST(LammpsForceStates, TwoImagesOfOneAtomAreRejected) {
  const std::string lines =
      "pair_style sw\npair_coeff * * " + *find_potential_file("Si.sw") + " Si\n";
  const Atoms at = diamond(2, 5.431, 0.0, 74);  // periodic box 10.9 Å < 2 × 7.6 Å
  const LammpsEngine engine(
      read_potential_commands_from_string("units metal\n" + lines, "sw.in", 1));
  try {
    (void)fallback_force_states(engine, at, 7.6);
    FAIL() << "expected InputError";
  } catch (const pdcg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("two periodic images"), std::string::npos) << e.what();
  }
}

// The same fallback as a Potential (what make_potential returns for a non-native style;
// tersoff is native, so it is built here by make_lammps_potential): force states per family
// on free clusters; the PD forces of the whole periodic body are the LAMMPS forces.
TEST(LammpsPotential, TersoffBodyForcesEqualLammpsForces) {
  const std::string lines =
      "pair_style tersoff\npair_coeff * * " + *find_potential_file("Si.tersoff") + " Si\n";
  const PotentialSpec spec =
      read_potential_commands_from_string("units metal\n" + lines, "si-tersoff.in", 1);
  const auto potential = make_lammps_potential(spec);
  // Si.tersoff: R = 3.0, D = 0.2 (the file) → r_c = 3.2 Å, family cutoff 2 r_c; measured by
  // bisection to 1e-9 relative
  EXPECT_NEAR(potential->cutoff(), 6.4, 1e-7);
  const Atoms at = diamond(2, 5.431, 0.03, 75);  // box 10.9 Å < 2 × 6.4 Å: images are partners
  const Families fam = build_families(at, family_options(*potential, spec, nullptr));
  std::vector<double> bonds(3 * fam.bonds()), psi(at.size()), t(3 * fam.bonds()), f(3 * at.size());
  deformed_bonds(fam, at.x, fam.h, bonds);
  const double total = force_states(*potential, fam, at.type, bonds, psi, t);
  pd_forces(fam, t, f);
  const LammpsResult direct = LammpsEngine(spec).evaluate(at);
  const double err = pdcg::test::max_norm_relative_error(f, direct.force);
  std::printf("tersoff body (cluster force states): max-norm relative force error %.3g\n", err);
  // central differences (h = 1e-5 × mean bond), as in LammpsForceStates above
  EXPECT_LT(err, 1e-7);
  // ψ_k on the cluster is LAMMPS's periodic pe/atom: summation-order round-off
  EXPECT_LT(pdcg::test::max_norm_relative_error(psi, direct.energy), 1e-12);
  EXPECT_NEAR(total, direct.total_energy, 1e-11 * std::abs(direct.total_energy));
}

// make_potential routes a style without a native implementation (tersoff/mod) to the
// embedded-LAMMPS fallback, whose body forces are LAMMPS's.
TEST(LammpsPotential, NonNativeStyleTersoffModIsTheFallback) {
  const std::string lines =
      "pair_style tersoff/mod\npair_coeff * * " + *find_potential_file("Si.tersoff.mod") + " Si\n";
  const PotentialSpec spec =
      read_potential_commands_from_string("units metal\n" + lines, "si-tersoff-mod.in", 1);
  EXPECT_FALSE(native_pair_style("tersoff/mod"));
  const auto potential = make_potential(spec);
  EXPECT_EQ(potential->style(), "tersoff/mod (embedded LAMMPS)");
  // Si.tersoff.mod: R = 3.0, D = 0.3 → r_c = 3.3 Å, family cutoff 2 r_c (bisection to 1e-9;
  // the modified f_C flattens at r_c, so the dimer energy rounds to 0 some 1e-7 Å before it)
  EXPECT_NEAR(potential->cutoff(), 6.6, 1e-6);
  const Atoms at = diamond(2, 5.431, 0.03, 76);
  const Families fam = build_families(at, family_options(*potential, spec, nullptr));
  std::vector<double> bonds(3 * fam.bonds()), psi(at.size()), t(3 * fam.bonds()), f(3 * at.size());
  deformed_bonds(fam, at.x, fam.h, bonds);
  force_states(*potential, fam, at.type, bonds, psi, t);
  pd_forces(fam, t, f);
  const LammpsResult direct = LammpsEngine(spec).evaluate(at);
  const double err = pdcg::test::max_norm_relative_error(f, direct.force);
  std::printf("tersoff/mod body (cluster force states): max-norm relative force error %.3g\n", err);
  EXPECT_LT(err, 1e-7);  // central differences, as above
  EXPECT_LT(pdcg::test::max_norm_relative_error(psi, direct.energy), 1e-12);
}

// Native sw and tersoff force states bond by bond against the fallback's central differences
// of LAMMPS's pe/atom on clusters (an independent path: LAMMPS's own per-atom energies): the
// attribution ψ_k = pe/atom and its derivative t_kj agree, not only the net forces.
TEST(LammpsPotential, NativeForceStatesEqualFallbackFiniteDifferences) {
  for (const std::string& lines :
       {"pair_style sw\npair_coeff * * " + *find_potential_file("Si.sw") + " Si\n",
        "pair_style tersoff\npair_coeff * * " + *find_potential_file("Si.tersoff") + " Si\n"}) {
    const PotentialSpec spec = read_potential_commands_from_string("units metal\n" + lines, "m", 1);
    const auto native = make_potential(spec);
    const auto fallback = make_lammps_potential(spec);
    EXPECT_EQ(native->style(), spec.pair_style);
    // the horizon 2 r_c: tersoff R + D = 3.2 Å, sw a σ = 3.77118 Å (the file); the fallback
    // measures it by bisection on dimer energies, which for sw's exp(σ/(r − aσ)) underflow to 0
    // some 3e-3 Å before a σ
    if (spec.pair_style == "tersoff") {
      EXPECT_NEAR(native->cutoff(), fallback->cutoff(), 1e-7);
    }
    EXPECT_NEAR(native->cutoff(), spec.pair_style == "sw" ? 2.0 * 2.0951 * 1.80 : 2.0 * (3.0 + 0.2),
                1e-12);
    EXPECT_GE(native->cutoff(), fallback->cutoff() - 1e-7);
    const Atoms at = diamond(2, 5.431, 0.03, 77);
    const Families fam = build_families(at, family_options(*native, spec, nullptr));
    std::vector<double> Y(3 * fam.bonds()), psi_n(at.size()), psi_f(at.size()),
        t_n(3 * fam.bonds()), t_f(3 * fam.bonds());
    deformed_bonds(fam, at.x, fam.h, Y);
    // every 8th atom's family through the slow fallback
    for (std::size_t k = 0; k < at.size(); k += 8) {
      const std::int64_t b0 = fam.offset[k], n = fam.offset[k + 1] - b0;
      std::vector<int> nt(static_cast<std::size_t>(n));
      for (std::int64_t b = 0; b < n; ++b)
        nt[static_cast<std::size_t>(b)] = at.type[static_cast<std::size_t>(fam.neighbor[b0 + b])];
      FamilyState st;
      st.type = at.type[k];
      st.size = n;
      st.neighbor_type = nt.data();
      st.bond = Y.data() + 3 * b0;
      psi_n[k] = native->force_state(st, t_n.data() + 3 * b0);
      psi_f[k] = fallback->force_state(st, t_f.data() + 3 * b0);
    }
    const double et = pdcg::test::max_norm_relative_error(t_n, t_f);
    const double ep = pdcg::test::max_norm_relative_error(psi_n, psi_f);
    std::printf("%s: native vs fallback force states %.3g, ψ %.3g\n", spec.pair_style.c_str(), et,
                ep);
    EXPECT_LT(et, 1e-7);   // central differences of pe/atom, as above
    EXPECT_LT(ep, 1e-12);  // the same energy, summation order
  }
}

TEST(LammpsEngine, UnknownStyleIsAnInputErrorNotAnAbort) {
  const auto spec = read_potential_commands_from_string(
      "pair_style no/such/style 2.0\npair_coeff * * 1 1\n", "bad.in", 1);
  try {
    LammpsEngine e(spec);
    FAIL() << "expected InputError";
  } catch (const pdcg::InputError& e) {
    EXPECT_EQ(e.line_number(), 1);
    EXPECT_EQ(e.bad_value(), "no/such/style");
  }
}

TEST(LammpsEngine, AtomTypeBeyondPotentialIsAnInputError) {
  const auto spec = read_potential_commands_from_string(
      "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1 1\n", "t.in");
  const LammpsEngine engine(spec);
  Atoms at = diamond(1, 3.0, 0.0, 1);
  at.type[3] = 2;
  EXPECT_THROW(engine.evaluate(at), pdcg::InputError);
}

TEST(LammpsEngine, MolecularChecksBeforeLammpsCouldAbort) {
  const std::string fene =
      "units lj\natom_style bond\npair_style lj/cut 1.12\npair_coeff * * 1 1\nbond_style fene\n"
      "bond_coeff 1 30 1.5 1 1\nspecial_bonds fene\n";
  const LammpsEngine engine(read_potential_commands_from_string(fene, "fene.in", 1));
  Atoms at = diamond(2, 4.0, 0.0, 1);
  // no bonds at all: the bond type still exists for bond_coeff (LAMMPS would abort otherwise)
  EXPECT_NO_THROW(engine.evaluate(at));
  // a bond longer than 2 R0 = 3: "Bad FENE bond" in LAMMPS, an InputError here
  at.bonds.push_back({1, 1, 2});  // (0,0,0)-(2,2,0): 2.83 < 3: fine
  EXPECT_NO_THROW(engine.evaluate(at));
  at.bonds.push_back({1, 1, 5});   // (0,0,0)-(1,1,1) = 1.73: fine
  at.bonds.push_back({1, 1, 36});  // (0,0,0)-(4,2,2) = 4.9 > 3 (box 8: no shorter image)
  try {
    engine.evaluate(at);
    FAIL() << "expected InputError";
  } catch (const pdcg::InputError& e) {
    EXPECT_EQ(e.line_number(), 6);
  }
  // bond_style with an atom style without bonds
  EXPECT_THROW(LammpsEngine(read_potential_commands_from_string(
                   "units lj\nbond_style harmonic\nbond_coeff 1 1 1\n", "b.in", 1)),
               pdcg::InputError);
}
#endif  // PDCG_WITH_LAMMPS
