// Every number a scene reads is checked (type, sign, range, finite) with an InputError naming
// file, line and key; contradictions between keys are refused with the reason; a refused scene
// leaves no output behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/scene/scene.hpp"
#include "pdcg_test.hpp"

namespace fs = std::filesystem;
using namespace pdcg;

namespace {

// Quasi-static base: every static numeric key on a line of its own.
const char* kStatic = R"(units: none
dimension: 2
plane: strain
geometry:
  shape: rectangle
  origin: [0.0, 0.0]
  size: [1.0, 0.5]
  spacing: 0.1
  holes: [{center: [0.5, 0.25], radius: 0.1}]
  cracks: [{from: [0.0, 0.25], to: [0.2, 0.25]}]
horizon: {factor: 3.015}
material:
  shear_modulus: 1.0
  bulk_modulus: 10.0
  density: 1.0
boundary:
  - {name: left, region: {x_max: 0.0}, displacement: {x: 0.0}}
  - {name: pin, region: {point: [0.05, 0.05]}, displacement: {y: 0.0}}
  - {name: right, region: {x_min: 1.0, y_min: 0.0, y_max: 0.5}, displacement: {x: "0.01*t"}}
  - {name: top, region: {y_min: 0.5}, traction: [0.0, 0.0]}
loading: {steps: 2}
solver:
  tolerance: 1.0e-8
  max_iterations: 30
  max_cutbacks: 4
output: {directory: out, every: 1, checkpoint_every: 1}
effects: [rupture]
rupture: {criterion: bond_stretch, critical: 2.5, max_passes: 5}
)";

// Dynamic base: the keys of explicit dynamics.
const char* kDynamic = R"(dimension: 2
geometry: {size: [1.0, 0.5], spacing: 0.1}
material: {shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left, region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, traction: [0.01, 0.0]}
effects: [inertia, damping, rupture]
inertia: {time_step: auto, safety: 0.8, end_time: 1.0}
damping: {type: viscous, coefficient: 0.1}
rupture: {criterion: bond_stretch, critical: 2.5, check_every: 2}
initial: {velocity: {x: "0.01*x", y: 0.0}}
output: {every: 10, series_every: 2}
)";

// 3D base: the z keys.
const char* k3D = R"(dimension: 3
geometry: {shape: box, size: [1.0, 0.5, 0.5], spacing: 0.25}
material: {shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left, region: {x_max: 0.0, z_min: 0.0, z_max: 0.5}, displacement: {x: 0.0, y: 0.0, z: 0.0}}
effects: [inertia]
inertia: {end_time: 1.0}
initial: {velocity: {x: 0.0, z: "0.01*z"}}
)";

// Fracture-energy bases: the energy-based rupture rule given G_c, or the surface energy.
const char* kFractureEnergy = R"(dimension: 2
geometry: {size: [1.0, 0.5], spacing: 0.1}
material: {shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left, region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "0.01*t"}}
effects: [rupture]
rupture: {criterion: fracture_energy, G_c: 1.5}
)";
// the softening (cohesive) law of the fracture-energy criterion (docs/fracture.md §6)
const char* kSoftening = R"(dimension: 2
geometry: {size: [1.0, 0.5], spacing: 0.1}
material: {shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left, region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "0.01*t"}}
effects: [rupture]
rupture: {criterion: fracture_energy, G_c: 1.5, softening: linear, elastic_limit: 0.1,
          damage_tolerance: 0.001, max_damage_increment: 0.5}
)";
const char* kSurfaceEnergy = R"(dimension: 2
geometry: {size: [1.0, 0.5], spacing: 0.1}
material: {shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left, region: {x_max: 0.0}, displacement: {x: 0.0, y: 0.0}}
  - {name: right, region: {x_min: 1.0}, displacement: {x: "0.01*t"}}
effects: [rupture]
rupture: {criterion: fracture_energy, surface_energy: 0.75}
)";

fs::path dir() {
  return pdcg::test::scratch_dir("pdcg_scene_checks");
}

fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = dir() / name;
  std::ofstream(p) << text;
  return p;
}

/// 1-based line of the first occurrence of `what` in `text`.
long line_of(const std::string& text, const std::string& what) {
  const auto i = text.find(what);
  if (i == std::string::npos) return -1;
  return 1 + static_cast<long>(std::count(text.begin(), text.begin() + i, '\n'));
}

struct Case {
  const char* base;
  const char* find;         ///< unique text of the base scene that holds the key
  const char* replacement;  ///< with {} where each bad value goes
  const char* key;          ///< the key the error must name
  std::vector<std::string> bad;
};

