#include "pdcg/scene/scene.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <set>
#include <sstream>

#include "checks.hpp"
#include "csv_units.hpp"
#include "pdcg/body/cauchy_born_material.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/progress.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg/scene/expression.hpp"
#include "pdcg/solver/explicit.hpp"

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
      if (!kv.first.IsScalar())  // e.g. `{!tag: 1}` or `{[a, b]: 1}`: as<std::string> would throw
        throw err(kv.first, where, "a key must be a plain name")
            .expected(fmt::format("one of: {}", fmt::join(valid, ", ")));
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

// `geometry: {shape: model, file: res.h5}` (docs/solver.md §2.1): the points (and volumes) of a
// model file; surface vectors and spacing from solver::analyse_cloud. Read at load time so a
// bad file is an input error with its line.
void load_model_geometry(const Ctx& c, const YAML::Node& g, const std::filesystem::path& scene_file,
                         Scene& s) {
  for (const char* k : {"origin", "size", "spacing", "nodes", "holes", "cracks"})
    if (g[k])
      throw c
          .err(g[k], std::string("geometry.") + k,
               fmt::format("geometry.{} is not allowed with shape: model", k))
          .expected("geometry: {shape: model, file: model.h5}")
          .fix(std::string(k) == "spacing"
                   ? "remove it: the spacing is the model's (its homogenisation grid step, or the "
                     "mean nearest-neighbour distance of its points)"
               : std::string(k) == "holes" || std::string(k) == "cracks"
                   ? fmt::format(
                         "remove it: the model's points and atomic bonds are the body; cut {0} "
                         "in the atoms before `pdcg atoms2pd` ({0} drawn over the model would "
                         "leave the model's own bonds, and its Cauchy–Born material, across it)",
                         std::string(k) == "holes" ? "a hole" : "a notch")
                   : "remove it: the body is the model's points");
  if (!g["file"])
    throw c.err(g, "geometry.file", "missing key")
        .expected("the pdcg model file, e.g. file: res.h5 (relative to the scene file)");
  std::filesystem::path f = c.text(g["file"], "geometry.file");
  if (f.is_relative()) f = std::filesystem::absolute(scene_file.parent_path() / f);
  if (!std::filesystem::exists(f))
    throw c.err(g["file"], "geometry.file", "the model file does not exist")
        .value(f.string())
        .fix("check the path (relative paths are relative to the scene file)");
  body::Body b;
  try {
    b = body::read_body(f);
  } catch (InputError& e) {
    throw e.line(g["file"].Mark().line + 1).key("geometry.file");
  }
  if (b.dimension != s.dimension)
    throw c.err(g["file"], "geometry.file", "the model's dimension differs from the scene's")
        .value(fmt::format("a {}D model in a {}D scene", b.dimension, s.dimension))
        .fix(fmt::format("set dimension: {}, or use a {}D model", b.dimension, s.dimension));
  auto m = std::make_shared<ModelGeometry>();
  m->file = f;
  m->kind = std::string(body::to_string(b.kind));
  std::vector<double> vol;
  double hint = 0.0;
  std::optional<Eigen::Matrix3d> basis;
  if (b.homogenisation) {
    const auto& h = *b.homogenisation;
    for (std::size_t p = 0; p < h.size(); ++p)
      m->points.emplace_back(h.points[3 * p], h.points[3 * p + 1], h.points[3 * p + 2]);
    vol = h.volume;
    if (h.grid_axes.size() == 9) {
      basis = Eigen::Map<const Eigen::Matrix3d>(h.grid_axes.data());
      for (int a = 0; a < s.dimension; ++a) hint += basis->col(a).norm() / s.dimension;
      if (s.dimension == 2) basis->col(2) = Vec3::UnitZ();
    }
  } else {
    for (std::size_t k = 0; k < b.size(); ++k)
      m->points.emplace_back(b.x[3 * k], b.x[3 * k + 1], b.x[3 * k + 2]);
  }
  if (s.dimension == 2)
    for (auto& p : m->points) p.z() = 0.0;  // a film in the xy plane (its z is the box's)
  const double fallback =
      b.reference_volume() / static_cast<double>(std::max<std::size_t>(1, b.size()));
  try {
    m->cloud =
        solver::analyse_cloud(s.dimension, m->points, std::move(vol), fallback, {}, hint, basis);
  } catch (InputError& e) {
    throw e.source(c.file).line(g["file"].Mark().line + 1);
  }
  s.model_geometry = std::move(m);
}

