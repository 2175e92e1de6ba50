// Homogenisation (docs/theory.md §3) and rescaling (§4): conservation of mass and energy to
// round-off on grids not aligned with the lattice, every kernel; W_ε(F) = W(F); the force-state
// scaling law checked against finite differences of the rescaled energy.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "../body/toy_potentials.hpp"
#include "pdcg/body/statistics.hpp"
#include "pdcg/coarsen/homogenise.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;
using namespace pdcg::body;
using namespace pdcg::coarsen;

namespace {

atomistic::PotentialSpec spec() {
  atomistic::PotentialSpec s;
  s.lines = {"pair_style test"};
  return s;
}

double total_mass(const Body& b) {
  double m = 0;
  for (double v : b.mass) m += v;
  return m;
}

}  // namespace

TEST(Homogenise, MassAndEnergyConservedForEveryKernelOnRotatedGrids) {
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.6);
  for (const bool periodic : {true, false}) {
    atomistic::Atoms a = test::cubic_lattice(6, 5, 4, 1.0, 0.05, periodic);
    if (periodic) a.box.xy = 0.7;  // triclinic
    const Body b = make_delta_body(a, pot, spec());
    Evaluator eva(b);
    std::mt19937 rng(21);
    for (const auto& name : kernel_names()) {
      const Kernel k = make_kernel(name, name == "gaussian" ? 0.9 : 2.3);
      GridOptions g;
      g.spacing = 0.83;  // incommensurate with the lattice
      g.rotation = test::random_rotation(rng);
      g.shift = {0.31, -0.17, 0.44};
      const Body h = homogenise_on_grid(b, k, g);
      const auto& hom = *h.homogenisation;
      // per-atom normalisation
      std::vector<double> wsum(b.size(), 0.0);
      for (std::size_t c = 0; c < hom.atom.size(); ++c)
        wsum[static_cast<std::size_t>(hom.atom[c])] += hom.weight[c];
      EXPECT_TRUE(test::all_close(wsum, std::vector<double>(b.size(), 1.0),
                                  {1e-14, 0}));  // round-off of a short sum
      double m = 0;
      for (double v : hom.mass) m += v;
      EXPECT_TRUE(test::close(m, total_mass(b), {0, 1e-12})) << name;  // round-off
      Evaluator evh(h);
      for (int trial = 0; trial < 4; ++trial) {
        const Eigen::Matrix3d F = test::random_deformation(rng);
        ASSERT_GT(F.determinant(), 0);
        const double U = eva.homogeneous(F).energy;
        (void)evh.homogeneous(F);
        double Ubar = 0;
        for (double e : evh.point_energies()) Ubar += e;
        EXPECT_TRUE(test::close(Ubar, U, {0, 1e-12}))
            << name << " periodic " << periodic;  // round-off
      }
    }
  }
}

TEST(Homogenise, GivenPointsAndWarnings) {
  auto pot = std::make_shared<test::Springs>(2.0, 1.0, 1.4);
  const Body b = make_delta_body(test::cubic_lattice(4, 4, 4, 1.0, 0.0, true), pot, spec());
  std::vector<double> pts;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 4.0);
  for (int p = 0; p < 40; ++p) pts.insert(pts.end(), {u(rng), u(rng), u(rng)});
  HomogeniseReport rep;
  const Body h = homogenise_on_points(b, make_kernel("wendland-c2", 2.5), pts, &rep);
  EXPECT_TRUE(rep.warnings.empty());
  EXPECT_NEAR(rep.lattice_spacing, 1.0, 1e-14);
  double m = 0, v = 0;
  for (std::size_t p = 0; p < h.homogenisation->size(); ++p) {
    m += h.homogenisation->mass[p];
    v += h.homogenisation->volume[p];
  }
  EXPECT_TRUE(test::close(m, total_mass(b), {0, 1e-12}));
  EXPECT_TRUE(test::close(v, b.reference_volume(), {0, 1e-12}));
  // width below the lattice spacing: warned
  GridOptions g;
  g.spacing = 0.5;
  (void)homogenise_on_grid(b, make_kernel("top-hat", 0.6), g, &rep);
  ASSERT_EQ(rep.warnings.size(), 1u);
  EXPECT_NE(rep.warnings[0].find("smaller than the lattice spacing"), std::string::npos);
  // a grid too coarse for the kernel leaves atoms unreached: error naming the atom
  g.spacing = 3.0;
  g.shift = {0.5, 0.5, 0.5};
  EXPECT_THROW((void)homogenise_on_grid(b, make_kernel("top-hat", 0.2), g), InputError);
  EXPECT_THROW((void)make_kernel("box", 1.0), InputError);
  EXPECT_THROW((void)make_kernel("top-hat", 0.0), InputError);
  g.spacing = -1;
  EXPECT_THROW((void)homogenise_on_grid(b, make_kernel("top-hat", 1.5), g), InputError);
}

