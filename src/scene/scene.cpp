#include "pdcg/scene/scene.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <sstream>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg/scene/expression.hpp"

namespace pdcg::scene {

using solver::Vec3;

namespace {

struct Ctx {
  std::string file;
  InputError err(const YAML::Node& n, const std::string& key, const std::string& problem) const {
    InputError e(problem);
    e.source(file).key(key);
    if (n.IsDefined() && n.Mark().line >= 0) e.line(n.Mark().line + 1);
    return e;
  }
  void keys(const YAML::Node& n, const std::string& where,
            const std::vector<std::string>& valid) const {
    if (!n.IsMap())
      throw err(n, where, "expected a mapping {key: value, ...}")
          .expected(fmt::format("keys {}", fmt::join(valid, ", ")));
    for (const auto& kv : n) {
      const std::string k = kv.first.as<std::string>();
      if (std::find(valid.begin(), valid.end(), k) == valid.end())
        throw err(kv.first, where.empty() ? k : where + "." + k, "unknown key")
            .value(k)
            .expected(fmt::format("one of: {}", fmt::join(valid, ", ")));
    }
  }
  double number(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<double>();
    } catch (const YAML::Exception&) {
      throw err(n, key, "not a number")
          .value(n.IsScalar() ? n.Scalar() : "(not a scalar)")
          .expected("a number");
    }
  }
  int integer(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<int>();
    } catch (const YAML::Exception&) {
      throw err(n, key, "not an integer")
          .value(n.IsScalar() ? n.Scalar() : "(not a scalar)")
          .expected("an integer");
    }
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) throw err(n, key, "expected a single value").expected("a string");
    return n.Scalar();
  }
  Vec3 vec(const YAML::Node& n, const std::string& key, int dim) const {
    if (!n.IsSequence() || static_cast<int>(n.size()) != dim)
      throw err(n, key, "wrong vector")
          .expected(
              fmt::format("a list of {} numbers, e.g. [0.0, 0.0{}]", dim, dim == 3 ? ", 0.0" : ""));
    Vec3 v = Vec3::Zero();
    for (int a = 0; a < dim; ++a) v(a) = number(n[a], key);
    return v;
  }
  std::string choice(const YAML::Node& n, const std::string& key,
                     const std::vector<std::string>& valid) const {
    const std::string v = text(n, key);
    if (std::find(valid.begin(), valid.end(), v) == valid.end())
      throw err(n, key, "invalid value")
          .value(v)
          .expected(fmt::format("one of: {}", fmt::join(valid, ", ")));
    return v;
  }
};

std::function<double(double)> value_fn(const Ctx& c, const YAML::Node& n, const std::string& key,
                                       std::string& text) {
  if (!n.IsScalar()) throw c.err(n, key, "expected a number or an expression in t");
  text = n.Scalar();
  try {
    const double v = n.as<double>();
    return [v](double) { return v; };
  } catch (const YAML::Exception&) {
  }
  try {
    return parse_expression(text, key);
  } catch (InputError& e) {
    throw e.source(c.file).line(n.Mark().line + 1);
  }
}

}  // namespace

const std::vector<std::string>& valid_effects() {
  static const std::vector<std::string> v{"inertia", "damping", "rupture"};
  return v;
}

