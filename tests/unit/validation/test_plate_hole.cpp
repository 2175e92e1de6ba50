// Acceptance: plate with a hole (L = 1, R = 0.2, plane strain, Neo-Hookean
// μ = 1, K = 10, right edge pulled to d = 1.0 in 20 steps, left edge x-fixed + pin, other
// edges free). pdcg's BA solver, run through the scene contract (load_scene + run_scene,
// exactly what `pdcg run` does), must give the right-edge reaction within 2% of an
// independent FEM solution at every load step. The FEM curve is not produced by pdcg:
// workflows/validation/plate_hole_fem.py (isoparametric P2 total-Lagrangian FEM in
// numpy/scipy, converged in mesh and Richardson-extrapolated) wrote
// tests/data/plate_hole_fem.csv; see docs/validation.md.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "pdcg/scene/scene.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg/solver/newton.hpp"
#include "pdcg_test.hpp"

namespace fs = std::filesystem;

namespace {

struct Curve {
  std::vector<double> d, reaction;
};

/// FEM reference: columns step,d,...,R_extrapolated (last column); '#' lines are provenance.
Curve read_fem(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in) << file;
  Curve c;
  std::string line;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      header = true;
      continue;
    }
    std::vector<double> v;
    std::stringstream ss(line);
    std::string tok;
    while (std::getline(ss, tok, ',')) v.push_back(std::stod(tok));
    c.d.push_back(v.at(1));
    c.reaction.push_back(v.back());
  }
  return c;
}

/// reactions.csv of a run: returns column `name`.
std::vector<double> read_column(const fs::path& file, const std::string& name) {
  std::ifstream in(file);
  EXPECT_TRUE(in) << file;
  std::string line;
  do std::getline(in, line);
  while (line.rfind('#', 0) == 0);  // the units line
  std::vector<std::string> head;
  {
    std::stringstream ss(line);
    std::string tok;
    while (std::getline(ss, tok, ',')) head.push_back(tok);
  }
  std::size_t col = head.size();
  for (std::size_t k = 0; k < head.size(); ++k)
    if (head[k] == name) col = k;
  EXPECT_LT(col, head.size()) << "no column " << name << " in " << file;
  std::vector<double> out;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string tok;
    for (std::size_t k = 0; std::getline(ss, tok, ','); ++k)
      if (k == col) out.push_back(std::stod(tok));
  }
  return out;
}

std::vector<double> run_plate(double spacing, const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path yaml = dir / "plate.yaml";
  std::ofstream(yaml) << "units: none\n"
                         "dimension: 2\n"
                         "plane: strain\n"
                         "geometry:\n"
                         "  shape: rectangle\n"
                         "  origin: [0.0, 0.0]\n"
                         "  size: [1.0, 1.0]\n"
                         "  spacing: "
                      << spacing
                      << "\n"
                         "  holes: [{center: [0.5, 0.5], radius: 0.2}]\n"
                         "horizon: {factor: 3.015}\n"
                         "material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, "
                         "density: 1.0}\n"
                         "boundary:\n"
                         "  - {name: left,  region: {x_max: 0.0},  displacement: {x: 0.0}}\n"
                         "  - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}\n"
                         "  - {name: right, region: {x_min: 1.0},  displacement: {x: \"1.0*t\"}}\n"
                         "loading: {steps: 20}\n"
                         "solver: {type: newton, tolerance: 1.0e-8, max_iterations: 30, linear: "
                         "umfpack}\n"
                         "output: {directory: out, every: 20}\n";
  const auto scene = pdcg::scene::load_scene(yaml);
  pdcg::scene::run_scene(scene, dir / "out");
  return read_column(dir / "out" / "reactions.csv", "right_fx");
}

