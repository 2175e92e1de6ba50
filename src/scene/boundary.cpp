// boundary: named regions with prescribed displacements or tractions (numbers or expressions
// in t), and the points a region selects.
#include <cmath>
#include <limits>
#include <set>

#include "checks.hpp"
#include "parse.hpp"

namespace pdcg::scene {

using solver::Vec3;

namespace {

class Boundary final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"boundary", 40, 40}}; }
  std::vector<NumberRule> number_rules() const override {
    std::vector<NumberRule> v;
    for (const char* b : {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"})
      v.push_back({std::string("boundary[].region.") + b, K::real, -inf, true, inf, true,
                   "a finite bound"});
    v.push_back(
        {"boundary[].region.point[]", K::real, -inf, true, inf, true, "a finite coordinate"});
    for (const char* a : {"x", "y", "z"})
      v.push_back({std::string("boundary[].displacement.") + a, K::real_or_fn, -inf, true, inf,
                   true, "a finite number or an expression in t"});
    v.push_back({"boundary[].traction[]", K::real_or_fn, -inf, true, inf, true,
                 "a finite number or an expression in t"});
    return v;
  }
  void parse(const std::string&, const Reader& r, const Node& rootn, Scene& s) override {
    const Ctx c{r.file()};
    const YAML::Node& root = rootn.yaml();
    const int d = s.dimension;
    const auto b = root["boundary"];
    if (!b || !b.IsSequence())
      throw(b ? c.err(b, "boundary", "expected a list")
              : InputError("missing section").source(c.file).key("boundary"))
          .expected("a list of {name, region, displacement|traction}");
    std::set<std::string> names;
    const char* axes[3] = {"x", "y", "z"};
    for (const auto& e : b) {
      c.keys(e, "boundary[]", {"name", "region", "displacement", "traction", "grip"});
      BoundaryCondition bc;
      bc.name = e["name"] ? c.text(e["name"], "boundary[].name")
                          : fmt::format("set{}", s.boundary.size());
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
            bc.value[a] =
                value_fn(c, dn[axes[a]], w + ".displacement." + axes[a], bc.value_text[a]);
        if (e["grip"])
          bc.grip_surface = c.choice(e["grip"], w + ".grip", {"points", "surface"}) == "surface";
      } else if (e["traction"]) {
        if (e["grip"])
          throw c.err(e["grip"], w + ".grip", "grip is a key of displacement sets")
              .fix("drop grip from the traction set");
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
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    auto& y = out.yaml();
    const int d = s.dimension;
    auto vec = [&](const Vec3& v) { emit_vec(y, v, d); };
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
        y << YAML::Key << "grip" << YAML::Value << (bc.grip_surface ? "surface" : "points");
      }
      y << YAML::EndMap;
    }
    y << YAML::EndSeq;
  }
};

}  // namespace

std::unique_ptr<Component> make_boundary_component() { return std::make_unique<Boundary>(); }

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

std::vector<solver::Vec3> surface_grip_offsets(const Scene& s, const solver::Discretization& body,
                                               const BoundaryCondition& bc,
                                               const std::vector<int>& points) {
  const std::string key = "boundary[" + bc.name + "].grip";
  if (s.model_geometry || s.geometry.nodes != solver::GridNodes::cell_centres)
    throw checks::error(s, key, "grip: surface needs a cell-centred grid")
        .value("surface")
        .expected(
            "geometry on a grid with nodes: cells (vertices and model points already "
            "lie on the surface)")
        .fix("drop grip: surface");
  if (s.inertia)
    throw checks::error(s, key,
                        "grip: surface is for static runs (explicit dynamics moves the "
                        "selected points themselves)")
        .value("surface")
        .fix("drop grip: surface");
  const auto& surf = body.surface();
  Vec3 n = Vec3::Zero();
  for (int p : points) n += surf[p];
  int axis = -1;
  if (n.norm() > 0) {
    n.normalize();
    for (int a = 0; a < body.dimension(); ++a)
      if (std::abs(std::abs(n(a)) - 1.0) < 1e-9) axis = a;
  }
  if (axis < 0)
    throw checks::error(s, key, "grip: surface needs a set on one flat face of the box")
        .value("surface")
        .expected(
            "a region selecting the point column (row, layer) next to one face, e.g. "
            "x_min: <right edge>")
        .fix("select one face per displacement set, or drop grip: surface");
  const double area = std::pow(body.spacing(), body.dimension() - 1);
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (int p : points)
    out.push_back(surf[p].dot(n) > 0.5 * area ? Vec3(0.5 * body.spacing() * n) : Vec3::Zero());
  return out;
}

}  // namespace pdcg::scene
