// The effect and material registries (docs/architecture.md, "Scene components"): this test
// registers its own material (St. Venant–Kirchhoff) and its own effect (a probe of the mean
// stretch) with one line each, without touching the scene core, and runs a scene with them.
// It is its own executable (tests/unit/scene/CMakeLists.txt), linked to a static archive of
// the scene module, so that it also shows the built-in registrations survive a static link.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "pdcg/core/error.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg/scene/effect.hpp"
#include "pdcg/scene/material_model.hpp"
#include "pdcg/scene/scene.hpp"
#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg_test.hpp"

namespace fs = std::filesystem;
using namespace pdcg;
using solver::Mat3;

namespace {

// ------------------------------------------------------------------ the material
// St. Venant–Kirchhoff: Ψ = λ/2 (tr E)² + μ tr(E²), E = ½(FᵀF − I), S = λ tr E I + 2μ E,
// P = F S, A_aJbL = δ_ab S_LJ + λ F_aJ F_bL + μ F_aL F_bJ + μ (F Fᵀ)_ab δ_JL. Plane strain:
// F₃₃ = 1, the in-plane blocks of P and A.
class StVenantKirchhoff final : public solver::Material {
 public:
  StVenantKirchhoff(double lambda, double mu) : lambda_(lambda), mu_(mu) {}
  int dimension() const override { return 2; }
  bool evaluate(const Mat3& F2, double* psi, Mat3* P, solver::Tangent* A) const override {
    const Mat3 F = full_deformation_gradient(F2);
    if (!(F.determinant() > 0)) return false;
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    const Mat3 S = lambda_ * E.trace() * Mat3::Identity() + 2 * mu_ * E;
    if (psi) *psi = 0.5 * lambda_ * E.trace() * E.trace() + mu_ * (E * E).trace();
    if (P) {
      *P = F * S;
      (*P).row(2).setZero();
      (*P).col(2).setZero();
    }
    if (A) {
      A->setZero();
      const Mat3 FFt = F * F.transpose();
      for (int a = 0; a < 2; ++a)
        for (int J = 0; J < 2; ++J)
          for (int b = 0; b < 2; ++b)
            for (int L = 0; L < 2; ++L)
              (*A)(solver::flat(a, J), solver::flat(b, L)) =
                  (a == b ? S(L, J) : 0.0) + lambda_ * F(a, J) * F(b, L) + mu_ * F(a, L) * F(b, J) +
                  (J == L ? mu_ * FFt(a, b) : 0.0);
    }
    return true;
  }
  Mat3 full_deformation_gradient(const Mat3& F2) const override {
    Mat3 F = Mat3::Identity();
    F.topLeftCorner<2, 2>() = F2.topLeftCorner<2, 2>();
    return F;
  }
  std::string name() const override { return "st-venant-kirchhoff (plane strain)"; }
  std::unique_ptr<solver::Material> clone() const override {
    return std::make_unique<StVenantKirchhoff>(*this);
  }

 private:
  double lambda_, mu_;
};

// its scene part: material: {model: st-venant-kirchhoff, lambda: …, mu: …, density: …}
class StVenantKirchhoffModel final : public scene::MaterialModel {
 public:
  std::vector<std::string> keys() const override { return {"lambda", "mu", "density"}; }
  std::vector<scene::NumberRule> number_rules() const override {
    using K = scene::NumberRule::Kind;
    const double inf = std::numeric_limits<double>::infinity();
    return {{"material.lambda", K::real, 0, false, inf, true, "a Lamé constant λ ≥ 0"},
            {"material.mu", K::real, 0, true, inf, true, "a shear modulus μ > 0"}};
  }
  void parse(const scene::Reader& r, const scene::Node& m, scene::Scene& s) override {
    if (s.dimension != 2 || s.plane != "strain")
      throw r.error(m, "material.model", "this St. Venant–Kirchhoff is plane strain only")
          .fix("set dimension: 2, plane: strain");
    if (!m["lambda"]) throw r.error(m, "material.lambda", "missing key").expected("λ ≥ 0");
    lambda_ = r.number(m["lambda"], "material.lambda");
    if (m["mu"]) mu_ = r.number(m["mu"], "material.mu");
  }
  void resolve(scene::Emitter& out, const scene::Scene&) const override {
    out.value("lambda", lambda_).value("mu", mu_);
  }
  std::unique_ptr<solver::Material> make(const scene::Scene&) const override {
    return std::make_unique<StVenantKirchhoff>(lambda_, mu_);
  }