// Classes of bad values: sign/range, NaN, infinity, a string, a list, a fraction for an integer.
const std::vector<std::string> kReal = {".nan", ".inf", "-.inf", "abc", "[1, 2]"};
const std::vector<std::string> kCoord = {".nan", ".inf", "abc", "[1]"};
const std::vector<std::string> kInt = {"2.5", "abc", ".inf", "[1]"};
const std::vector<std::string> kFn = {".nan", ".inf", "\"0.5*\"", "[1]"};

std::vector<std::string> with(std::vector<std::string> v, std::vector<std::string> more) {
  v.insert(v.end(), more.begin(), more.end());
  return v;
}

// Every numeric key of the scene format (docs/solver.md §6, docs/effects.md).
const std::vector<Case>& cases() {
  static const std::vector<Case> c = {
      {kStatic, "dimension: 2", "dimension: {}", "dimension", with(kInt, {"4", "1", "0"})},
      {kStatic, "origin: [0.0, 0.0]", "origin: [{}, 0.0]", "geometry.origin[0]", kCoord},
      {kStatic, "size: [1.0, 0.5]", "size: [1.0, {}]", "geometry.size[1]",
       with(kReal, {"0", "-0.5"})},
      {kStatic, "spacing: 0.1", "spacing: {}", "geometry.spacing", with(kReal, {"0", "-0.1"})},
      {kStatic, "center: [0.5, 0.25]", "center: [{}, 0.25]", "geometry.holes[0].center[0]", kCoord},
      {kStatic, "radius: 0.1", "radius: {}", "geometry.holes[0].radius",
       with(kReal, {"0", "-0.1"})},
      {kStatic, "from: [0.0, 0.25]", "from: [0.0, {}]", "geometry.cracks[0].from[1]", kCoord},
      {kStatic, "to: [0.2, 0.25]", "to: [{}, 0.25]", "geometry.cracks[0].to[0]", kCoord},
      {kStatic, "{factor: 3.015}", "{factor: {}}", "horizon.factor",
       with(kReal, {"0.5", "0", "-3"})},
      {kStatic, "{factor: 3.015}", "{value: {}}", "horizon.value", with(kReal, {"-0.3", "0"})},
      {kStatic, "shear_modulus: 1.0", "shear_modulus: {}", "material.shear_modulus",
       with(kReal, {"0", "-1"})},
      {kStatic, "bulk_modulus: 10.0", "bulk_modulus: {}", "material.bulk_modulus",
       with(kReal, {"0", "-10"})},
      {kStatic, "density: 1.0", "density: {}", "material.density", with(kReal, {"0", "-1"})},
      {kStatic, "{x_max: 0.0}", "{x_max: {}}", "boundary[left].region.x_max", kCoord},
      {kStatic, "{x_min: 1.0,", "{x_min: {},", "boundary[right].region.x_min", kCoord},
      {kStatic, "y_min: 0.0,", "y_min: {},", "boundary[right].region.y_min", kCoord},
      {kStatic, "y_max: 0.5}", "y_max: {}}", "boundary[right].region.y_max", kCoord},
      {kStatic, "point: [0.05, 0.05]", "point: [0.05, {}]", "boundary[pin].region.point[1]",
       kCoord},
      {kStatic, "displacement: {x: \"0.01*t\"}", "displacement: {x: {}}",
       "boundary[right].displacement.x", kFn},
      {kStatic, "displacement: {y: 0.0}", "displacement: {y: {}}", "boundary[pin].displacement.y",
       kFn},
      {kStatic, "traction: [0.0, 0.0]", "traction: [0.0, {}]", "boundary[top].traction[1]", kFn},
      {kStatic, "steps: 2", "steps: {}", "loading.steps", with(kInt, {"0", "-1"})},
      {kStatic, "tolerance: 1.0e-8", "tolerance: {}", "solver.tolerance",
       with(kReal, {"0", "-1e-8", "1", "2"})},
      {kStatic, "max_iterations: 30", "max_iterations: {}", "solver.max_iterations",
       with(kInt, {"0", "-3"})},
      {kStatic, "max_cutbacks: 4", "max_cutbacks: {}", "solver.max_cutbacks", with(kInt, {"-1"})},
      {kStatic, "every: 1,", "every: {},", "output.every", with(kInt, {"0", "-1"})},
      {kStatic, "checkpoint_every: 1", "checkpoint_every: {}", "output.checkpoint_every",
       with(kInt, {"0", "-1"})},
      {kStatic, "critical: 2.5", "critical: {}", "rupture.critical", with(kReal, {"0", "-2"})},
      {kStatic, "max_passes: 5", "max_passes: {}", "rupture.max_passes", with(kInt, {"0"})},
      {kFractureEnergy, "G_c: 1.5", "G_c: {}", "rupture.G_c", with(kReal, {"0", "-2"})},
      {kSoftening, "elastic_limit: 0.1", "elastic_limit: {}", "rupture.elastic_limit",
       with(kReal, {"0", "-0.1", "1.5"})},
      {kSoftening, "damage_tolerance: 0.001", "damage_tolerance: {}", "rupture.damage_tolerance",
       with(kReal, {"0", "1", "2"})},
      {kSoftening, "max_damage_increment: 0.5", "max_damage_increment: {}",
       "rupture.max_damage_increment", with(kReal, {"0", "-0.5", "1.5"})},
      {kSurfaceEnergy, "surface_energy: 0.75", "surface_energy: {}", "rupture.surface_energy",
       with(kReal, {"0", "-2"})},
      {kDynamic, "time_step: auto, safety: 0.8", "time_step: {}", "inertia.time_step",
       with(kReal, {"0", "-0.01"})},
      {kDynamic, "safety: 0.8", "safety: {}", "inertia.safety", with(kReal, {"0", "1.5", "-1"})},
      {kDynamic, "end_time: 1.0", "end_time: {}", "inertia.end_time", with(kReal, {"0", "-1"})},
      {kDynamic, "coefficient: 0.1", "coefficient: {}", "damping.coefficient",
       with(kReal, {"0", "-0.1"})},
      {kDynamic, "check_every: 2", "check_every: {}", "rupture.check_every",
       with(kInt, {"0", "-2"})},
      {kDynamic, "{x: \"0.01*x\"", "{x: {}", "initial.velocity.x", kFn},
      {kDynamic, "\", y: 0.0}}", "\", y: {}}}", "initial.velocity.y", kFn},
      {kDynamic, "series_every: 2", "series_every: {}", "output.series_every",
       with(kInt, {"0", "-1"})},
      {k3D, "z_min: 0.0", "z_min: {}", "boundary[left].region.z_min", kCoord},
      {k3D, "z_max: 0.5", "z_max: {}", "boundary[left].region.z_max", kCoord},
      {k3D, "z: 0.0}", "z: {}}", "boundary[left].displacement.z", kFn},
      {k3D, "z: \"0.01*z\"", "z: {}", "initial.velocity.z", kFn},
  };
  return c;
}

