#include "pdcg/solver/point_cloud.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

#include "pdcg/core/error.hpp"

namespace pdcg::solver {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Cell list of cell size r: all points within r of a point are in the 3^d surrounding cells.
struct CellList {
  int d;
  double r;
  Vec3 lo;
  std::array<long, 3> nc{1, 1, 1};
  std::vector<std::int64_t> start;
  std::vector<int> pts;
  CellList(int dim, const std::vector<Vec3>& x, double radius) : d(dim), r(radius) {
    lo = x[0];
    Vec3 hi = x[0];
    for (const auto& p : x) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    for (int a = 0; a < d; ++a)
      nc[a] = std::clamp<long>(static_cast<long>((hi(a) - lo(a)) / r) + 1, 1, 1L << 20);
    start.assign(static_cast<std::size_t>(nc[0] * nc[1] * nc[2] + 1), 0);
    std::vector<long> cid(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      cid[i] = id(cell(x[i], 0), cell(x[i], 1), cell(x[i], 2));
      ++start[static_cast<std::size_t>(cid[i] + 1)];
    }
    std::partial_sum(start.begin(), start.end(), start.begin());
    pts.resize(x.size());
    std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
    for (std::size_t i = 0; i < x.size(); ++i)
      pts[static_cast<std::size_t>(fill[static_cast<std::size_t>(cid[i])]++)] = static_cast<int>(i);
  }
  long cell(const Vec3& p, int a) const {
    if (a >= d) return 0;
    return std::clamp<long>(static_cast<long>((p(a) - lo(a)) / r), 0, nc[a] - 1);
  }
  long id(long i, long j, long k) const { return i + nc[0] * (j + nc[1] * k); }
  template <class Fn>
  void near(const Vec3& p, Fn&& fn) const {
    const long c[3] = {cell(p, 0), cell(p, 1), cell(p, 2)};
    for (long k = std::max(0L, c[2] - 1); k <= std::min(nc[2] - 1, c[2] + 1); ++k)
      for (long j = std::max(0L, c[1] - 1); j <= std::min(nc[1] - 1, c[1] + 1); ++j)
        for (long i = std::max(0L, c[0] - 1); i <= std::min(nc[0] - 1, c[0] + 1); ++i) {
          const auto cc = static_cast<std::size_t>(id(i, j, k));
          for (auto q = start[cc]; q < start[cc + 1]; ++q) fn(pts[static_cast<std::size_t>(q)]);
        }
  }
};

// Rough spacing: median nearest-neighbour distance of up to 64 points (brute force).
double rough_spacing(const std::vector<Vec3>& x) {
  const std::size_t n = x.size(), m = std::min<std::size_t>(n, 64);
  std::vector<double> d;
  for (std::size_t s = 0; s < m; ++s) {
    const std::size_t i = s * n / m;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j)
      if (j != i) best = std::min(best, (x[j] - x[i]).squaredNorm());
    if (std::isfinite(best) && best > 0) d.push_back(std::sqrt(best));
  }
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + static_cast<long>(d.size() / 2), d.end());
  return d[d.size() / 2];
}

// A convex polygon in 3D clipped by half-spaces w·p ≤ c (Sutherland–Hodgman).
using Poly = std::vector<Vec3>;
void clip(Poly& poly, const Vec3& w, double c, Poly& tmp) {
  tmp.clear();
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3& a = poly[i];
    const Vec3& b = poly[(i + 1) % n];
    const double fa = w.dot(a) - c, fb = w.dot(b) - c;
    if (fa <= 0) tmp.push_back(a);
    if ((fa < 0 && fb > 0) || (fa > 0 && fb < 0)) tmp.push_back(a + (fa / (fa - fb)) * (b - a));
  }
  poly.swap(tmp);
}
double polygon_area(const Poly& p, const Vec3& normal) {
  Vec3 s = Vec3::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) s += p[i].cross(p[(i + 1) % p.size()]);
  return std::abs(0.5 * s.dot(normal));
}
// Two unit vectors spanning the plane normal to n.
void plane_axes(const Vec3& n, Vec3& t1, Vec3& t2) {
  int a = 0;
  for (int b = 1; b < 3; ++b)
    if (std::abs(n(b)) < std::abs(n(a))) a = b;
  Vec3 e = Vec3::Zero();
  e(a) = 1.0;
  t1 = n.cross(e).normalized();
  t2 = n.cross(t1);
}