 private:
  double lambda_ = 0.0, mu_ = 1.0;
};

// ------------------------------------------------------------------ the effect
// strain_probe: {axis: x, scale: 1}: a column mean_F<axis><axis> = scale × the mean of F_aa
// over the points, a field fields/strain_probe (F_aa per point), and a checkpoint entry.
int g_restored = 0;

class StrainProbeRun final : public scene::EffectRun {
 public:
  StrainProbeRun(const scene::RunContext& c, int axis, double scale)
      : model_(c.model), axis_(axis), scale_(scale) {}
  std::vector<std::string> columns() const override {
    const char* ax[3] = {"x", "y", "z"};
    return {std::string("mean_F") + ax[axis_] + ax[axis_]};
  }
  void on_step(const scene::StepState& st, std::vector<double>& values) override {
    const auto F = model_.point_deformation_gradients(st.u);
    double sum = 0;
    for (const auto& f : F) sum += f(axis_, axis_);
    values.push_back(scale_ * sum / static_cast<double>(F.size()));
    ++samples_;
  }
  void write_fields(io::H5Writer& h5, const scene::StepState& st) const override {
    const auto F = model_.point_deformation_gradients(st.u);
    std::vector<double> v;
    for (const auto& f : F) v.push_back(f(axis_, axis_));
    h5.write("fields/strain_probe", v, {v.size()});
  }
  void checkpoint(io::H5Writer& h5, const std::string& group) const override {
    h5.write(group + "/samples", std::vector<double>{static_cast<double>(samples_)});
  }
  void restore(const io::H5Reader& h5, const std::string& group) override {
    samples_ = static_cast<long>(h5.read_double(group + "/samples").at(0));
    g_restored = static_cast<int>(samples_);
  }

 private:
  const solver::Model& model_;
  int axis_;
  double scale_;
  long samples_ = 0;
};

class StrainProbe final : public scene::Effect {
 public:
  std::vector<scene::NumberRule> number_rules() const override {
    using K = scene::NumberRule::Kind;
    return {{"strain_probe.scale", K::real, 0, true, std::numeric_limits<double>::infinity(), true,
             "a factor > 0"}};
  }
  void parse(const std::string&, const scene::Reader& r, const scene::Node& root,
             scene::Scene& s) override {
    if (!listed(s)) return;
    const auto n = root["strain_probe"];
    if (!n) return;  // defaults
    r.keys(n, "strain_probe", {"axis", "scale"});
    if (n["axis"]) {
      const auto a = r.choice(n["axis"], "strain_probe.axis", {"x", "y", "z"});
      axis_ = a == "x" ? 0 : a == "y" ? 1 : 2;
      if (axis_ >= s.dimension)
        throw r.error(n["axis"], "strain_probe.axis", "axis beyond the scene dimension").value(a);
    }
    if (n["scale"]) scale_ = r.number(n["scale"], "strain_probe.scale");
  }
  void resolve(const std::string&, scene::Emitter& out, const scene::Scene& s) const override {
    if (!listed(s)) return;
    const char* ax[3] = {"x", "y", "z"};
    out.begin_map("strain_probe").value("axis", ax[axis_]).value("scale", scale_).end_map();
  }
  std::unique_ptr<scene::EffectRun> attach(const scene::RunContext& c) const override {
    return std::make_unique<StrainProbeRun>(c, axis_, scale_);
  }

 private:
  int axis_ = 0;
  double scale_ = 1.0;
};

}  // namespace

