// Delta bodies (docs/theory.md §1): forces = −∂U/∂y (finite differences of the energy, the MD
// definition), momentum balances, objectivity, and energy densities under homogeneous F against
// closed forms for a spring lattice.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"
#include "toy_potentials.hpp"

using namespace pdcg;
using namespace pdcg::body;

namespace {

atomistic::PotentialSpec spec_for_tests() {
  atomistic::PotentialSpec s;
  s.units = UnitStyle::lj;
  s.lines = {"pair_style test"};
  return s;
}

std::vector<double> deform_randomly(const Body& b, double amp, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amp, amp);
  std::vector<double> y = b.x;
  for (auto& v : y) v += u(rng);
  return y;
}

}  // namespace

TEST(DeltaBody, ForcesAreMinusEnergyGradientOnFreeCluster) {
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.8);
  const Body b =
      make_delta_body(test::cubic_lattice(4, 4, 3, 1.0, 0.05, false), pot, spec_for_tests());
  Evaluator ev(b);
  std::vector<double> y = deform_randomly(b, 0.08, 3);
  const Evaluation e = ev.deformed(y);
  const std::vector<double> f(e.forces.begin(), e.forces.end());
  // central differences of U(y): the MD force −∂U/∂y, independent of the force-state code
  const double h = 1e-6;
  std::vector<double> fd(y.size());
  for (std::size_t c = 0; c < y.size(); ++c) {
    auto yp = y, ym = y;
    yp[c] += h;
    ym[c] -= h;
    const double up = ev.deformed(yp).energy;
    const double um = ev.deformed(ym).energy;
    fd[c] = -(up - um) / (2 * h);
  }
  // O(h²) truncation plus round-off U·ε/h ≈ 1e-9 relative to forces of order 1
  EXPECT_LT(test::max_norm_relative_error(f, fd), 1e-7);
}

TEST(DeltaBody, LinearAndAngularMomentumBalanceOnFreeBody) {
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.8);
  const Body b =
      make_delta_body(test::cubic_lattice(5, 4, 4, 1.0, 0.05, false), pot, spec_for_tests());
  Evaluator ev(b);
  const std::vector<double> y = deform_randomly(b, 0.1, 5);
  const Evaluation e = ev.deformed(y);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), torque = Eigen::Vector3d::Zero();
  double fmax = 0, scale = 0;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const Eigen::Vector3d f(e.forces[3 * i], e.forces[3 * i + 1], e.forces[3 * i + 2]);
    const Eigen::Vector3d yi(y[3 * i], y[3 * i + 1], y[3 * i + 2]);
    sum += f;
    torque += yi.cross(f);
    fmax = std::max(fmax, f.norm());
    scale = std::max(scale, yi.norm() * f.norm());
  }
  ASSERT_GT(fmax, 0.1);
  // round-off: N terms of size fmax (resp. |y||f|) summed, ~N·1e-16
  EXPECT_LT(sum.norm(), 1e-13 * fmax * static_cast<double>(b.size()));
  EXPECT_LT(torque.norm(), 1e-13 * scale * static_cast<double>(b.size()));
}

TEST(DeltaBody, Objectivity) {
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.8);
  const Body b =
      make_delta_body(test::cubic_lattice(4, 4, 4, 1.0, 0.05, false), pot, spec_for_tests());
  Evaluator ev(b);
  const std::vector<double> y = deform_randomly(b, 0.1, 9);
  const Evaluation e1 = ev.deformed(y);
  const double U1 = e1.energy;
  const std::vector<double> f1(e1.forces.begin(), e1.forces.end());
  std::mt19937 rng(4);
  const Eigen::Matrix3d Q = test::random_rotation(rng);
  std::vector<double> yq(y.size()), fq(y.size());
  for (std::size_t i = 0; i < b.size(); ++i) {
    const Eigen::Vector3d r =
        Q * Eigen::Vector3d(y[3 * i], y[3 * i + 1], y[3 * i + 2]) + Eigen::Vector3d(3, -1, 2);
    const Eigen::Vector3d g = Q * Eigen::Vector3d(f1[3 * i], f1[3 * i + 1], f1[3 * i + 2]);
    for (int k = 0; k < 3; ++k) {
      yq[3 * i + k] = r[k];
      fq[3 * i + k] = g[k];
    }
  }
  const Evaluation e2 = ev.deformed(yq);
  // round-off of sums of O(N) terms: 1e-12 relative as required
  EXPECT_TRUE(test::close(e2.energy, U1, {0, 1e-12}));
  EXPECT_LT(test::max_norm_relative_error(e2.forces, fq), 1e-12);
}