// Measure of the face {p : v·p = |v|²/2 (relative to the origin)} ∩ {w·p ≤ |w|²/2 ∀ w} ∩ disc
// of radius rho around v/2 (2D: a segment; 3D: a polygon, the disc as a regular 64-gon).
template <class Others>
double face_measure(int d, const Vec3& v, double rho, const Others& others, Poly& poly, Poly& tmp) {
  const Vec3 m = 0.5 * v;
  const Vec3 n = v.normalized();
  if (d == 2) {
    const Vec3 t(-n.y(), n.x(), 0.0);
    double lo = -rho, hi = rho;
    for (const Vec3& w : others) {
      const double a = w.dot(t), c = 0.5 * w.squaredNorm() - w.dot(m);
      if (std::abs(a) < 1e-300) {
        if (c < 0) return 0.0;
        continue;
      }
      if (a > 0)
        hi = std::min(hi, c / a);
      else
        lo = std::max(lo, c / a);
      if (hi <= lo) return 0.0;
    }
    return hi - lo;
  }
  Vec3 t1, t2;
  plane_axes(n, t1, t2);
  poly.clear();
  constexpr int kSides = 64;
  for (int i = 0; i < kSides; ++i) {
    const double phi = 2 * kPi * i / kSides;
    poly.push_back(m + rho * (std::cos(phi) * t1 + std::sin(phi) * t2));
  }
  for (const Vec3& w : others) {
    clip(poly, w, 0.5 * w.squaredNorm(), tmp);
    if (poly.size() < 3) return 0.0;
  }
  return polygon_area(poly, n);
}

struct IntKey {
  std::size_t operator()(const std::array<long, 3>& k) const {
    return static_cast<std::size_t>(k[0] * 73856093L ^ k[1] * 19349663L ^ k[2] * 83492791L);
  }
};

}  // namespace

double mean_nearest_neighbour_distance(int d, const std::vector<Vec3>& x) {
  if (x.size() < 2) return 0.0;
  const double h0 = rough_spacing(x);
  if (!(h0 > 0)) return 0.0;
  const CellList cl(d, x, 2.0 * h0);
  double sum = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    cl.near(x[i], [&](int j) {
      if (j != static_cast<int>(i)) best = std::min(best, (x[j] - x[i]).squaredNorm());
    });
    if (!std::isfinite(best))  // isolated point: brute force
      for (std::size_t j = 0; j < x.size(); ++j)
        if (j != i) best = std::min(best, (x[j] - x[i]).squaredNorm());
    sum += std::sqrt(best);
  }
  return sum / static_cast<double>(x.size());
}

std::optional<Eigen::Matrix3d> detect_lattice(int d, const std::vector<Vec3>& x,
                                              const std::optional<Eigen::Matrix3d>& hint,
                                              double rel_tol) {
  if (x.size() < 2) return std::nullopt;
  auto check = [&](const Eigen::Matrix3d& A) -> bool {
    if (!(std::abs(A.determinant()) > 0)) return false;
    const Eigen::Matrix3d Ai = A.inverse();
    double amin = std::numeric_limits<double>::infinity();
    for (int a = 0; a < d; ++a) amin = std::min(amin, A.col(a).norm());
    for (const auto& p : x) {
      const Vec3 n = Ai * (p - x[0]);
      const Vec3 r = A * (n.array().round().matrix()) - (p - x[0]);
      if (r.norm() > rel_tol * amin) return false;
    }
    return true;
  };
  // A lattice that holds every point can still be denser than the cloud: the bond vectors of
  // diamond or of a honeycomb sheet span a lattice with empty sites (the tetrahedral holes,
  // the hexagons' centres), whose cell is a fraction of the volume per point (diamond a³/16
  // against a³/8). A Bravais cloud has points whose 2d lattice neighbours x ± A e_a are all
  // present (its interior); a cloud without one is not taken as a lattice.
  auto filled = [&](const Eigen::Matrix3d& A) -> bool {
    const Eigen::Matrix3d Ai = A.inverse();
    std::unordered_set<std::int64_t> sites;
    sites.reserve(2 * x.size());
    const auto key = [](const Vec3& n) {
      const auto c = [](double v) {
        return static_cast<std::int64_t>(std::llround(v)) + (1 << 20);
      };
      return (c(n.x()) << 42) | (c(n.y()) << 21) | c(n.z());
    };
    std::vector<Vec3> idx(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      idx[i] = (Ai * (x[i] - x[0])).array().round().matrix();
      sites.insert(key(idx[i]));
    }
    for (const auto& n : idx) {
      bool all = true;
      for (int a = 0; a < d && all; ++a)
        for (double sgn : {-1.0, 1.0})
          if (!sites.count(key(n + sgn * Vec3::Unit(a)))) {
            all = false;
            break;
          }
      if (all) return true;
    }
    return false;
  };
  if (hint && check(*hint) && filled(*hint)) return hint;
  // Central point: nearest to the centroid.
  Vec3 c = Vec3::Zero();
  for (const auto& p : x) c += p;
  c /= static_cast<double>(x.size());
  std::size_t i0 = 0;
  for (std::size_t i = 1; i < x.size(); ++i)
    if ((x[i] - c).squaredNorm() < (x[i0] - c).squaredNorm()) i0 = i;
  const double h0 = rough_spacing(x);
  if (!(h0 > 0)) return std::nullopt;
  std::vector<Vec3> v;
  for (const auto& p : x) {
    const Vec3 r = p - x[i0];
    if (r.squaredNorm() > 0 && r.norm() <= 3.0 * h0) v.push_back(r);
  }
  std::sort(v.begin(), v.end(),
            [](const Vec3& a, const Vec3& b) { return a.squaredNorm() < b.squaredNorm(); });
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  int found = 0;
  for (const auto& r : v) {
    if (found == d) break;
    if (found == 0) {
      A.col(0) = r;
      found = 1;
    } else if (found == 1) {
      if (A.col(0).cross(r).norm() > 0.1 * A.col(0).norm() * r.norm()) {
        A.col(1) = r;
        found = 2;
      }
    } else {
      if (std::abs(A.col(0).cross(A.col(1)).dot(r)) >
          0.1 * A.col(0).norm() * A.col(1).norm() * r.norm()) {
        A.col(2) = r;
        found = 3;
      }
    }
  }
  if (found < d) return std::nullopt;
  if (d == 2) A.col(2) = Vec3::UnitZ();
  if (!check(A) || !filled(A)) return std::nullopt;
  return A;
}

