// Scenes on the points of a pdcg model file, `geometry: {shape: model, file: m.h5}`
// (docs/solver.md §2.1): homogeneous patch tests through `pdcg run`'s code path on atoms that
// form a square (2D) and cubic (3D) lattice (lattice rule: exact to round-off, as the grid
// path) and on a perturbed square grid (Voronoi rule: stated tolerance), plus input errors.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/scene/scene.hpp"
#include "pdcg/solver/material.hpp"

namespace fs = std::filesystem;
using namespace pdcg;

namespace {

const fs::path kDir = fs::temp_directory_path() / "pdcg_scene_model_geometry_test";

// Atoms at cell centres (i + ½)h of an n^d grid, each coordinate jittered by up to ±jitter·h;
// box [0, n h]^d (free), so V₀/N = h^d. LJ families with cutoff 1.5 h (unused by neo-Hookean).
fs::path grid_model(const std::string& name, int d, int n, double jitter) {
  atomistic::Atoms at;
  const double h = 1.0;
  at.box.hi = {n * h, n * h, d == 3 ? n * h : 10.0};
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::int64_t id = 0;
  for (int k = 0; k < (d == 3 ? n : 1); ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        at.id.push_back(++id);
        at.type.push_back(1);
        const double z = d == 3 ? (k + 0.5 + jitter * U(rng)) * h : 5.0;
        at.x.insert(at.x.end(),
                    {(i + 0.5 + jitter * U(rng)) * h, (j + 0.5 + jitter * U(rng)) * h, z});
      }
  const auto spec = atomistic::read_potential_commands_from_string(
      "units lj\npair_style lj/cut 1.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", name, 1);
  const std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  fs::create_directories(kDir);
  body::write_body(
      body::make_delta_body(at, pot, spec, {.dimension = d, .cutoff = 0.0, .source = name}),
      kDir / (name + ".h5"));
  return kDir / (name + ".h5");
}

fs::path write(const std::string& name, const std::string& text) {
  fs::create_directories(kDir);
  std::ofstream(kDir / name) << text;
  return kDir / name;
}

// Uniaxial stress: left face x-fixed, right face x-displaced by (λ − 1)(n − 1)h (cell centres
// 0.5 … n − 0.5), a pin (and in 3D a second one) against rigid motion, other faces free.
std::string uniaxial(const std::string& model, int d, int n, double lambda,
                     const std::string& geometry_extra = {}) {
  const double hi = n - 0.5;
  std::string pins = d == 2
                         ? "  - {name: pin, region: {point: [0.5, 0.5]}, displacement: {y: 0.0}}\n"
                         : "  - {name: pin, region: {point: [0.5, 0.5, 0.5]}, displacement: "
                           "{y: 0.0, z: 0.0}}\n"
                           "  - {name: pin2, region: {point: [0.5, " +
                               fmt::format("{}", hi) + ", 0.5]}, displacement: {z: 0.0}}\n";
  return fmt::format(R"(units: none
dimension: {d}
{plane}geometry: {{shape: model, file: {model}{extra}}}
horizon: {{factor: {m}}}
material: {{model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0}}
boundary:
  - {{name: left,  region: {{x_max: 0.5}}, displacement: {{x: 0.0}}}}
  - {{name: right, region: {{x_min: {hi}}}, displacement: {{x: "{u}*t"}}}}
{pins}loading: {{steps: 2}}
solver: {{type: newton, tolerance: 1.0e-11, max_iterations: 30, linear: umfpack}}
output: {{directory: out, every: 2}}
)",
                     fmt::arg("d", d), fmt::arg("plane", d == 2 ? "plane: strain\n" : ""),
                     fmt::arg("model", model), fmt::arg("extra", geometry_extra),
                     fmt::arg("m", d == 2 ? 3.015 : 2.015), fmt::arg("hi", hi),
                     fmt::arg("u", (lambda - 1.0) * (n - 1)), fmt::arg("pins", pins));
}

// Closed-form uniaxial stress of the neo-Hookean law: lateral stretch f from P22(diag(λ, f[, f]))
// = 0 by bisection (plane strain: F33 = 1); returns P11.
double closed_form_p11(int d, double lambda) {
  const auto mat = solver::make_neo_hookean(
      {1.0, 10.0}, d == 2 ? solver::Kinematics::plane_strain : solver::Kinematics::three_d);
  auto p = [&](double f, int i) {
    solver::Mat3 F = solver::Mat3::Identity(), P;
    F(0, 0) = lambda;
    F(1, 1) = f;
    if (d == 3) F(2, 2) = f;
    mat->evaluate(F, nullptr, &P, nullptr);
    return P(i, i);
  };
  double lo = 0.3, hi = 1.2;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (p(mid, 1) > 0 ? hi : lo) = mid;
  }
  return p(0.5 * (lo + hi), 0);
}

