// Scene files: the issue-6 contract is accepted, bad input gives InputErrors
// that name the key and list the valid choices, and a small run writes the
// promised files with the homogeneous reaction of the closed form.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "pdcg/core/error.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg/scene/expression.hpp"
#include "pdcg/scene/scene.hpp"
#include "pdcg_test.hpp"

namespace fs = std::filesystem;
using namespace pdcg;

namespace {

const char* kContract = R"(units: none            # lj | metal | real | si | none
dimension: 2
plane: strain          # strain | stress (2D only)
geometry:
  shape: rectangle     # rectangle | box | model
  origin: [0.0, 0.0]
  size: [1.0, 1.0]
  spacing: 0.025
  holes: [{center: [0.5, 0.5], radius: 0.2}]
  cracks: [{from: [0.0, 0.5], to: [0.2, 0.5]}]
horizon: {factor: 3.015}            # or {value: 0.075}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left,  region: {x_max: 0.0},  displacement: {x: 0.0}}
  - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}
  - {name: right, region: {x_min: 1.0},  displacement: {x: "0.5*t"}}
  - {name: top,   region: {y_min: 1.0},  traction: [0.0, 0.0]}
loading: {steps: 20}                # t runs from 0 to 1 over the steps
solver: {type: newton, tolerance: 1.0e-8, max_iterations: 30, linear: cholmod}
output: {directory: out, every: 1}
)";

fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = pdcg::test::scratch_dir("pdcg_scene_test") / name;
  std::ofstream(p) << text;
  return p;
}

std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto i = s.find(a);
  EXPECT_NE(i, std::string::npos) << a;
  return s.replace(i, a.size(), b);
}

std::string error_of(const std::string& text) {
  try {
    const auto s = scene::load_scene(write("bad.yaml", text));
    solver::DiscretizationOptions o;
    o.horizon_factor = s.horizon_factor;
    o.horizon = s.horizon_value;
    const auto body = solver::Discretization::grid(s.geometry, o);
    for (const auto& bc : s.boundary) scene::select(s, body, bc);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Expression, Evaluates) {
  EXPECT_DOUBLE_EQ(scene::parse_expression("0.5*t", "x")(0.4), 0.2);
  EXPECT_DOUBLE_EQ(scene::parse_expression("-2^2 + (1 - t)/4", "x")(0.0), -4 + 0.25);
  EXPECT_NEAR(scene::parse_expression("sin(pi*t)", "x")(0.5), 1.0, 1e-15);
  EXPECT_THROW(scene::parse_expression("0.5*", "x"), InputError);
  EXPECT_THROW(scene::parse_expression("foo(t)", "x"), InputError);
}

TEST(Scene, ContractIsAccepted) {
  const auto s = scene::load_scene(write("contract.yaml", kContract));
  EXPECT_EQ(s.dimension, 2);
  EXPECT_EQ(s.boundary.size(), 4u);
  EXPECT_DOUBLE_EQ(s.boundary[2].value[0](1.0), 0.5);
  EXPECT_TRUE(s.boundary[3].is_traction);
  EXPECT_EQ(s.steps, 20);
  EXPECT_EQ(s.geometry.holes.size(), 1u);
  EXPECT_EQ(s.geometry.cracks.size(), 1u);
  // The resolved scene is itself a valid scene with the same content.
  const auto r = scene::load_scene(write("resolved.yaml", scene::resolved_yaml(s)));
  EXPECT_EQ(scene::resolved_yaml(r), scene::resolved_yaml(s));
}

TEST(Scene, BadInputIsReported) {
  auto e = error_of(replace(kContract, "loading: {steps: 20}", "loading: {steps: 20, stpes: 3}"));
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("steps"), std::string::npos) << e;  // valid keys listed
  EXPECT_NE(e.find(":18"), std::string::npos) << e;    // line number
  e = error_of(replace(kContract, "material: {model", "materials: {model"));
  EXPECT_NE(e.find("one of: units, dimension"), std::string::npos) << e;
  e = error_of(replace(kContract, "{factor: 3.015}", "{value: 0.01}"));
  EXPECT_NE(e.find("horizon smaller than the grid spacing"), std::string::npos) << e;
  e = error_of(replace(kContract, "{x_min: 1.0}", "{x_min: 1.5}"));
  EXPECT_NE(e.find("selects no point"), std::string::npos) << e;
  EXPECT_NE(e.find("boundary[right]"), std::string::npos) << e;
  e = error_of(replace(kContract, "linear: cholmod", "linear: pardiso"));
  EXPECT_NE(e.find("cholmod, umfpack"), std::string::npos) << e;
  e = error_of(replace(kContract, "\"0.5*t\"", "\"0.5*\""));
  EXPECT_NE(e.find("cannot parse"), std::string::npos) << e;
}

