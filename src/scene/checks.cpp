#include "checks.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pdcg/core/error.hpp"

namespace pdcg::scene::checks {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

using Kind = NumberRule::Kind;

YAML::Node child(const YAML::Node& n, const std::string& key) {
  if (!n.IsDefined() || !n.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
  return n[key];
}

/// Label of item k of the list `key` (boundary items by their name, as the parser names them).
std::string item_label(const std::string& key, const YAML::Node& item, std::size_t k) {
  if (key == "boundary") {
    const auto name = child(item, "name");
    if (name.IsDefined() && name.IsScalar()) return name.Scalar();
    return fmt::format("set{}", k);
  }
  return std::to_string(k);
}

/// The nodes at `path` (segments split at '.'; "name[]" = every item of the list name).
void collect(const YAML::Node& n, const std::vector<std::string>& seg, std::size_t i,
             const std::string& prefix, std::vector<std::pair<YAML::Node, std::string>>& out) {
  if (i == seg.size()) {
    out.emplace_back(n, prefix);
    return;
  }
  const std::string& s = seg[i];
  const bool list = s.size() > 2 && s.compare(s.size() - 2, 2, "[]") == 0;
  const std::string name = list ? s.substr(0, s.size() - 2) : s;
  const std::string key = prefix.empty() ? name : prefix + "." + name;
  const auto c = child(n, name);
  if (!c.IsDefined()) return;
  if (!list) return collect(c, seg, i + 1, key, out);
  if (!c.IsSequence()) return;  // the parser names the structural error
  for (std::size_t k = 0; k < c.size(); ++k)
    collect(c[k], seg, i + 1, key + "[" + item_label(name, c[k], k) + "]", out);
}

std::vector<std::string> split(const std::string& path) {
  std::vector<std::string> seg;
  std::size_t a = 0;
  for (std::size_t b; (b = path.find('.', a)) != std::string::npos; a = b + 1)
    seg.push_back(path.substr(a, b - a));
  seg.push_back(path.substr(a));
  return seg;
}

std::string shown(const YAML::Node& n) {
  if (n.IsScalar()) return n.Scalar();
  if (n.IsSequence()) return "(a list)";
  if (n.IsMap()) return "(a mapping)";
  return "(nothing)";
}

void check(const NumberRule& r, const YAML::Node& n, const std::string& key,
           const std::string& file) {
  auto fail = [&](const std::string& problem) {
    InputError e(problem);
    e.source(file).key(key).value(shown(n)).expected(r.expected);
    if (n.Mark().line >= 0) e.line(n.Mark().line + 1);
    return e;
  };
  if (!n.IsScalar())
    throw fail(r.kind == Kind::integer ? "expected an integer" : "expected a number");
  if (r.kind == Kind::real_or_auto && n.Scalar() == "auto") return;
  double v = 0;
  if (r.kind == Kind::integer) {
    try {
      v = n.as<int>();
    } catch (const YAML::Exception&) {
      throw fail("not an integer");
    }
  } else {
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      if (r.kind == Kind::real_or_fn) return;  // an expression: parsed and evaluated later
      throw fail("not a number");
    }
    if (!std::isfinite(v)) throw fail("not a finite number");
  }
  const bool low = r.lo_open ? v > r.lo : v >= r.lo;
  const bool high = r.hi_open ? v < r.hi : v <= r.hi;
  if (!low || !high) throw fail("out of range");
}

void lines(const YAML::Node& n, const std::string& key, std::map<std::string, long>& out) {
  if (n.IsMap()) {
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) continue;
      const std::string k = key.empty() ? kv.first.Scalar() : key + "." + kv.first.Scalar();
      out[k] = kv.first.Mark().line + 1;
      lines(kv.second, k, out);
    }
  } else if (n.IsSequence()) {
    const std::string name =
        key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1);
    for (std::size_t k = 0; k < n.size(); ++k) {
      const std::string item = key + "[" + item_label(name, n[k], k) + "]";
      out[item] = n[k].Mark().line + 1;
      lines(n[k], item, out);
    }
  }
}

/// The parameter values the run evaluates boundary values at: the load factors k/steps
/// (quasi-static), or 65 times in [0, end_time] (dynamic; the time steps are not known yet).
std::vector<double> sample_times(const Scene& s) {
  std::vector<double> t;
  if (s.inertia) {
    for (int k = 0; k <= 64; ++k) t.push_back(s.end_time * k / 64.0);
  } else {
    for (int k = 0; k <= s.steps; ++k) t.push_back(static_cast<double>(k) / s.steps);
  }
  return t;
}

const char* kAxes[3] = {"x", "y", "z"};

}  // namespace

void numbers(const YAML::Node& root, const std::string& file,
             const std::vector<NumberRule>& rules) {
  for (const auto& r : rules) {
    std::vector<std::pair<YAML::Node, std::string>> found;
    collect(root, split(r.path), 0, "", found);
    for (const auto& [n, key] : found) check(r, n, key, file);
  }
}

std::map<std::string, long> key_lines(const YAML::Node& root) {
  std::map<std::string, long> out;
  lines(root, "", out);
  return out;
}

long line_of(const Scene& s, const std::string& key) {
  std::string k = key;
  while (!k.empty()) {
    if (const auto it = s.key_lines.find(k); it != s.key_lines.end()) return it->second;
    const auto cut = k.find_last_of(".[");
    if (cut == std::string::npos) break;
    k.resize(cut);
  }
  return 0;
}

InputError error(const Scene& s, const std::string& key, const std::string& problem) {
  InputError e(problem);
  e.source(s.source.string()).key(key);
  if (const long l = line_of(s, key); l > 0) e.line(l);
  return e;
}