// `material: {model: cauchy-born, file: model.h5}` (docs/elastic.md §6): the model file is
// read here once so that a bad file, a statistical body or a dimension mismatch is an input
// error of the scene (with its line), not a failure at run time.
void load_cauchy_born(const Ctx& c, const YAML::Node& m, const std::filesystem::path& scene_file,
                      Scene& s) {
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
  // every number first, from one table (src/scene/checks.cpp): type, sign, range, finite
  checks::numbers(root, c.file);
  s.key_lines = checks::key_lines(root);
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
  c.keys(g, "geometry", {"shape", "origin", "size", "spacing", "nodes", "holes", "cracks", "file"});
  const std::string shape =
      g["shape"] ? c.choice(g["shape"], "geometry.shape", {"rectangle", "box", "model"})
                 : (d == 2 ? "rectangle" : "box");
  if (shape == "model") {
    load_model_geometry(c, g, file, s);
  } else if (g["file"]) {
    throw c.err(g["file"], "geometry.file", "a model file is for geometry.shape: model")
        .fix("set shape: model, or remove geometry.file");
  }
  if (shape != "model" && (shape == "rectangle") != (d == 2))
    throw c.err(g["shape"], "geometry.shape", "shape does not match the dimension")
        .value(shape)
        .expected(d == 2 ? "rectangle" : "box");
  s.geometry.dimension = d;
  if (!s.model_geometry) {
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
  }
  // horizon
  if (const auto h = root["horizon"]) {
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
  // material
  if (const auto m = root["material"]) {
    c.keys(m, "material",
           {"model", "shear_modulus", "bulk_modulus", "density", "file", "per_point"});
    if (m["model"])
      s.material_model = c.choice(m["model"], "material.model", {"neo-hookean", "cauchy-born"});
    if (m["density"]) s.density = c.number(m["density"], "material.density");
    if (s.material_model == "cauchy-born") {
      load_cauchy_born(c, m, file, s);
    } else {
      if (m["per_point"])
        throw c
            .err(m["per_point"], "material.per_point", "per_point is for the Cauchy–Born material")
            .fix("remove material.per_point, or set material.model: cauchy-born");
      if (m["file"])
        throw c.err(m["file"], "material.file", "a model file is for the Cauchy–Born material")
            .fix("remove material.file, or set material.model: cauchy-born");
      if (m["shear_modulus"])
        s.shear_modulus = c.number(m["shear_modulus"], "material.shear_modulus");
      if (m["bulk_modulus"]) s.bulk_modulus = c.number(m["bulk_modulus"], "material.bulk_modulus");
    }
  } else {
    throw InputError("missing section")
        .source(c.file)
        .key("material")
        .expected(
            "material: {model: neo-hookean, shear_modulus, bulk_modulus} or "
            "{model: cauchy-born, file: model.h5}");
  }
  // boundary
  const auto b = root["boundary"];
  if (!b || !b.IsSequence())
    throw(b ? c.err(b, "boundary", "expected a list")
            : InputError("missing section").source(c.file).key("boundary"))
        .expected("a list of {name, region, displacement|traction}");
  std::set<std::string> names;
  const char* axes[3] = {"x", "y", "z"};
  for (const auto& e : b) {
    c.keys(e, "boundary[]", {"name", "region", "displacement", "traction"});
    BoundaryCondition bc;
    bc.name =
        e["name"] ? c.text(e["name"], "boundary[].name") : fmt::format("set{}", s.boundary.size());
    if (!names.insert(bc.name).second)
      throw c.err(e["name"] ? e["name"] : e, "boundary[].name", "duplicate boundary name")
          .value(bc.name);
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
        bc.value[a] = value_fn(c, tn[a], fmt::format("{}.traction[{}]", w, a), bc.value_text[a]);
    } else {
      throw c.err(e, w, "boundary condition without displacement or traction")
          .expected("displacement: {x: ...} or traction: [...]");
    }
    s.boundary.push_back(std::move(bc));
  }
  if (const auto l = root["loading"]) {
    c.keys(l, "loading", {"steps"});
    if (l["steps"]) s.steps = c.integer(l["steps"], "loading.steps");
  }
  s.newton.steps = s.steps;
  if (const auto v = root["solver"]) {
    c.keys(v, "solver",
           {"type", "tolerance", "max_iterations", "linear", "formulation", "correspondence",
            "max_cutbacks", "check_stability", "matrix_free"});
    if (v["type"]) c.choice(v["type"], "solver.type", {"newton"});
    if (v["tolerance"]) s.newton.tolerance = c.number(v["tolerance"], "solver.tolerance");
    if (v["max_iterations"])
      s.newton.max_iterations = c.integer(v["max_iterations"], "solver.max_iterations");
    if (v["max_cutbacks"])
      s.newton.max_cutbacks = c.integer(v["max_cutbacks"], "solver.max_cutbacks");
    if (v["check_stability"]) {
      try {
        s.newton.check_stability = v["check_stability"].as<bool>();
      } catch (const YAML::Exception&) {
        throw c.err(v["check_stability"], "solver.check_stability", "not a boolean")
            .value(v["check_stability"].IsScalar() ? v["check_stability"].Scalar() : "")
            .expected("true or false");
      }
    }
    if (v["linear"]) {
      s.linear_name =
          c.choice(v["linear"], "solver.linear", {"cholmod", "umfpack", "lu", "bicgstab", "gmres"});
      s.newton.linear = solver::parse_linear_solver(s.linear_name);
    }
    if (v["matrix_free"]) {
      try {
        s.newton.matrix_free = v["matrix_free"].as<bool>();
      } catch (const YAML::Exception&) {
        throw c.err(v["matrix_free"], "solver.matrix_free", "not a boolean")
            .value(v["matrix_free"].IsScalar() ? v["matrix_free"].Scalar() : "")
            .expected("true or false");
      }
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
  if (const auto o = root["output"]) {
    c.keys(o, "output", {"directory", "every", "series_every", "checkpoint_every"});
    if (o["directory"]) s.output_directory = c.text(o["directory"], "output.directory");
    if (o["every"]) s.output_every = c.integer(o["every"], "output.every");
    if (o["series_every"]) s.series_every = c.integer(o["series_every"], "output.series_every");
    if (o["checkpoint_every"])
      s.checkpoint_every = c.integer(o["checkpoint_every"], "output.checkpoint_every");
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
    if (in["time_step"] && !(in["time_step"].IsScalar() && in["time_step"].Scalar() == "auto")) {
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
               "loading.steps is for quasi-static runs: with inertia, t in the boundary values is "
               "the time, and inertia.end_time ends the run")
          .fix("remove the loading section");
  }
  if (!s.inertia && root["output"] && root["output"]["series_every"])
    throw c
        .err(root["output"]["series_every"], "output.series_every",
             "series_every samples the energy time series of dynamic runs; a quasi-static run "
             "writes reactions.csv at every load step")
        .fix("remove series_every, or add inertia to effects");
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
  if (has("rupture")) {
    s.rupture = true;
    const auto r = root["rupture"];
    if (!r)
      throw c.err(root["effects"], "rupture", "rupture is listed but has no settings")
          .expected("rupture: {criterion: bond_stretch, critical: 2.5}");
    c.keys(r, "rupture", {"criterion", "critical", "max_passes", "check_every"});
    if (r["criterion"])
      s.rupture_options.criterion = solver::parse_rupture_criterion(
          c.choice(r["criterion"], "rupture.criterion",
                   {"bond_stretch", "principal_stretch", "energy_density"}));
    if (!r["critical"])
      throw c.err(r, "rupture.critical", "missing key")
          .expected("the critical value of the criterion, e.g. critical: 2.5");
    s.rupture_options.critical = c.number(r["critical"], "rupture.critical");
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
  checks::consistency(s);  // contradictions between keys (empty regions, non-finite values)
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
  if (s.model_geometry) {
    y << YAML::Key << "shape" << YAML::Value << "model" << YAML::Key << "file" << YAML::Value
      << s.model_geometry->file.string() << YAML::EndMap;
  } else {
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
  }
  y << YAML::Key << "horizon" << YAML::Value << YAML::Flow << YAML::BeginMap;
  if (s.horizon_value > 0)
    y << YAML::Key << "value" << YAML::Value << s.horizon_value;
  else
    y << YAML::Key << "factor" << YAML::Value << s.horizon_factor;
  y << YAML::EndMap;
  y << YAML::Key << "material" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
    << "model" << YAML::Value << s.material_model;
  if (s.material_model == "cauchy-born") {
    y << YAML::Key << "file" << YAML::Value << s.material_file.string();
    if (s.material_per_point) y << YAML::Key << "per_point" << YAML::Value << true;
  } else
    y << YAML::Key << "shear_modulus" << YAML::Value << s.shear_modulus << YAML::Key
      << "bulk_modulus" << YAML::Value << s.bulk_modulus;
  y << YAML::Key << "density" << YAML::Value << s.density << YAML::EndMap;
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
  if (!s.inertia)  // with inertia t is the time; end_time ends the run
    y << YAML::Key << "loading" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
      << "steps" << YAML::Value << s.steps << YAML::EndMap;
  y << YAML::Key << "solver" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key << "type"
    << YAML::Value << "newton" << YAML::Key << "tolerance" << YAML::Value << s.newton.tolerance
    << YAML::Key << "max_iterations" << YAML::Value << s.newton.max_iterations << YAML::Key
    << "max_cutbacks" << YAML::Value << s.newton.max_cutbacks << YAML::Key << "linear"
    << YAML::Value << s.linear_name << YAML::Key << "formulation" << YAML::Value
    << (s.model.boundary == solver::BoundaryForm::weak ? "weak" : "energy") << YAML::Key
    << "correspondence" << YAML::Value
    << (s.model.correspondence == solver::Correspondence::classical ? "classical"
                                                                    : "bond-associated")
    << YAML::Key << "check_stability" << YAML::Value << s.newton.check_stability << YAML::Key
    << "matrix_free" << YAML::Value << s.newton.matrix_free << YAML::EndMap;
  y << YAML::Key << "effects" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (const auto& e : s.effects) y << e;
  y << YAML::EndSeq;
  if (s.rupture) {
    y << YAML::Key << "rupture" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
      << "criterion" << YAML::Value << solver::to_string(s.rupture_options.criterion) << YAML::Key
      << "critical" << YAML::Value << s.rupture_options.critical;
    if (s.inertia)
      y << YAML::Key << "check_every" << YAML::Value << s.rupture_options.check_every;
    else
      y << YAML::Key << "max_passes" << YAML::Value << s.rupture_options.max_passes;
    y << YAML::EndMap;
  }
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
  if (!s.damping_type.empty()) {
    y << YAML::Key << "damping" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
      << "type" << YAML::Value << s.damping_type;
    if (s.damping_type == "viscous")
      y << YAML::Key << "coefficient" << YAML::Value << s.damping_coefficient;
    y << YAML::EndMap;
  }
  if (s.inertia) {
    const char* ax[3] = {"x", "y", "z"};
    y << YAML::Key << "initial" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
      << "velocity" << YAML::Value << YAML::BeginMap;
    for (int a = 0; a < d; ++a)
      if (s.initial_velocity[a])
        y << YAML::Key << ax[a] << YAML::Value << YAML::DoubleQuoted << s.initial_velocity_text[a];
    y << YAML::EndMap << YAML::EndMap;
  }
  y << YAML::Key << "output" << YAML::Value << YAML::Flow << YAML::BeginMap << YAML::Key
    << "directory" << YAML::Value << s.output_directory.string() << YAML::Key << "every"
    << YAML::Value << s.output_every;
  if (s.inertia) y << YAML::Key << "series_every" << YAML::Value << s.series_every;
  if (s.checkpoint_every > 0)
    y << YAML::Key << "checkpoint_every" << YAML::Value << s.checkpoint_every;
  y << YAML::EndMap;
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
    throw checks::error(s, "boundary[" + bc.name + "].region", "the region selects no point")
        .expected(
            fmt::format("bounds that contain grid points (cell centres or vertices, spacing {}; "
                        "bounds are inclusive with a tolerance of half a spacing)",
                        body.spacing()))
        .fix(s.model_geometry ? "check the bounds against the model's points (pdcg info MODEL)"
                              : "check the bounds against geometry.origin and geometry.size");
  return out;
}

namespace {

void write_xdmf(const std::filesystem::path& dir, std::size_t n,
                const std::vector<std::pair<int, double>>& steps, bool damage,
                bool velocity = false) {
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
    if (velocity) attr("velocity", "/fields/velocity", "Vector", 3);
    if (damage) attr("damage", "/fields/damage", "Scalar", 1);
    o << "   </Grid>\n";
  }
  o << "  </Grid>\n </Domain>\n</Xdmf>\n";
  f.commit();
}

/// results_NNNN.h5: points and fields at displacement u (and velocity v when given).
void write_fields(const std::filesystem::path& dir, const Scene& s,
                  const solver::Discretization& body, const solver::Model& model,
                  const solver::Material& material, const Eigen::VectorXd& u,
                  const Eigen::VectorXd* v, bool damage, int step,
                  const std::function<void(io::H5Writer&)>& attributes) {
  const int d = s.dimension;
  const std::size_t N = body.size();
  const auto F = model.point_deformation_gradients(u);
  std::vector<double> X(3 * N), U(3 * N, 0.0), Y(3 * N), Fv(9 * N), Pv(9 * N), Sv(9 * N), W(N);
  std::vector<double> V(v ? 3 * N : 0, 0.0);
  for (std::size_t i = 0; i < N; ++i) {
    for (int a = 0; a < 3; ++a) {
      X[3 * i + a] = body.positions()[i](a);
      if (a < d) U[3 * i + a] = u[d * i + a];
      if (v && a < d) V[3 * i + a] = (*v)[d * i + a];
      Y[3 * i + a] = X[3 * i + a] + U[3 * i + a];
    }
    double psi = 0;
    solver::Mat3 P = solver::Mat3::Zero();
    material.evaluate_at(static_cast<int>(i), F[i], &psi, &P, nullptr);
    const solver::Mat3 Ff = material.full_deformation_gradient(F[i]);
    const solver::Mat3 sigma = P * Ff.transpose() / Ff.determinant();
    for (int a = 0; a < 3; ++a)
      for (int J = 0; J < 3; ++J) {
        Fv[9 * i + 3 * a + J] = Ff(a, J);
        Pv[9 * i + 3 * a + J] = P(a, J);
        Sv[9 * i + 3 * a + J] = sigma(a, J);
      }
    W[i] = psi;
  }
  io::H5Writer h5(dir / fmt::format("results_{:04d}.h5", step),
                  {"pdcg-results", 1, s.units, {}, {}});
  h5.write("points/reference", X, {N, 3});
  h5.write("points/volume", body.volumes(), {N});
  h5.write("fields/displacement", U, {N, 3});
  h5.write("fields/deformed_position", Y, {N, 3});
  h5.write("fields/deformation_gradient", Fv, {N, 9});
  h5.write("fields/first_piola_kirchhoff", Pv, {N, 9});
  h5.write("fields/cauchy_stress", Sv, {N, 9});
  h5.write("fields/energy_density", W, {N});
  if (v) h5.write("fields/velocity", V, {N, 3});
  if (damage) h5.write("fields/damage", body.damage(), {N});
  attributes(h5);
  h5.commit();
}

// ------------------------------------------------------------------ checkpoints
//
// checkpoint_NNNNNNNN.h5 (format pdcg-checkpoint) in the output directory, written
// atomically (H5Writer: temporary + rename) after the outputs of step N; the previous one
// is deleted only after the new one is in place, so a kill at any moment leaves at least
// one complete checkpoint. It holds the complete solver state, the series text written so
// far and the list of field files, and the resolved scene (a restart refuses another scene).

std::string scene_identity(const Scene& s) {
  Scene c = s;
  c.output_directory = "";  // the restart directory replaces it
  return resolved_yaml(c);
}

std::filesystem::path checkpoint_path(const std::filesystem::path& dir, long step) {
  return dir / fmt::format("checkpoint_{:08d}.h5", step);
}

/// Highest-numbered complete checkpoint in dir (temporaries never match the name).
std::optional<std::filesystem::path> last_checkpoint(const std::filesystem::path& dir) {
  std::optional<std::filesystem::path> best;
  long best_n = -1;
  if (!std::filesystem::is_directory(dir)) return best;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.size() != 22 || name.rfind("checkpoint_", 0) != 0 || name.substr(19) != ".h5")
      continue;
    const std::string digits = name.substr(11, 8);
    if (digits.find_first_not_of("0123456789") != std::string::npos) continue;
    const long n = std::stol(digits);
    if (n > best_n) best_n = n, best = e.path();
  }
  return best;
}

struct Restart {
  std::filesystem::path file;
  std::string kind;  // static | dynamic
  long step = 0;     // completed (load or time) steps
  double t = 0.0;
  std::string series;
  std::vector<std::pair<int, double>> written;
  std::unique_ptr<io::H5Reader> h5;
  std::vector<double> vec(const char* name) const { return h5->read_double(name); }
};

Restart load_checkpoint(const Scene& s, const std::filesystem::path& dir) {
  const auto file = last_checkpoint(dir);
  if (!file)
    throw InputError("no checkpoint to restart from")
        .source(dir.string())
        .key("--restart")
        .expected(
            "a directory holding checkpoint_NNNNNNNN.h5 (written with "
            "output: {checkpoint_every: N})")
        .fix("check the directory, or run without --restart");
  Restart r;
  r.file = *file;
  try {
    // every dataset against its checksum before any is used: a damaged checkpoint (a copy cut
    // short, a disk error) is refused, never restarted from
    r.h5 = std::make_unique<io::H5Reader>(*file);
    r.h5->verify();
  } catch (const InputError& e) {
    throw InputError(std::string("the checkpoint is truncated or corrupt: ") + e.what())
        .source(file->string())
        .key("--restart")
        .fix(
            "run the scene again from the start (without --restart, into another directory), "
            "or put back an intact copy of the checkpoint");
  }
  r.h5->require_format("pdcg-checkpoint", 1);
  r.kind = r.h5->attribute_string("/", "kind");
  r.step = static_cast<long>(r.h5->attribute_int("/", "step"));
  r.t = r.h5->attribute_double("/", "t");
  if (r.h5->read_string("scene") != scene_identity(s))
    throw InputError("the checkpoint was written by another scene")
        .source(file->string())
        .key("--restart")
        .expected(fmt::format("the scene of {} (see scene.resolved.yaml there)", dir.string()))
        .fix("restart with the scene file of the interrupted run");
  r.series = r.h5->read_string("series");
  const auto ws = r.h5->read_int("written/steps");
  const auto wt = r.h5->read_double("written/times");
  for (std::size_t i = 0; i < ws.size(); ++i)
    r.written.emplace_back(static_cast<int>(ws[i]), wt[i]);
  log::info("restart from {}: step {}, t = {:.6g}", file->string(), r.step, r.t);
  return r;
}

/// Starts a checkpoint file with the common part; the caller adds the state and commits.
std::unique_ptr<io::H5Writer> begin_checkpoint(const Scene& s, const std::filesystem::path& dir,
                                               const char* kind, long step, double t,
                                               const std::string& series,
                                               const std::vector<std::pair<int, double>>& written) {
  auto h5 = std::make_unique<io::H5Writer>(checkpoint_path(dir, step),
                                           io::FileInfo{"pdcg-checkpoint", 1, s.units, {}, {}});
  h5->attribute("/", "kind", kind);
  h5->attribute("/", "step", static_cast<std::int64_t>(step));
  h5->attribute("/", "t", t);
  h5->write("scene", scene_identity(s));
  h5->write("series", series);
  std::vector<std::int64_t> ws;
  std::vector<double> wt;
  for (const auto& [n, tw] : written) ws.push_back(n), wt.push_back(tw);
  h5->write("written/steps", ws);
  h5->write("written/times", wt);
  return h5;
}

void finish_checkpoint(io::H5Writer& h5, const std::filesystem::path& dir, long step) {
  h5.commit();
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("checkpoint_", 0) == 0 && name.size() == 22 && name.substr(19) == ".h5" &&
        e.path() != checkpoint_path(dir, step))
      std::filesystem::remove(e.path());
  }
}