TEST(Scene, MatrixFreeGmres) {
  // solver.matrix_free: accepted with gmres, kept in the resolved scene, refused otherwise.
  const auto s = scene::load_scene(
      write("mf.yaml", replace(kContract, "linear: cholmod", "linear: gmres, matrix_free: true")));
  EXPECT_TRUE(s.newton.matrix_free);
  EXPECT_EQ(s.newton.linear, solver::LinearSolver::gmres);
  const auto r = scene::load_scene(write("mf_resolved.yaml", scene::resolved_yaml(s)));
  EXPECT_TRUE(r.newton.matrix_free);
  auto e = error_of(replace(kContract, "linear: cholmod", "linear: cholmod, matrix_free: true"));
  EXPECT_NE(e.find("need the GMRES linear solver"), std::string::npos) << e;
  EXPECT_NE(e.find("linear: gmres"), std::string::npos) << e;
  e = error_of(replace(kContract, "linear: cholmod", "linear: gmres, matrix_free: yes please"));
  EXPECT_NE(e.find("not a boolean"), std::string::npos) << e;
  e = error_of(replace(kContract, "linear: cholmod", "linear: gmres, matrixfree: true"));
  EXPECT_NE(e.find("matrix_free"), std::string::npos) << e;  // valid keys listed
}

TEST(Scene, MissingConstraintIsReported) {
  // No y-constraint: the static problem is singular.
  std::string text = replace(
      kContract, "  - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}\n", "");
  text = replace(text, "spacing: 0.025", "spacing: 0.1");
  text = replace(text, "holes: [{center: [0.5, 0.5], radius: 0.2}]", "holes: []");
  text = replace(text, "cracks: [{from: [0.0, 0.5], to: [0.2, 0.5]}]", "cracks: []");
  const auto s = scene::load_scene(write("nopin.yaml", text));
  try {
    scene::run_scene(s, fs::temp_directory_path() / "pdcg_scene_test" / "nopin");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no displacement constraint in y"), std::string::npos)
        << e.what();
  }
}