Scene load_scene(const std::filesystem::path& file) {
  Ctx c{file.string()};
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::BadFile&) {
    throw InputError("cannot open the scene file").source(file.string()).fix("check the path");
  } catch (const YAML::ParserException& e) {
    throw InputError("YAML syntax error: " + e.msg).source(file.string()).line(e.mark.line + 1);
  }
  Scene s;
  s.source = file;
  c.keys(root, "",
         {"units", "dimension", "plane", "geometry", "horizon", "material", "boundary", "loading",
          "solver", "output", "effects", "inertia", "damping", "rupture", "initial"});
  if (root["units"]) {
    try {
      s.units = parse_unit_style(c.text(root["units"], "units"), file.string());
    } catch (InputError& e) {
      throw e.line(root["units"].Mark().line + 1);
    }
  }
  if (root["dimension"]) {
    s.dimension = c.integer(root["dimension"], "dimension");
    if (s.dimension != 2 && s.dimension != 3)
      throw c.err(root["dimension"], "dimension", "unsupported dimension")
          .value(std::to_string(s.dimension))
          .expected("2 or 3");
  }
  const int d = s.dimension;
  if (root["plane"]) {
    if (d != 2)
      throw c.err(root["plane"], "plane", "plane is for 2D scenes only")
          .fix("remove it or set dimension: 2");
    s.plane = c.choice(root["plane"], "plane", {"strain", "stress"});
  }
  // geometry
  const auto g = root["geometry"];
  if (!g)
    throw InputError("missing section")
        .source(c.file)
        .key("geometry")
        .expected("geometry: {shape: rectangle, origin, size, spacing}");
  c.keys(g, "geometry", {"shape", "origin", "size", "spacing", "nodes", "holes", "cracks"});
  const std::string shape =
      g["shape"] ? c.choice(g["shape"], "geometry.shape", {"rectangle", "box", "model"})
                 : (d == 2 ? "rectangle" : "box");
  if (shape == "model")
    throw c
        .err(g["shape"], "geometry.shape", "geometry from a pdcg model file is not implemented yet")
        .value("model")
        .expected("rectangle or box");
  if ((shape == "rectangle") != (d == 2))
    throw c.err(g["shape"], "geometry.shape", "shape does not match the dimension")
        .value(shape)
        .expected(d == 2 ? "rectangle" : "box");
  s.geometry.dimension = d;
  if (g["origin"]) s.geometry.origin = c.vec(g["origin"], "geometry.origin", d);
  if (!g["size"])
    throw c.err(g, "geometry.size", "missing key").expected("the body size, e.g. [1.0, 1.0]");
  s.geometry.size = c.vec(g["size"], "geometry.size", d);
  if (d == 2) s.geometry.size.z() = 1.0;
  if (!g["spacing"])
    throw c.err(g, "geometry.spacing", "missing key").expected("the grid spacing, e.g. 0.025");
  s.geometry.spacing = c.number(g["spacing"], "geometry.spacing");
  // Grid points at cell centres (default) or on the grid vertices, boundary included.
  if (g["nodes"])
    s.geometry.nodes = c.choice(g["nodes"], "geometry.nodes", {"cells", "vertices"}) == "vertices"
                           ? solver::GridNodes::vertices
                           : solver::GridNodes::cell_centres;
  if (g["holes"]) {
    if (!g["holes"].IsSequence())
      throw c.err(g["holes"], "geometry.holes", "expected a list")
          .expected("[{center: [...], radius: r}, ...]");
    for (const auto& h : g["holes"]) {
      c.keys(h, "geometry.holes[]", {"center", "radius"});
      solver::Hole hole;
      hole.center = c.vec(h["center"], "geometry.holes[].center", d);
      hole.radius = c.number(h["radius"], "geometry.holes[].radius");
      if (!(hole.radius > 0))
        throw c.err(h["radius"], "geometry.holes[].radius", "radius must be positive")
            .value(h["radius"].Scalar());
      s.geometry.holes.push_back(hole);
    }
  }
  if (g["cracks"]) {
    if (!g["cracks"].IsSequence())
      throw c.err(g["cracks"], "geometry.cracks", "expected a list")
          .expected("[{from: [...], to: [...]}, ...]");
    for (const auto& k : g["cracks"]) {
      c.keys(k, "geometry.cracks[]", {"from", "to"});
      s.geometry.cracks.push_back({c.vec(k["from"], "geometry.cracks[].from", d),
                                   c.vec(k["to"], "geometry.cracks[].to", d)});
    }
  }
  // horizon
  if (const auto h = root["horizon"]) {
    c.keys(h, "horizon", {"factor", "value"});
    if (h["factor"] && h["value"])
      throw c.err(h, "horizon", "give either factor or value, not both");
    if (h["factor"]) s.horizon_factor = c.number(h["factor"], "horizon.factor");
    if (h["value"]) s.horizon_value = c.number(h["value"], "horizon.value");
    const double delta =
        s.horizon_value > 0 ? s.horizon_value : s.horizon_factor * s.geometry.spacing;
    if (!(delta >= s.geometry.spacing))
      throw c.err(h, "horizon", "horizon smaller than the grid spacing")
          .value(fmt::format("{}", delta))
          .expected(
              fmt::format("at least the spacing {} (usually 3.015 spacings)", s.geometry.spacing))
          .fix("use horizon: {factor: 3.015}");
  }
  // material
  if (const auto m = root["material"]) {
    c.keys(m, "material", {"model", "shear_modulus", "bulk_modulus", "density"});
    if (m["model"]) c.choice(m["model"], "material.model", {"neo-hookean"});
    if (m["shear_modulus"])
      s.shear_modulus = c.number(m["shear_modulus"], "material.shear_modulus");
    if (m["bulk_modulus"]) s.bulk_modulus = c.number(m["bulk_modulus"], "material.bulk_modulus");
    if (m["density"]) s.density = c.number(m["density"], "material.density");
    if (!(s.shear_modulus > 0) || !(s.bulk_modulus > 0))
      throw c.err(m, "material", "moduli must be positive")
          .value(fmt::format("mu = {}, K = {}", s.shear_modulus, s.bulk_modulus));
  } else {
    throw InputError("missing section")
        .source(c.file)
        .key("material")
        .expected("material: {model: neo-hookean, shear_modulus, bulk_modulus}");
  }
  // boundary
  const auto b = root["boundary"];
  if (!b || !b.IsSequence())
    throw InputError("missing or malformed section")
        .source(c.file)
        .key("boundary")
        .expected("a list of {name, region, displacement|traction}");
  std::set<std::string> names;
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& e : b) {
    c.keys(e, "boundary[]", {"name", "region", "displacement", "traction"});
    BoundaryCondition bc;
    bc.name =
        e["name"] ? c.text(e["name"], "boundary[].name") : fmt::format("set{}", s.boundary.size());
    if (!names.insert(bc.name).second)
      throw c.err(e["name"], "boundary[].name", "duplicate boundary name").value(bc.name);
    const std::string w = "boundary[" + bc.name + "]";
    if (!e["region"])
      throw c.err(e, w + ".region", "missing key")
          .expected("region: {x_min: ...} or {point: [...]}");
    const auto r = e["region"];
    c.keys(r, w + ".region", {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max", "point"});
    for (int a = 0; a < 3; ++a) {
      const std::string lo = std::string(axes[a]) + "_min", hi = std::string(axes[a]) + "_max";
      if ((r[lo] || r[hi]) && a >= d)
        throw c.err(r, w + ".region." + lo, "bound beyond the scene dimension");
      if (r[lo]) bc.region.min[a] = c.number(r[lo], w + ".region." + lo);
      if (r[hi]) bc.region.max[a] = c.number(r[hi], w + ".region." + hi);
    }
    if (r["point"]) bc.region.point = c.vec(r["point"], w + ".region.point", d);
    if (e["displacement"] && e["traction"])
      throw c.err(e, w, "give displacement or traction, not both");
    if (e["displacement"]) {
      const auto dn = e["displacement"];
      std::vector<std::string> valid(axes, axes + d);
      c.keys(dn, w + ".displacement", valid);
      for (int a = 0; a < d; ++a)
        if (dn[axes[a]])
          bc.value[a] = value_fn(c, dn[axes[a]], w + ".displacement." + axes[a], bc.value_text[a]);
    } else if (e["traction"]) {
      bc.is_traction = true;
      const auto tn = e["traction"];
      if (!tn.IsSequence() || static_cast<int>(tn.size()) != d)
        throw c.err(tn, w + ".traction", "wrong traction vector")
            .expected(fmt::format("a list of {} numbers or expressions in t", d));
      for (int a = 0; a < d; ++a)
        bc.value[a] = value_fn(c, tn[a], w + ".traction", bc.value_text[a]);
    } else {
      throw c.err(e, w, "boundary condition without displacement or traction")
          .expected("displacement: {x: ...} or traction: [...]");
    }
    s.boundary.push_back(std::move(bc));
  }
  if (const auto l = root["loading"]) {
    c.keys(l, "loading", {"steps"});
    if (l["steps"]) s.steps = c.integer(l["steps"], "loading.steps");
    if (s.steps < 1)
      throw c.err(l["steps"], "loading.steps", "need at least one step")
          .value(std::to_string(s.steps));
  }
  s.newton.steps = s.steps;
  if (const auto v = root["solver"]) {
    c.keys(v, "solver",
           {"type", "tolerance", "max_iterations", "linear", "formulation", "correspondence",
            "max_cutbacks"});
    if (v["type"]) c.choice(v["type"], "solver.type", {"newton"});
    if (v["tolerance"]) s.newton.tolerance = c.number(v["tolerance"], "solver.tolerance");
    if (v["max_iterations"])
      s.newton.max_iterations = c.integer(v["max_iterations"], "solver.max_iterations");
    if (v["max_cutbacks"])
      s.newton.max_cutbacks = c.integer(v["max_cutbacks"], "solver.max_cutbacks");
    if (v["linear"]) {
      s.linear_name =
          c.choice(v["linear"], "solver.linear", {"cholmod", "umfpack", "lu", "bicgstab"});
      s.newton.linear = solver::parse_linear_solver(s.linear_name);
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
    if (!(s.newton.tolerance > 0))
      throw c.err(v["tolerance"], "solver.tolerance", "tolerance must be positive");
  }
  if (const auto o = root["output"]) {
    c.keys(o, "output", {"directory", "every"});
    if (o["directory"]) s.output_directory = c.text(o["directory"], "output.directory");
    if (o["every"]) s.output_every = c.integer(o["every"], "output.every");
    if (s.output_every < 1) throw c.err(o["every"], "output.every", "must be at least 1");
  }
  // effects (docs/effects.md)
  if (const auto e = root["effects"]) {
    if (!e.IsSequence())
      throw c.err(e, "effects", "expected a list")
          .expected(fmt::format("a list of effects, any of: {}", fmt::join(valid_effects(), ", ")))
          .fix("effects: [rupture]");
    for (const auto& n : e) {
      const std::string name = c.choice(n, "effects[]", valid_effects());
      if (std::find(s.effects.begin(), s.effects.end(), name) != s.effects.end())
        throw c.err(n, "effects[]", "effect listed twice").value(name);
      s.effects.push_back(name);
    }
  }
  auto has = [&](const std::string& name) {
    return std::find(s.effects.begin(), s.effects.end(), name) != s.effects.end();
  };
  for (const char* sec : {"inertia", "damping", "rupture"})
    if (root[sec] && !has(sec))
      throw c.err(root[sec], sec, "settings for an effect the scene does not list")
          .expected(fmt::format("'{}' in effects: [...] when a '{}:' section is given", sec, sec))
          .fix(fmt::format("add {} to effects, or remove the {} section", sec, sec));
  if (root["initial"] && !has("inertia"))
    throw c
        .err(root["initial"], "initial",
             "initial velocities without inertia: a quasi-static run has no velocities")
        .fix("add inertia to effects, or remove the initial section");
  if (has("damping") && !has("inertia"))
    throw c
        .err(root["effects"], "effects",
             "damping without inertia: damping acts on velocities, which a quasi-static run "
             "does not have")
        .fix("add inertia to effects (damped dynamics), or remove damping");
  for (const char* eff : {"inertia", "damping"})
    if (has(eff))
      throw c
          .err(root["effects"], "effects",
               fmt::format("the effect '{}' is not implemented in this build of pdcg", eff))
          .value(eff)
          .expected("effects: [rupture] (quasi-static with rupture) or no effects");
  if (has("rupture")) {
    s.rupture = true;
    const auto r = root["rupture"];
    if (!r)
      throw c.err(root["effects"], "rupture", "rupture is listed but has no settings")
          .expected("rupture: {criterion: bond_stretch, critical: 2.5}");
    c.keys(r, "rupture", {"criterion", "critical", "max_passes"});
    if (r["criterion"])
      s.rupture_options.criterion = solver::parse_rupture_criterion(
          c.choice(r["criterion"], "rupture.criterion",
                   {"bond_stretch", "principal_stretch", "energy_density"}));
    if (!r["critical"])
      throw c.err(r, "rupture.critical", "missing key")
          .expected("the critical value of the criterion, e.g. critical: 2.5");
    s.rupture_options.critical = c.number(r["critical"], "rupture.critical");
    if (r["max_passes"]) {
      s.rupture_options.max_passes = c.integer(r["max_passes"], "rupture.max_passes");
      if (s.rupture_options.max_passes < 1)
        throw c.err(r["max_passes"], "rupture.max_passes", "must be at least 1");
    }
    const bool stretch = s.rupture_options.criterion != solver::RuptureCriterion::energy_density;
    if (stretch && !(s.rupture_options.critical > 1.0))
      throw c
          .err(r["critical"], "rupture.critical",
               "a critical stretch must exceed 1: the undeformed body (stretch 1) would break")
          .value(r["critical"].Scalar())
          .expected("a stretch > 1, e.g. 2.5");
    if (!stretch && !(s.rupture_options.critical > 0.0))
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
  // relative output directory: relative to the working directory (like every CLI path)
  return s;
}

std::string resolved_yaml(const Scene& s) {
  YAML::Emitter y;
  y.SetDoublePrecision(15);
  const int d = s.dimension;
  auto vec = [&](const Vec3& v) {
    y << YAML::Flow << YAML::BeginSeq;
    for (int a = 0; a < d; ++a) y << v(a);
    y << YAML::EndSeq;
  };
  y << YAML::BeginMap;
  y << YAML::Key << "units" << YAML::Value << std::string(to_string(s.units));
  y << YAML::Key << "dimension" << YAML::Value << d;
  if (d == 2) y << YAML::Key << "plane" << YAML::Value << s.plane;
  y << YAML::Key << "geometry" << YAML::Value << YAML::BeginMap;
  y << YAML::Key << "shape" << YAML::Value << (d == 2 ? "rectangle" : "box");
  y << YAML::Key << "origin" << YAML::Value;
  vec(s.geometry.origin);
  y << YAML::Key << "size" << YAML::Value;
  vec(s.geometry.size);
  y << YAML::Key << "spacing" << YAML::Value << s.geometry.spacing;
  y << YAML::Key << "nodes" << YAML::Value
    << (s.geometry.nodes == solver::GridNodes::vertices ? "vertices" : "cells");
  y << YAML::Key << "holes" << YAML::Value << YAML::BeginSeq;
  for (const auto& h : s.geometry.holes) {
    y << YAML::Flow << YAML::BeginMap << YAML::Key << "center" << YAML::Value;
    vec(h.center);
    y << YAML::Key << "radius" << YAML::Value << h.radius << YAML::EndMap;
  }
  y << YAML::EndSeq << YAML::Key << "cracks" << YAML::Value << YAML::BeginSeq;
  for (const auto& k : s.geometry.cracks) {
    y << YAML::Flow << YAML::BeginMap << YAML::Key << "from" << YAML::Value;
    vec(k.from);
    y << YAML::Key << "to" << YAML::Value;
    vec(k.to);
    y << YAML::EndMap;
  }
  y << YAML::EndSeq << YAML::EndMap;
  y << YAML::Key << "horizon" << YAML::Value << YAML::Flow << YAML::BeginMap;
  if (s.horizon_value > 0)
    y << YAML::Key << "value" << YAML::Value << s.horizon_value;
  else
    y << YAML::Key << "factor" << YAML::Value << s.horizon_factor;
  y << YAML::EndMap;
  y << YAML::Key << "material" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
    << "model" << YAML::Value << "neo-hookean" << YAML::Key << "shear_modulus" << YAML::Value
    << s.shear_modulus << YAML::Key << "bulk_modulus" << YAML::Value << s.bulk_modulus << YAML::Key
    << "density" << YAML::Value << s.density << YAML::EndMap;
  y << YAML::Key << "boundary" << YAML::Value << YAML::BeginSeq;
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& bc : s.boundary) {
    y << YAML::Flow << YAML::BeginMap << YAML::Key << "name" << YAML::Value << bc.name;
    y << YAML::Key << "region" << YAML::Value << YAML::BeginMap;
    for (int a = 0; a < d; ++a) {
      if (bc.region.min[a])
        y << YAML::Key << std::string(axes[a]) + "_min" << YAML::Value << *bc.region.min[a];
      if (bc.region.max[a])
        y << YAML::Key << std::string(axes[a]) + "_max" << YAML::Value << *bc.region.max[a];
    }
    if (bc.region.point) {
      y << YAML::Key << "point" << YAML::Value;
      vec(*bc.region.point);
    }
    y << YAML::EndMap;
    if (bc.is_traction) {
      y << YAML::Key << "traction" << YAML::Value << YAML::BeginSeq;
      for (int a = 0; a < d; ++a) y << bc.value_text[a];
      y << YAML::EndSeq;
    } else {
      y << YAML::Key << "displacement" << YAML::Value << YAML::BeginMap;
      for (int a = 0; a < d; ++a)
        if (bc.value[a]) y << YAML::Key << axes[a] << YAML::Value << bc.value_text[a];
      y << YAML::EndMap;
    }
    y << YAML::EndMap;
  }
  y << YAML::EndSeq;
  y << YAML::Key << "loading" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "steps"
    << YAML::Value << s.steps << YAML::EndMap;
  y << YAML::Key << "solver" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "type"
    << YAML::Value << "newton" << YAML::Key << "tolerance" << YAML::Value << s.newton.tolerance
    << YAML::Key << "max_iterations" << YAML::Value << s.newton.max_iterations << YAML::Key
    << "max_cutbacks" << YAML::Value << s.newton.max_cutbacks << YAML::Key << "linear"
    << YAML::Value << s.linear_name << YAML::Key << "formulation" << YAML::Value
    << (s.model.boundary == solver::BoundaryForm::weak ? "weak" : "energy") << YAML::Key
    << "correspondence" << YAML::Value
    << (s.model.correspondence == solver::Correspondence::classical ? "classical"
                                                                    : "bond-associated")
    << YAML::EndMap;
  y << YAML::Key << "effects" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const auto& e : s.effects) y << e;
  y << YAML::EndSeq;
  if (s.rupture)
    y << YAML::Key << "rupture" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
      << "criterion" << YAML::Value << solver::to_string(s.rupture_options.criterion) << YAML::Key
      << "critical" << YAML::Value << s.rupture_options.critical << YAML::Key << "max_passes"
      << YAML::Value << s.rupture_options.max_passes << YAML::EndMap;
  y << YAML::Key << "output" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
    << "directory" << YAML::Value << s.output_directory.string() << YAML::Key << "every"
    << YAML::Value << s.output_every << YAML::EndMap;
  y << YAML::EndMap;
  return std::string(y.c_str()) + "\n";
}

std::vector<int> select(const Scene& s, const solver::Discretization& body,
                        const BoundaryCondition& bc) {
  std::vector<int> out;
  const double tol = 0.5 * body.spacing() * (1 + 1e-9);
  const auto& x = body.positions();
  if (bc.region.point) {
    int best = -1;
    double bd = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double r = (x[i] - *bc.region.point).norm();
      if (r < bd) {
        bd = r;
        best = static_cast<int>(i);
      }
    }
    out.push_back(best);
    return out;
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    bool in = true;
    for (int a = 0; a < body.dimension(); ++a) {
      if (bc.region.min[a] && x[i](a) < *bc.region.min[a] - tol) in = false;
      if (bc.region.max[a] && x[i](a) > *bc.region.max[a] + tol) in = false;
    }
    if (in) out.push_back(static_cast<int>(i));
  }
  if (out.empty())
    throw InputError("the region selects no point")
        .source(s.source.string())
        .key("boundary[" + bc.name + "].region")
        .expected(
            fmt::format("bounds that contain grid points (cell centres or vertices, spacing {}; "
                        "bounds are inclusive with a tolerance of half a spacing)",
                        body.spacing()))
        .fix("check the bounds against geometry.origin and geometry.size");
  return out;
}