/// An InputError of the solver set-up as an error of the scene file (file:line of its key).
InputError& with_line(const Scene& s, InputError& e) {
  e.source(s.source.string());
  if (const long l = checks::line_of(s, e.key_name()); l > 0 && e.line_number() == 0) e.line(l);
  return e;
}

Eigen::VectorXd vec_of(const std::vector<double>& v) {
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}
std::vector<double> std_of(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

// ------------------------------------------------------------------ dynamics

void run_dynamic(const Scene& s, const std::filesystem::path& dir,
                 const std::optional<Restart>& restart, solver::Discretization& body,
                 solver::Model& model, const solver::Material& material,
                 std::vector<solver::DisplacementSet> dsets, std::vector<solver::TractionSet> tsets,
                 const std::function<void()>& begin_outputs) {
  const int d = s.dimension;
  const std::size_t N = body.size();
  if (restart && restart->kind != "dynamic")
    throw InputError("the checkpoint is of a quasi-static run").source(restart->file.string());
  solver::ExplicitOptions eo;
  eo.density = s.density;
  eo.time_step = s.time_step;
  eo.safety = s.safety;
  eo.allow_unstable = s.allow_unstable;
  if (s.damping_type == "viscous") {
    eo.damping_type = solver::ExplicitDamping::viscous;
    eo.damping = s.damping_coefficient;
  } else if (s.damping_type == "adaptive-dynamic-relaxation") {
    eo.damping_type = solver::ExplicitDamping::adaptive;
  }
  std::unique_ptr<solver::ExplicitSolver> ex;
  try {
    // tractions: nominal t*(t) with t the time, as the displacement values of dynamic scenes
    ex = std::make_unique<solver::ExplicitSolver>(model, dsets, std::move(tsets), eo);
  } catch (InputError& e) {
    throw with_line(s, e);  // e.g. a time step above the stable limit: refused, nothing written
  }
  begin_outputs();
  // Steps: auto → Δt = end_time / ⌈end_time / (safety Δt_crit)⌉ (ends exactly at end_time,
  // still ≤ safety Δt_crit); a given Δt is kept and the last step may pass end_time.
  const double dt0 = ex->time_step();
  long steps = static_cast<long>(std::ceil(s.end_time / dt0 * (1 - 1e-12)));
  if (!(s.time_step > 0)) ex->shorten_time_step(s.end_time / static_cast<double>(steps));
  double dt = ex->time_step();
  const double dt_start = dt;
  double dt_min = dt;
  // Dynamic fracture (docs/effects.md §3c): only when the scene lists rupture.
  std::unique_ptr<solver::Rupture> rupture;
  if (s.rupture) {
    rupture = std::make_unique<solver::Rupture>(body, model, s.rupture_options);
    ex->attach_rupture(rupture.get());
    log::info("dynamic fracture: {} > {} breaks a bond (checked every {} step{})",
              solver::to_string(s.rupture_options.criterion), s.rupture_options.critical,
              s.rupture_options.check_every, s.rupture_options.check_every == 1 ? "" : "s");
  }
  log::info("explicit dynamics: {} steps of {:.6g} to t = {:.6g} (stable limit {:.6g}, {:.3g}×)",
            steps, dt, s.end_time, ex->stable_limit(), dt / ex->stable_limit());
  // initial velocity (free components only; prescribed ones follow ū(t))
  bool any_v = false;
  for (int a = 0; a < d; ++a) any_v = any_v || static_cast<bool>(s.initial_velocity[a]);
  if (any_v && !restart) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(model.dofs());
    for (std::size_t k = 0; k < N; ++k) {
      const double x[3] = {body.positions()[k](0), body.positions()[k](1), body.positions()[k](2)};
      for (int a = 0; a < d; ++a)
        if (s.initial_velocity[a]) v[d * k + a] = s.initial_velocity[a](x);
    }
    for (const auto& ds : dsets)
      for (int p : ds.points)
        for (int a = 0; a < d; ++a)
          if (ds.component[a]) v[d * p + a] = 0.0;
    ex->set_velocity(v);
  }
  const char* axes[3] = {"x", "y", "z"};
  std::ostringstream csv;
  std::vector<std::pair<int, double>> written;
  long first = 1;
  if (restart) {
    solver::ExplicitSolver::State st;
    st.u = vec_of(restart->vec("state/u"));
    st.v = vec_of(restart->vec("state/v"));
    st.a = vec_of(restart->vec("state/a"));
    st.f = vec_of(restart->vec("state/f"));
    if (restart->h5->exists("state/f_prev")) st.f_prev = vec_of(restart->vec("state/f_prev"));
    st.t = restart->t;
    st.c = restart->h5->attribute_double("/", "damping_coefficient");
    st.dt = restart->h5->attribute_double("/", "time_step");
    st.crit = restart->h5->attribute_double("/", "stable_limit");
    st.steps = static_cast<long>(restart->h5->attribute_int("/", "solver_steps"));
    steps = static_cast<long>(restart->h5->attribute_int("/", "steps_planned"));
    if (rupture)
      rupture->restore(restart->h5->read_int("rupture/broken"), {}, {},
                       restart->h5->read_int("rupture/point_stencils_off"));
    if (st.u.size() != static_cast<Eigen::Index>(model.dofs()))
      throw InputError("the checkpoint does not fit the scene's body")
          .source(restart->file.string());
    ex->restore(st);
    dt = ex->time_step();
    csv << restart->series;
    written = restart->written;
    first = restart->step + 1;
  } else {
    csv << csv_units_comment(s, true) << "step,t,kinetic,internal,total,total_verlet";
    for (const auto& ds : dsets)  // reactions of the prescribed components only
      for (int a = 0; a < d; ++a)
        if (ds.component[a]) csv << "," << ds.name << "_f" << axes[a];
    if (!s.damping_type.empty()) csv << ",damping_coefficient";
    if (rupture) csv << ",broken_bonds";
    csv << "\n";
  }
  auto sample = [&](long n) {
    const double ek = ex->kinetic_energy(), ei = model.energy(ex->displacement());
    // total_verlet: ½ v_{n−½}·M v_{n+½} + Π, the energy velocity Verlet conserves exactly for
    // a linear system (E_kin + Π oscillates by O((ωΔt)²) around it; docs/effects.md)
    csv << n << ","
        << fmt::format("{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", ex->time(), ek, ei, ek + ei,
                       ex->modified_kinetic_energy() + ei);
    for (std::size_t i = 0; i < dsets.size(); ++i) {
      const Vec3 r = ex->reaction(i);
      for (int a = 0; a < d; ++a)
        if (dsets[i].component[a]) csv << "," << fmt::format("{:.17g}", r(a));
    }
    if (!s.damping_type.empty()) csv << "," << fmt::format("{:.17g}", ex->damping_coefficient());
    if (rupture) csv << "," << body.broken_bonds();
    csv << "\n";
    return ek + ei;
  };
  auto write_series = [&] {
    io::AtomicTextFile f(dir / "series.csv");
    f.stream() << csv.str();
    f.commit();
  };
  auto write_step = [&](long n) {
    write_fields(dir, s, body, model, material, ex->displacement(), &ex->velocity(), s.rupture,
                 static_cast<int>(n), [&](io::H5Writer& h5) {
                   h5.attribute("/", "step", static_cast<std::int64_t>(n));
                   h5.attribute("/", "time", ex->time());
                 });
    written.emplace_back(static_cast<int>(n), ex->time());
    write_xdmf(dir, N, written, s.rupture, true);
    write_series();
  };
  double E0 = 0.0;
  if (!restart) {
    E0 = sample(0);
    write_step(0);
  } else {
    E0 = ex->kinetic_energy() + model.energy(ex->displacement());
  }
  Progress progress("steps", static_cast<std::uint64_t>(steps));
  const long progress_every = std::max(1L, steps / 2000);
  double E = E0;
  std::size_t break_events = 0;
  for (long n = first; n <= steps; ++n) {
    try {
      ex->step();
      if (rupture && ex->last_rupture().broken > 0) {
        const auto& p = ex->last_rupture();
        if (body.broken_bonds() == p.broken)
          log::info("dynamic fracture: first bonds break at step {} (t = {:.6g}): {} bonds", n,
                    ex->time(), p.broken);
        ++break_events;
        log::debug(
            "step {} t = {:.6g}: {} bonds broke ({} with an inverted stencil; {} in total), {} "
            "stencils rebuilt, {} ill-posed stencils off",
            n, ex->time(), p.broken, p.inverted, body.broken_bonds(), p.rebuilt,
            body.suppressed_stencils());
      }
      if (rupture && ex->time_step() != dt) {
        // rebuilt stencils changed the stable limit: the remaining time in steps of the new
        // size (auto: shortened to end exactly at end_time)
        const double rest = s.end_time - ex->time();
        const long k =
            rest <= 1e-12 * s.end_time
                ? 0L  // end_time reached: this step is the last
                : std::max(1L, static_cast<long>(std::ceil(rest / ex->time_step() * (1 - 1e-12))));
        if (!(s.time_step > 0) && k > 0) ex->shorten_time_step(rest / static_cast<double>(k));
        dt = ex->time_step();
        dt_min = std::min(dt_min, dt);
        steps = n + k;
      }
    } catch (const NumericalError& e) {
      write_series();  // the series up to the failure, for the diagnosis
      throw NumericalError(
          fmt::format("{} (step {}; Δt = {:.6g} is {:.3g}× the stable limit {:.6g})", e.what(), n,
                      dt, dt / ex->stable_limit(), ex->stable_limit()));
    }
    const bool last = n == steps;
    if (n % s.series_every == 0 || last) E = sample(n);
    if (!std::isfinite(E) || !ex->displacement().allFinite())
      throw NumericalError(fmt::format(
          "explicit dynamics diverged at step {} (t = {:.6g}): energy {} — the time step {:.6g} "
          "is {:.3g}× the stable limit {:.6g}",
          n, ex->time(), E, dt, dt / ex->stable_limit(), ex->stable_limit()));
    if (n % s.output_every == 0 || last) write_step(n);
    if (s.checkpoint_every > 0 && (n % s.checkpoint_every == 0 || last)) {
      if (n % s.output_every != 0 && !last) write_series();
      auto h5 = begin_checkpoint(s, dir, "dynamic", n, ex->time(), csv.str(), written);
      const auto st = ex->state();
      h5->write("state/u", std_of(st.u));
      h5->write("state/v", std_of(st.v));
      h5->write("state/a", std_of(st.a));
      h5->write("state/f", std_of(st.f));
      if (st.f_prev.size() > 0) h5->write("state/f_prev", std_of(st.f_prev));
      h5->attribute("/", "damping_coefficient", st.c);
      h5->attribute("/", "time_step", st.dt);
      h5->attribute("/", "stable_limit", st.crit);
      h5->attribute("/", "solver_steps", static_cast<std::int64_t>(st.steps));
      h5->attribute("/", "steps_planned", static_cast<std::int64_t>(steps));
      if (rupture) {
        h5->write("rupture/broken", rupture->broken_pairs());
        const auto po = body.suppressed_point_stencils();
        h5->write("rupture/point_stencils_off", std::vector<std::int64_t>(po.begin(), po.end()));
      }
      finish_checkpoint(*h5, dir, n);
    }
    if (n % progress_every == 0)  // formatting the line allocates: not every step
      progress.update(static_cast<std::uint64_t>(n),
                      fmt::format("t = {:.4g}, E = {:.6g} ({:+.2e}){}", ex->time(), E,
                                  E0 != 0 ? (E - E0) / std::abs(E0) : 0.0,
                                  rupture ? fmt::format(", {} bonds broken", body.broken_bonds())
                                          : std::string()));
  }
  progress.finish(rupture
                      ? fmt::format("t = {:.4g}, {} bonds broken", ex->time(), body.broken_bonds())
                      : fmt::format("t = {:.4g}", ex->time()));
  write_series();
  if (rupture)
    log::info("dynamic fracture: {} bonds broken in {} break events, {} ill-posed stencils off{}",
              body.broken_bonds(), break_events, body.suppressed_stencils(),
              dt != dt_start ? fmt::format("; time step at the end {:.6g} (start {:.6g}, smallest "
                                           "{:.6g}, stable limit {:.6g})",
                                           dt, dt_start, dt_min, ex->stable_limit())
                             : std::string());
  log::info(
      "done: {} steps to t = {:.6g}; total energy {:.10g} (start {:.10g}, change {:.3e}); "
      "results in {}",
      steps, ex->time(), E, E0, E0 != 0 ? (E - E0) / std::abs(E0) : 0.0, dir.string());
}

}  // namespace

