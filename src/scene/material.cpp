// material: the component (model, density) and the built-in models neo-hookean and
// cauchy-born; the model is looked up in the material registry (material_model.hpp).
#include <filesystem>

#include "parse.hpp"
#include "pdcg/body/cauchy_born_material.hpp"
#include "pdcg/body/model_file.hpp"

namespace pdcg::scene {

namespace {

/// `temperature: T, free_energy: quasi-harmonic [, quasi_harmonic_step: h]` of the Cauchy–Born
/// material (docs/temperature.md §3.1): the isothermal material W_T(F) of the model file's
/// crystal cell, its vibrational part differentiated with strain step h (pdcg elastic's
/// --quasi-harmonic-step).
struct FreeEnergyKeys {
  std::string free_energy = "none";
  double temperature = 0.0;
  double step = body::kQuasiHarmonicStepDefault;
};

// `material: {model: cauchy-born, file: model.h5}` (docs/elastic.md §6): the model file is
// read here once so that a bad file, a statistical body or a dimension mismatch is an input
// error of the scene (with its line), not a failure at run time.
void load_cauchy_born(const Ctx& c, const YAML::Node& m, const std::filesystem::path& scene_file,
                      Scene& s, FreeEnergyKeys& fe) {
  for (const char* k : {"shear_modulus", "bulk_modulus"})
    if (m[k])
      throw c
          .err(m[k], std::string("material.") + k,
               "the Cauchy–Born material takes its moduli from the model file")
          .fix(fmt::format("remove material.{}", k));
  if (!m["file"])
    throw c.err(m, "material.file", "missing key")
        .expected("the pdcg model file, e.g. file: res.h5 (relative to the scene file)");
  std::filesystem::path f = c.text(m["file"], "material.file");
  if (f.is_relative()) f = std::filesystem::absolute(scene_file.parent_path() / f);
  s.material_file = f;
  std::shared_ptr<const body::Body> b;
  try {
    b = std::make_shared<const body::Body>(body::read_body(f));
    body::CauchyBornMaterial probe(b, f.string());  // refuses statistical bodies
    (void)probe;
  } catch (InputError& e) {
    throw e.line(m["file"].Mark().line + 1).key("material.file");
  }

  // The scene's numbers are in the model's units (lengths, energy/length^3): a scene without a
  // unit system takes the model's (so its CSV headers and result files name it); a different
  // one is a contradiction.
  if (s.units == UnitStyle::none) {
    s.units = b->units;
  } else if (s.units != b->units) {
    throw c.err(m["file"], "material.file", "the model's units differ from the scene's")
        .value(fmt::format("a model in units {}, the scene in units {}", to_string(b->units),
                           to_string(s.units)))
        .fix(fmt::format("set units: {} (or leave units out: the scene then takes the model's)",
                         to_string(b->units)));
  }
  if (b->dimension != s.dimension)
    throw c.err(m["file"], "material.file", "the model's dimension differs from the scene's")
        .value(fmt::format("a {}D model in a {}D scene", b->dimension, s.dimension))
        .fix(fmt::format("set dimension: {} (a 2D model is its own areal plane-strain "
                         "material; a 3D model needs a 3D scene)",
                         b->dimension));
  if (s.dimension == 2 && s.plane != "strain")
    throw c.err(m, "plane", "a 2D Cauchy–Born model is a plane-strain (areal) material")
        .value(s.plane)
        .fix("set plane: strain");
  if (m["per_point"]) {
    try {
      s.material_per_point = m["per_point"].as<bool>();
    } catch (const YAML::Exception&) {
      throw c.err(m["per_point"], "material.per_point", "not a boolean")
          .value(m["per_point"].Scalar())
          .expected("true or false");
    }
  }
  if (m["ion_relaxation"]) {
    const std::string v = c.text(m["ion_relaxation"], "material.ion_relaxation");
    if (v != "automatic" && v != "relaxed" && v != "clamped")
      throw c.err(m["ion_relaxation"], "material.ion_relaxation", "unknown value")
          .value(v)
          .expected("automatic, relaxed or clamped");
    if (v == "relaxed" && !s.material_per_point) {
      try {  // relaxed on request: the body must be a perfect crystal (refused here, with the line)
        body::CauchyBorn probe(*b, body::IonRelaxation::relaxed);
        (void)probe;
      } catch (InputError& e) {
        throw e.line(m["ion_relaxation"].Mark().line + 1).key("material.ion_relaxation");
      }
    }
    s.material_ion_relaxation = v;
  }
  if (m["free_energy"]) {
    fe.free_energy = c.choice(m["free_energy"], "material.free_energy", {"none", "quasi-harmonic"});
  }
  if (m["temperature"]) {
    fe.temperature = c.number(m["temperature"], "material.temperature");
    if (!(fe.temperature >= 0.0))
      throw c.err(m["temperature"], "material.temperature", "a temperature must be ≥ 0")
          .value(m["temperature"].Scalar())
          .expected(fmt::format("T ≥ 0 in the model's temperature unit ({})",
                                b->units == UnitStyle::lj ? "k_B T/ε in units lj" : "kelvin"));
    if (fe.free_energy != "quasi-harmonic")
      throw c
          .err(m["temperature"], "material.temperature",
               "a temperature needs a free energy: the static Cauchy–Born material has none")
          .fix("add free_energy: quasi-harmonic, or remove material.temperature");
  }
  if (fe.free_energy == "quasi-harmonic") {
    if (!m["temperature"])
      throw c.err(m["free_energy"], "material.temperature", "missing key")
          .expected(
              "the temperature of the quasi-harmonic free energy, e.g. temperature: 300 "
              "(kelvin; k_B T/ε in units lj)");
    for (const char* k : {"per_point", "ion_relaxation"})
      if (m[k])
        throw c
            .err(m[k], std::string("material.") + k,
                 "the quasi-harmonic material is the body-level free energy of the crystal cell "
                 "with every atom at F x")
            .fix(fmt::format("remove material.{}", k));
    if (m["quasi_harmonic_step"]) {
      fe.step = c.number(m["quasi_harmonic_step"], "material.quasi_harmonic_step");
      if (!(fe.step >= body::kQuasiHarmonicStepMin && fe.step <= body::kQuasiHarmonicStepMax))
        throw c
            .err(m["quasi_harmonic_step"], "material.quasi_harmonic_step",
                 "the central-difference strain step of the quasi-harmonic tangent is out of "
                 "range")
            .value(m["quasi_harmonic_step"].Scalar())
            .expected(fmt::format("{:g} ≤ h ≤ {:g} (default {:g})", body::kQuasiHarmonicStepMin,
                                  body::kQuasiHarmonicStepMax, body::kQuasiHarmonicStepDefault))
            .fix(
                "quasi_harmonic_step: 1e-4 for analytic potentials, ≈ 1e-2 for tabulated EAM "
                "(docs/temperature.md §3.1)");
    }
    try {  // refused here, with the line: not a periodic 3D delta body, too many atoms, a basis
      body::QuasiHarmonicCauchyBorn probe(*b, fe.temperature, fe.step);
      (void)probe;
    } catch (InputError& e) {
      throw e.line(m["free_energy"].Mark().line + 1).key("material.free_energy");
    }
  } else if (m["quasi_harmonic_step"]) {
    throw c
        .err(m["quasi_harmonic_step"], "material.quasi_harmonic_step",
             "a strain step of the quasi-harmonic free energy without the free energy")
        .fix(
            "add free_energy: quasi-harmonic and temperature: T, or remove "
            "material.quasi_harmonic_step");
  }
  if (s.material_per_point) {
    if (!s.model_geometry)
      throw c
          .err(m["per_point"], "material.per_point",
               "a per-point material needs the model's own points as the body")
          .fix(fmt::format("set geometry: {{shape: model, file: {}}}", f.filename().string()));
    if (std::filesystem::weakly_canonical(s.model_geometry->file) !=
        std::filesystem::weakly_canonical(f))
      throw c
          .err(m["file"], "material.file",
               "a per-point material must come from the geometry's model file (point p of the "
               "body is point p of the model)")
          .value(fmt::format("material {} vs geometry {}", f.string(),
                             s.model_geometry->file.string()));
  }
  if (s.material_per_point && s.material_ion_relaxation != "clamped" &&
      fe.free_energy != "quasi-harmonic") {
    // per point, relaxed: every atom must belong to a sublattice of the model's bulk crystal
    // (refused here, with the line; `relaxed` also refuses a model without a bulk crystal)
    try {
      body::CauchyBorn probe(*b,
                             s.material_ion_relaxation == "relaxed"
                                 ? body::IonRelaxation::relaxed
                                 : body::IonRelaxation::automatic,
                             true);
      (void)probe;
    } catch (InputError& e) {
      const auto& at = m["ion_relaxation"] ? m["ion_relaxation"] : m["per_point"];
      throw e.line(at.Mark().line + 1);
    }
  }
  if (!m["density"]) {
    double mass = 0;
    for (double v : b->mass) mass += v;
    s.density = mass / b->reference_volume();
    // On the model's own points the body's volume is Σ V_p (a free model's box has vacuum).
    if (s.model_geometry && std::filesystem::weakly_canonical(s.model_geometry->file) ==
                                std::filesystem::weakly_canonical(f)) {
      double vol = 0;
      for (double v : s.model_geometry->cloud.volume) vol += v;
      if (vol > 0) s.density = mass / vol;
    }
  }
}

class NeoHookeanModel final : public MaterialModel {
 public:
  std::vector<std::string> keys() const override {
    return {"shear_modulus", "bulk_modulus", "density"};
  }
  std::vector<NumberRule> number_rules() const override {
    return {{"material.shear_modulus", K::real, 0, true, inf, true, "a shear modulus > 0"},
            {"material.bulk_modulus", K::real, 0, true, inf, true, "a bulk modulus > 0"},
            {"material.density", K::real, 0, true, inf, true, "a mass density > 0"}};
  }
  void parse(const Reader& r, const Node& mn, Scene& s) override {
    const Ctx c{r.file()};
    const YAML::Node& m = mn.yaml();
    if (m["per_point"])
      throw c.err(m["per_point"], "material.per_point", "per_point is for the Cauchy–Born material")
          .fix("remove material.per_point, or set material.model: cauchy-born");
    if (m["file"])
      throw c.err(m["file"], "material.file", "a model file is for the Cauchy–Born material")
          .fix("remove material.file, or set material.model: cauchy-born");
    if (m["shear_modulus"])
      s.shear_modulus = c.number(m["shear_modulus"], "material.shear_modulus");
    if (m["bulk_modulus"]) s.bulk_modulus = c.number(m["bulk_modulus"], "material.bulk_modulus");
  }
  void resolve(Emitter& out, const Scene& s) const override {
    out.value("shear_modulus", s.shear_modulus).value("bulk_modulus", s.bulk_modulus);
  }
  std::unique_ptr<solver::Material> make(const Scene& s) const override {
    const auto kin = s.dimension == 3      ? solver::Kinematics::three_d
                     : s.plane == "stress" ? solver::Kinematics::plane_stress
                                           : solver::Kinematics::plane_strain;
    return solver::make_neo_hookean({s.shear_modulus, s.bulk_modulus}, kin);
  }
};

class CauchyBornModel final : public MaterialModel {
 public:
  std::vector<std::string> keys() const override {
    return {"density",     "file",        "per_point",          "ion_relaxation",
            "free_energy", "temperature", "quasi_harmonic_step"};
  }
  void parse(const Reader& r, const Node& m, Scene& s) override {
    load_cauchy_born(Ctx{r.file()}, m.yaml(), std::filesystem::path(r.file()), s, fe_);
  }
  void resolve(Emitter& out, const Scene& s) const override {
    out.value("file", s.material_file.string());
    if (fe_.free_energy == "quasi-harmonic") {
      out.value("free_energy", fe_.free_energy)
          .value("temperature", fe_.temperature)
          .value("quasi_harmonic_step", fe_.step);
      return;
    }
    if (s.material_per_point) out.value("per_point", true);
    out.value("ion_relaxation", s.material_ion_relaxation);
  }
  std::unique_ptr<solver::Material> make(const Scene& s) const override {
    if (fe_.free_energy == "quasi-harmonic")
      return body::QuasiHarmonicCauchyBornMaterial::from_file(s.material_file, fe_.temperature,
                                                              fe_.step);
    const auto ion = s.material_ion_relaxation == "relaxed"   ? body::IonRelaxation::relaxed
                     : s.material_ion_relaxation == "clamped" ? body::IonRelaxation::clamped
                                                              : body::IonRelaxation::automatic;
    if (s.material_per_point)
      return std::make_unique<body::PerPointCauchyBornMaterial>(
          std::make_shared<const body::Body>(body::read_body(s.material_file)),
          s.model_geometry->cloud.volume, s.material_file.string(), ion);
    return body::CauchyBornMaterial::from_file(s.material_file, ion);
  }