namespace {

void write_xdmf(const std::filesystem::path& dir, std::size_t n,
                const std::vector<std::pair<int, double>>& steps, bool damage) {
  io::AtomicTextFile f(dir / "results.xdmf");
  auto& o = f.stream();
  o << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
       "  <Grid Name=\"pdcg\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const auto& [step, t] : steps) {
    const std::string h5 = fmt::format("results_{:04d}.h5", step);
    o << fmt::format("   <Grid Name=\"step {}\" GridType=\"Uniform\">\n    <Time Value=\"{}\"/>\n",
                     step, t);
    o << fmt::format("    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\"/>\n", n);
    o << fmt::format(
        "    <Geometry GeometryType=\"XYZ\"><DataItem Dimensions=\"{} 3\" "
        "Format=\"HDF\">{}:/points/reference</DataItem></Geometry>\n",
        n, h5);
    auto attr = [&](const char* name, const char* path, const char* type, int comps) {
      o << fmt::format(
          "    <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\"><DataItem "
          "Dimensions=\"{}{}\" Format=\"HDF\">{}:{}</DataItem></Attribute>\n",
          name, type, n, comps > 1 ? fmt::format(" {}", comps) : std::string(), h5, path);
    };
    attr("displacement", "/fields/displacement", "Vector", 3);
    attr("deformed_position", "/fields/deformed_position", "Vector", 3);
    attr("deformation_gradient", "/fields/deformation_gradient", "Tensor", 9);
    attr("first_piola_kirchhoff", "/fields/first_piola_kirchhoff", "Tensor", 9);
    attr("cauchy_stress", "/fields/cauchy_stress", "Tensor", 9);
    attr("energy_density", "/fields/energy_density", "Scalar", 1);
    if (damage) attr("damage", "/fields/damage", "Scalar", 1);
    o << "   </Grid>\n";
  }
  o << "  </Grid>\n </Domain>\n</Xdmf>\n";
  f.commit();
}

}  // namespace