solver::Discretization make_discretization(const Scene& s) {
  solver::DiscretizationOptions dopt;
  dopt.horizon_factor = s.horizon_factor;
  dopt.horizon = s.horizon_value;
  if (!s.model_geometry) return solver::Discretization::grid(s.geometry, dopt);
  const auto& m = *s.model_geometry;
  log::info("geometry: {} points of {} model {}; surface rule {} ({} surface points), spacing {}",
            m.points.size(), m.kind, m.file.string(),
            m.cloud.rule == solver::SurfaceRule::lattice ? "lattice (Wigner–Seitz faces)"
                                                         : "voronoi (ball-clipped cells)",
            m.cloud.surface_points, m.cloud.spacing);
  return solver::Discretization::from_points(s.dimension, m.points, m.cloud.volume, m.cloud.surface,
                                             m.cloud.spacing, {}, dopt);
}

std::unique_ptr<solver::Material> make_material(const Scene& s) {
  if (s.material_model == "cauchy-born" && s.material_per_point)
    return std::make_unique<body::PerPointCauchyBornMaterial>(
        std::make_shared<const body::Body>(body::read_body(s.material_file)),
        s.model_geometry->cloud.volume, s.material_file.string());
  if (s.material_model == "cauchy-born")
    return body::CauchyBornMaterial::from_file(s.material_file);
  const auto kin = s.dimension == 3      ? solver::Kinematics::three_d
                   : s.plane == "stress" ? solver::Kinematics::plane_stress
                                         : solver::Kinematics::plane_strain;
  return solver::make_neo_hookean({s.shear_modulus, s.bulk_modulus}, kin);
}

