// The built-in effects (docs/effects.md): inertia (with its initial velocities), damping and
// rupture: their sections, numeric keys, checks and resolved output. Their run part is the
// runners' code (run_static.cpp, run_dynamic.cpp).
#include <limits>

#include "parse.hpp"
#include "pdcg/scene/expression.hpp"

namespace pdcg::scene {

namespace {

/// `inertia:` (explicit dynamics) and `initial:` (its initial velocities).
class Inertia final : public Effect {
 public:
  std::vector<Section> sections() const override {
    return {{"inertia", 110, 91}, {"initial", 130, 93}};
  }
  std::vector<NumberRule> number_rules() const override {
    std::vector<NumberRule> v{
        {"inertia.time_step", K::real_or_auto, 0, true, inf, true, "auto or a time step > 0"},
        {"inertia.safety", K::real, 0, true, 1, false,
         "0 < safety ≤ 1, e.g. 0.8 (1 is the stable limit itself)"},
        {"inertia.end_time", K::real, 0, true, inf, true, "an end time > 0"}};
    for (const char* a : {"x", "y", "z"})
      v.push_back({std::string("initial.velocity.") + a, K::real_or_fn, -inf, true, inf, true,
                   "a finite number or an expression in x, y, z"});
    return v;
  }
  void check_listing(const Reader& r, const Node& rootn, const Scene& s) const override {
    const Ctx c{r.file()};
    const YAML::Node& root = rootn.yaml();
    if (root["initial"] && !has_effect(s, "inertia"))
      throw c
          .err(root["initial"], "initial",
               "initial velocities without inertia: a quasi-static run has no velocities")
          .fix("add inertia to effects, or remove the initial section");
  }
  void parse(const std::string& section, const Reader& r, const Node& rootn, Scene& s) override {
    const Ctx c{r.file()};
    const YAML::Node& root = rootn.yaml();
    const int d = s.dimension;
    const char* axes[3] = {"x", "y", "z"};
    (void)d;
    (void)axes;
    auto has = [&](const std::string& name) { return has_effect(s, name); };
    if (section == "inertia") {
      if (has("inertia")) {
        s.inertia = true;
        const auto in = root["inertia"];
        if (!in)
          throw c.err(root["effects"], "inertia", "inertia is listed but has no settings")
              .expected(
                  "inertia: {integrator: velocity-verlet, time_step: auto, safety: 0.8, "
                  "end_time: 10.0}");
        c.keys(in, "inertia", {"integrator", "time_step", "safety", "end_time", "allow_unstable"});
        if (in["integrator"])
          s.integrator = c.choice(in["integrator"], "inertia.integrator", {"velocity-verlet"});
        if (in["time_step"] &&
            !(in["time_step"].IsScalar() && in["time_step"].Scalar() == "auto")) {
          s.time_step = c.number(in["time_step"], "inertia.time_step");
          if (in["safety"])
            throw c
                .err(in["safety"], "inertia.safety",
                     "safety applies to time_step: auto only (the step is safety × the stable "
                     "limit); with a given time_step it would be ignored")
                .fix("remove safety, or set time_step: auto");
        }
        if (in["safety"]) s.safety = c.number(in["safety"], "inertia.safety");
        if (!in["end_time"])
          throw c.err(in, "inertia.end_time", "missing key")
              .expected("the simulated time at which the run ends, e.g. end_time: 10.0");
        s.end_time = c.number(in["end_time"], "inertia.end_time");
        if (in["allow_unstable"]) {
          try {
            s.allow_unstable = in["allow_unstable"].as<bool>();
          } catch (const YAML::Exception&) {
            throw c.err(in["allow_unstable"], "inertia.allow_unstable", "not a boolean")
                .value(in["allow_unstable"].IsScalar() ? in["allow_unstable"].Scalar() : "")
                .expected("true or false");
          }
          if (s.allow_unstable && !(s.time_step > 0))
            throw c
                .err(in["allow_unstable"], "inertia.allow_unstable",
                     "allow_unstable needs a given time_step (time_step: auto is always stable)")
                .fix("give time_step: <value>, or remove allow_unstable");
        }
        if (root["loading"])
          throw c
              .err(root["loading"], "loading",
                   "loading.steps is for quasi-static runs: with inertia, t in the boundary values "
                   "is "
                   "the time, and inertia.end_time ends the run")
              .fix("remove the loading section");
      }
      if (!s.inertia && root["output"] && root["output"]["series_every"])
        throw c
            .err(root["output"]["series_every"], "output.series_every",
                 "series_every samples the energy time series of dynamic runs; a quasi-static run "
                 "writes reactions.csv at every load step")
            .fix("remove series_every, or add inertia to effects");
    } else {
      if (const auto iv = root["initial"]) {
        c.keys(iv, "initial", {"velocity"});
        if (const auto vel = iv["velocity"]) {
          std::vector<std::string> valid(axes, axes + d);
          c.keys(vel, "initial.velocity", valid);
          for (int a = 0; a < d; ++a) {
            if (!vel[axes[a]]) continue;
            const auto n = vel[axes[a]];
            const std::string key = std::string("initial.velocity.") + axes[a];
            if (!n.IsScalar()) throw c.err(n, key, "expected a number or an expression in x, y, z");
            s.initial_velocity_text[a] = n.Scalar();
            try {
              s.initial_velocity[a] = parse_expression(n.Scalar(), key, {"x", "y", "z"});
            } catch (InputError& e) {
              throw e.source(c.file).line(n.Mark().line + 1);
            }
          }
        }
      }
    }
  }
  void resolve(const std::string& section, Emitter& out, const Scene& s) const override {
    auto& y = out.yaml();
    const int d = s.dimension;
    if (section == "inertia") {
      if (s.inertia) {
        y << YAML::Key << "inertia" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
          << "integrator" << YAML::Value << s.integrator << YAML::Key << "time_step" << YAML::Value;
        if (s.time_step > 0)
          y << s.time_step;
        else
          y << "auto" << YAML::Key << "safety" << YAML::Value << s.safety;
        y << YAML::Key << "end_time" << YAML::Value << s.end_time;
        if (s.allow_unstable) y << YAML::Key << "allow_unstable" << YAML::Value << true;
        y << YAML::EndMap;
      }
    } else {
      if (s.inertia) {
        const char* ax[3] = {"x", "y", "z"};
        y << YAML::Key << "initial" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
          << "velocity" << YAML::Value << YAML::BeginMap;
        for (int a = 0; a < d; ++a)
          if (s.initial_velocity[a])
            y << YAML::Key << ax[a] << YAML::Value << YAML::DoubleQuoted
              << s.initial_velocity_text[a];
        y << YAML::EndMap << YAML::EndMap;
      }
    }
  }
};

class Damping final : public Effect {
 public:
  std::vector<Section> sections() const override { return {{"damping", 120, 92}}; }
  std::vector<NumberRule> number_rules() const override {
    return {{"damping.coefficient", K::real, 0, true, inf, true,
             "a viscous coefficient > 0 (remove damping for undamped motion)"}};
  }
  void check_listing(const Reader& r, const Node& rootn, const Scene& s) const override {
    const Ctx c{r.file()};
    if (has_effect(s, "damping") && !has_effect(s, "inertia"))
      throw c
          .err(rootn.yaml()["effects"], "effects",
               "damping without inertia: damping acts on velocities, which a quasi-static run "
               "does not have")
          .fix("add inertia to effects (damped dynamics), or remove damping");
  }
  void parse(const std::string&, const Reader& r, const Node& rootn, Scene& s) override {
    const Ctx c{r.file()};
    const YAML::Node& root = rootn.yaml();
    auto has = [&](const std::string& name) { return has_effect(s, name); };
    if (has("damping")) {
      const auto dn = root["damping"];
      if (!dn)
        throw c.err(root["effects"], "damping", "damping is listed but has no settings")
            .expected(
                "damping: {type: viscous, coefficient: 0.1} or "
                "{type: adaptive-dynamic-relaxation}");
      c.keys(dn, "damping", {"type", "coefficient"});
      if (!dn["type"])
        throw c.err(dn, "damping.type", "missing key")
            .expected("type: viscous or type: adaptive-dynamic-relaxation");
      s.damping_type =
          c.choice(dn["type"], "damping.type", {"viscous", "adaptive-dynamic-relaxation"});
      if (s.damping_type == "viscous") {
        if (!dn["coefficient"])
          throw c.err(dn, "damping.coefficient", "missing key")
              .expected("the viscous coefficient c (1/time) of the force −c M v, e.g. 0.1");
        s.damping_coefficient = c.number(dn["coefficient"], "damping.coefficient");
      } else if (dn["coefficient"]) {
        throw c
            .err(dn["coefficient"], "damping.coefficient",
                 "adaptive dynamic relaxation computes its coefficient each step (Underwood): a "
                 "given coefficient contradicts it")
            .fix("remove coefficient, or use type: viscous");
      }
    }
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    auto& y = out.yaml();
    if (!s.damping_type.empty()) {
      y << YAML::Key << "damping" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "type" << YAML::Value << s.damping_type;
      if (s.damping_type == "viscous")
        y << YAML::Key << "coefficient" << YAML::Value << s.damping_coefficient;
      y << YAML::EndMap;
    }
  }
};

class RuptureEffect final : public Effect {
 public:
  std::vector<Section> sections() const override { return {{"rupture", 140, 90}}; }
  std::vector<NumberRule> number_rules() const override {
    return {
        {"rupture.critical", K::real, 0, true, inf, true,
         "a critical value > 0 (a stretch > 1, or an energy density > 0)"},
        {"rupture.G_c", K::real, 0, true, inf, true,
         "a critical energy release rate G_c > 0 (energy per unit crack area)"},
        {"rupture.surface_energy", K::real, 0, true, inf, true,
         "a surface energy γ > 0 (energy per unit area; G_c = 2γ)"},
        {"rupture.elastic_limit", K::real, 0, true, 1, false,
         "e₀/e_f in (0, 1]: the equivalent strain at which softening starts over the one at "
         "full separation"},
        {"rupture.damage_tolerance", K::real, 0, true, 1, true,
         "a damage increment in (0, 1), e.g. 1e-3"},
        {"rupture.max_damage_increment", K::real, 0, true, 1, false,
         "a damage increment per pass in (0, 1]"},
        {"rupture.max_passes", K::integer, 1, false, inf, true, "an integer ≥ 1"},
        {"rupture.check_every", K::integer, 1, false, inf, true, "an integer ≥ 1 (time steps)"}};
  }
  void parse(const std::string&, const Reader& r, const Node& rootn, Scene& s) override {
    const Ctx c{r.file()};
    const YAML::Node& root = rootn.yaml();
    auto has = [&](const std::string& name) { return has_effect(s, name); };
    if (has("rupture")) {
      s.rupture = true;
      const auto r = root["rupture"];
      if (!r)
        throw c.err(root["effects"], "rupture", "rupture is listed but has no settings")
            .expected("rupture: {criterion: bond_stretch, critical: 2.5}");
      c.keys(r, "rupture",
             {"criterion", "critical", "max_passes", "check_every", "G_c", "surface_energy",
              "softening", "elastic_limit", "damage_tolerance", "max_damage_increment", "fallback",
              "fragments", "factorisations"});
      if (r["criterion"])
        s.rupture_options.criterion = solver::parse_rupture_criterion(
            c.choice(r["criterion"], "rupture.criterion",
                     {"bond_stretch", "principal_stretch", "energy_density", "fracture_energy"}));
      const bool griffith =
          s.rupture_options.criterion == solver::RuptureCriterion::fracture_energy;
      if (griffith) {
        // calibrated from the energy release rate: G_c, or G_c = 2γ (docs/fracture.md §5)
        if (r["critical"])
          throw c
              .err(r["critical"], "rupture.critical",
                   "fracture_energy is calibrated from the energy release rate, not a critical "
                   "value")
              .fix(
                  "replace critical by G_c: <energy per unit crack area> (or surface_energy: "
                  "γ, G_c = 2γ)");
        if (r["G_c"] && r["surface_energy"])
          throw c
              .err(r["surface_energy"], "rupture.surface_energy",
                   "both G_c and surface_energy given (G_c = 2γ: one determines the other)")
              .fix("keep one of them");
        if (!r["G_c"] && !r["surface_energy"])
          throw c.err(r, "rupture.G_c", "missing key")
              .expected(
                  "G_c: <critical energy release rate> or surface_energy: <γ>, e.g. "
                  "rupture: {criterion: fracture_energy, G_c: 0.01}");
        s.rupture_options.fracture_energy =
            r["G_c"] ? c.number(r["G_c"], "rupture.G_c")
                     : 2.0 * c.number(r["surface_energy"], "rupture.surface_energy");
        s.rupture_options.critical = 1.0;
        // the softening (cohesive) failure law (docs/fracture.md §6)
        if (r["softening"])
          s.rupture_options.softening = solver::parse_rupture_softening(
              c.choice(r["softening"], "rupture.softening", {"none", "linear"}));
        const bool soft = s.rupture_options.softening != solver::RuptureSoftening::none;
        for (const char* k : {"elastic_limit", "damage_tolerance", "max_damage_increment"})
          if (r[k] && !soft)
            throw c
                .err(r[k], std::string("rupture.") + k,
                     std::string(k) + " is a parameter of the softening failure law")
                .fix("add softening: linear, or remove " + std::string(k));
        if (r["elastic_limit"])
          s.rupture_options.elastic_limit = c.number(r["elastic_limit"], "rupture.elastic_limit");
        if (r["damage_tolerance"])
          s.rupture_options.damage_tolerance =
              c.number(r["damage_tolerance"], "rupture.damage_tolerance");
        if (r["max_damage_increment"])
          s.rupture_options.max_damage_increment =
              c.number(r["max_damage_increment"], "rupture.max_damage_increment");
      } else {
        for (const char* k : {"G_c", "surface_energy", "softening", "elastic_limit",
                              "damage_tolerance", "max_damage_increment"})
          if (r[k])
            throw c
                .err(r[k], std::string("rupture.") + k,
                     std::string(k) +
                         " belongs to the fracture_energy criterion only (G_c, γ calibrate it; "
                         "softening is its failure law)")
                .fix("set criterion: fracture_energy, or remove " + std::string(k));
        if (!r["critical"])
          throw c.err(r, "rupture.critical", "missing key")
              .expected("the critical value of the criterion, e.g. critical: 2.5");
        s.rupture_options.critical = c.number(r["critical"], "rupture.critical");
      }
      if (r["max_passes"] && s.inertia)
        throw c
            .err(r["max_passes"], "rupture.max_passes",
                 "max_passes bounds the staggered re-equilibration passes of quasi-static runs; "
                 "with inertia bonds break during the motion (checked every check_every steps)")
            .fix("remove max_passes (use check_every to check less often)");
      if (r["check_every"] && !s.inertia)
        throw c
            .err(r["check_every"], "rupture.check_every",
                 "check_every is the number of time steps between rupture checks of a dynamic "
                 "run; a quasi-static run checks after every load step until no bond breaks")
            .fix("remove check_every, or add inertia to effects (dynamic fracture)");
      if (r["check_every"])
        s.rupture_options.check_every = c.integer(r["check_every"], "rupture.check_every");
      if (s.inertia) {
        s.rupture_options.anchor_detached = false;  // fragments move on
        // Dynamic fracture switches nearly singular rebuilt stencils off earlier: their
        // large G lower the stable step (measured on a 20×20 edge-cracked sheet: the step
        // shrank 12× with 1e-3, 4× with 1e-2; docs/effects.md §3c).
        s.rupture_options.min_reciprocal_condition = 1e-2;
      }
      if (r["max_passes"])
        s.rupture_options.max_passes = c.integer(r["max_passes"], "rupture.max_passes");
      if (r["fallback"] && s.inertia)
        throw c
            .err(r["fallback"], "rupture.fallback",
                 "fallback chooses how a quasi-static staggered pass re-equilibrates when Newton "
                 "fails; a dynamic run has no re-equilibration")
            .fix("remove fallback");
      // docs/effects.md §2: pseudo-transient continuation, then ADR (default); ADR only
      if (r["fallback"])
        s.rupture_options.pseudo_transient =
            c.choice(r["fallback"], "rupture.fallback", {"pseudo_transient", "relaxation"}) ==
            "pseudo_transient";
      if (r["fragments"] && s.inertia)
        throw c
            .err(r["fragments"], "rupture.fragments",
                 "fragments chooses whether a quasi-static run parks free fragments; in a "
                 "dynamic run a fragment flies on with its velocity")
            .fix("remove fragments");
      // docs/effects.md §2, "Free fragments": park them, or leave them free (default)
      if (r["fragments"])
        s.rupture_options.anchor_fragments =
            c.choice(r["fragments"], "rupture.fragments", {"anchor", "free"}) == "anchor";
      if (r["factorisations"] && s.inertia)
        throw c
            .err(r["factorisations"], "rupture.factorisations",
                 "factorisations applies to the Newton solves of quasi-static staggered passes")
            .fix("remove factorisations");
      // docs/effects.md §2, "Factor reuse": a factorisation per Newton iteration (default) or
      // the last one reused as the GMRES preconditioner
      if (r["factorisations"] && c.choice(r["factorisations"], "rupture.factorisations",
                                          {"every_iteration", "reuse"}) == "reuse")
        s.rupture_options.factor_reuse = solver::RuptureOptions{}.reuse_products;
      const bool stretch =
          s.rupture_options.criterion != solver::RuptureCriterion::energy_density && !griffith;
      if (stretch && !(s.rupture_options.critical > 1.0))
        throw c
            .err(r["critical"], "rupture.critical",
                 "a critical stretch must exceed 1: the undeformed body (stretch 1) would break")
            .value(r["critical"].Scalar())
            .expected("a stretch > 1, e.g. 2.5");
      if (!stretch && !griffith && !(s.rupture_options.critical > 0.0))
        throw c
            .err(r["critical"], "rupture.critical",
                 "a critical energy density must be positive: the undeformed body (Ψ = 0) "
                 "would break")
            .value(r["critical"].Scalar())
            .expected("an energy density > 0");
      if (s.model.correspondence == solver::Correspondence::classical)
        throw c
            .err(root["solver"]["correspondence"], "solver.correspondence",
                 "rupture needs bond-associated correspondence (broken bonds leave the BA "
                 "families; the classical model has no bond stencils)")
            .value("classical")
            .fix("remove solver.correspondence or set it to bond-associated");
    }
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    auto& y = out.yaml();
    if (s.rupture) {
      y << YAML::Key << "rupture" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
        << "criterion" << YAML::Value << solver::to_string(s.rupture_options.criterion);
      if (s.rupture_options.criterion == solver::RuptureCriterion::fracture_energy) {
        y << YAML::Key << "G_c" << YAML::Value << s.rupture_options.fracture_energy;
        if (s.rupture_options.softening != solver::RuptureSoftening::none)
          y << YAML::Key << "softening" << YAML::Value
            << solver::to_string(s.rupture_options.softening) << YAML::Key << "elastic_limit"
            << YAML::Value << s.rupture_options.elastic_limit << YAML::Key << "damage_tolerance"
            << YAML::Value << s.rupture_options.damage_tolerance << YAML::Key
            << "max_damage_increment" << YAML::Value << s.rupture_options.max_damage_increment;
      } else {
        y << YAML::Key << "critical" << YAML::Value << s.rupture_options.critical;
      }
      if (s.inertia)
        y << YAML::Key << "check_every" << YAML::Value << s.rupture_options.check_every;
      else
        y << YAML::Key << "max_passes" << YAML::Value << s.rupture_options.max_passes << YAML::Key
          << "fallback" << YAML::Value
          << (s.rupture_options.pseudo_transient ? "pseudo_transient" : "relaxation");
      if (!s.inertia && s.rupture_options.anchor_fragments)
        y << YAML::Key << "fragments" << YAML::Value << "anchor";
      if (!s.inertia && s.rupture_options.factor_reuse > 0)
        y << YAML::Key << "factorisations" << YAML::Value << "reuse";
      y << YAML::EndMap;
    }
  }
};

}  // namespace

void register_builtin_effects(const std::function<void(std::string, EffectFactory)>& add) {
  add("inertia", [] { return std::make_unique<Inertia>(); });
  add("damping", [] { return std::make_unique<Damping>(); });
  add("rupture", [] { return std::make_unique<RuptureEffect>(); });
}

}  // namespace pdcg::scene
