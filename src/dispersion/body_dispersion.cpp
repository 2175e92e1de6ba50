#include "pdcg/dispersion/body_dispersion.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "pdcg/core/error.hpp"
#include "pdcg/core/units.hpp"

namespace pdcg::dispersion {

LatticeGuess detect_lattice(const body::Body& b, std::size_t k) {
  const auto& f = b.families;
  double dmin = std::numeric_limits<double>::infinity();
  for (auto i = f.offset[k]; i < f.offset[k + 1]; ++i) {
    const Eigen::Vector3d xi = atomistic::bond_vector(f, b.x, k, static_cast<std::size_t>(i));
    dmin = std::min(dmin, std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]));
  }
  int z = 0;
  bool planar = true, linear = true;
  for (auto i = f.offset[k]; i < f.offset[k + 1]; ++i) {
    const Eigen::Vector3d xi = atomistic::bond_vector(f, b.x, k, static_cast<std::size_t>(i));
    const double r = std::sqrt(xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]);
    if (r > 1.01 * dmin) continue;
    ++z;
    if (std::abs(xi[2]) > 1e-6 * r) planar = false;
    if (std::abs(xi[1]) > 1e-6 * r || std::abs(xi[2]) > 1e-6 * r) linear = false;
  }
  LatticeGuess g;
  g.nearest = dmin;
  g.coordination = z;
  if (z == 2 && linear)
    g = {"chain", dmin, dmin, z};
  else if (z == 6 && planar)
    g = {"hex", dmin, dmin, z};
  else if (z == 6)
    g = {"sc", dmin, dmin, z};
  else if (z == 8)
    g = {"bcc", 2.0 * dmin / std::sqrt(3.0), dmin, z};
  else if (z == 12)
    g = {"fcc", std::sqrt(2.0) * dmin, dmin, z};
  else
    throw InputError("cannot tell the Bravais lattice from the nearest-neighbour shell")
        .key("--path")
        .value(fmt::format("{} nearest neighbours at {:.6g}", z, dmin))
        .expected("2 (chain), 6 (hex in a plane, sc), 8 (bcc) or 12 (fcc)")
        .fix("pass --lattice and --a, or use --direction");
  return g;
}

namespace {

std::size_t nearest_centre(const body::Body& b, const std::vector<double>& pts) {
  const Eigen::Vector3d c = 0.5 * (b.box.lo + b.box.hi);
  std::size_t best = 0;
  double d2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < pts.size() / 3; ++i) {
    const double dd =
        (Eigen::Vector3d(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]) - c).squaredNorm();
    if (dd < d2) {
      d2 = dd;
      best = i;
    }
  }
  return best;
}

}  // namespace

double zone_edge(const body::Body& body, std::size_t atom, const Eigen::Vector3d& direction,
                 std::string_view option, std::string_view given) {
  const auto& f = body.families;
  double nearest = std::numeric_limits<double>::infinity();
  for (auto i = f.offset[atom]; i < f.offset[atom + 1]; ++i)
    nearest = std::min(nearest,
                       atomistic::bond_vector(f, body.x, atom, static_cast<std::size_t>(i)).norm());
  double proj = std::numeric_limits<double>::infinity();
  for (auto i = f.offset[atom]; i < f.offset[atom + 1]; ++i) {
    const Eigen::Vector3d xi = atomistic::bond_vector(f, body.x, atom, static_cast<std::size_t>(i));
    if (xi.norm() > 1.01 * nearest) continue;
    const double p = std::abs(xi.dot(direction));
    if (p > 1e-9 * nearest) proj = std::min(proj, p);
  }
  if (!std::isfinite(proj))
    throw InputError("no nearest-neighbour bond has a component along the direction")
        .key(option)
        .value(given.empty() ? fmt::format("{},{},{}", direction[0], direction[1], direction[2])
                             : std::string(given))
        .expected("a direction with a zone edge from the nearest-neighbour shell")
        .fix(option == "--direction" ? "pass --kmax" : "pass kmax=");
  return std::numbers::pi / proj;
}

