// `pdcg export-lammps` (docs/dynamics.md, "Running a coarse model in LAMMPS"): the emulation of
// LAMMPS's table interpolation against closed forms (exact for the polynomials each scheme
// reproduces, the convergence orders the N search relies on), the table of a rescaled LJ chain
// against the closed form ε^d φ(r/ε), and the refusals. The trajectories against LAMMPS itself:
// tests/cli/export_lammps.sh.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/dynamics/lammps_export.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;

namespace {

/// Knots uniform in s = r² from r_lo to r_cut of E(s) = g(s), F(r) = −2r g'(s), with
/// dF/dr = −2g'(s) − 4s g''(s) at both ends.
template <class G, class G1, class G2>
dynamics::TableInterpolant tabulate(dynamics::TableStyle style, double r_lo, double r_cut, int n,
                                    G g, G1 g1, G2 g2) {
  std::vector<double> e(static_cast<std::size_t>(n)), f(e.size());
  const double s0 = r_lo * r_lo, ds = (r_cut * r_cut - s0) / (n - 1);
  for (int i = 0; i < n; ++i) {
    const double s = s0 + i * ds;
    e[static_cast<std::size_t>(i)] = g(s);
    f[static_cast<std::size_t>(i)] = -2.0 * std::sqrt(s) * g1(s);
  }
  auto fprime = [&](double s) { return -2.0 * g1(s) - 4.0 * s * g2(s); };
  return dynamics::table_interpolant(style, r_lo, r_cut, e, f, fprime(s0), fprime(r_cut * r_cut));
}

template <class G, class G1>
double max_force_error(const dynamics::TableInterpolant& t, double r_lo, double r_cut, G g, G1 g1,
                       double* energy_error = nullptr) {
  double ef = 0.0, ee = 0.0;
  for (int i = 0; i < 997; ++i) {
    const double r = r_lo + (r_cut - r_lo) * (i + 0.37) / 997.0;
    double e, f;
    t.eval(r, e, f);
    const double s = r * r, fx = -2.0 * r * g1(s);
    ef = std::max(ef, std::abs(f - fx) / std::max(1.0, std::abs(fx)));
    ee = std::max(ee, std::abs(e - g(s)) / std::max(1.0, std::abs(g(s))));
  }
  if (energy_error) *energy_error = ee;
  return ef;
}

const char* kLJ = "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n";

body::Body lj_chain(int n, const char* commands = kLJ) {
  atomistic::Atoms a;
  const double h = std::pow(2.0, 1.0 / 6.0);
  a.box.lo = {0, -5, -5};
  a.box.hi = {n * h, 5, 5};
  a.box.periodic = {true, false, false};
  for (int i = 0; i < n; ++i) {
    a.id.push_back(i + 1);
    a.type.push_back(1);
    a.x.insert(a.x.end(), {i * h, 0.0, 0.0});
  }
  const auto spec = atomistic::read_potential_commands_from_string(commands, "lj", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  return body::make_delta_body(a, pot, spec, {.dimension = 1, .cutoff = 3.0, .source = "chain"});
}

}  // namespace

TEST(LammpsTable, SplineIsExactForCubicsInRSquaredLinearForLines) {
  // a clamped cubic spline in s = r² reproduces E cubic in s and F/r = −2g'(s) quadratic in s
  auto g = [](double s) { return 1.0 + 2.0 * s - 0.5 * s * s + 0.1 * s * s * s; };
  auto g1 = [](double s) { return 2.0 - s + 0.3 * s * s; };
  auto g2 = [](double s) { return -1.0 + 0.6 * s; };
  const auto t = tabulate(dynamics::TableStyle::spline, 0.8, 2.5, 37, g, g1, g2);
  double ee;
  const double ef = max_force_error(t, 0.8, 2.5, g, g1, &ee);
  // exact up to round-off of the tridiagonal solve (values O(10))
  EXPECT_LT(ef, 1e-12);
  EXPECT_LT(ee, 1e-12);
  // linear interpolation in s reproduces E linear in s (F/r constant)
  auto l = [](double s) { return 3.0 - 0.25 * s; };
  auto l1 = [](double) { return -0.25; };
  auto l2 = [](double) { return 0.0; };
  const auto tl = tabulate(dynamics::TableStyle::linear, 0.8, 2.5, 11, l, l1, l2);
  EXPECT_LT(max_force_error(tl, 0.8, 2.5, l, l1, &ee), 1e-13);
  EXPECT_LT(ee, 1e-13);
}

TEST(LammpsTable, ErrorsFallAsNToTheMinusFourAndTwo) {
  // LJ in s: E = 4(s⁻⁶ − s⁻³); doubling N divides the spline error by 2⁴, the linear by 2²
  // (the N search of export_lammps grows N by these orders)
  auto g = [](double s) { return 4.0 * (std::pow(s, -6) - std::pow(s, -3)); };
  auto g1 = [](double s) { return 4.0 * (-6.0 * std::pow(s, -7) + 3.0 * std::pow(s, -4)); };
  auto g2 = [](double s) { return 4.0 * (42.0 * std::pow(s, -8) - 12.0 * std::pow(s, -5)); };
  for (auto style : {dynamics::TableStyle::spline, dynamics::TableStyle::linear}) {
    const double e1 = max_force_error(tabulate(style, 0.9, 2.5, 2000, g, g1, g2), 0.9, 2.5, g, g1);
    const double e2 = max_force_error(tabulate(style, 0.9, 2.5, 4000, g, g1, g2), 0.9, 2.5, g, g1);
    const double order = std::log2(e1 / e2);
    // asymptotic order within 0.3 (the test points sit at different fractions of the bins)
    EXPECT_NEAR(order, style == dynamics::TableStyle::spline ? 4.0 : 2.0, 0.3) << e1 << " " << e2;
  }
}

TEST(LammpsExport, RescaledChainTableIsTheClosedFormAndMeetsTheBound) {
  const auto b = coarsen::rescale(lj_chain(16), 2.0);
  const auto dir =
      std::filesystem::temp_directory_path() / ("pdcg_export_" + std::to_string(::getpid()));
  dynamics::LammpsExportOptions o;
  o.dt = 0.005;
  const auto ex = dynamics::export_lammps(b, {}, dir, o, "chain");
  ASSERT_EQ(ex.tables.size(), 1u);
  const auto& t = ex.tables[0];
  EXPECT_LE(t.force_error, o.table_tolerance);
  EXPECT_LE(t.energy_error, o.table_tolerance);
  EXPECT_EQ(ex.pair_style, "table spline " + std::to_string(t.points));
  // cutoff located to round-off: ε r_c = 5
  EXPECT_NEAR(t.r_cut, 5.0, 1e-14);
  // every knot against φ_ε(r) = ε^d 4[(ε/r)^12 − (ε/r)^6] (ε = 2, d = 1) and F = −dφ_ε/dr
  std::ifstream in(dir / "model.table");
  std::string line;
  std::int64_t rows = 0;
  double worst = 0.0;
  bool data = false;
  while (std::getline(in, line)) {
    if (line.rfind("N ", 0) == 0) {
      data = true;
      continue;
    }
    if (!data || line.empty()) continue;
    std::istringstream ss(line);
    double i, r, e, f;
    ss >> i >> r >> e >> f;
    const double q = 2.0 / r;
    const double ex_e = 2.0 * 4.0 * (std::pow(q, 12) - std::pow(q, 6));
    const double ex_f = 2.0 * 4.0 * (12.0 * std::pow(q, 12) - 6.0 * std::pow(q, 6)) / r;
    worst = std::max({worst, std::abs(e - ex_e) / std::max(1.0, std::abs(ex_e)),
                      std::abs(f - ex_f) / std::max(1.0, std::abs(ex_f))});
    ++rows;
  }
  EXPECT_EQ(rows, t.points);
  // round-off of (r/ε) and the powers: a few ulps of values up to 1e3
  EXPECT_LT(worst, 1e-13);
  std::filesystem::remove_all(dir);
}

TEST(LammpsExport, RefusesWhatLammpsCannotRepresent) {
  // harmonic bonds: not implemented (named)
  const char* bonded =
      "units lj\natom_style bond\npair_style zero 2.5\npair_coeff * *\nbond_style harmonic\n"
      "bond_coeff 1 0.5 1.0\nspecial_bonds lj/coul 0.0 1.0 1.0\nmass 1 1.0\n";
  atomistic::Atoms a;
  a.box.lo = {0, -0.5, -0.5};
  a.box.hi = {8, 0.5, 0.5};
  a.box.periodic = {true, false, false};
  for (int i = 0; i < 8; ++i) {
    a.id.push_back(i + 1);
    a.type.push_back(1);
    a.x.insert(a.x.end(), {static_cast<double>(i), 0.0, 0.0});
    a.bonds.push_back({1, i + 1, (i + 1) % 8 + 1});
  }
  const auto spec = atomistic::read_potential_commands_from_string(bonded, "bonded", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  const auto b =
      body::make_delta_body(a, pot, spec, {.dimension = 1, .cutoff = 0.0, .source = "c"});
  try {
    dynamics::check_exportable(b, "bonded.h5");
    ADD_FAILURE() << "bonded body accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("molecular bonds"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(dynamics::check_exportable(lj_chain(8), "lj.h5"));
}
