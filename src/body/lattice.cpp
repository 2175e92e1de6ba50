#include "pdcg/body/lattice.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>

namespace pdcg::body {

namespace {

/// One bond of an environment: partner type, bond type, pair factor and ξ quantised to q (for
/// ordering) with the exact ξ kept for the tolerance comparison.
struct EnvBond {
  int type = 0, bond_type = 0;
  double factor = 1.0;
  std::int64_t key[3] = {0, 0, 0};
  Eigen::Vector3d xi;
};

bool less(const EnvBond& a, const EnvBond& b) {
  if (a.type != b.type) return a.type < b.type;
  if (a.bond_type != b.bond_type) return a.bond_type < b.bond_type;
  for (int c = 0; c < 3; ++c)
    if (a.key[c] != b.key[c]) return a.key[c] < b.key[c];
  return a.factor < b.factor;
}

bool same(const std::vector<EnvBond>& a, const std::vector<EnvBond>& b, double tol) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].type != b[i].type || a[i].bond_type != b[i].bond_type) return false;
    if (std::abs(a[i].factor - b[i].factor) > 1e-12) return false;
    if ((a[i].xi - b[i].xi).cwiseAbs().maxCoeff() > tol) return false;
  }
  return true;
}

}  // namespace

LatticeInfo detect_lattice(const Body& body, const LatticeOptions& options) {
  LatticeInfo info;
  const auto& f = body.families;
  const std::size_t n = body.size();
  info.class_of.assign(n, -1);
  if (n == 0 || f.points() != n || f.bonds() == 0) {
    info.summary = "not a perfect crystal (no atoms or no bonds)";
    return info;
  }
  double dmin = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < n; ++k)
    for (auto b = static_cast<std::size_t>(f.offset[k]);
         b < static_cast<std::size_t>(f.offset[k + 1]); ++b) {
      const double r = atomistic::bond_vector(f, body.x, k, b).norm();
      if (r > 0) dmin = std::min(dmin, r);
    }
  info.nearest = dmin;
  const double tol = options.tolerance * dmin;
  const double q = tol;  // quantum of the ordering keys

  auto environment = [&](std::size_t k, std::vector<EnvBond>& env) {
    env.clear();
    for (auto b = static_cast<std::size_t>(f.offset[k]);
         b < static_cast<std::size_t>(f.offset[k + 1]); ++b) {
      EnvBond e;
      e.type = body.type[static_cast<std::size_t>(f.neighbor[b])];
      e.bond_type = f.bond_type.empty() ? 0 : f.bond_type[b];
      e.factor = f.pair_factor.empty() ? 1.0 : f.pair_factor[b];
      e.xi = atomistic::bond_vector(f, body.x, k, b);
      for (int c = 0; c < 3; ++c) e.key[c] = std::llround(e.xi[c] / q);
      env.push_back(e);
    }
    std::sort(env.begin(), env.end(), less);
  };

  std::vector<std::vector<EnvBond>> reps;  // one environment per class
  std::vector<int> rep_type;
  std::vector<std::size_t> count;
  std::vector<EnvBond> env;
  bool stopped = false;
  for (std::size_t k = 0; k < n && !stopped; ++k) {
    environment(k, env);
    int c = -1;
    for (std::size_t r = 0; r < reps.size(); ++r)
      if (rep_type[r] == body.type[k] && same(env, reps[r], tol)) {
        c = static_cast<int>(r);
        break;
      }
    if (c < 0) {
      if (static_cast<int>(reps.size()) >= options.max_classes) {
        stopped = true;
        break;
      }
      c = static_cast<int>(reps.size());
      reps.push_back(env);
      rep_type.push_back(body.type[k]);
      count.push_back(0);
    }
    info.class_of[k] = c;
    ++count[static_cast<std::size_t>(c)];
  }
  info.classes = static_cast<int>(reps.size()) + (stopped ? 1 : 0);

  // centres of inversion: every class's environment is its own mirror image ξ → −ξ
  info.centrosymmetric = !stopped;
  for (std::size_t r = 0; r < reps.size() && info.centrosymmetric; ++r) {
    std::vector<EnvBond> m = reps[r];
    for (auto& e : m) {
      e.xi = -e.xi;
      for (int c = 0; c < 3; ++c) e.key[c] = std::llround(e.xi[c] / q);
    }
    std::sort(m.begin(), m.end(), less);
    info.centrosymmetric = same(m, reps[r], tol);
  }

  const int d = std::clamp(body.dimension, 1, 3);
  bool periodic = true;
  for (int i = 0; i < d; ++i) periodic = periodic && body.box.periodic[static_cast<std::size_t>(i)];
  const bool equal = !stopped && std::all_of(count.begin(), count.end(),
                                             [&](std::size_t c) { return c == count.front(); });
  info.perfect = periodic && equal;
  if (!info.perfect) {
    std::size_t largest = 0;
    for (auto c : count) largest = std::max(largest, c);
    info.summary = !periodic ? fmt::format(
                                   "not a perfect crystal (not periodic along all {} directions of "
                                   "the body; {} atom environments)",
                                   d,
                                   stopped ? fmt::format("more than {}", options.max_classes)
                                           : std::to_string(reps.size()))
                   : stopped ? fmt::format(
                                   "not a perfect crystal (more than {} different atom "
                                   "environments: defects, surfaces or displaced atoms)",
                                   options.max_classes)
                             : fmt::format(
                                   "not a perfect crystal ({} atom environments of unequal "
                                   "population, the largest {} of {} atoms: defects or displaced "
                                   "atoms)",
                                   reps.size(), largest, n);
    return info;
  }
  info.basis = static_cast<int>(reps.size());

  // primitive vectors: translations between atoms of class 0 (minimum image, and the family
  // bonds of the first atom to class-0 partners), the shortest independent ones
  std::vector<Eigen::Vector3d> t;
  std::size_t k0 = 0;
  while (info.class_of[k0] != 0) ++k0;
  const Eigen::Vector3d x0(body.x[3 * k0], body.x[3 * k0 + 1], body.x[3 * k0 + 2]);
  for (std::size_t k = 0; k < n; ++k) {
    if (k == k0 || info.class_of[k] != 0) continue;
    const Eigen::Vector3d dx =
        Eigen::Vector3d(body.x[3 * k], body.x[3 * k + 1], body.x[3 * k + 2]) - x0;
    t.push_back(body.box.minimum_image_exact(dx));
  }
  for (auto b = static_cast<std::size_t>(f.offset[k0]);
       b < static_cast<std::size_t>(f.offset[k0 + 1]); ++b)
    if (info.class_of[static_cast<std::size_t>(f.neighbor[b])] == 0)
      t.push_back(atomistic::bond_vector(f, body.x, k0, b));
  const Eigen::Matrix3d H = body.box.h();
  for (int i = 0; i < d; ++i) t.push_back(H.col(i));  // the box itself is a translation
  std::sort(t.begin(), t.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return a.squaredNorm() < b.squaredNorm();
  });
  // translations of a d-dimensional body lie in the span of its first d box edges (a 2D body
  // whose z is periodic in the input has images along z that are not lattice vectors of it)
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  if (d == 2) normal = H.col(0).cross(H.col(1)).normalized();
  std::vector<Eigen::Vector3d> p;
  for (const auto& v : t) {
    if (v.norm() <= tol) continue;
    if (d == 2 && std::abs(v.dot(normal)) > tol) continue;
    if (d == 1 && H.col(0).normalized().cross(v).norm() > tol) continue;
    if (static_cast<int>(p.size()) == d) break;
    if (p.empty()) {
      p.push_back(v);
    } else if (p.size() == 1) {
      if (p[0].cross(v).norm() > 1e-6 * p[0].norm() * v.norm()) p.push_back(v);
    } else if (std::abs(p[0].cross(p[1]).dot(v)) > 1e-6 * p[0].cross(p[1]).norm() * v.norm()) {
      p.push_back(v);
    }
  }
  if (static_cast<int>(p.size()) == d) {
    double measure = 0.0, box_measure = 0.0;
    if (d == 1) {
      measure = p[0].norm();
      box_measure = H.col(0).norm();
    } else if (d == 2) {
      measure = p[0].cross(p[1]).norm();
      box_measure = H.col(0).cross(H.col(1)).norm();
    } else {
      measure = std::abs(p[0].cross(p[1]).dot(p[2]));
      box_measure = std::abs(H.determinant());
    }
    const double expect = box_measure * info.basis / static_cast<double>(n);

    if (std::abs(measure - expect) <= 1e-6 * expect) info.primitive = p;
  }
  info.summary =
      info.basis == 1
          ? "perfect Bravais lattice (one atom per primitive cell)"
          : fmt::format("perfect crystal with a basis of {} atoms per primitive cell{}", info.basis,
                        info.centrosymmetric ? " (every atom a centre of inversion)" : "");
  return info;
}