/// Runs pdcg on the plate and compares with the FEM curve; returns the largest relative
/// deviation over the 20 steps (printed per step).
double max_deviation_from_fem(double default_spacing) {
  const Curve fem = read_fem(fs::path(PDCG_TEST_DATA_DIR) / "plate_hole_fem.csv");
  EXPECT_EQ(fem.d.size(), 21u);
  // PDCG_PLATE_SPACING overrides the spacing (Δx-convergence study of docs/validation.md).
  const char* env = std::getenv("PDCG_PLATE_SPACING");
  const double spacing = env ? std::atof(env) : default_spacing;
  const auto pd = run_plate(
      spacing, fs::temp_directory_path() / ("pdcg_test_plate_hole_" + std::to_string(spacing)));
  EXPECT_EQ(pd.size(), fem.d.size());  // row 0 = unloaded state, then 20 steps
  double worst = 0.0;
  for (std::size_t k = 1; k < std::min(pd.size(), fem.d.size()); ++k) {
    const double rel = (pd[k] - fem.reaction[k]) / fem.reaction[k];
    std::printf("step %2zu d = %.2f  pdcg %.6f  FEM %.6f  rel %+.3e\n", k, fem.d[k], pd[k],
                fem.reaction[k], rel);
    worst = std::max(worst, std::abs(rel));
  }
  std::printf("spacing %g: max relative deviation %.3e\n", spacing, worst);
  return worst;
}

}  // namespace

#ifdef PDCG_PLATE_ACCEPTANCE
// Acceptance: 2% at every step, at Δx = 0.0125 (5 588 points). Measured (hole s_k
// from the true circle): pdcg is 0.57% … 1.06% below FEM (largest at d = 1); at Δx = 0.05 /
// 0.025 the deviation is 4.6% / 3.0%: the error converges with Δx (docs/validation.md,
// convergence table; with the staircase s_k of the hole it was 1.58% … 1.98%).
// Executable test_validation_acceptance, label `slow` (minutes).
TEST(PlateWithHole, ReactionMatchesFemWithin2Percent) {
  EXPECT_LT(max_deviation_from_fem(0.0125), 0.02);  // acceptance: 2% of FEM
}
#else
// Fast regression guard on the coarse grid (Δx = 0.05, 20 points across, seconds): the
// deviation measured there (4.6%, pdcg below FEM, with the one-stress-per-point correction;
// +0.50% with the balanced one, +0.79% with cut cells, the grips on the point columns making
// it stiffer by ≈ Δx: docs/validation.md §1) must not grow; 5% leaves room for round-off and
// solver-tolerance changes only.
TEST(PlateWithHole, ReactionWithinCurrentBoundOfFem) {
  EXPECT_LT(max_deviation_from_fem(0.05), 0.05);
}
#endif

namespace {

/// Vertical closure of the hole, u_y(0.5, 0.7 + Δx/2) − u_y(0.5, 0.3 − Δx/2), of the plate
/// with its Dirichlet columns on the faces (body [−Δx/2, 1 + Δx/2] × [0, 1], columns at x = 0
/// and 1: workflows/accuracy "faces" layout), horizon 3.015 Δx, right edge pulled to
/// d = 0.05 in one step (linear regime).
double hole_closure(double h) {
  const fs::path dir = fs::temp_directory_path() / ("pdcg_test_hole_closure_" + std::to_string(h));
  fs::create_directories(dir);
  const fs::path yaml = dir / "plate.yaml";
  std::ofstream(yaml) << "units: none\ndimension: 2\nplane: strain\ngeometry:\n"
                         "  shape: rectangle\n  origin: ["
                      << -h / 2 << ", 0.0]\n  size: [" << 1 + h << ", 1.0]\n  spacing: " << h
                      << "\n  holes: [{center: [0.5, 0.5], radius: 0.2}]\n"
                         "horizon: {factor: 3.015}\n"
                         "material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, "
                         "density: 1.0}\n"
                         "boundary:\n"
                         "  - {name: left,  region: {x_max: 0.0},  displacement: {x: 0.0}}\n"
                         "  - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}\n"
                         "  - {name: right, region: {x_min: 1.0},  displacement: {x: \"0.05*t\"}}\n"
                         "loading: {steps: 1}\n";
  const auto s = pdcg::scene::load_scene(yaml);
  const auto body = pdcg::scene::make_discretization(s);
  const auto mat = pdcg::scene::make_material(s);
  pdcg::solver::Model model(body, *mat, s.model);
  const auto& x = body.positions();
  pdcg::solver::DisplacementSet L{"left", {}, {}}, P{"pin", {}, {}}, Rt{"right", {}, {}};
  int pin = 0, top = -1, bottom = -1;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::abs(x[i].x()) < 1e-9) L.points.push_back(static_cast<int>(i));
    if (std::abs(x[i].x() - 1) < 1e-9) Rt.points.push_back(static_cast<int>(i));
    if (x[i].head<2>().norm() < x[pin].head<2>().norm()) pin = static_cast<int>(i);
    if (std::abs(x[i].x() - 0.5) < 1e-9 && std::abs(x[i].y() - (0.7 + h / 2)) < 1e-9)
      top = static_cast<int>(i);
    if (std::abs(x[i].x() - 0.5) < 1e-9 && std::abs(x[i].y() - (0.3 - h / 2)) < 1e-9)
      bottom = static_cast<int>(i);
  }
  EXPECT_GE(top, 0);
  EXPECT_GE(bottom, 0);
  P.points = {pin};
  L.component[0] = [](double) { return 0.0; };
  P.component[1] = [](double) { return 0.0; };
  Rt.component[0] = [](double t) { return 0.05 * t; };
  pdcg::solver::NewtonOptions no;
  no.steps = 1;
  no.tolerance = 1e-10;
  pdcg::solver::StaticSolver solver(model, {L, P, Rt}, {}, no);
  solver.run();
  const auto& u = solver.displacement();
  return u[2 * top + 1] - u[2 * bottom + 1];
}

}  // namespace