std::string substitute(const Case& c, const std::string& bad) {
  std::string text = c.base;
  std::string r = c.replacement;
  r.replace(r.find("{}"), 2, bad);
  text.replace(text.find(c.find), std::string(c.find).size(), r);
  return text;
}

}  // namespace

TEST(SceneChecks, BaseScenesAreValid) {
  for (const char* base : {kStatic, kDynamic, k3D, kFractureEnergy, kSurfaceEnergy, kSoftening})
    EXPECT_NO_THROW(scene::load_scene(write("base.yaml", base))) << base;
}

TEST(SceneChecks, EveryNumericKeyRefusesBadValuesWithFileLineAndKey) {
  EXPECT_EQ(cases().size(),
            46u);  // one row per numeric rule of the built-in components (scene::number_rules)
  for (const auto& c : cases()) {
    ASSERT_EQ(std::string(c.base).find(c.find), std::string(c.base).rfind(c.find))
        << "not unique: " << c.find;
    ASSERT_NE(line_of(c.base, c.find), -1) << c.find;
    for (const auto& bad : c.bad) {
      const std::string text = substitute(c, bad);
      const fs::path file = write("bad.yaml", text);
      const std::string what = std::string(c.key) + " = " + bad;
      try {
        scene::load_scene(file);
        ADD_FAILURE() << what << ": accepted";
        continue;
      } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_EQ(e.source_name(), file.string()) << what << ": " << m;
        EXPECT_EQ(e.line_number(), line_of(c.base, c.find)) << what << ": " << m;
        EXPECT_EQ(e.key_name(), c.key) << what << ": " << m;
        EXPECT_NE(m.find(file.string() + ":" + std::to_string(e.line_number()) + ": "),
                  std::string::npos)
            << what << ": " << m;
      } catch (const std::exception& e) {
        ADD_FAILURE() << what << ": not an InputError: " << e.what();
      }
    }
  }
}

namespace {

/// Runs a scene into a fresh directory; returns the InputError, and whether the output
/// directory exists afterwards.
struct Refusal {
  std::string message;
  long line = 0;
  std::string key;
  bool output_exists = true;
};

Refusal refuse(const std::string& name, const std::string& text) {
  Refusal r;
  const fs::path out = dir() / (name + "_out");
  fs::remove_all(out);
  try {
    const auto s = scene::load_scene(write(name + ".yaml", text));
    scene::run_scene(s, out);
    r.message = "(accepted)";
  } catch (const InputError& e) {
    r.message = e.what();
    r.line = e.line_number();
    r.key = e.key_name();
  }
  r.output_exists = fs::exists(out);
  return r;
}

std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto i = s.find(a);
  EXPECT_NE(i, std::string::npos) << a;
  return s.replace(i, a.size(), b);
}

