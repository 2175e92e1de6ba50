// Molecular statics (include/pdcg/body/statics.hpp) and surface energies
// (include/pdcg/body/surface.hpp) against closed forms: the LJ dimer and linear trimer minima,
// and the unrelaxed surface energy of a pair potential on a Bravais lattice,
//   γ = −(1/(4Ω)) Σ_ξ |n·ξ| φ(|ξ|)   (sum over all lattice vectors within the cutoff,
// Ω the volume per atom: each bond ξ crosses a unit area of the plane |n·ξ|/Ω times).
// The LAMMPS cross-checks are tests/cli/surface_lammps.sh.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/statics.hpp"
#include "pdcg/body/statistics.hpp"
#include "pdcg/body/surface.hpp"
#include "pdcg/core/error.hpp"

using namespace pdcg;
using namespace pdcg::body;

namespace {

double lj(double r) { return 4.0 * (std::pow(r, -12) - std::pow(r, -6)); }
double dlj(double r) { return 4.0 * (-12.0 * std::pow(r, -13) + 6.0 * std::pow(r, -7)); }

struct LjBody {
  atomistic::PotentialSpec spec;
  std::shared_ptr<const atomistic::Potential> pot;
};

LjBody lj_potential() {
  LjBody l;
  l.spec = atomistic::read_potential_commands_from_string(
      "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", "lj", 1);
  l.pot = atomistic::make_potential(l.spec);
  return l;
}

/// Free atoms on the x axis at the given positions.
Body free_line(const LjBody& l, const std::vector<double>& xs) {
  atomistic::Atoms a;
  a.box.lo = {-10, -10, -10};
  a.box.hi = {10, 10, 10};
  a.box.periodic = {false, false, false};
  for (std::size_t i = 0; i < xs.size(); ++i) {
    a.id.push_back(static_cast<std::int64_t>(i + 1));
    a.type.push_back(1);
    a.x.insert(a.x.end(), {xs[i], 0.0, 0.0});
  }
  a.type_mass = {NAN, 1.0};
  return make_delta_body(a, l.pot, l.spec);
}

/// fcc crystal, one cubic cell of edge a, periodic.
Body fcc_cell(const LjBody& l, double a) {
  atomistic::Atoms at;
  at.box.lo = {0, 0, 0};
  at.box.hi = {a, a, a};
  const double b[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < 4; ++i) {
    at.id.push_back(i + 1);
    at.type.push_back(1);
    at.x.insert(at.x.end(), {b[i][0] * a, b[i][1] * a, b[i][2] * a});
  }
  at.type_mass = {NAN, 1.0};
  return make_delta_body(at, l.pot, l.spec);
}

}  // namespace

TEST(Statics, DimerRelaxesToTheLennardJonesMinimum) {
  const LjBody l = lj_potential();
  for (MinStyle style : {MinStyle::cg, MinStyle::fire}) {
    const Body b = free_line(l, {0.0, 1.5});
    std::vector<double> y = b.x;
    StaticsOptions o;
    o.style = style;
    o.force_tolerance = 1e-12;
    const StaticsResult r = relax(b, y, o);
    ASSERT_TRUE(r.converged) << r.stop;
    // closed form: r₀ = 2^(1/6) σ, φ(r₀) = −ε. |f| ≤ 1e-12 with stiffness φ''(r₀) ≈ 57 gives
    // |Δr| ≤ 2e-14; the tolerance is round-off of the positions (1e-12 relative)
    EXPECT_NEAR(y[3] - y[0], std::pow(2.0, 1.0 / 6.0), 1e-12);
    EXPECT_NEAR(r.energy, -1.0, 1e-13);  // energy: quadratic in Δr, round-off only
    EXPECT_LE(r.force_norm, 1e-12);
  }
}

TEST(Statics, FamiliesAreRebuiltWhenAtomsComeIntoRange) {
  // Atoms 0 and 1 start compressed (repel); atom 2 starts 2.53 from atom 1, outside the
  // family radius r_c + skin = 2.52. The dimer expands, atom 1 comes within r_c of atom 2 and
  // the three relax to the linear trimer: φ'(r) + φ'(2r) = 0 (2r < r_c). Stale families would
  // leave atom 2 alone (energy −1, the dimer's).
  const LjBody l = lj_potential();
  double lo = 1.0, hi = 1.2;  // bisection of φ'(r) + φ'(2r), independent of the minimiser
  for (int i = 0; i < 200; ++i) {
    const double m = 0.5 * (lo + hi);
    (dlj(m) + dlj(2 * m) < 0.0 ? lo : hi) = m;
  }
  const double r3 = 0.5 * (lo + hi);
  const double e3 = 2 * lj(r3) + lj(2 * r3);
  for (MinStyle style : {MinStyle::cg, MinStyle::fire}) {
    const Body b = free_line(l, {0.0, 1.0, 3.53});
    std::vector<double> y = b.x;
    StaticsOptions o;
    o.style = style;
    o.force_tolerance = 1e-11;
    o.skin = 0.02;
    const StaticsResult r = relax(b, y, o);
    ASSERT_TRUE(r.converged) << r.stop;
    EXPECT_GE(r.rebuilds, 1);
    EXPECT_NEAR(y[3] - y[0], r3, 1e-11);  // |f| ≤ 1e-11, stiffness ≈ 50: Δr ≤ 1e-12
    EXPECT_NEAR(y[6] - y[3], r3, 1e-11);
    EXPECT_NEAR(r.energy, e3, 1e-12);
  }
}