std::vector<LatticeFace> wigner_seitz_faces(int d, const Eigen::Matrix3d& A) {
  std::vector<LatticeFace> cand;
  const int r = 2;
  for (int k = (d == 3 ? -r : 0); k <= (d == 3 ? r : 0); ++k)
    for (int j = -r; j <= r; ++j)
      for (int i = -r; i <= r; ++i) {
        if (i == 0 && j == 0 && k == 0) continue;
        LatticeFace f;
        f.n = {i, j, k};
        f.v = A.col(0) * i + A.col(1) * j;
        if (d == 3) f.v += A.col(2) * k;
        cand.push_back(f);
      }
  double L = 0;
  for (const auto& f : cand) L = std::max(L, f.v.norm());
  std::vector<LatticeFace> out;
  Poly poly, tmp;
  std::vector<Vec3> others;
  for (std::size_t a = 0; a < cand.size(); ++a) {
    others.clear();
    for (std::size_t b = 0; b < cand.size(); ++b)
      if (b != a) others.push_back(cand[b].v);
    const double area = face_measure(d, cand[a].v, 2.0 * L, others, poly, tmp);
    const double scale = d == 2 ? cand[a].v.norm() : cand[a].v.squaredNorm();
    if (area > 1e-9 * scale) {
      LatticeFace f = cand[a];
      f.area = area * f.v.normalized();
      out.push_back(f);
    }
  }
  // Check: the faces close (Σ a n = 0) and Σ a n ⊗ v/2 = V I (divergence theorem; the face
  // between 0 and v is centrally symmetric about v/2).
  Vec3 sum = Vec3::Zero();
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (const auto& f : out) {
    sum += f.area;
    M += 0.5 * f.area * f.v.transpose();
  }
  const double V = d == 2 ? std::abs(A.col(0).cross(A.col(1)).z()) : std::abs(A.determinant());
  Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  if (d == 2) I(2, 2) = 0.0;
  if (sum.norm() > 1e-9 * std::pow(V, (d - 1.0) / d) || (M - V * I).norm() > 1e-9 * V)
    throw NumericalError(
        fmt::format("internal error: the Wigner–Seitz cell of the lattice does not close "
                    "(|Σ a n| = {:.3g}, |Σ a n⊗v/2 − V I| = {:.3g})",
                    sum.norm(), (M - V * I).norm()));
  return out;
}