TEST(DeltaBody, HomogeneousDeformationOfSpringLatticeMatchesClosedForm) {
  // Simple cubic lattice (spacing h), nearest-neighbour springs ½c(r − r0)²: per atom
  // ψ = Σ_{a=1..3} ½ c (h|F e_a| − r0)², W(F) = ψ / h³.
  const double h = 1.1, c = 2.5, r0 = 1.0;
  auto pot = std::make_shared<test::Springs>(c, r0, 1.3 * h);
  for (const bool triclinic : {false, true}) {
    atomistic::Atoms a = test::cubic_lattice(4, 3, 5, h, 0.0, true);
    if (triclinic) {  // tilt by whole lattice vectors: the same lattice in a triclinic cell
      a.box.xy = 2 * h;
      a.box.xz = -h;
      a.box.yz = 3 * h;
    }
    const Body b = make_delta_body(a, pot, spec_for_tests());
    ASSERT_EQ(b.families.bonds(), 6 * b.size());
    Evaluator ev(b);
    std::mt19937 rng(11);
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::Matrix3d F = test::random_deformation(rng);
      const Evaluation e = ev.homogeneous(F);
      double psi = 0;
      for (int k = 0; k < 3; ++k) psi += 0.5 * c * std::pow(h * F.col(k).norm() - r0, 2);
      // sums of N·6 terms: round-off
      EXPECT_TRUE(test::close(energy_density(b, e), psi / (h * h * h), {0, 1e-12}))
          << "triclinic " << triclinic;
      EXPECT_TRUE(test::close(b.reference_volume(), 60 * h * h * h, {0, 1e-14}));
      // homogeneous deformation of a perfect periodic lattice: no net force on any atom
      double fmax = 0;
      for (double v : e.forces) fmax = std::max(fmax, std::abs(v));
      EXPECT_LT(fmax, 1e-12 * c * h);  // cancellation of equal and opposite bond forces
    }
  }
}

TEST(DeltaBody, ReferenceEqualsIdentityDeformation) {
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.8);
  atomistic::Atoms a = test::cubic_lattice(4, 4, 4, 1.0, 0.1, true);
  a.box.xy = 0.4;
  const Body b = make_delta_body(a, pot, spec_for_tests());
  Evaluator ev(b);
  const double U0 = ev.reference().energy;
  const std::vector<double> f0(ev.reference().forces.begin(), ev.reference().forces.end());
  const Evaluation e = ev.homogeneous(Eigen::Matrix3d::Identity());
  EXPECT_EQ(e.energy, U0);
  EXPECT_TRUE(test::all_close(e.forces, f0, {1e-14, 0}));  // same arithmetic
}