TEST(Homogenise, ChainDensityAndEnergyCarryTheSameFactor) {
  // docs/theory.md §3: ρ̄ and W̄ carry the same S(x) = Σ_k φ(x_k − x): E_p / m_p = ψ / M at every
  // point, so the homogenised chain keeps the chain's dispersion.
  atomistic::Atoms c;
  c.box.lo = {0, -5, -5};
  c.box.hi = {20, 5, 5};
  c.box.periodic = {true, false, false};
  for (int i = 0; i < 20; ++i) {
    c.id.push_back(i + 1);
    c.type.push_back(1);
    c.x.insert(c.x.end(), {i + 0.5, 0.0, 0.0});
  }
  c.type_mass = {NAN, 2.0, 2.0};
  auto pot = std::make_shared<test::Springs>(2.0, 0.9, 1.5);
  const Body b =
      make_delta_body(c, pot, spec(), {.dimension = 1, .cutoff = 0.0, .source = "chain"});
  GridOptions g;
  g.spacing = 0.37;
  const Body h = homogenise_on_grid(b, make_kernel("cubic-bspline", 2.0), g);
  Evaluator ev(h);
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 0) = 1.2;
  const double psi = ev.homogeneous(F).psi[0];
  const auto E = ev.point_energies();
  for (std::size_t p = 0; p < E.size(); ++p)
    EXPECT_NEAR(E[p] / h.homogenisation->mass[p], psi / 2.0, 1e-14 * std::abs(psi));  // round-off
}

TEST(Rescale, EnergyDensityInvariantUnderHomogeneousDeformation) {
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.6);
  atomistic::Atoms a = test::cubic_lattice(4, 4, 4, 1.0, 0.05, true);
  a.box.xz = 0.5;
  const Body b = make_delta_body(a, pot, spec());
  Evaluator ev(b);
  std::mt19937 rng(31);
  for (const double eps : {2.0, 3.5, 8.0}) {
    const Body r = rescale(b, eps);
    EXPECT_DOUBLE_EQ(r.potential->cutoff(), eps * 1.6);
    Evaluator evr(r);
    for (int trial = 0; trial < 4; ++trial) {
      const Eigen::Matrix3d F = test::random_deformation(rng);
      const double W = energy_density(b, ev.homogeneous(F));
      const double We = energy_density(r, evr.homogeneous(F));
      EXPECT_TRUE(test::close(We, W, {0, 1e-12})) << "eps " << eps;  // round-off of scaled sums
    }
  }
  EXPECT_THROW((void)rescale(b, 0.0), InputError);
  EXPECT_THROW((void)rescale(b, -1.5), InputError);
  EXPECT_THROW((void)epsilon_for_horizon(b, -1.0), InputError);
  EXPECT_DOUBLE_EQ(epsilon_for_horizon(b, 4.8), 3.0);
}