std::vector<Vec3> lattice_surface(int d, const std::vector<Vec3>& x, const Eigen::Matrix3d& A,
                                  const std::vector<Crack>& cracks) {
  const auto faces = wigner_seitz_faces(d, A);
  const Eigen::Matrix3d Ai = A.inverse();
  std::unordered_map<std::array<long, 3>, int, IntKey> index;
  std::vector<std::array<long, 3>> n(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Vec3 q = Ai * (x[i] - x[0]);
    n[i] = {std::lround(q(0)), std::lround(q(1)), d == 3 ? std::lround(q(2)) : 0L};
    index.emplace(n[i], static_cast<int>(i));
  }
  std::vector<Vec3> s(x.size(), Vec3::Zero());
  for (std::size_t i = 0; i < x.size(); ++i)
    for (const auto& f : faces) {
      const std::array<long, 3> m{n[i][0] + f.n[0], n[i][1] + f.n[1], n[i][2] + f.n[2]};
      const auto it = index.find(m);
      bool open = it == index.end();
      if (!open)
        for (const auto& c : cracks) open = open || crosses(c, x[i], x[it->second]);
      if (open) s[i] += f.area;
    }
  return s;
}

std::vector<Vec3> voronoi_surface(int d, const std::vector<Vec3>& x, double R,
                                  const std::vector<Crack>& cracks) {
  const std::size_t N = x.size();
  const CellList cl(d, x, 2.0 * R);
  const double r2 = 4.0 * R * R;
  // Neighbours within 2R (they are the only points that can cut a face inside the ball).
  std::vector<std::vector<int>> nb(N);
#pragma omp parallel for schedule(dynamic, 64)
  for (std::size_t i = 0; i < N; ++i)
    cl.near(x[i], [&](int j) {
      if (j != static_cast<int>(i) && (x[j] - x[i]).squaredNorm() < r2) nb[i].push_back(j);
    });
  // Face vector of each pair (k < j), from k's side, then scattered with opposite signs.
  std::vector<std::vector<std::pair<int, Vec3>>> faces(N);
#pragma omp parallel
  {
    Poly poly, tmp;
    std::vector<Vec3> others;
#pragma omp for schedule(dynamic, 64)
    for (std::size_t k = 0; k < N; ++k)
      for (int j : nb[k]) {
        if (j < static_cast<int>(k)) continue;
        bool cut = false;
        for (const auto& c : cracks) cut = cut || crosses(c, x[k], x[j]);
        if (cut) continue;  // a crack face: free surface for both ends
        const Vec3 v = x[j] - x[k];
        const double rho2 = R * R - 0.25 * v.squaredNorm();
        if (!(rho2 > 0)) continue;
        others.clear();
        for (int l : nb[k])
          if (l != j) others.push_back(x[l] - x[k]);
        const double a = face_measure(d, v, std::sqrt(rho2), others, poly, tmp);
        if (a > 0) faces[k].emplace_back(j, a * v.normalized());
      }
  }
  std::vector<Vec3> s(N, Vec3::Zero());
  for (std::size_t k = 0; k < N; ++k)
    for (const auto& [j, f] : faces[k]) {
      s[k] -= f;
      s[static_cast<std::size_t>(j)] += f;
    }
  // Round-off of the closed interior cells (|Σ faces| ~ 1e-16 · area) is zero.
  const double tiny = 1e-12 * std::pow(R, d - 1);
  for (auto& v : s)
    if (v.norm() < tiny) v.setZero();
  return s;
}

CloudGeometry analyse_cloud(int d, const std::vector<Vec3>& x, std::vector<double> volume,
                            double fallback_volume, const std::vector<Crack>& cracks,
                            double spacing_hint, const std::optional<Eigen::Matrix3d>& basis_hint,
                            double radius_factor) {
  if (x.size() < 2)
    throw InputError("the model holds fewer than two points")
        .key("geometry.file")
        .expected("a model with a body of points");
  CloudGeometry g;
  g.nearest_neighbour = mean_nearest_neighbour_distance(d, x);
  g.spacing = spacing_hint > 0 ? spacing_hint : g.nearest_neighbour;
  if (!(g.spacing > 0))
    throw InputError("the model's points coincide (zero spacing)").key("geometry.file");
  if (const auto A = detect_lattice(d, x, basis_hint)) {
    g.rule = SurfaceRule::lattice;
    g.basis = *A;
    g.surface = lattice_surface(d, x, *A, cracks);
    const double cell =
        d == 2 ? std::abs(A->col(0).cross(A->col(1)).z()) : std::abs(A->determinant());
    if (volume.empty()) volume.assign(x.size(), cell);
  } else {
    g.rule = SurfaceRule::voronoi;
    g.voronoi_radius = radius_factor * g.nearest_neighbour;
    g.surface = voronoi_surface(d, x, g.voronoi_radius, cracks);
    if (volume.empty()) volume.assign(x.size(), fallback_volume);
  }
  g.volume = std::move(volume);
  for (const auto& v : g.surface)
    if (v.squaredNorm() > 0) ++g.surface_points;
  return g;
}

}  // namespace pdcg::solver