std::size_t representative_atom(const body::Body& b, std::optional<std::size_t> point) {
  if (b.homogenisation) {
    const auto& h = *b.homogenisation;
    const std::size_t p = point ? *point : nearest_centre(b, h.points);
    if (p >= h.size() || h.offset[p] == h.offset[p + 1])
      throw InputError("point index out of range or point without atoms")
          .key("--point")
          .value(std::to_string(p))
          .expected(fmt::format("0 … {}", h.size() - 1));
    return static_cast<std::size_t>(h.atom[static_cast<std::size_t>(h.offset[p])]);
  }
  const std::size_t k = point ? *point : nearest_centre(b, b.x);
  if (k >= b.size())
    throw InputError("point index out of range")
        .key("--point")
        .value(std::to_string(k))
        .expected(fmt::format("0 … {}", b.size() - 1));
  return k;
}

BodyDispersion::BodyDispersion(const body::Body& b, std::optional<std::size_t> point, bool cell)
    : body_(b), cell_(cell) {
  if (b.statistics)
    throw InputError("model dispersion of statistical bodies is not available yet")
        .key("body kind")
        .value("statistical")
        .expected("a delta, homogenised or rescaled body")
        .fix("compute the dispersion of the delta body built from the mean positions");
  if (!b.potential) throw InputError("the body has no potential to linearise").key("potential");
  const std::size_t n = b.size();
  std::vector<std::int32_t> atoms;
  if (cell) {
    if (!b.periodic())
      throw InputError("cell dispersion needs a periodic body")
          .key("--cell")
          .expected("a periodic box");
    description_ = fmt::format("periodic cell of {} atoms (3N = {} branches)", n, 3 * n);
  } else if (b.homogenisation) {
    const auto& h = *b.homogenisation;
    const std::size_t p = point ? *point : nearest_centre(b, h.points);
    if (p >= h.size())
      throw InputError("point index out of range")
          .key("--point")
          .value(std::to_string(p))
          .expected(fmt::format("0 … {}", h.size() - 1));
    for (auto i = h.offset[p]; i < h.offset[p + 1]; ++i) {
      site_.emplace_back(h.atom[static_cast<std::size_t>(i)],
                         h.weight[static_cast<std::size_t>(i)]);
      atoms.push_back(h.atom[static_cast<std::size_t>(i)]);
    }
    if (site_.empty())
      throw InputError("homogenised point carries no atoms")
          .key("--point")
          .value(std::to_string(p));
    representative_ = static_cast<std::size_t>(site_.front().first);
    description_ =
        fmt::format("homogenised point {} ({} atoms, kernel {})", p, site_.size(), h.kernel);
  } else {
    const std::size_t k = point ? *point : nearest_centre(b, b.x);
    if (k >= n)
      throw InputError("point index out of range")
          .key("--point")
          .value(std::to_string(k))
          .expected(fmt::format("0 … {}", n - 1));
    site_.emplace_back(static_cast<std::int32_t>(k), 1.0);
    atoms.push_back(static_cast<std::int32_t>(k));
    representative_ = k;
    description_ = fmt::format("atom id {} ({} body)", b.id[k], body::to_string(b.kind));
  }
  lin_ = std::make_unique<LinearisedFamilies>(*b.potential, b.families, b.x, b.type, atoms);
}

Eigen::VectorXd BodyDispersion::omega(const Eigen::Vector3d& kappa) const {
  const double mvv2e = unit_constants(body_.units).mvv2e;
  if (cell_) return cell_omega(*lin_, body_.mass, kappa, mvv2e);
  return point_omega(*lin_, site_, body_.mass, kappa, mvv2e);
}

KappaGrid BodyDispersion::grid() const {
  if (cell_)
    throw InputError("--grid works for one point of a Bravais-lattice body, not in cell mode")
        .key("--grid")
        .value("--cell")
        .expected("--grid without --cell")
        .fix("drop --cell, or use --direction/--path with --cell");
  return point_omega_grid(*lin_, site_, body_.mass, body_.box, unit_constants(body_.units).mvv2e);
}

}  // namespace pdcg::dispersion