FamilyCheck check_families(const Body& body, const std::vector<double>& y,
                           const atomistic::Box& deformed) {
  FamilyCheck out;
  const auto& f = body.families;
  const std::size_t n = body.size();
  out.family_cutoff = body.horizon();
  if (!body.potential || n == 0 || y.size() != 3 * n || f.points() != n) return out;
  out.cutoff = body.potential->cutoff();
  atomistic::Atoms at;
  at.id = body.id;
  at.type = body.type;
  at.x = y;
  at.box = deformed;
  at.box.periodic = body.box.periodic;
  const atomistic::Families g = atomistic::build_families(at, {.cutoff = out.cutoff});
  const Eigen::Matrix3d Hy = at.box.h();
  for (std::size_t k = 0; k < n; ++k) {
    for (auto b = static_cast<std::size_t>(f.offset[k]);
         b < static_cast<std::size_t>(f.offset[k + 1]); ++b) {
      const double r0 = atomistic::bond_vector(f, body.x, k, b).norm();
      const double r1 = atomistic::bond_vector(f, y, Hy, k, b).norm();
      out.max_stretch = std::max(out.max_stretch, std::abs(r1 - r0));
    }
    // both families sorted by (neighbour, shift): a merge finds the frame's pairs missing
    auto b = static_cast<std::size_t>(f.offset[k]);
    const auto be = static_cast<std::size_t>(f.offset[k + 1]);
    for (auto c = static_cast<std::size_t>(g.offset[k]);
         c < static_cast<std::size_t>(g.offset[k + 1]); ++c) {
      auto key = [](const atomistic::Families& ff, std::size_t i) {
        return std::make_tuple(ff.neighbor[i], ff.shift[3 * i], ff.shift[3 * i + 1],
                               ff.shift[3 * i + 2]);
      };
      while (b < be && key(f, b) < key(g, c)) ++b;
      if (b < be && key(f, b) == key(g, c)) continue;
      ++out.missing;
      // the same pair in the reference: x_j − x_k + H n (same image n: y is aligned with x)
      const auto j = static_cast<std::size_t>(g.neighbor[c]);
      const Eigen::Vector3d nvec(g.shift[3 * c], g.shift[3 * c + 1], g.shift[3 * c + 2]);
      const Eigen::Vector3d xi =
          Eigen::Vector3d(body.x[3 * j] - body.x[3 * k], body.x[3 * j + 1] - body.x[3 * k + 1],
                          body.x[3 * j + 2] - body.x[3 * k + 2]) +
          f.h * nvec;
      if (xi.norm() > out.needed_cutoff) {
        out.needed_cutoff = xi.norm();
        out.example_k = body.id[k];
        out.example_j = body.id[j];
      }
    }
  }
  return out;
}

}  // namespace pdcg::body