void consistency(const Scene& s) {
  const int d = s.dimension;
  if (!s.model_geometry)
    for (int a = 0; a < d; ++a)
      if (s.geometry.spacing > s.geometry.size(a))
        throw error(s, "geometry.spacing", "the spacing exceeds the body size")
            .value(fmt::format("spacing {} > size {} along {}", s.geometry.spacing,
                               s.geometry.size(a), kAxes[a]))
            .expected("a spacing well below every body length (10 or more points across)")
            .fix("reduce geometry.spacing or enlarge geometry.size");
  const auto times = sample_times(s);
  for (const auto& bc : s.boundary) {
    const std::string w = "boundary[" + bc.name + "]";
    bool bounds = false;
    for (int a = 0; a < 3; ++a) {
      bounds = bounds || bc.region.min[a] || bc.region.max[a];
      if (bc.region.min[a] && bc.region.max[a] && *bc.region.min[a] > *bc.region.max[a])
        throw error(s, w + ".region." + kAxes[a] + "_min", "the region is empty")
            .value(fmt::format("{0}_min = {1} > {0}_max = {2}", kAxes[a], *bc.region.min[a],
                               *bc.region.max[a]))
            .expected(fmt::format("{0}_min ≤ {0}_max", kAxes[a]))
            .fix("swap the bounds");
    }
    if (bc.region.point && bounds)
      throw error(s, w + ".region.point", "a point region takes no bounds")
          .expected("region: {point: [...]} (the nearest point) or bounds, not both")
          .fix("remove the point or the bounds");
    for (int a = 0; a < d; ++a) {
      if (!bc.value[a]) continue;
      for (double t : times) {
        const double v = bc.value[a](t);
        if (std::isfinite(v)) continue;
        throw error(s,
                    bc.is_traction ? fmt::format("{}.traction[{}]", w, a)
                                   : w + ".displacement." + std::string(kAxes[a]),
                    fmt::format("the value is not finite at {} = {}",
                                s.inertia ? "time t" : "load factor t", t))
            .value(fmt::format("{} = {}", bc.value_text[a], v))
            .expected(s.inertia ? "finite values for 0 ≤ t ≤ inertia.end_time"
                                : "finite values at every load factor t = k/loading.steps")
            .fix("check the expression (division by zero, log or sqrt of a negative number)");
      }
    }
  }
}

void boundary_sets(const Scene& s, const solver::Discretization& body,
                   const std::vector<solver::DisplacementSet>& dsets) {
  const int d = s.dimension;
  const auto& x = body.positions();
  // A point region picks the nearest point, however far: farther than two spacings from every
  // point it is almost certainly a typo (a coordinate outside the body).
  for (const auto& bc : s.boundary) {
    if (!bc.region.point) continue;
    double best = inf;
    for (const auto& p : x) best = std::min(best, (p - *bc.region.point).norm());
    if (best > 2 * body.spacing())
      throw error(s, "boundary[" + bc.name + "].region.point", "the point is not on the body")
          .value(fmt::format("the nearest point is {:.6g} away ({:.3g} spacings)", best,
                             best / body.spacing()))
          .expected("a point within two spacings of a point of the body")
          .fix(s.model_geometry ? "check the point against the model's points (pdcg info MODEL)"
                                : "check the point against geometry.origin and geometry.size");
  }
  // Two conditions fixing the same dof to different values: one would silently win.
  const auto times = sample_times(s);
  for (std::size_t i = 0; i < dsets.size(); ++i)
    for (std::size_t j = i + 1; j < dsets.size(); ++j)
      for (int a = 0; a < d; ++a) {
        if (!dsets[i].component[a] || !dsets[j].component[a]) continue;
        std::vector<int> p = dsets[i].points, q = dsets[j].points, both;
        std::sort(p.begin(), p.end());
        std::sort(q.begin(), q.end());
        std::set_intersection(p.begin(), p.end(), q.begin(), q.end(), std::back_inserter(both));
        if (both.empty()) continue;
        for (double t : times) {
          const double u = dsets[i].component[a](t), v = dsets[j].component[a](t);
          // equal up to rounding of the two expressions: the same prescription
          if (std::abs(u - v) <= 1e-12 * std::max({1.0, std::abs(u), std::abs(v)})) continue;
          const auto& X = x[both.front()];
          throw error(s, "boundary[" + dsets[j].name + "].displacement." + kAxes[a],
                      fmt::format("boundary conditions '{}' and '{}' fix the same dof to "
                                  "different values",
                                  dsets[i].name, dsets[j].name))
              .value(fmt::format("{} = {} ('{}') vs {} ('{}') at t = {} on {} shared point(s), "
                                 "the first at ({:.6g}, {:.6g}, {:.6g})",
                                 kAxes[a], u, dsets[i].name, v, dsets[j].name, t, both.size(),
                                 X.x(), X.y(), X.z()))
              .expected("one prescribed value per point and component")
              .fix("make the regions disjoint, or give both the same value");
        }
      }
  // Initial velocities at every point of the body.
  for (int a = 0; a < d; ++a) {
    if (!s.initial_velocity[a]) continue;
    for (const auto& p : x) {
      const double xyz[3] = {p.x(), p.y(), p.z()};
      const double v = s.initial_velocity[a](xyz);
      if (std::isfinite(v)) continue;
      throw error(s, std::string("initial.velocity.") + kAxes[a],
                  "the initial velocity is not finite at a point")
          .value(fmt::format("{} = {} at ({:.6g}, {:.6g}, {:.6g})", s.initial_velocity_text[a], v,
                             p.x(), p.y(), p.z()))
          .expected("finite values at every point of the body")
          .fix("check the expression (division by zero, log or sqrt of a negative number)");
    }
  }
}

}  // namespace pdcg::scene::checks