PDCG_REGISTER_MATERIAL(st_venant_kirchhoff, StVenantKirchhoffModel)
PDCG_REGISTER_EFFECT(strain_probe, StrainProbe)

namespace {

const char* kScene = R"(dimension: 2
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0], spacing: 0.1}
material: {model: st-venant-kirchhoff, lambda: 1.0, mu: 1.0, density: 1.0}
boundary:
  - {name: left,  region: {x_max: 0.0},  displacement: {x: 0.0}}
  - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}
  - {name: right, region: {x_min: 1.0},  displacement: {x: "0.18*t"}}
loading: {steps: 2}
solver: {tolerance: 1.0e-10}
effects: [strain_probe]
strain_probe: {axis: x, scale: 2.0}
output: {directory: out, checkpoint_every: 1}
)";

fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = pdcg::test::scratch_dir("pdcg_registry_test") / name;
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
    scene::load_scene(write("bad.yaml", text));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::vector<double> last_row(const fs::path& csv, std::string& header) {
  std::ifstream in(csv);
  std::string line, last;
  std::getline(in, header);  // # units
  std::getline(in, header);
  while (std::getline(in, line)) last = line;
  std::vector<double> v;
  std::stringstream ss(last);
  for (std::string tok; std::getline(ss, tok, ',');) v.push_back(std::stod(tok));
  return v;
}

}  // namespace

TEST(Registries, ListBuiltInsFirstThenRegistered) {
  // built-ins by the library's explicit list (present in a static link), then this file's
  EXPECT_EQ(scene::registered_effects(),
            (std::vector<std::string>{"inertia", "damping", "rupture", "strain_probe"}));
  EXPECT_EQ(scene::valid_effects(), scene::registered_effects());
  EXPECT_EQ(scene::registered_materials(),
            (std::vector<std::string>{"neo-hookean", "cauchy-born", "st-venant-kirchhoff"}));
  // the numeric rules: the built-in components' 46 (one per row of test_scene_checks.cpp) and
  // this file's 3, each path once
  const auto rules = scene::number_rules();
  EXPECT_EQ(rules.size(), 46u + 3u);
  std::set<std::string> paths;
  for (const auto& r : rules) EXPECT_TRUE(paths.insert(r.path).second) << r.path;
  EXPECT_TRUE(paths.count("material.lambda") && paths.count("strain_probe.scale"));
  EXPECT_THROW(scene::register_effect("rupture", [] { return std::make_unique<StrainProbe>(); }),
               Error);
}

TEST(Registries, OwnParametersAreParsedCheckedAndResolved) {
  const auto s = scene::load_scene(write("probe.yaml", kScene));
  ASSERT_EQ(s.effects, (std::vector<std::string>{"strain_probe"}));
  const std::string y = scene::resolved_yaml(s);
  EXPECT_NE(y.find("material: {model: st-venant-kirchhoff, lambda: 1, mu: 1, density: 1}"),
            std::string::npos)
      << y;
  // after the effects list and before output (its section's rank)
  EXPECT_NE(y.find("effects: [strain_probe]\nstrain_probe: {axis: x, scale: 2}\noutput:"),
            std::string::npos)
      << y;
  const auto r = scene::load_scene(write("probe_resolved.yaml", y));
  EXPECT_EQ(scene::resolved_yaml(r), y);
  // their errors: file:line, key, value, expected, as the built-in ones
  auto e = error_of(replace(kScene, "scale: 2.0", "scale: -1"));
  EXPECT_NE(e.find("bad.yaml:11: strain_probe.scale"), std::string::npos) << e;
  EXPECT_NE(e.find("strain_probe.scale: out of range: got '-1', expected a factor > 0"),
            std::string::npos)
      << e;
  e = error_of(replace(kScene, "axis: x", "axes: x"));
  EXPECT_NE(e.find("strain_probe.axes: unknown key"), std::string::npos) << e;
  EXPECT_NE(e.find("one of: axis, scale"), std::string::npos) << e;
  e = error_of(replace(kScene, "effects: [strain_probe]\n", ""));
  EXPECT_NE(e.find("settings for an effect the scene does not list"), std::string::npos) << e;
  e = error_of(replace(kScene, "effects: [strain_probe]", "effects: [strain_prob]"));
  EXPECT_NE(e.find("one of: inertia, damping, rupture, strain_probe"), std::string::npos) << e;
  e = error_of(replace(kScene, "lambda: 1.0, ", ""));
  EXPECT_NE(e.find("bad.yaml:3: material.lambda: missing key"), std::string::npos) << e;
  e = error_of(replace(kScene, "mu: 1.0", "mu: 0"));
  EXPECT_NE(e.find("material.mu: out of range"), std::string::npos) << e;
  // a key of another model: refused with the model's own keys
  e = error_of(replace(kScene, "mu: 1.0", "mu: 1.0, shear_modulus: 2.0"));
  EXPECT_NE(e.find("material model st-venant-kirchhoff takes no shear_modulus"), std::string::npos)
      << e;
  e = error_of(replace(kScene, "model: st-venant-kirchhoff", "model: st-venant"));
  EXPECT_NE(e.find("one of: neo-hookean, cauchy-born, st-venant-kirchhoff"), std::string::npos)
      << e;
}