// The static base without holes, cracks and rupture (contradiction tests run it).
std::string plain() {
  std::string t = replace(kStatic, "  holes: [{center: [0.5, 0.25], radius: 0.1}]\n", "");
  t = replace(t, "  cracks: [{from: [0.0, 0.25], to: [0.2, 0.25]}]\n", "");
  t = replace(t, "effects: [rupture]\n", "");
  return replace(t, "rupture: {criterion: bond_stretch, critical: 2.5, max_passes: 5}\n", "");
}

}  // namespace

TEST(SceneChecks, ContradictionsAreRefusedBeforeAnyOutput) {
  struct C {
    const char* name;
    std::string text;
    const char* key;
    const char* line_text;  ///< the line the error must name
    const char* reason;
  };
  const std::string p = plain();
  const std::vector<C> cs = {
      {"empty_region", replace(p, "y_min: 0.0, y_max: 0.5", "y_min: 0.4, y_max: 0.1"),
       "boundary[right].region.y_min", "name: right", "the region is empty"},
      {"point_and_bounds", replace(p, "{point: [0.05, 0.05]}", "{point: [0.05, 0.05], x_min: 0.5}"),
       "boundary[pin].region.point", "name: pin", "takes no bounds"},
      {"no_point", replace(p, "{x_min: 1.0,", "{x_min: 1.5,"), "boundary[right].region",
       "name: right", "selects no point"},
      {"point_off_body", replace(p, "[0.05, 0.05]", "[5.0, 5.0]"), "boundary[pin].region.point",
       "name: pin", "not on the body"},
      {"spacing_above_size", replace(p, "spacing: 0.1", "spacing: 0.8"), "geometry.spacing",
       "spacing: 0.8", "exceeds the body size"},
      {"not_finite_at_t", replace(p, "\"0.01*t\"", "\"0.01/(t - 0.5)\""),
       "boundary[right].displacement.x", "name: right", "not finite at load factor t = 0.5"},
      {"same_dof_two_values",
       replace(
           p, "  - {name: top,",
           "  - {name: right2, region: {x_min: 0.9}, displacement: {x: 0.02}}\n  - {name: top,"),
       "boundary[right2].displacement.x", "name: right2", "fix the same dof to different values"},
      {"unstable_step", replace(kDynamic, "time_step: auto, safety: 0.8", "time_step: 10.0"),
       "inertia.time_step", "time_step: 10.0", "above the stable limit"},
      {"velocity_not_finite", replace(kDynamic, "\"0.01*x\"", "\"log(x - 0.5)\""),
       "initial.velocity.x", "log(x - 0.5)", "not finite at a point"},
  };
  for (const auto& c : cs) {
    const Refusal r = refuse(c.name, c.text);
    EXPECT_NE(r.message.find(c.reason), std::string::npos) << c.name << ": " << r.message;
    EXPECT_EQ(r.key, c.key) << c.name << ": " << r.message;
    EXPECT_EQ(r.line, line_of(c.text, c.line_text)) << c.name << ": " << r.message;
    EXPECT_FALSE(r.output_exists) << c.name << ": the refused run left its output directory";
  }
  // The same dof fixed twice to the same value is one prescription: accepted.
  const std::string same =
      replace(p, "  - {name: top,",
              "  - {name: left2, region: {x_max: 0.05}, displacement: {x: 0.0}}\n  - {name: top,");
  const Refusal r = refuse("same", same);
  EXPECT_EQ(r.message, "(accepted)");
  EXPECT_TRUE(r.output_exists);
}

TEST(SceneChecks, ReactionsOnlyForPrescribedComponentsAndUnitsLine) {
  // pin fixes y only, left and right x only: no pin_fx, left_fy, right_fy columns (the force
  // on a free dof is no reaction); the first line names the units and starts with '#'.
  const fs::path out = dir() / "reactions_out";
  fs::remove_all(out);
  scene::run_scene(scene::load_scene(write("reactions.yaml", plain())), out);
  std::ifstream csv(out / "reactions.csv");
  std::string units, header, row;
  std::getline(csv, units);
  std::getline(csv, header);
  EXPECT_EQ(units.rfind("# units: none (model units", 0), 0u) << units;
  EXPECT_EQ(header, "step,t,left_fx,pin_fy,right_fx");
  std::getline(csv, row);
  EXPECT_EQ(row, "0,0,0,0,0");
}