TEST(DeltaBody, BadInputIsReported) {
  auto pot = std::make_shared<test::Springs>(1.0, 1.0, 1.5);
  atomistic::Atoms a = test::cubic_lattice(2, 2, 2, 1.0, 0.0, false);
  a.type[3] = 3;  // potential defines 2 types
  try {
    (void)make_delta_body(a, pot, spec_for_tests(), {.source = "conf.data"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'3'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("conf.data"), std::string::npos) << e.what();
  }
  atomistic::Atoms m = test::cubic_lattice(2, 2, 2, 1.0, 0.0, false);
  m.type_mass = {NAN, 1.0, NAN};  // type 2 has no mass
  try {
    (void)make_delta_body(m, pot, spec_for_tests());
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mass of type 2"), std::string::npos) << e.what();
  }
  // masses from the potential file's `mass` commands fill the gap
  atomistic::PotentialSpec s = spec_for_tests();
  s.type_mass = {NAN, 5.0, 7.0};
  const Body ok = make_delta_body(m, pot, s);
  EXPECT_EQ(ok.mass[1], 7.0);
  EXPECT_THROW((void)rescaled_potential(pot, 0.0, 3), InputError);
  EXPECT_THROW((void)rescaled_potential(pot, -2.0, 3), InputError);
}

// A data file does not say which directions are periodic. A free cluster written into a box
// that only just holds it overlaps its own images under LAMMPS's default p p p: refused (with
// the fix) when nothing stated the periodicity, a warning when something did; crystals and
// liquids in their periodic cells pass.
TEST(DeltaBody, OverlappingPeriodicImagesAreRefusedWhenAssumed) {
  auto pot = std::make_shared<test::Springs>(1.0, 1.0, 1.5);
  // 4×4×4 simple cubic cluster, spacing 1, atoms at 0.5 … 3.5: a box of 3.2 puts the image of
  // the face at 0.5 at 3.7, 0.2 from the face at 3.5
  atomistic::Atoms a = test::cubic_lattice(4, 4, 4, 1.0, 0.0, true);
  a.box.hi = {3.2, 4.0, 4.0};
  const auto spec = spec_for_tests();
  try {
    (void)make_delta_body(a, pot, spec, {.source = "cluster.data", .periodicity_assumed = true});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("periodic images overlap"), std::string::npos) << m;
    EXPECT_NE(m.find("cluster.data"), std::string::npos) << m;
    EXPECT_NE(m.find("shifted by (-1, 0, 0)"), std::string::npos) << m;  // the x direction
    EXPECT_NE(m.find("0.2 apart"), std::string::npos) << m;
    EXPECT_NE(m.find("boundary s s s"), std::string::npos) << m;
    EXPECT_NE(m.find("--boundary \"f f f\""), std::string::npos) << m;
  }
  // stated periodic (a boundary command, a dump header, --boundary): built, as LAMMPS would
  EXPECT_NO_THROW((void)make_delta_body(a, pot, spec,
                                        {.source = "cluster.data", .periodicity_assumed = false}));
  // free along x: nothing overlaps
  atomistic::Atoms f = a;
  f.box.periodic = {false, true, true};
  EXPECT_NO_THROW(
      (void)make_delta_body(f, pot, spec, {.source = "cluster.data", .periodicity_assumed = true}));
  // a jittered periodic crystal (box 4: images about one spacing away) passes
  EXPECT_NO_THROW((void)make_delta_body(test::cubic_lattice(4, 4, 4, 1.0, 0.1, true), pot, spec,
                                        {.source = "crystal.data", .periodicity_assumed = true}));
  // one atom per cell (no pair inside the box): cannot be judged, passes
  atomistic::Atoms one = test::cubic_lattice(1, 1, 1, 1.0, 0.0, true);
  EXPECT_NO_THROW((void)make_delta_body(one, pot, spec,
                                        {.source = "crystal.data", .periodicity_assumed = true}));
  // an atom closer to its own image than the closest pair: a film with a z height of 0.3
  atomistic::Atoms film = test::cubic_lattice(4, 4, 1, 1.0, 0.0, true);
  film.box.hi[2] = 0.3;
  EXPECT_THROW((void)make_delta_body(film, pot, spec,
                                     {.source = "crystal.data", .periodicity_assumed = true}),
               InputError);
}

