// A scene's `model: cauchy-born` material relaxes the basis of a crystal with a basis
// (docs/elastic.md §2.2): a BA-solver run of a graphene model (honeycomb, BNC.tersoff C,
// dimension 2) under homogeneous uniaxial strain reports the reaction P₁₁(F)·H with P of the
// relaxed-ion body::CauchyBorn — and not the clamped-ion one (4.5 % stiffer at this strain).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/cauchy_born.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/scene/scene.hpp"

namespace fs = std::filesystem;
using namespace pdcg;

TEST(SceneCauchyBornRelaxed, GrapheneRunReactionIsTheRelaxedStress) {
  const fs::path dir = fs::temp_directory_path() / "pdcg_scene_cb_relaxed_test";
  fs::create_directories(dir);
  atomistic::Atoms at;
  const double d = 1.44, sq3 = std::sqrt(3.0);
  const int nx = 4, ny = 6;
  at.box.hi = {nx * 3 * d, ny * sq3 * d, 10.0};
  at.box.periodic = {true, true, false};
  const double f[4][2] = {{0, 0}, {1.0 / 3.0, 0}, {0.5, 0.5}, {5.0 / 6.0, 0.5}};
  std::int64_t id = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (const auto& s : f) {
        at.id.push_back(++id);
        at.type.push_back(1);
        at.x.insert(at.x.end(), {(i + s[0]) * 3 * d, (j + s[1]) * sq3 * d, 5.0});
      }
  const auto file = atomistic::find_potential_file("BNC.tersoff");
  const auto spec = atomistic::read_potential_commands_from_string(
      "units metal\nmass 1 12.011\npair_style tersoff\npair_coeff * * " +
          file.value_or("/usr/share/lammps/potentials/BNC.tersoff") + " C\n",
      "graphene", 1);
  const std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  const body::Body b =
      body::make_delta_body(at, pot, spec, {.dimension = 2, .cutoff = 0.0, .source = "g"});
  body::write_body(b, dir / "graphene.h5");
  const double lambda = 1.02;
  std::ofstream(dir / "run.yaml") << fmt::format(R"(units: metal
dimension: 2
plane: strain
geometry: {{shape: rectangle, origin: [0.0, 0.0], size: [4.0, 4.0], spacing: 0.5}}
horizon: {{factor: 3.015}}
material: {{model: cauchy-born, file: graphene.h5}}
boundary:
  - {{name: left,   region: {{x_max: 0.25}}, displacement: {{x: 0.0}}}}
  - {{name: right,  region: {{x_min: 3.75}}, displacement: {{x: "{}*t"}}}}
  - {{name: bottom, region: {{y_max: 0.25}}, displacement: {{y: 0.0}}}}
  - {{name: top,    region: {{y_min: 3.75}}, displacement: {{y: 0.0}}}}
loading: {{steps: 2}}
solver: {{type: newton, tolerance: 1.0e-10, max_iterations: 30, linear: umfpack}}
output: {{directory: out, every: 2}}
)",
                                                 3.5 * (lambda - 1.0));
  const auto s = scene::load_scene(dir / "run.yaml");
  const fs::path out = dir / "run";
  fs::remove_all(out);
  scene::run_scene(s, out);
  std::ifstream csv(out / "reactions.csv");
  std::string line, last;
  while (std::getline(csv, line)) last = line;
  std::vector<double> v;
  std::stringstream ss(last);
  for (std::string tok; std::getline(ss, tok, ',');) v.push_back(std::stod(tok));
  ASSERT_EQ(v.size(), 6u);
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 0) = lambda;
  const body::CauchyBorn rel(b), cl(b, body::IonRelaxation::clamped);
  ASSERT_TRUE(rel.relaxing());
  const double P11 = rel.evaluate(F, false).P(0, 0), P11c = cl.evaluate(F, false).P(0, 0);
  std::printf("  graphene λ = %.2f: reaction %.10g, relaxed P11·H %.10g, clamped %.10g\n", lambda,
              v[3], P11 * 4.0, P11c * 4.0);
  // the weak form is exact for the affine field up to the Newton tolerance 1e-10 (1e-8 relative
  // covers it with the condition number of the 64-point system, as for the LJ sheet)
  EXPECT_NEAR(v[3], P11 * 4.0, 1e-8 * std::abs(P11 * 4.0));
  EXPECT_GT(std::abs(P11c - P11), 1e-2 * std::abs(P11));  // the clamped material is not used
  fs::remove_all(dir);
}
