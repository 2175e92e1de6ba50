// The sections of the scene core: units, dimension, plane, horizon, loading, solver, output
// and the effects list (geometry, material and boundary have their own files).
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <limits>

#include "checks.hpp"
#include "parse.hpp"

namespace pdcg::scene {

namespace {

/// units, dimension, plane.
class Basics final : public Component {
 public:
  std::vector<Section> sections() const override {
    return {{"units", 0, 0}, {"dimension", 1, 1}, {"plane", 2, 2}};
  }
  std::vector<NumberRule> number_rules() const override {
    return {{"dimension", K::integer, 2, false, 3, false, "2 or 3"}};
  }
  void parse(const std::string& section, const Reader& r, const Node& rootn, Scene& s) override {
    const Ctx c{r.file()};
    const YAML::Node& root = rootn.yaml();
    if (section == "units" && root["units"]) {
      try {
        s.units = parse_unit_style(c.text(root["units"], "units"), c.file);
      } catch (InputError& e) {
        throw e.line(root["units"].Mark().line + 1);
      }
    } else if (section == "dimension" && root["dimension"]) {
      s.dimension = c.integer(root["dimension"], "dimension");
      if (s.dimension != 2 && s.dimension != 3)
        throw c.err(root["dimension"], "dimension", "unsupported dimension")
            .value(std::to_string(s.dimension))
            .expected("2 or 3");
    } else if (section == "plane" && root["plane"]) {
      if (s.dimension != 2)
        throw c.err(root["plane"], "plane", "plane is for 2D scenes only")
            .fix("remove it or set dimension: 2");
      s.plane = c.choice(root["plane"], "plane", {"strain", "stress"});
    }
  }
  void resolve(const std::string& section, Emitter& out, const Scene& s) const override {
    auto& y = out.yaml();
    if (section == "units")
      y << YAML::Key << "units" << YAML::Value << std::string(to_string(s.units));
    else if (section == "dimension")
      y << YAML::Key << "dimension" << YAML::Value << s.dimension;
    else if (section == "plane" && s.dimension == 2)
      y << YAML::Key << "plane" << YAML::Value << s.plane;
  }
};

class Horizon final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"horizon", 20, 20}}; }
  std::vector<NumberRule> number_rules() const override {
    return {{"horizon.factor", K::real, 1, false, inf, true,
             "a factor ≥ 1 (the horizon in grid spacings, usually 3.015)"},
            {"horizon.value", K::real, 0, true, inf, true,
             "a horizon > 0 (a length, at least the grid spacing)"}};
  }
  void parse(const std::string&, const Reader& r, const Node& root, Scene& s) override {
    const Ctx c{r.file()};
    const auto h = root.yaml()["horizon"];
    if (!h) return;
    c.keys(h, "horizon", {"factor", "value"});
    if (h["factor"] && h["value"])
      throw c.err(h, "horizon", "give either factor or value, not both");
    if (h["factor"]) s.horizon_factor = c.number(h["factor"], "horizon.factor");
    if (h["value"]) s.horizon_value = c.number(h["value"], "horizon.value");
    const double delta = s.horizon_value > 0 ? s.horizon_value : s.horizon_factor * s.spacing();
    if (!(delta >= s.spacing()))
      throw c.err(h, "horizon", "horizon smaller than the grid spacing")
          .value(fmt::format("{}", delta))
          .expected(fmt::format("at least the spacing {} (usually 3.015 spacings)", s.spacing()))
          .fix("use horizon: {factor: 3.015}");
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    out.begin_map("horizon");
    if (s.horizon_value > 0)
      out.value("value", s.horizon_value);
    else
      out.value("factor", s.horizon_factor);
    out.end_map();
  }
};