TEST(Rescale, ForceStateScalingLaw) {
  // T_ε⟨ξ'⟩ = ε^−(d+1) T⟨ξ'/ε⟩ with force-state densities T_b = t_b/(V_k V_j), V = V₀/N.
  // The rescaled t' are checked against finite differences of the rescaled energy (so the
  // scaling is not just read back from the code that applies it).
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.6);
  const Body b = make_delta_body(test::cubic_lattice(3, 3, 3, 1.0, 0.05, false), pot, spec());
  const double eps = 3.5;
  const Body r = rescale(b, eps);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  std::vector<double> y = b.x, yr(y.size());
  for (auto& v : y) v += u(rng);
  for (std::size_t c = 0; c < y.size(); ++c) yr[c] = eps * y[c];  // Y' = εY on bonds εξ
  Evaluator ev(b), evr(r);
  const Evaluation e = ev.deformed(y);
  const std::vector<double> t(e.t.begin(), e.t.end());
  const Evaluation er = evr.deformed(yr);
  const std::vector<double> tr(er.t.begin(), er.t.end()), fr(er.forces.begin(), er.forces.end());
  // forces of the rescaled body = −∂U_ε/∂y' by central differences
  const double h = 1e-5;
  std::vector<double> fd(yr.size());
  for (std::size_t c = 0; c < yr.size(); ++c) {
    auto p = yr, m = yr;
    p[c] += h;
    m[c] -= h;
    fd[c] = -(evr.deformed(p).energy - evr.deformed(m).energy) / (2 * h);
  }
  EXPECT_LT(test::max_norm_relative_error(fr, fd), 1e-7);  // O(h²) + round-off/h
  const int d = 3;
  const double V = b.reference_volume() / b.size(), Vr = r.reference_volume() / r.size();
  EXPECT_TRUE(test::close(Vr, std::pow(eps, d) * V, {0, 1e-13}));
  std::vector<double> T(t.size()), Tr(t.size());
  for (std::size_t c = 0; c < t.size(); ++c) {
    T[c] = std::pow(eps, -(d + 1)) * t[c] / (V * V);
    Tr[c] = tr[c] / (Vr * Vr);
  }
  EXPECT_LT(test::max_norm_relative_error(Tr, T), 1e-13);  // one multiplication's round-off
}

TEST(Rescale, LatticeBodyOnCoarseGrid) {
  // A rescaled lattice sits on a lattice of spacing εh; homogenised on that grid with a
  // symmetric kernel, every point has mass ε^d M and the density M/h^d is unchanged.
  const double hsp = 1.0, eps = 2.5;
  auto pot = std::make_shared<test::Springs>(2.0, 1.0, 1.4);
  atomistic::Atoms a = test::cubic_lattice(4, 4, 4, hsp, 0.0, true);
  a.type.assign(a.type.size(), 1);
  const Body r = rescale(make_delta_body(a, pot, spec()), eps);
  for (std::size_t i = 0; i < r.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double g = r.x[3 * i + k] / (eps * hsp) - 0.5;
      EXPECT_NEAR(g, std::round(g), 1e-12);  // on the εh lattice
    }
  GridOptions g;
  g.spacing = eps * hsp;
  g.shift = {0.0, 0.0, 0.0};
  const Body h = homogenise_on_grid(r, make_kernel("wendland-c2", 1.7 * eps * hsp), g);
  ASSERT_EQ(h.homogenisation->size(), r.size());
  for (std::size_t p = 0; p < h.homogenisation->size(); ++p)
    EXPECT_NEAR(h.homogenisation->mass[p] / h.homogenisation->volume[p], 1.0 / std::pow(hsp, 3),
                1e-12);
}

TEST(Rescale, StatisticalAndHomogenisedLayersKeepEnergyDensity) {
  // widths scale with ε (covariances ε²), so the expected energy density is unchanged too;
  // and homogenised point energies add up to the rescaled total.
  auto pot = std::make_shared<test::Springs>(2.0, 0.95, 1.4);
  Body b = make_delta_body(test::cubic_lattice(4, 4, 4, 1.0, 0.05, true), pot, spec());
  Statistics s = isotropic_gaussian(b, 0.05);
  s.order = 4;
  make_statistical(b, s);
  const Body h = homogenise_on_grid(b, make_kernel("cubic-bspline", 2.5),
                                    GridOptions{0.9, Eigen::Matrix3d::Identity(), {0.2, 0.1, 0.3}});
  Evaluator ev(b);
  std::mt19937 rng(41);
  for (const double eps : {2.0, 3.5, 8.0}) {
    const Body r = rescale(h, eps);
    Evaluator evr(r);
    const Eigen::Matrix3d F = test::random_deformation(rng, 0.8, 1.25);
    const double W = energy_density(b, ev.homogeneous(F));
    const Evaluation er = evr.homogeneous(F);
    EXPECT_TRUE(test::close(energy_density(r, er), W, {0, 1e-12})) << "eps " << eps;  // round-off
    double Ep = 0;
    for (double e : evr.point_energies()) Ep += e;
    EXPECT_TRUE(test::close(Ep, er.energy, {0, 1e-12}));  // per-atom normalised weights
  }
}
