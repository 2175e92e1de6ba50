// Scene effects (docs/effects.md): the effects list, its errors, and
// "only what a scene asks for" in the output files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "pdcg/core/error.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg/scene/scene.hpp"
#include "pdcg_test.hpp"

namespace fs = std::filesystem;
using namespace pdcg;

namespace {

const char* kBase = R"(dimension: 2
plane: stress
geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0], spacing: 0.1,
           cracks: [{from: [0.0, 0.5], to: [0.3, 0.5]}]}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 100.0}
boundary:
  - {name: bottom, region: {y_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: top,    region: {y_min: 1.0}, displacement: {x: 0.0, y: "0.15*t"}}
loading: {steps: 3}
)";

fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = pdcg::test::scratch_dir("pdcg_effects_test") / name;
  std::ofstream(p) << text;
  return p;
}

std::string error_of(const std::string& extra) {
  try {
    scene::load_scene(write("bad.yaml", std::string(kBase) + extra));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

bool has(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

}  // namespace

TEST(Effects, BadInputIsReported) {
  auto e = error_of("effects: [rupture, cracking]\nrupture: {critical: 2}\n");
  EXPECT_TRUE(has(e, "cracking") && has(e, "inertia, damping, rupture")) << e;
  EXPECT_TRUE(has(e, ":10")) << e;  // line of the bad entry
  e = error_of("effects: [rupture, rupture]\nrupture: {critical: 2}\n");
  EXPECT_TRUE(has(e, "listed twice")) << e;
  e = error_of("rupture: {critical: 2}\n");
  EXPECT_TRUE(has(e, "does not list") && has(e, "add rupture to effects")) << e;
  e = error_of("effects: [damping]\n");
  EXPECT_TRUE(has(e, "damping without inertia")) << e;
  e = error_of("initial: {velocity: {x: \"0\"}}\n");
  EXPECT_TRUE(has(e, "without inertia")) << e;
  e = error_of("effects: [inertia]\n");
  EXPECT_TRUE(has(e, "inertia is listed but has no settings")) << e;
  e = error_of("effects: [rupture]\n");
  EXPECT_TRUE(has(e, "no settings")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: bond_stretch}\n");
  EXPECT_TRUE(has(e, "rupture.critical") && has(e, "missing")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: stretchiness, critical: 2}\n");
  EXPECT_TRUE(has(e, "principal_stretch, energy_density")) << e;
  e = error_of("effects: [rupture]\nrupture: {critical: 2, crit: 3}\n");
  EXPECT_TRUE(has(e, "unknown key") && has(e, "criterion, critical, max_passes")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: principal_stretch, critical: 0.9}\n");
  EXPECT_TRUE(has(e, "must exceed 1")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: energy_density, critical: 0}\n");
  EXPECT_TRUE(has(e, "rupture.critical: out of range") && has(e, "energy density > 0")) << e;
  e = error_of("solver: {correspondence: classical}\neffects: [rupture]\nrupture: {critical: 2}\n");
  EXPECT_TRUE(has(e, "bond-associated")) << e;
}

// The energy-based rule (docs/fracture.md §5): G_c or surface_energy (G_c = 2γ), its errors,
// the resolved scene, and the dissipated-energy column of a run.
TEST(Effects, FractureEnergyCriterion) {
  auto e = error_of("effects: [rupture]\nrupture: {criterion: fracture_energy}\n");
  EXPECT_TRUE(has(e, "rupture.G_c") && has(e, "missing") && has(e, "surface_energy")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: fracture_energy, critical: 2}\n");
  EXPECT_TRUE(has(e, "calibrated from the energy release rate") && has(e, "G_c")) << e;
  e = error_of(
      "effects: [rupture]\nrupture: {criterion: fracture_energy, G_c: 1, surface_energy: 0.5}\n");
  EXPECT_TRUE(has(e, "both G_c and surface_energy")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: fracture_energy, G_c: -1}\n");
  EXPECT_TRUE(has(e, "rupture.G_c: out of range") && has(e, "G_c > 0")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: fracture_energy, surface_energy: 0}\n");
  EXPECT_TRUE(has(e, "rupture.surface_energy: out of range")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: bond_stretch, critical: 2, G_c: 1}\n");
  EXPECT_TRUE(has(e, "fracture_energy criterion only")) << e;
  e = error_of("effects: [rupture]\nrupture: {criterion: fracture, G_c: 1}\n");
  EXPECT_TRUE(has(e, "energy_density, fracture_energy")) << e;

  const auto s = scene::load_scene(write(
      "fe.yaml", std::string(kBase) +
                     "effects: [rupture]\nrupture: {criterion: fracture_energy, surface_energy: "
                     "0.006}\n"));
  EXPECT_EQ(s.rupture_options.criterion, solver::RuptureCriterion::fracture_energy);
  EXPECT_EQ(s.rupture_options.fracture_energy, 0.012);  // G_c = 2γ
  const auto s2 = scene::load_scene(write("fe2.yaml", scene::resolved_yaml(s)));
  EXPECT_EQ(s2.rupture_options.criterion, solver::RuptureCriterion::fracture_energy);
  EXPECT_EQ(s2.rupture_options.fracture_energy, 0.012);

  // a run: the pre-cracked sheet pulled to 15 % breaks bonds; reactions.csv carries the
  // dissipated energy, which never decreases and is positive once bonds broke
  const fs::path out = fs::temp_directory_path() / "pdcg_effects_test" / "fracture_energy";
  fs::remove_all(out);
  scene::run_scene(s, out);
  std::ifstream csv(out / "reactions.csv");
  std::string line, header;
  while (std::getline(csv, line) && line.rfind("#", 0) == 0) {
  }
  header = line;
  EXPECT_TRUE(has(header, ",broken_bonds,dissipated_energy")) << header;
  double last = 0, broken = 0;
  while (std::getline(csv, line)) {
    const auto c2 = line.rfind(',');
    const auto c1 = line.rfind(',', c2 - 1);
    const double d = std::stod(line.substr(c2 + 1));
    broken = std::stod(line.substr(c1 + 1, c2 - c1 - 1));
    EXPECT_GE(d, last);
    last = d;
  }
  EXPECT_GT(broken, 0);
  EXPECT_GT(last, 0);
}

// The softening failure law of fracture_energy (docs/fracture.md §6): its keys are checked,
// survive the resolved scene, and a run dissipates energy monotonically.
TEST(Effects, SofteningFailureLawKeys) {
  auto e = error_of(
      "effects: [rupture]\nrupture: {criterion: bond_stretch, critical: 2, softening: linear}\n");
  EXPECT_TRUE(has(e, "rupture.softening") && has(e, "fracture_energy criterion only")) << e;
  e = error_of(
      "effects: [rupture]\nrupture: {criterion: fracture_energy, G_c: 1, softening: "
      "exponential}\n");
  EXPECT_TRUE(has(e, "rupture.softening") && has(e, "linear")) << e;
  e = error_of(
      "effects: [rupture]\nrupture: {criterion: fracture_energy, G_c: 1, elastic_limit: 0.2}\n");
  EXPECT_TRUE(has(e, "rupture.elastic_limit") && has(e, "softening: linear")) << e;
  for (const char* bad : {"elastic_limit: 0", "elastic_limit: 1.5", "damage_tolerance: 1",
                          "max_damage_increment: 0"}) {
    e = error_of(std::string("effects: [rupture]\nrupture: {criterion: fracture_energy, G_c: 1, "
                             "softening: linear, ") +
                 bad + "}\n");
    EXPECT_TRUE(has(e, "out of range")) << bad << ": " << e;
  }
  const auto s = scene::load_scene(
      write("soft.yaml", std::string(kBase) +
                             "effects: [rupture]\nrupture: {criterion: fracture_energy, G_c: "
                             "0.012, softening: linear, elastic_limit: 0.3, "
                             "max_damage_increment: 0.5}\n"));
  EXPECT_EQ(s.rupture_options.softening, solver::RuptureSoftening::linear);
  EXPECT_EQ(s.rupture_options.elastic_limit, 0.3);
  const auto s2 = scene::load_scene(write("soft2.yaml", scene::resolved_yaml(s)));
  EXPECT_EQ(s2.rupture_options.softening, solver::RuptureSoftening::linear);
  EXPECT_EQ(s2.rupture_options.elastic_limit, 0.3);
  EXPECT_EQ(s2.rupture_options.max_damage_increment, 0.5);
  EXPECT_EQ(s2.rupture_options.damage_tolerance, 1e-3);
  const fs::path out = fs::temp_directory_path() / "pdcg_effects_test" / "softening";
  fs::remove_all(out);
  scene::run_scene(s, out);
  std::ifstream csv(out / "reactions.csv");
  std::string line;
  while (std::getline(csv, line) && line.rfind("#", 0) == 0) {
  }
  EXPECT_TRUE(has(line, ",dissipated_energy")) << line;
  double last = 0;
  while (std::getline(csv, line)) {
    const double d = std::stod(line.substr(line.rfind(',') + 1));
    EXPECT_GE(d, last);  // damage is irreversible
    last = d;
  }
  EXPECT_GT(last, 0);
}

TEST(Effects, ResolvedSceneKeepsTheEffects) {
  const auto s = scene::load_scene(
      write("r.yaml", std::string(kBase) +
                          "effects: [rupture]\nrupture: {criterion: energy_density, critical: "
                          "0.75, max_passes: 7}\n"));
  const auto s2 = scene::load_scene(write("r2.yaml", scene::resolved_yaml(s)));
  EXPECT_TRUE(s2.rupture);
  EXPECT_EQ(s2.rupture_options.criterion, solver::RuptureCriterion::energy_density);
  EXPECT_EQ(s2.rupture_options.critical, 0.75);
  EXPECT_EQ(s2.rupture_options.max_passes, 7);
}

// Only what a scene asks for: no damage field, no broken-bond column without rupture;
// with rupture both exist, the XDMF lists the damage, and damage is in [0, 1].
TEST(Effects, OutputsOnlyWhatTheSceneAsksFor) {
  const fs::path out0 = fs::temp_directory_path() / "pdcg_effects_test" / "plain";
  const fs::path out1 = fs::temp_directory_path() / "pdcg_effects_test" / "rupture";
  fs::remove_all(out0);
  fs::remove_all(out1);
  scene::run_scene(scene::load_scene(write("plain.yaml", kBase)), out0);
  scene::run_scene(scene::load_scene(write(
                       "rup.yaml", std::string(kBase) + "effects: [rupture]\nrupture: {criterion: "
                                                        "bond_stretch, critical: 1.15}\n")),
                   out1);
  {
    io::H5Reader h5(out0 / "results_0003.h5");
    EXPECT_FALSE(h5.exists("fields/damage"));
    std::ifstream csv(out0 / "reactions.csv");
    std::string header;
    std::getline(csv, header);  // the units line
    std::getline(csv, header);
    EXPECT_FALSE(has(header, "broken"));
  }
  io::H5Reader h5(out1 / "results_0003.h5");
  ASSERT_TRUE(h5.exists("fields/damage"));
  const auto D = h5.read_double("fields/damage");
  double dmax = 0;
  for (double v : D) {
    EXPECT_GE(v, 0.0);
    EXPECT_LE(v, 1.0);
    dmax = std::max(dmax, v);
  }
  EXPECT_GT(dmax, 0.0);  // the pre-crack tip opened past a stretch of 1.15
  std::ifstream x(out1 / "results.xdmf");
  std::stringstream ss;
  ss << x.rdbuf();
  EXPECT_TRUE(has(ss.str(), "/fields/damage"));
}

// rupture.fallback (docs/effects.md §2, "Unstable passes"): pseudo-transient continuation
// then ADR by default, ADR only on request; a bad value names the choices.
TEST(Effects, RuptureFallbackKey) {
  const auto s0 = scene::load_scene(
      write("fb0.yaml", std::string(kBase) + "effects: [rupture]\nrupture: {critical: 2}\n"));
  EXPECT_TRUE(s0.rupture_options.pseudo_transient);
  const auto s1 = scene::load_scene(write(
      "fb1.yaml",
      std::string(kBase) + "effects: [rupture]\nrupture: {critical: 2, fallback: relaxation}\n"));
  EXPECT_FALSE(s1.rupture_options.pseudo_transient);
  const auto e = error_of("effects: [rupture]\nrupture: {critical: 2, fallback: newton}\n");
  EXPECT_TRUE(has(e, "rupture.fallback") && has(e, "pseudo_transient, relaxation")) << e;
}

// rupture.fragments and rupture.factorisations (docs/effects.md §2, "Free fragments",
// "Factor reuse"): fragments left free and a factorisation per Newton iteration by
// default; the alternatives on request; bad values name the choices.
TEST(Effects, RuptureFragmentsAndFactorisationsKeys) {
  const auto s0 = scene::load_scene(
      write("fr0.yaml", std::string(kBase) + "effects: [rupture]\nrupture: {critical: 2}\n"));
  EXPECT_FALSE(s0.rupture_options.anchor_fragments);
  EXPECT_EQ(s0.rupture_options.factor_reuse, 0);
  const auto s1 = scene::load_scene(
      write("fr1.yaml", std::string(kBase) +
                            "effects: [rupture]\nrupture: {critical: 2, fragments: anchor, "
                            "factorisations: reuse}\n"));
  EXPECT_TRUE(s1.rupture_options.anchor_fragments);
  EXPECT_EQ(s1.rupture_options.factor_reuse, s1.rupture_options.reuse_products);
  EXPECT_GT(s1.rupture_options.factor_reuse, 0);
  const auto e = error_of("effects: [rupture]\nrupture: {critical: 2, fragments: keep}\n");
  EXPECT_TRUE(has(e, "rupture.fragments") && has(e, "anchor, free")) << e;
  const auto e2 = error_of("effects: [rupture]\nrupture: {critical: 2, factorisations: 3}\n");
  EXPECT_TRUE(has(e2, "rupture.factorisations") && has(e2, "every_iteration, reuse")) << e2;
}
