// geometry: a rectangle or box on a grid (holes, cracks), or the points of a model file.
#include <Eigen/Dense>
#include <filesystem>
#include <optional>

#include "parse.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::scene {

using solver::Vec3;

namespace {

// `geometry: {shape: model, file: res.h5}` (docs/solver.md §2.1): the points (and volumes) of a
// model file; surface vectors and spacing from solver::analyse_cloud. Read at load time so a
// bad file is an input error with its line.
void load_model_geometry(const Ctx& c, const YAML::Node& g, const std::filesystem::path& scene_file,
                         Scene& s) {
  for (const char* k : {"origin", "size", "spacing", "nodes", "holes", "cracks", "cut_cells"})
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

class Geometry final : public Component {
 public:
  std::vector<Section> sections() const override { return {{"geometry", 10, 10}}; }
  std::vector<NumberRule> number_rules() const override {
    return {
        {"geometry.origin[]", K::real, -inf, true, inf, true, "a finite coordinate"},
        {"geometry.size[]", K::real, 0, true, inf, true, "a body length > 0"},
        {"geometry.spacing", K::real, 0, true, inf, true, "a grid spacing > 0, e.g. 0.025"},
        {"geometry.holes[].center[]", K::real, -inf, true, inf, true, "a finite coordinate"},
        {"geometry.holes[].radius", K::real, 0, true, inf, true, "a radius > 0"},
        {"geometry.cracks[].from[]", K::real, -inf, true, inf, true, "a finite coordinate"},
        {"geometry.cracks[].to[]", K::real, -inf, true, inf, true, "a finite coordinate"},
    };
  }
  void parse(const std::string&, const Reader& r, const Node& rootn, Scene& s) override {
    const Ctx c{r.file()};
    const YAML::Node& root = rootn.yaml();
    const int d = s.dimension;
    const auto g = root["geometry"];
    if (!g)
      throw InputError("missing section")
          .source(c.file)
          .key("geometry")
          .expected("geometry: {shape: rectangle, origin, size, spacing}");
    c.keys(g, "geometry",
           {"shape", "origin", "size", "spacing", "nodes", "holes", "cracks", "cut_cells", "file"});
    const std::string shape =
        g["shape"] ? c.choice(g["shape"], "geometry.shape", {"rectangle", "box", "model"})
                   : (d == 2 ? "rectangle" : "box");
    if (shape == "model") {
      load_model_geometry(c, g, std::filesystem::path(c.file), s);
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
        s.geometry.nodes =
            c.choice(g["nodes"], "geometry.nodes", {"cells", "vertices"}) == "vertices"
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
      // Cut-cell volumes at the holes (default true; false: whole grid cells).
      if (g["cut_cells"]) s.geometry.cut_cells = c.boolean(g["cut_cells"], "geometry.cut_cells");
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
  }
  void resolve(const std::string&, Emitter& out, const Scene& s) const override {
    auto& y = out.yaml();
    const int d = s.dimension;
    auto vec = [&](const Vec3& v) { emit_vec(y, v, d); };
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
      y << YAML::EndSeq << YAML::Key << "cut_cells" << YAML::Value << s.geometry.cut_cells;
      y << YAML::Key << "cracks" << YAML::Value << YAML::BeginSeq;
      for (const auto& k : s.geometry.cracks) {
        y << YAML::Flow << YAML::BeginMap << YAML::Key << "from" << YAML::Value;
        vec(k.from);
        y << YAML::Key << "to" << YAML::Value;
        vec(k.to);
        y << YAML::EndMap;
      }
      y << YAML::EndSeq << YAML::EndMap;
    }
  }
};

}  // namespace

std::unique_ptr<Component> make_geometry_component() { return std::make_unique<Geometry>(); }

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

}  // namespace pdcg::scene