 private:
  FreeEnergyKeys fe_;
};

/// The model of a scene: the parsed one, or a fresh one of s.material_model (a Scene built in
/// code).
std::shared_ptr<const MaterialModel> model_of(const Scene& s) {
  if (s.material_impl && s.material_impl->name() == s.material_model) return s.material_impl;
  std::shared_ptr<const MaterialModel> m = make_material_model(s.material_model);
  if (!m)
    throw InputError("unknown material model")
        .source(s.source.string())
        .key("material.model")
        .value(s.material_model)
        .expected(fmt::format("one of: {}", fmt::join(registered_materials(), ", ")));
  return m;
}

class MaterialSection final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"material", 30, 30}}; }
  /// The rules of every registered model (a key's rule applies whichever model reads it).
  std::vector<NumberRule> number_rules() const override {
    std::vector<NumberRule> v;
    for (const auto& name : registered_materials())
      for (auto& rule : make_material_model(name)->number_rules())
        if (std::none_of(v.begin(), v.end(),
                         [&](const NumberRule& q) { return q.path == rule.path; }))
          v.push_back(std::move(rule));
    return v;
  }
  void parse(const std::string&, const Reader& r, const Node& root, Scene& s) override {
    const Ctx c{r.file()};
    const auto m = root.yaml()["material"];
    if (!m)
      throw InputError("missing section")
          .source(c.file)
          .key("material")
          .expected(
              "material: {model: neo-hookean, shear_modulus, bulk_modulus} or "
              "{model: cauchy-born, file: model.h5}");
    // the keys of every registered model; those the chosen model does not take are refused
    // below with the reason
    const auto models = registered_materials();
    std::vector<std::string> keys{"model"};
    for (const auto& name : models)
      for (const auto& k : make_material_model(name)->keys())
        if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
    c.keys(m, "material", keys);
    if (m["model"]) s.material_model = c.choice(m["model"], "material.model", models);
    if (m["density"]) s.density = c.number(m["density"], "material.density");
    std::shared_ptr<MaterialModel> model = make_material_model(s.material_model);
    model->parse(r, Node(m), s);
    const auto own = model->keys();
    for (const auto& kv : m) {
      const std::string k = kv.first.as<std::string>();
      if (k != "model" && std::find(own.begin(), own.end(), k) == own.end())
        throw c
            .err(kv.first, "material." + k,
                 fmt::format("material model {} takes no {}", s.material_model, k))
            .expected(fmt::format("keys model, {}", fmt::join(own, ", ")))
            .fix(fmt::format("remove material.{}, or choose a model that takes it", k));
    }
    s.material_impl = std::move(model);
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    out.begin_map("material").value("model", s.material_model);
    model_of(s)->resolve(out, s);
    out.value("density", s.density).end_map();
  }
};

}  // namespace

void register_builtin_materials(const std::function<void(std::string, MaterialFactory)>& add) {
  add("neo-hookean", [] { return std::make_unique<NeoHookeanModel>(); });
  add("cauchy-born", [] { return std::make_unique<CauchyBornModel>(); });
}

std::unique_ptr<Component> make_material_component() { return std::make_unique<MaterialSection>(); }

std::unique_ptr<solver::Material> make_material(const Scene& s) { return model_of(s)->make(s); }

}  // namespace pdcg::scene