TEST(Statics, RefusesStatisticalBodiesAndBadOptions) {
  const LjBody l = lj_potential();
  Body b = free_line(l, {0.0, 1.2});
  std::vector<double> y = b.x;
  StaticsOptions bad;
  bad.force_tolerance = -1.0;
  EXPECT_THROW(relax(b, y, bad), InputError);
  std::vector<double> short_y(3);
  EXPECT_THROW(relax(b, short_y, {}), InputError);
  make_statistical(b, isotropic_gaussian(b, 0.01));
  EXPECT_THROW(relax(b, y, {}), InputError);
}

TEST(Surface, UnrelaxedGammaOfFccLjIsTheLatticeSum) {
  const LjBody l = lj_potential();
  const double a = 1.55;
  const Body bulk = fcc_cell(l, a);
  const double omega = a * a * a / 4.0;
  const std::vector<Eigen::Vector3d> planes = {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {2, 1, 0}};
  for (const auto& hkl : planes) {
    const Eigen::Vector3d n = hkl.normalized();
    // lattice sum over fcc vectors (a/2)(i, j, k), i + j + k even, 0 < |ξ| < 2.5
    double sum = 0.0;
    for (int i = -4; i <= 4; ++i)
      for (int j = -4; j <= 4; ++j)
        for (int k = -4; k <= 4; ++k) {
          if ((i + j + k) % 2 != 0 || (i == 0 && j == 0 && k == 0)) continue;
          const Eigen::Vector3d xi = 0.5 * a * Eigen::Vector3d(i, j, k);
          if (xi.norm() < 2.5) sum += std::abs(n.dot(xi)) * lj(xi.norm());
        }
    const double expected = -sum / (4.0 * omega);
    SlabOptions so;
    so.normal = hkl;
    const Slab s = make_slab(bulk, so);
    const SurfaceEnergy e = surface_energy(s, std::nullopt);
    // sums of ~10³ pair energies, difference of two totals ~20× larger than γA: round-off
    EXPECT_NEAR(e.gamma, expected, 1e-11 * std::abs(expected)) << hkl.transpose();
    EXPECT_GE(s.height, 4.0 * 2.5);  // default thickness: 4 r_c
    EXPECT_EQ(static_cast<double>(s.slab.size()),
              std::round(s.area * s.height / omega));  // whole cell: area × height / Ω atoms
  }
}

TEST(Surface, RefusesNonLatticeNormalAndFreeBody) {
  const LjBody l = lj_potential();
  const Body bulk = fcc_cell(l, 1.55);
  SlabOptions so;
  so.normal = {1.0, std::sqrt(2.0), 0.0};  // irrational: no in-plane lattice translations
  EXPECT_THROW(make_slab(bulk, so), InputError);
  const Body free = free_line(l, {0.0, 1.2});
  so.normal = {0, 0, 1};
  EXPECT_THROW(make_slab(free, so), InputError);
}

TEST(Surface, TriclinicPrimitiveCellGivesTheCubicCellsGamma) {
  // The fcc primitive cell (one atom, a triclinic box in LAMMPS's form after a rotation Q)
  // and the cubic cell give the same γ for the same crystal plane (normal rotated by Qᵀ),
  // unrelaxed and relaxed: the slab cell is built from whichever lattice the box spans.
  const LjBody l = lj_potential();
  const double a = 1.55;
  Eigen::Matrix3d P;
  P << 0, 1, 1, 1, 0, 1, 1, 1, 0;
  P *= 0.5 * a;  // columns: primitive vectors
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(P);
  Eigen::Matrix3d Q = qr.householderQ();
  Eigen::Matrix3d R = qr.matrixQR().triangularView<Eigen::Upper>();
  for (int c = 0; c < 3; ++c)
    if (R(c, c) < 0.0) {
      R.row(c) *= -1.0;
      Q.col(c) *= -1.0;
    }
  atomistic::Atoms at;
  at.box.lo = {0, 0, 0};
  at.box.hi = {R(0, 0), R(1, 1), R(2, 2)};
  at.box.xy = R(0, 1);
  at.box.xz = R(0, 2);
  at.box.yz = R(1, 2);
  at.id = {1};
  at.type = {1};
  at.x = {0.0, 0.0, 0.0};
  at.type_mass = {NAN, 1.0};
  const Body prim = make_delta_body(at, l.pot, l.spec);
  const Body cubic = fcc_cell(l, a);
  StaticsOptions st;
  st.force_tolerance = 1e-10;
  for (const Eigen::Vector3d& hkl : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 0, 0)}) {
    SlabOptions sc, sp;
    sc.normal = hkl;
    sp.normal = Q.transpose() * hkl;
    sc.min_thickness = sp.min_thickness = 12.0;
    const Slab slab_c = make_slab(cubic, sc), slab_p = make_slab(prim, sp);
    ASSERT_EQ(slab_c.layers, slab_p.layers);  // same height: the same number of layers
    const SurfaceEnergy ec = surface_energy(slab_c, st), ep = surface_energy(slab_p, st);
    // same crystal and plane, other cells: round-off of the sums (unrelaxed), minimiser stop
    // points within |f| ≤ 1e-10 (relaxed; energy error ~|f|²/k)
    EXPECT_NEAR(ep.gamma, ec.gamma, 1e-11 * ec.gamma) << hkl.transpose();
    EXPECT_NEAR(*ep.gamma_relaxed, *ec.gamma_relaxed, 1e-10 * *ec.gamma_relaxed) << hkl.transpose();
  }
}