#ifndef PDCG_PLATE_ACCEPTANCE
namespace {

/// The contract plate with `grip: surface` on the left and right faces (the FEM's gauge,
/// docs/solver.md §4), plane strain K = 10, d = 0.2 in 2 steps (Newton 1e-10), with or without
/// cut-cell volumes at the hole; returns the right-edge reaction per step.
std::vector<double> run_plate_surface_grips(double spacing, bool cut_cells) {
  const fs::path dir =
      fs::temp_directory_path() /
      ("pdcg_test_plate_cut_" + std::to_string(spacing) + (cut_cells ? "_1" : "_0"));
  fs::create_directories(dir);
  const fs::path yaml = dir / "plate.yaml";
  std::ofstream(yaml) << "units: none\ndimension: 2\nplane: strain\ngeometry:\n"
                         "  shape: rectangle\n  origin: [0.0, 0.0]\n  size: [1.0, 1.0]\n"
                         "  spacing: "
                      << spacing << "\n  holes: [{center: [0.5, 0.5], radius: 0.2}]\n  cut_cells: "
                      << (cut_cells ? "true" : "false")
                      << "\nhorizon: {factor: 3.015}\n"
                         "material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, "
                         "density: 1.0}\n"
                         "boundary:\n"
                         "  - {name: left,  region: {x_max: 0.0}, displacement: {x: 0.0}, grip: "
                         "surface}\n"
                         "  - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}\n"
                         "  - {name: right, region: {x_min: 1.0}, displacement: {x: \"0.2*t\"}, "
                         "grip: surface}\n"
                         "loading: {steps: 2}\n"
                         "solver: {type: newton, tolerance: 1.0e-10, max_iterations: 30, linear: "
                         "umfpack}\n"
                         "output: {directory: out, every: 2}\n";
  const auto scene = pdcg::scene::load_scene(yaml);
  pdcg::scene::run_scene(scene, dir / "out");
  return read_column(dir / "out" / "reactions.csv", "right_fx");
}

}  // namespace

// Cut-cell volumes at the hole (docs/solver.md §2) against the FEM at Δx = 0.025 (1 408
// points; two runs of two steps, ≈ 10 s with 2 threads on the loaded machine), at d = 0.1 and
// 0.2, where the deviation is largest along the path (it falls with d: docs/validation.md §1,
// −0.55% at d = 1). Measured R/R_FEM − 1: whole cells −1.11% / −0.94%, cut cells −0.88% /
// −0.73%.
TEST(PlateWithHole, CutCellsMeetOnePercentOfFemAtCoarseSpacing) {
  const Curve fem = read_fem(fs::path(PDCG_TEST_DATA_DIR) / "plate_hole_fem.csv");
  ASSERT_EQ(fem.d.size(), 21u);
  const auto cut = run_plate_surface_grips(0.025, true);
  const auto whole = run_plate_surface_grips(0.025, false);
  ASSERT_EQ(cut.size(), 3u);
  ASSERT_EQ(whole.size(), 3u);
  for (std::size_t k = 1; k <= 2; ++k) {
    const double ref = fem.reaction[2 * k];  // d = 0.1 k: row 2k of the 20-step FEM curve
    ASSERT_NEAR(fem.d[2 * k], 0.1 * k, 1e-12);
    const double e_cut = cut[k] / ref - 1, e_whole = whole[k] / ref - 1;
    std::printf("d = %.1f  cut cells %+.3e  whole cells %+.3e\n", 0.1 * k, e_cut, e_whole);
    // 1%: the acceptance at Δx = 0.025 (measured 0.88% / 0.73%)
    EXPECT_LT(std::abs(e_cut), 0.01) << "d = " << 0.1 * k;
    // The gain is the cut cells' (measured ratio 0.79 / 0.78); 0.85 leaves the solver's
    // 1e-10 tolerance and round-off (≪ 0.01 points) far behind.
    EXPECT_LT(std::abs(e_cut), 0.85 * std::abs(e_whole)) << "d = " << 0.1 * k;
  }
}