void run_scene(const Scene& s, const std::optional<std::filesystem::path>& out_override) {
  const std::filesystem::path dir = out_override ? *out_override : s.output_directory;
  std::filesystem::create_directories(dir);
  {
    io::AtomicTextFile f(dir / "scene.resolved.yaml");
    f.stream() << resolved_yaml(s);
    f.commit();
  }
  solver::DiscretizationOptions dopt;
  dopt.horizon_factor = s.horizon_factor;
  dopt.horizon = s.horizon_value;
  auto body = solver::Discretization::grid(s.geometry, dopt);
  log::info("body: {} points, spacing {}, horizon {}", body.size(), body.spacing(), body.horizon());
  const auto kin = s.dimension == 3      ? solver::Kinematics::three_d
                   : s.plane == "stress" ? solver::Kinematics::plane_stress
                                         : solver::Kinematics::plane_strain;
  const auto material = solver::make_neo_hookean({s.shear_modulus, s.bulk_modulus}, kin);
  solver::Model model(body, *material, s.model);
  std::vector<solver::DisplacementSet> dsets;
  std::vector<solver::TractionSet> tsets;
  for (const auto& bc : s.boundary) {
    auto pts = select(s, body, bc);
    log::info("boundary '{}': {} points", bc.name, pts.size());
    if (bc.is_traction) {
      auto v = bc.value;
      tsets.push_back({bc.name, std::move(pts), [v](double t) {
                         return Vec3(v[0] ? v[0](t) : 0.0, v[1] ? v[1](t) : 0.0,
                                     v[2] ? v[2](t) : 0.0);
                       }});
    } else {
      solver::DisplacementSet ds{bc.name, std::move(pts), {}};
      ds.component = bc.value;
      dsets.push_back(std::move(ds));
    }
  }
  solver::NewtonOptions nopt = s.newton;
  nopt.steps = s.steps;
  std::unique_ptr<solver::StaticSolver> solver_ptr;
  try {
    solver_ptr = std::make_unique<solver::StaticSolver>(model, dsets, tsets, nopt);
  } catch (InputError& e) {
    throw e.source(s.source.string());
  }
  solver::StaticSolver& solver = *solver_ptr;
  // Rupture: only when the scene lists it (no broken flags, no checks otherwise).
  std::unique_ptr<solver::Rupture> rupture;
  if (s.rupture) {
    rupture = std::make_unique<solver::Rupture>(body, model, s.rupture_options);
    log::info("rupture: {} > {} breaks a bond; staggered re-equilibration at fixed load",
              solver::to_string(s.rupture_options.criterion), s.rupture_options.critical);
  }
  const int d = s.dimension;
  const std::size_t N = body.size();
  std::vector<std::pair<int, double>> written;
  std::ostringstream csv;
  csv << "step,t";
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& ds : dsets)
    for (int a = 0; a < d; ++a) csv << "," << ds.name << "_f" << axes[a];
  if (rupture) csv << ",broken_bonds";
  csv << "\n";
  auto write_csv = [&] {
    io::AtomicTextFile f(dir / "reactions.csv");
    f.stream() << csv.str();
    f.commit();
  };
  csv << "0,0";
  for (std::size_t i = 0; i < dsets.size(); ++i)
    for (int a = 0; a < d; ++a) csv << ",0";
  if (rupture) csv << ",0";
  csv << "\n";
  write_csv();
  int counter = 0;
  auto on_step = [&](const solver::StepReport& rep) {
    if (rupture) rupture->stagger(solver);  // re-equilibrate at this load until no bond breaks
    csv << rep.step << "," << fmt::format("{:.10g}", rep.t);
    for (std::size_t i = 0; i < dsets.size(); ++i) {
      const Vec3 r = solver.reaction(i);
      for (int a = 0; a < d; ++a) csv << "," << fmt::format("{:.10g}", r(a));
    }
    if (rupture) csv << "," << body.broken_bonds();
    csv << "\n";
    write_csv();
    ++counter;
    const bool last = rep.t >= 1.0 - 1e-12;
    if (counter % s.output_every != 0 && !last) return;
    const Eigen::VectorXd& u = solver.displacement();
    const auto F = model.point_deformation_gradients(u);
    std::vector<double> X(3 * N), U(3 * N, 0.0), Y(3 * N), Fv(9 * N), Pv(9 * N), Sv(9 * N), W(N);
    for (std::size_t i = 0; i < N; ++i) {
      for (int a = 0; a < 3; ++a) {
        X[3 * i + a] = body.positions()[i](a);
        if (a < d) U[3 * i + a] = u[d * i + a];
        Y[3 * i + a] = X[3 * i + a] + U[3 * i + a];
      }
      double psi = 0;
      solver::Mat3 P = solver::Mat3::Zero();
      material->evaluate(F[i], &psi, &P, nullptr);
      const solver::Mat3 Ff = material->full_deformation_gradient(F[i]);
      const solver::Mat3 sigma = P * Ff.transpose() / Ff.determinant();
      for (int a = 0; a < 3; ++a)
        for (int J = 0; J < 3; ++J) {
          Fv[9 * i + 3 * a + J] = Ff(a, J);
          Pv[9 * i + 3 * a + J] = P(a, J);
          Sv[9 * i + 3 * a + J] = sigma(a, J);
        }
      W[i] = psi;
    }
    io::H5Writer h5(dir / fmt::format("results_{:04d}.h5", rep.step),
                    {"pdcg-results", 1, s.units, {}, {}});
    h5.write("points/reference", X, {N, 3});
    h5.write("points/volume", body.volumes(), {N});
    h5.write("fields/displacement", U, {N, 3});
    h5.write("fields/deformed_position", Y, {N, 3});
    h5.write("fields/deformation_gradient", Fv, {N, 9});
    h5.write("fields/first_piola_kirchhoff", Pv, {N, 9});
    h5.write("fields/cauchy_stress", Sv, {N, 9});
    h5.write("fields/energy_density", W, {N});
    if (rupture) h5.write("fields/damage", body.damage(), {N});
    h5.attribute("/", "step", static_cast<std::int64_t>(rep.step));
    h5.attribute("/", "load_factor", rep.t);
    h5.attribute("/", "newton_iterations", static_cast<std::int64_t>(rep.iterations));
    h5.attribute("/", "residual", rep.residual);
    h5.commit();
    written.emplace_back(rep.step, rep.t);
    write_xdmf(dir, N, written, s.rupture);
  };
  solver.run(on_step);
  log::info("done: {} steps, results in {}", counter, dir.string());
}

}  // namespace pdcg::scene