TEST(Scene, SmallRunWritesResultsAndReactions) {
  // Plane-strain uniaxial stretch to λ = 1.5 of a 10×10 block: the reaction
  // must be the closed-form nominal stress (weak form reproduces it exactly).
  std::string text = replace(kContract, "spacing: 0.025", "spacing: 0.1");
  text = replace(text, "holes: [{center: [0.5, 0.5], radius: 0.2}]", "holes: []");
  text = replace(text, "cracks: [{from: [0.0, 0.5], to: [0.2, 0.5]}]", "cracks: []");
  text = replace(text, "\"0.5*t\"", "\"0.45*t\"");  // x_r − x_l = 0.9 → λ = 1.5
  text = replace(text, "steps: 20", "steps: 2");
  const auto s = scene::load_scene(write("small.yaml", text));
  const fs::path out = fs::temp_directory_path() / "pdcg_scene_test" / "small";
  fs::remove_all(out);
  scene::run_scene(s, out);
  for (const char* f : {"scene.resolved.yaml", "reactions.csv", "results.xdmf", "results_0001.h5",
                        "results_0002.h5"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  std::ifstream csv(out / "reactions.csv");
  std::string header, line, last;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("# units: none (model units", 0), 0u) << header;
  std::getline(csv, header);
  // reactions of the prescribed components only: pin fixes y, left and right x
  EXPECT_EQ(header, "step,t,left_fx,pin_fy,right_fx");
  while (std::getline(csv, line)) last = line;
  std::vector<double> v;
  std::stringstream ss(last);
  for (std::string tok; std::getline(ss, tok, ',');) v.push_back(std::stod(tok));
  ASSERT_EQ(v.size(), 5u);
  EXPECT_DOUBLE_EQ(v[1], 1.0);
  // Closed form (plane strain, μ = 1, K = 10, λ = 1.5): P₁₁ = 1.105538 from a
  // root solve of P₂₂ = 0 (test_patch.cpp prints 1.105538); 1e-5 covers its 7 digits.
  EXPECT_NEAR(v[4], 1.105538, 1e-5);
  io::H5Reader h5(out / "results_0002.h5");
  EXPECT_EQ(h5.dims("fields/displacement"), (std::vector<std::size_t>{100, 3}));
  const auto F = h5.read_double("fields/deformation_gradient");
  EXPECT_NEAR(F[0], 1.5, 1e-9);  // homogeneous state: F₁₁ = λ at every point
}

TEST(Scene, SurfaceGripsActOnTheFaces) {
  // The uniaxial block of SmallRunWritesResultsAndReactions with `grip: surface`: the faces
  // x = 0 and x = 1 (not the point columns at 0.05 and 0.95) move apart by 0.5, so λ = 1.5
  // and the reaction is the closed form 1.105538 (docs/solver.md §4, "Grips on the surface").
  std::string text = replace(kContract, "spacing: 0.025", "spacing: 0.1");
  text = replace(text, "holes: [{center: [0.5, 0.5], radius: 0.2}]", "holes: []");
  text = replace(text, "cracks: [{from: [0.0, 0.5], to: [0.2, 0.5]}]", "cracks: []");
  text = replace(text, "displacement: {x: 0.0}}", "displacement: {x: 0.0}, grip: surface}");
  text = replace(text, "displacement: {x: \"0.5*t\"}}",
                 "displacement: {x: \"0.5*t\"}, grip: surface}");
  text = replace(text, "steps: 20", "steps: 2");
  const auto s = scene::load_scene(write("grips.yaml", text));
  ASSERT_TRUE(s.boundary[0].grip_surface);
  EXPECT_FALSE(s.boundary[1].grip_surface);  // the pin: points (default)
  // the resolved scene keeps the choice
  const auto r = scene::load_scene(write("grips_resolved.yaml", scene::resolved_yaml(s)));
  EXPECT_TRUE(r.boundary[2].grip_surface);
  const fs::path out = fs::temp_directory_path() / "pdcg_scene_test" / "grips";
  fs::remove_all(out);
  scene::run_scene(s, out);
  std::ifstream csv(out / "reactions.csv");
  std::string line, last;
  while (std::getline(csv, line)) last = line;
  std::vector<double> v;
  std::stringstream ss(last);
  for (std::string tok; std::getline(ss, tok, ',');) v.push_back(std::stod(tok));
  ASSERT_EQ(v.size(), 5u);
  EXPECT_NEAR(v[4], 1.105538, 1e-5);  // the closed form's 7 printed digits
  const auto F = io::H5Reader(out / "results_0002.h5").read_double("fields/deformation_gradient");
  EXPECT_NEAR(F[0], 1.5, 1e-9);  // F₁₁ = λ of the faces at every point

  // refused: vertices (their points already lie on the faces), a corner point, a traction set
  auto refused = [&](const std::string& t, const std::string& what) {
    const auto sc = scene::load_scene(write("grips_bad.yaml", t));
    try {
      scene::run_scene(sc, fs::temp_directory_path() / "pdcg_scene_test" / "grips_bad");
      ADD_FAILURE() << "accepted: " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("grip"), std::string::npos) << e.what();
    }
  };
  refused(replace(text, "spacing: 0.1", "spacing: 0.1\n  nodes: vertices"), "vertices");
  refused(replace(text, "displacement: {y: 0.0}}", "displacement: {y: 0.0}, grip: surface}"),
          "a corner point");
  EXPECT_NE(error_of(replace(text, "traction: [0.0, 0.0]}", "traction: [0.0, 0.0], grip: surface}"))
                .find("grip"),
            std::string::npos);
}