// Topology: a bond style needs molecular bonds; bonds need a bond_coeff per bond type.
TEST(DeltaBody, BondStyleWithoutBondsIsRefused) {
  auto pot = std::make_shared<test::Springs>(1.0, 1.0, 1.5);
  atomistic::Atoms a = test::cubic_lattice(2, 2, 2, 1.0, 0.0, false);
  atomistic::PotentialSpec s = spec_for_tests();
  s.source = "mol.in";
  s.bond_style = "harmonic";
  s.bond_style_line = 4;
  s.bond_coeff.push_back({"1", "", {"100", "1.0"}, "bond_coeff 1 100 1.0", 5});
  try {
    (void)make_delta_body(a, pot, s, {.source = "dump.lammpstrj"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("mol.in:4"), std::string::npos) << m;
    EXPECT_NE(m.find("carries no bonds"), std::string::npos) << m;
    EXPECT_NE(m.find("write_data"), std::string::npos) << m;
  }
  // bond_style zero with no bonds adds nothing: accepted
  s.bond_style = "zero";
  EXPECT_NO_THROW((void)make_delta_body(a, pot, s));
  // bonds of type 2 without coefficients: refused, naming the type and the fix
  s.bond_style = "harmonic";
  a.bonds = {{1, 1, 2}, {2, 2, 3}};
  try {
    (void)make_delta_body(a, pot, s, {.source = "mol.data"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("bond type 2"), std::string::npos) << m;
    EXPECT_NE(m.find("bond_coeff 2"), std::string::npos) << m;
  }
  // `bond_coeff 2*` reaches type 2 (and any beyond)
  s.bond_coeff.push_back({"2*", "", {"50", "1.1"}, "bond_coeff 2* 50 1.1", 6});
  EXPECT_NO_THROW((void)make_delta_body(a, pot, s, {.source = "mol.data"}));
}

// A body of dimension 2 is LAMMPS's `dimension 2`: atoms interact in the xy plane only, although
// LAMMPS keeps z periodic (a 2D dump says `pp` for z, with a box one lattice unit thick). The
// energy of a triangular LJ crystal must be the in-plane lattice sum, with no z images.
TEST(DeltaBody, Dimension2HasNoImagesAlongZ) {
  const double a = 1.1, rc = 2.5;
  const int nx = 8, ny = 5;  // box 8.8 × 9.53: more than 2 rc in-plane
  atomistic::Atoms at;
  at.box.lo = {0, 0, -0.5};
  at.box.hi = {nx * a, ny * a * std::sqrt(3.0), 0.5};
  at.box.periodic = {true, true, true};
  std::int64_t id = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int b = 0; b < 2; ++b) {
        at.id.push_back(++id);
        at.type.push_back(1);
        at.x.insert(at.x.end(), {(i + 0.5 * b) * a, (j + 0.5 * b) * a * std::sqrt(3.0), 0.0});
      }
  at.type_mass = {0.0, 1.0};
  const auto spec = atomistic::read_potential_commands_from_string(
      "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n", "lj2d.pot", 1);
  const Body b = make_delta_body(at, atomistic::make_potential(spec), spec,
                                 {.dimension = 2, .cutoff = 0.0, .source = "hex2d"});
  Evaluator ev(b);
  const double U = ev.reference().energy;
  // closed form: ½ Σ φ(|i a1 + j a2|) over the triangular lattice within rc, per atom
  double per_atom = 0.0;
  for (int i = -6; i <= 6; ++i)
    for (int j = -6; j <= 6; ++j) {
      if (i == 0 && j == 0) continue;
      const double x = (i + 0.5 * j) * a, y = j * a * std::sqrt(3.0) / 2;
      const double r = std::hypot(x, y);
      if (r < rc) per_atom += 0.5 * 4.0 * (std::pow(r, -12) - std::pow(r, -6));
    }
  const double want = per_atom * static_cast<double>(at.size());
  // the same pair sum in another order: round-off
  EXPECT_TRUE(test::close(U, want, {0, 1e-12})) << U << " vs " << want;
  EXPECT_FALSE(b.box.periodic[2]);
}