// The lateral contraction near the hole (its vertical closure), which the staircase surface
// vectors of the hole got wrong by an amount that grew with refinement (docs/accuracy-cost.md
// §1: +8.4% / +13.3% at Δx = 1/40 / 1/80 with 3.015 Δx), against the FEM at the same two
// points. FEM numbers (independent code): `python3 workflows/validation/plate_hole_fem.py`'s
// solve(48, 24) with STEPS = 1, D_FINAL = 0.05 and evaluate() at (0.5, 0.7 ± …):
//   Δx = 1/40: u_y(0.5, 0.7125) − u_y(0.5, 0.2875)   = −1.7768522778e-02
//   Δx = 1/80: u_y(0.5, 0.70625) − u_y(0.5, 0.29375) = −1.6753043697e-02
// (the 24×12 and 48×24 FEM meshes agree to 4 digits: FEM error ≪ the tolerances).
TEST(PlateWithHole, HoleClosureMatchesFemAndConverges) {
  const double fem40 = -1.7768522778e-02, fem80 = -1.6753043697e-02;
  const double e40 = hole_closure(1.0 / 40) / fem40 - 1, e80 = hole_closure(1.0 / 80) / fem80 - 1;
  std::printf("hole closure rel. to FEM: Δx = 1/40 %+.3e, 1/80 %+.3e\n", e40, e80);
  // With cut-cell volumes at the hole (docs/solver.md §2): −4.04% / −1.00% (ratio 4.0).
  // Balanced (bond-flux) weak form with whole cells, docs/solver.md §3: −4.58% / −1.21%, and
  // −0.39% at 1/160
  // (FEM −1.6212645445e-2 there; HoleClosureAtFineSpacingMatchesFem, label `slow`). The
  // one-stress-per-point correction gave −1.44% / +0.34% / −0.31%: a sign crossing, the same limit
  // (docs/solver.md §3, "Accuracy of the balanced correction"); the staircase s_k +8.4% / +13%.
  EXPECT_LT(std::abs(e40), 0.05);   // 1/40: measured 4.58%; the first-order boundary layer
  EXPECT_LT(std::abs(e80), 0.015);  // 1/80: measured 1.21%; the same layer at half the width
  EXPECT_LT(std::abs(e80), std::abs(e40) / 3.0);  // monotone, faster than first order (3.8×)
}
#else
// The hole closure of HoleClosureMatchesFemAndConverges one spacing further, Δx = 1/160
// (≈ 1.5 min on the loaded 2-core machine; label `slow`): FEM (the same P2 48×24 solve,
// evaluate() at (0.5, 0.703125) and (0.5, 0.296875)) −1.6212645445e-02. Measured −0.33% with
// cut-cell volumes (docs/solver.md §2), −0.39% with whole cells (the
// one-stress-per-point correction gave −0.31%: both forms reach the same value,
// docs/solver.md §3, "Accuracy of the balanced correction").
TEST(PlateWithHole, HoleClosureAtFineSpacingMatchesFem) {
  const double fem160 = -1.6212645445e-02;
  const double e160 = hole_closure(1.0 / 160) / fem160 - 1;
  std::printf("hole closure rel. to FEM: Δx = 1/160 %+.3e\n", e160);
  // 0.6%: half the 1/80 error (1.21%), i.e. the convergence continues at least at first order
  EXPECT_LT(std::abs(e160), 0.006);
}
#endif