void run_scene(const Scene& s, const std::optional<std::filesystem::path>& out_override) {
  RunOptions o;
  o.output = out_override;
  run_scene(s, o);
}

void run_scene(const Scene& s, const RunOptions& ro) {
  const std::filesystem::path dir =
      ro.restart ? *ro.restart : (ro.output ? *ro.output : s.output_directory);
  std::optional<Restart> restart;
  if (ro.restart) restart = load_checkpoint(s, dir);
  // Before any computation the output directory is checked: it exists or can be created, and
  // takes a file (docs/formats.md). Directories this check creates are removed again if the
  // scene's set-up is refused below, so that a refused scene leaves nothing behind
  // (docs/solver.md §6); scene.resolved.yaml is written once everything is checked.
  const char* dir_option = ro.restart ? "--restart" : ro.output ? "--output" : "output.directory";
  std::vector<std::filesystem::path> created;  // directories the check creates, outermost last
  {
    std::error_code ec;
    for (auto p = std::filesystem::absolute(dir, ec); !ec && !p.empty() &&
                                                      !std::filesystem::exists(p, ec) &&
                                                      p != p.parent_path();
         p = p.parent_path())
      created.push_back(p);
  }
  io::require_writable_directory(dir, dir_option);
  if (const int n = io::remove_stale_temporaries(dir))
    log::info("removed {} temporary file{} left in {} by a killed run", n, n == 1 ? "" : "s",
              dir.string());
  bool outputs_begun = false;
  struct RemoveCreatedOnRefusal {
    const std::vector<std::filesystem::path>& dirs;
    const bool& begun;
    ~RemoveCreatedOnRefusal() {
      if (begun) return;
      std::error_code ec;
      for (const auto& p : dirs) std::filesystem::remove(p, ec);  // only removes empty ones
    }
  } remove_created{created, outputs_begun};
  auto begin_outputs = [&] {
    outputs_begun = true;
    io::AtomicTextFile f(dir / "scene.resolved.yaml");
    f.stream() << resolved_yaml(s);
    f.commit();
  };
  auto body = make_discretization(s);
  log::info("body: {} points, spacing {}, horizon {}", body.size(), body.spacing(), body.horizon());
  const auto material = make_material(s);
  log::info("material: {}", material->name());
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
  checks::boundary_sets(s, body, dsets);
  if (s.inertia) {
    run_dynamic(s, dir, restart, body, model, *material, std::move(dsets), std::move(tsets),
                begin_outputs);
    return;
  }
  solver::NewtonOptions nopt = s.newton;
  nopt.steps = s.steps;
  std::unique_ptr<solver::StaticSolver> solver_ptr;
  try {
    solver_ptr = std::make_unique<solver::StaticSolver>(model, dsets, tsets, nopt);
  } catch (InputError& e) {
    throw with_line(s, e);
  }
  solver::StaticSolver& solver = *solver_ptr;
  // Rupture: only when the scene lists it (no broken flags, no checks otherwise).
  std::unique_ptr<solver::Rupture> rupture;
  if (s.rupture) {
    rupture = std::make_unique<solver::Rupture>(body, model, s.rupture_options);
    log::info("rupture: {} > {} breaks a bond; staggered re-equilibration at fixed load",
              solver::to_string(s.rupture_options.criterion), s.rupture_options.critical);
  }
  begin_outputs();
  const int d = s.dimension;
  const std::size_t N = body.size();
  std::vector<std::pair<int, double>> written;
  std::ostringstream csv;
  const char* axes[3] = {"x", "y", "z"};
  int first = 1;
  if (restart) {
    if (restart->kind != "static")
      throw InputError("the checkpoint is of a dynamic run").source(restart->file.string());
    solver.prepare_restart();  // pattern analysis on the model of a fresh start
    if (rupture) {
      const auto pairs = restart->h5->read_int("rupture/broken");
      const auto ap = restart->h5->read_int("rupture/anchor_points");
      rupture->restore(pairs, std::vector<int>(ap.begin(), ap.end()),
                       restart->vec("rupture/anchor_targets"),
                       restart->h5->exists("rupture/point_stencils_off")
                           ? restart->h5->read_int("rupture/point_stencils_off")
                           : std::vector<std::int64_t>{});
    }
    solver.restore(vec_of(restart->vec("state/u")), vec_of(restart->vec("state/f")), restart->t,
                   static_cast<int>(restart->h5->attribute_int("/", "solver_step")));
    csv << restart->series;
    written = restart->written;
    first = static_cast<int>(restart->step) + 1;
  } else {
    csv << csv_units_comment(s, false) << "step,t";
    for (const auto& ds : dsets)  // reactions of the prescribed components only
      for (int a = 0; a < d; ++a)
        if (ds.component[a]) csv << "," << ds.name << "_f" << axes[a];
    if (rupture) csv << ",broken_bonds";
    csv << "\n";
    csv << "0,0";
    for (std::size_t i = 0; i < dsets.size(); ++i)
      for (int a = 0; a < d; ++a)
        if (dsets[i].component[a]) csv << ",0";
    if (rupture) csv << ",0";
    csv << "\n";
  }
  auto write_csv = [&] {
    io::AtomicTextFile f(dir / "reactions.csv");
    f.stream() << csv.str();
    f.commit();
  };
  write_csv();
  int counter = 0;
  auto on_step = [&](const solver::StepReport& rep) {
    if (rupture) rupture->stagger(solver);  // re-equilibrate at this load until no bond breaks
    csv << rep.step << "," << fmt::format("{:.10g}", rep.t);
    for (std::size_t i = 0; i < dsets.size(); ++i) {
      const Vec3 r = solver.reaction(i);
      for (int a = 0; a < d; ++a)
        if (dsets[i].component[a]) csv << "," << fmt::format("{:.10g}", r(a));
    }
    if (rupture) csv << "," << body.broken_bonds();
    csv << "\n";
    write_csv();
    ++counter;
    const bool last = rep.t >= 1.0 - 1e-12;
    if (counter % s.output_every != 0 && !last) return;
    write_fields(dir, s, body, model, *material, solver.displacement(), nullptr, s.rupture,
                 rep.step, [&](io::H5Writer& h5) {
                   h5.attribute("/", "step", static_cast<std::int64_t>(rep.step));
                   h5.attribute("/", "load_factor", rep.t);
                   h5.attribute("/", "newton_iterations",
                                static_cast<std::int64_t>(rep.iterations));
                   h5.attribute("/", "residual", rep.residual);
                 });
    written.emplace_back(rep.step, rep.t);
    write_xdmf(dir, N, written, s.rupture);
  };
  // Nominal load steps t = k/steps; a checkpoint after every checkpoint_every of them.
  auto progress_text = [&] {
    return rupture ? fmt::format("t = {:.4g}, {} bonds broken", solver.load_factor(),
                                 body.broken_bonds())
                   : fmt::format("t = {:.4g}", solver.load_factor());
  };
  Progress progress("load steps", static_cast<std::uint64_t>(s.steps));
  for (int k = first; k <= s.steps; ++k) {
    solver.advance_to(static_cast<double>(k) / s.steps, on_step);
    if (s.checkpoint_every > 0 && (k % s.checkpoint_every == 0 || k == s.steps)) {
      auto h5 = begin_checkpoint(s, dir, "static", k, solver.load_factor(), csv.str(), written);
      h5->write("state/u", std_of(solver.displacement()));
      h5->write("state/f", std_of(solver.internal_force()));
      h5->attribute("/", "solver_step", static_cast<std::int64_t>(solver.step()));
      if (rupture) {
        h5->write("rupture/broken", rupture->broken_pairs());
        const auto po = body.suppressed_point_stencils();
        h5->write("rupture/point_stencils_off", std::vector<std::int64_t>(po.begin(), po.end()));
        const auto& ap = model.anchors();
        h5->write("rupture/anchor_points", std::vector<std::int64_t>(ap.begin(), ap.end()));
        h5->write("rupture/anchor_targets", model.anchor_targets());
      }
      finish_checkpoint(*h5, dir, k);
    }
    progress.update(static_cast<std::uint64_t>(k), progress_text());
  }
  progress.finish(progress_text());
  log::info("done: {} steps, results in {}", counter, dir.string());
}

}  // namespace pdcg::scene