class Loading final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"loading", 50, 50}}; }
  std::vector<NumberRule> number_rules() const override {
    return {{"loading.steps", K::integer, 1, false, inf, true, "an integer ≥ 1 (load steps)"}};
  }
  void parse(const std::string&, const Reader& r, const Node& root, Scene& s) override {
    const Ctx c{r.file()};
    if (const auto l = root.yaml()["loading"]) {
      c.keys(l, "loading", {"steps"});
      if (l["steps"]) s.steps = c.integer(l["steps"], "loading.steps");
    }
    s.newton.steps = s.steps;
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    if (!s.inertia)  // with inertia t is the time; end_time ends the run
      out.begin_map("loading").value("steps", s.steps).end_map();
  }
};

class SolverSection final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"solver", 60, 60}}; }
  std::vector<NumberRule> number_rules() const override {
    return {
        {"solver.tolerance", K::real, 0, true, 1, true,
         "a relative residual 0 < tolerance < 1, e.g. 1e-8 (≥ 1 would accept the unloaded "
         "state)"},
        {"solver.max_iterations", K::integer, 1, false, inf, true,
         "an integer ≥ 1 (Newton iterations per step)"},
        {"solver.max_cutbacks", K::integer, 0, false, inf, true,
         "an integer ≥ 0 (step halvings; 0 = none)"},
    };
  }
  void parse(const std::string&, const Reader& r, const Node& root, Scene& s) override {
    const Ctx c{r.file()};
    const auto v = root.yaml()["solver"];
    if (!v) return;
    c.keys(v, "solver",
           {"type", "tolerance", "max_iterations", "linear", "formulation", "correspondence",
            "max_cutbacks", "check_stability", "matrix_free"});
    if (v["type"]) c.choice(v["type"], "solver.type", {"newton"});
    if (v["tolerance"]) s.newton.tolerance = c.number(v["tolerance"], "solver.tolerance");
    if (v["max_iterations"])
      s.newton.max_iterations = c.integer(v["max_iterations"], "solver.max_iterations");
    if (v["max_cutbacks"])
      s.newton.max_cutbacks = c.integer(v["max_cutbacks"], "solver.max_cutbacks");
    if (v["check_stability"])
      s.newton.check_stability = c.boolean(v["check_stability"], "solver.check_stability");
    if (v["linear"]) {
      s.linear_name =
          c.choice(v["linear"], "solver.linear",
                   {"cholmod", "umfpack", "lu", "bicgstab", "gmres", "mumps", "gamg", "hypre"});
      s.newton.linear = solver::parse_linear_solver(s.linear_name);
    }
    if (v["matrix_free"]) {
      s.newton.matrix_free = c.boolean(v["matrix_free"], "solver.matrix_free");
      // products from the per-stencil tangents: only the Krylov solver takes them
      if (s.newton.matrix_free && s.newton.linear != solver::LinearSolver::gmres)
        throw c
            .err(v["matrix_free"], "solver.matrix_free",
                 "matrix-free products need the GMRES linear solver")
            .value("true")
            .expected("solver.linear: gmres (the direct solvers factorise an assembled K)")
            .fix("add linear: gmres to solver, or remove matrix_free");
    }
    if (v["formulation"])
      s.model.boundary =
          c.choice(v["formulation"], "solver.formulation", {"weak", "energy"}) == "weak"
              ? solver::BoundaryForm::weak
              : solver::BoundaryForm::energy;
    if (v["correspondence"])
      s.model.correspondence = c.choice(v["correspondence"], "solver.correspondence",
                                        {"bond-associated", "classical"}) == "classical"
                                   ? solver::Correspondence::classical
                                   : solver::Correspondence::bond_associated;
    // The weak form's tangent is unsymmetric and the inertia of its symmetric part is no
    // stability test: on the plate with a hole in tension it has 2 (dx = 0.05) / 4 (0.025)
    // negative eigenvalues already at d = 0.01 (docs/validation.md §2), a false alarm.
    if (s.newton.check_stability && s.model.boundary == solver::BoundaryForm::weak)
      throw c
          .err(v["check_stability"], "solver.check_stability",
               "the stability check needs the energy formulation")
          .value("true")
          .expected(
              "solver.formulation: energy (symmetric tangent; the weak form's is not, "
              "and the inertia of its symmetric part reports stable states as unstable)")
          .fix("add formulation: energy to solver, or remove check_stability");
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    out.begin_map("solver")
        .value("type", "newton")
        .value("tolerance", s.newton.tolerance)
        .value("max_iterations", s.newton.max_iterations)
        .value("max_cutbacks", s.newton.max_cutbacks)
        .value("linear", s.linear_name)
        .value("formulation", s.model.boundary == solver::BoundaryForm::weak ? "weak" : "energy")
        .value("correspondence", s.model.correspondence == solver::Correspondence::classical
                                     ? "classical"
                                     : "bond-associated")
        .value("check_stability", s.newton.check_stability)
        .value("matrix_free", s.newton.matrix_free)
        .end_map();
  }
};