TEST(Registries, RunsAHomogeneousStretchAgainstTheClosedForm) {
  // Uniaxial stress in plane strain of the 10×10 block (x_r − x_l = 0.9, u_r = 0.18 → λ₁ = 1.2;
  // y free): S₂₂ = 0 gives E₂₂ = −λE₁₁/(λ+2μ), S₁₁ = 4μ(λ+μ)/(λ+2μ) E₁₁, and the reaction on
  // the right edge (height 1, unit thickness) is P₁₁ = λ₁ S₁₁.
  const auto s = scene::load_scene(write("probe.yaml", kScene));
  EXPECT_EQ(scene::make_material(s)->name(), "st-venant-kirchhoff (plane strain)");
  const fs::path out = fs::temp_directory_path() / "pdcg_registry_test" / "run";
  fs::remove_all(out);
  scene::run_scene(s, out);
  const double lam = 1.0, mu = 1.0, l1 = 1.2, E11 = 0.5 * (l1 * l1 - 1);
  const double P11 = l1 * 4 * mu * (lam + mu) / (lam + 2 * mu) * E11;  // 0.704
  std::string header;
  const auto v = last_row(out / "reactions.csv", header);
  EXPECT_EQ(header, "step,t,left_fx,pin_fy,right_fx,mean_Fxx");
  ASSERT_EQ(v.size(), 6u);
  EXPECT_DOUBLE_EQ(v[1], 1.0);
  // the weak form reproduces a homogeneous state exactly (test_scene.cpp, patch tests); 1e-8
  // covers the Newton tolerance 1e-10 and the 10 digits reactions.csv keeps
  EXPECT_NEAR(v[4], P11, 1e-8);
  EXPECT_NEAR(v[2], -P11, 1e-8);  // equilibrium: the left edge holds it back
  // the effect's column: scale 2 × mean F₁₁ = 2 λ₁ (homogeneous; 10 digits in the CSV)
  EXPECT_NEAR(v[5], 2 * l1, 1e-9);
  // its field in the results file, and its state in the checkpoint
  io::H5Reader h5(out / "results_0002.h5");
  const auto f = h5.read_double("fields/strain_probe");
  ASSERT_EQ(f.size(), 100u);
  for (double x : f) EXPECT_NEAR(x, l1, 1e-9);  // F₁₁ = λ₁ at every point
  io::H5Reader cp(out / "checkpoint_00000002.h5");
  EXPECT_EQ(cp.read_double("effects/strain_probe/samples").at(0), 3.0);  // rows 0, 1, 2
  // restart from it: the effect's state comes back
  scene::RunOptions ro;
  ro.restart = out;
  scene::run_scene(s, ro);
  EXPECT_EQ(g_restored, 3);
}