std::vector<double> last_reactions(const fs::path& out) {
  std::ifstream csv(out / "reactions.csv");
  std::string line, last;
  std::getline(csv, line);
  while (std::getline(csv, line)) last = line;
  std::vector<double> v;
  std::stringstream ss(last);
  for (std::string tok; std::getline(ss, tok, ',');) v.push_back(std::stod(tok));
  return v;
}

std::string error_of(const std::string& text) {
  try {
    scene::load_scene(write("bad.yaml", text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST(SceneModelGeometry, PatchTestOnLatticeModelsIsExact) {
  // Square (2D, 12×12) and cubic (3D, 5×5×5) lattices of atoms: lattice rule, V = h^d, s_k the
  // missing Wigner–Seitz faces. Reaction of the right face vs P11·(face area), P11 of the
  // closed-form uniaxial state: the weak form is exact for it, so only the Newton tolerance
  // (1e-11) and the conditioning remain (1e-8 relative).
  struct Case {
    int d, n;
  };
  for (const Case c : {Case{2, 12}, Case{3, 5}}) {
    const std::string name = fmt::format("grid{}d", c.d);
    grid_model(name, c.d, c.n, 0.0);
    const double lambda = 1.5;
    const auto s =
        scene::load_scene(write(name + ".yaml", uniaxial(name + ".h5", c.d, c.n, lambda)));
    ASSERT_TRUE(s.model_geometry);
    EXPECT_EQ(s.model_geometry->cloud.rule, solver::SurfaceRule::lattice);
    EXPECT_NEAR(s.spacing(), 1.0, 1e-12);
    const fs::path out = kDir / ("run" + name);
    fs::remove_all(out);
    scene::run_scene(s, out);
    const auto v = last_reactions(out);
    const double ref = closed_form_p11(c.d, lambda) * std::pow(c.n, c.d - 1);
    const double right = v[3];  // step,t,left_fx,right_fx,pin...: prescribed components only
    std::printf("  %dD lattice model, λ = %.1f: right reaction %.12g, closed form %.12g (%.1e)\n",
                c.d, lambda, right, ref, right / ref - 1);
    EXPECT_NEAR(right, ref, 1e-8 * ref);
    EXPECT_NEAR(v[2], -ref, 1e-8 * ref);
  }
}

TEST(SceneModelGeometry, PatchTestOnAPerturbedCloud) {
  // 2D 24×24 grid jittered by ±0.1h per coordinate: no lattice → Voronoi rule. The uniform
  // state is not exact: the free edges' s_k have tangential components P s_k ≠ 0 (jitter) and
  // the right face carries Σ s_x = 24h + 2·(corner bulge ≈ 0.37h). Tolerance 5%: the corner
  // bulge is 3% of this face, the jitter ±0.1h moves faces by O(0.1h) at random.
  grid_model("jitter2d", 2, 24, 0.1);
  const double lambda = 1.2;
  const auto s = scene::load_scene(write("jitter.yaml", uniaxial("jitter2d.h5", 2, 24, lambda)));
  EXPECT_EQ(s.model_geometry->cloud.rule, solver::SurfaceRule::voronoi);
  const fs::path out = kDir / "runjitter";
  fs::remove_all(out);
  scene::run_scene(s, out);
  const auto v = last_reactions(out);
  const double ref = closed_form_p11(2, lambda) * 24;
  std::printf("  perturbed cloud, λ = %.1f: right reaction %.8g, closed form %.8g (%+.2f%%)\n",
              lambda, v[3], ref, 100 * (v[3] / ref - 1));
  EXPECT_NEAR(v[3], ref, 0.05 * ref);  // step,t,left_fx,right_fx,pin_fy
}

TEST(SceneModelGeometry, BadInputIsAnInputError) {
  grid_model("grid2d", 2, 12, 0.0);
  grid_model("grid3d", 2 + 1, 5, 0.0);
  auto has = [](const std::string& msg, const std::string& what) {
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  };
  const std::string ok = uniaxial("grid2d.h5", 2, 12, 1.1);
  std::string t = ok;
  has(error_of(t.replace(t.find("grid2d.h5"), 9, "nothere.h5")), "does not exist");
  t = ok;
  has(error_of(t.replace(t.find("grid2d.h5"), 9, "grid3d.h5")), "dimension");
  has(error_of(uniaxial("grid2d.h5", 2, 12, 1.1, ", spacing: 0.5")), "spacing is the model's");
  has(error_of(uniaxial("grid2d.h5", 2, 12, 1.1, ", holes: [{center: [5, 5], radius: 2}]")),
      "cut a hole in the atoms");
  has(error_of(uniaxial("grid2d.h5", 2, 12, 1.1, ", cracks: [{from: [0, 5], to: [3, 5]}]")),
      "not allowed with shape: model");
  t = ok;
  has(error_of(t.replace(t.find("shape: model"), 12, "shape: rectangle")), "geometry.file");
}