class Output final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"output", 70, 900}}; }
  std::vector<NumberRule> number_rules() const override {
    return {
        {"output.every", K::integer, 1, false, inf, true, "an integer ≥ 1 (steps between outputs)"},
        {"output.series_every", K::integer, 1, false, inf, true,
         "an integer ≥ 1 (time steps between series samples)"},
        {"output.checkpoint_every", K::integer, 1, false, inf, true,
         "an integer ≥ 1 (remove the key for no checkpoints)"}};
  }
  void parse(const std::string&, const Reader& r, const Node& root, Scene& s) override {
    const Ctx c{r.file()};
    if (const auto o = root.yaml()["output"]) {
      c.keys(o, "output", {"directory", "every", "series_every", "checkpoint_every"});
      if (o["directory"]) s.output_directory = c.text(o["directory"], "output.directory");
      if (o["every"]) s.output_every = c.integer(o["every"], "output.every");
      if (o["series_every"]) s.series_every = c.integer(o["series_every"], "output.series_every");
      if (o["checkpoint_every"])
        s.checkpoint_every = c.integer(o["checkpoint_every"], "output.checkpoint_every");
    }
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    out.begin_map("output")
        .value("directory", s.output_directory.string())
        .value("every", s.output_every);
    if (s.inertia) out.value("series_every", s.series_every);
    if (s.checkpoint_every > 0) out.value("checkpoint_every", s.checkpoint_every);
    out.end_map();
  }
};

/// `effects: [...]`: the names of registered effects, each at most once.
class EffectsList final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"effects", 80, 80}}; }
  void parse(const std::string&, const Reader& r, const Node& root, Scene& s) override {
    const Ctx c{r.file()};
    const auto e = root.yaml()["effects"];
    if (!e) return;
    const auto valid = valid_effects();
    if (!e.IsSequence())
      throw c.err(e, "effects", "expected a list")
          .expected(fmt::format("a list of effects, any of: {}", fmt::join(valid, ", ")))
          .fix("effects: [rupture]");
    for (const auto& n : e) {
      const std::string name = c.choice(n, "effects[]", valid);
      if (has_effect(s, name)) throw c.err(n, "effects[]", "effect listed twice").value(name);
      s.effects.push_back(name);
    }
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    auto& y = out.yaml();
    y << YAML::Key << "effects" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (const auto& e : s.effects) y << e;
    y << YAML::EndSeq;
  }
};

}  // namespace

std::unique_ptr<Component> make_geometry_component();
std::unique_ptr<Component> make_material_component();
std::unique_ptr<Component> make_boundary_component();

std::vector<std::unique_ptr<Component>> core_components() {
  std::vector<std::unique_ptr<Component>> v;
  v.push_back(std::make_unique<Basics>());
  v.push_back(make_geometry_component());
  v.push_back(std::make_unique<Horizon>());
  v.push_back(make_material_component());
  v.push_back(make_boundary_component());
  v.push_back(std::make_unique<Loading>());
  v.push_back(std::make_unique<SolverSection>());
  v.push_back(std::make_unique<Output>());
  v.push_back(std::make_unique<EffectsList>());
  return v;
}

}  // namespace pdcg::scene
