#include "pdcg/coarsen/homogenise.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::coarsen {

using body::Body;

double lattice_spacing(const Body& b) {
  const auto& fam = b.families;
  std::vector<double> nn;
  nn.reserve(b.size());
  for (std::size_t i = 0; i < fam.points(); ++i) {
    double m = INFINITY;
    for (auto k = static_cast<std::size_t>(fam.offset[i]);
         k < static_cast<std::size_t>(fam.offset[i + 1]); ++k)
      m = std::min(m, atomistic::bond_vector(fam, b.x, i, k).norm());
    if (std::isfinite(m)) nn.push_back(m);
  }
  if (nn.empty()) return 0.0;
  std::nth_element(nn.begin(), nn.begin() + static_cast<std::ptrdiff_t>(nn.size() / 2), nn.end());
  return nn[nn.size() / 2];
}

namespace {

double measure(const Eigen::Matrix3d& A, int d) {
  switch (d) {
    case 1:
      return A.col(0).norm();
    case 2:
      return A.col(0).cross(A.col(1)).norm();
    default:
      return std::abs(A.determinant());
  }
}

void check_body(const Body& b, const Kernel& kernel, HomogeniseReport& rep) {
  if (b.homogenisation)
    throw InputError("the body is already homogenised")
        .key("kind")
        .value("homogenised")
        .expected("a delta, statistical or rescaled body")
        .fix("homogenise the original body with the kernel you want");
  rep.lattice_spacing = lattice_spacing(b);
  // The kernel reaches no further than its support radius (= the width of the compact kernels,
  // 3σ for the Gaussian): below one lattice spacing no point averages over neighbouring atoms.
  const double w = kernel_width(kernel), R = kernel_support(kernel);
  if (rep.lattice_spacing > 0 && R < rep.lattice_spacing) {
    rep.warnings.push_back(fmt::format(
        "kernel width {} (support radius {}) is smaller than the lattice spacing {}: no point averages over "
        "neighbouring atoms, homogenisation does nothing; use --width of a few lattice spacings",
        w, R, rep.lattice_spacing));
    log::warn("{}", rep.warnings.back());
  }
}

/// Raw kernel weights of every atom on every point (periodic images summed), normalised per
/// atom; returns per-atom lists (point, w_kp).
std::vector<std::vector<std::pair<std::int32_t, double>>> atom_weights(
    const Body& b, const Kernel& kernel, const std::vector<double>& pts, bool require_all) {
  const std::size_t np = pts.size() / 3, n = b.size();
  const double R = kernel_support(kernel);
  const auto& box = b.box;
  const Eigen::Matrix3d H = box.h();
  const Eigen::Matrix3d Hinv = box.h_inverse();
  const Eigen::Vector3d heights = box.heights();
  std::array<int, 3> shells{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    if (box.periodic[static_cast<std::size_t>(k)])
      shells[static_cast<std::size_t>(k)] = static_cast<int>(std::ceil(R / heights[k])) + 1;

  // Cell list over the points, cells of edge ≥ R.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY),
                  hi = Eigen::Vector3d::Constant(-INFINITY);
  for (std::size_t p = 0; p < np; ++p) {
    const Eigen::Vector3d x(pts[3 * p], pts[3 * p + 1], pts[3 * p + 2]);
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  std::array<std::int64_t, 3> nc{};
  for (int k = 0; k < 3; ++k)
    nc[static_cast<std::size_t>(k)] =
        std::max<std::int64_t>(1, static_cast<std::int64_t>(std::floor((hi[k] - lo[k]) / R)));
  while (nc[0] * nc[1] * nc[2] > static_cast<std::int64_t>(4 * np + 64)) {
    auto& m = *std::max_element(nc.begin(), nc.end());
    m = std::max<std::int64_t>(1, m / 2);
  }
  Eigen::Vector3d cell;
  for (int k = 0; k < 3; ++k)
    cell[k] = std::max((hi[k] - lo[k]) / static_cast<double>(nc[static_cast<std::size_t>(k)]), R);
  auto cell_of = [&](double v, int k) {
    return static_cast<std::int64_t>(std::floor((v - lo[k]) / cell[k]));
  };
  const std::int64_t ncell = nc[0] * nc[1] * nc[2];
  std::vector<std::int64_t> head(static_cast<std::size_t>(ncell + 1), 0), cidx(np);
  for (std::size_t p = 0; p < np; ++p) {
    std::int64_t c[3];
    for (int k = 0; k < 3; ++k)
      c[k] = std::clamp<std::int64_t>(cell_of(pts[3 * p + static_cast<std::size_t>(k)], k), 0,
                                      nc[static_cast<std::size_t>(k)] - 1);
    cidx[p] = (c[0] * nc[1] + c[1]) * nc[2] + c[2];
    ++head[static_cast<std::size_t>(cidx[p] + 1)];
  }
  std::partial_sum(head.begin(), head.end(), head.begin());
  std::vector<std::int64_t> fill(head.begin(), head.end() - 1);
  std::vector<std::int32_t> sorted(np);
  for (std::size_t p = 0; p < np; ++p)
    sorted[static_cast<std::size_t>(fill[static_cast<std::size_t>(cidx[p])]++)] =
        static_cast<std::int32_t>(p);

  std::vector<std::vector<std::pair<std::int32_t, double>>> out(n);
  std::int64_t unreached = -1;
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    Eigen::Vector3d xa(b.x[3 * i], b.x[3 * i + 1], b.x[3 * i + 2]);
    // wrap into the box along periodic directions so the image range above suffices
    Eigen::Vector3d s = Hinv * (xa - box.lo);
    for (int k = 0; k < 3; ++k)
      if (box.periodic[static_cast<std::size_t>(k)]) s[k] -= std::floor(s[k]);
    xa = box.lo + H * s;
    auto& list = out[i];
    for (int a = -shells[0]; a <= shells[0]; ++a)
      for (int bb = -shells[1]; bb <= shells[1]; ++bb)
        for (int c = -shells[2]; c <= shells[2]; ++c) {
          const Eigen::Vector3d xi = xa + H * Eigen::Vector3d(a, bb, c);
          if ((xi.array() < (lo.array() - R)).any() || (xi.array() > (hi.array() + R)).any())
            continue;
          std::int64_t c0[3], c1[3];
          for (int k = 0; k < 3; ++k) {
            c0[k] = std::max<std::int64_t>(0, cell_of(xi[k] - R, k));
            c1[k] =
                std::min<std::int64_t>(nc[static_cast<std::size_t>(k)] - 1, cell_of(xi[k] + R, k));
          }
          for (std::int64_t u = c0[0]; u <= c1[0]; ++u)
            for (std::int64_t v = c0[1]; v <= c1[1]; ++v)
              for (std::int64_t w = c0[2]; w <= c1[2]; ++w) {
                const std::int64_t id = (u * nc[1] + v) * nc[2] + w;
                for (auto q = head[static_cast<std::size_t>(id)];
                     q < head[static_cast<std::size_t>(id + 1)]; ++q) {
                  const auto p = static_cast<std::size_t>(sorted[static_cast<std::size_t>(q)]);
                  const double r =
                      (xi - Eigen::Vector3d(pts[3 * p], pts[3 * p + 1], pts[3 * p + 2])).norm();
                  if (r >= R) continue;
                  const double phi = std::visit([r](const auto& k) { return k(r); }, kernel);
                  if (phi > 0.0) list.emplace_back(static_cast<std::int32_t>(p), phi);
                }
              }
        }
    // merge images of the same point, normalise per atom
    std::sort(list.begin(), list.end());
    std::size_t m = 0;
    for (std::size_t e = 0; e < list.size(); ++e) {
      if (m > 0 && list[m - 1].first == list[e].first)
        list[m - 1].second += list[e].second;
      else
        list[m++] = list[e];
    }
    list.resize(m);
    double sum = 0.0;
    for (const auto& [p, w] : list) sum += w;
    if (sum > 0.0) {
      for (auto& [p, w] : list) w /= sum;
    } else {
#pragma omp critical
      if (unreached < 0) unreached = ii;
    }
  }
  if (unreached >= 0 && require_all) {
    const auto i = static_cast<std::size_t>(unreached);
    throw InputError("an atom is reached by no continuum point within the kernel support")
        .key(fmt::format("atom id {} at ({:.6g}, {:.6g}, {:.6g})", b.id[i], b.x[3 * i],
                         b.x[3 * i + 1], b.x[3 * i + 2]))
        .value(fmt::format("support radius {:.6g}", R))
        .expected("every atom within the support of at least one point")
        .fix("widen the kernel (--width) or refine the grid (--spacing ≤ support radius)");
  }
  return out;
}

Body finish(const Body& b, const Kernel& kernel, std::vector<double> pts,
            const std::vector<std::vector<std::pair<std::int32_t, double>>>& aw,
            std::vector<double> volume) {
  const std::size_t np = pts.size() / 3;
  body::Homogenisation h;
  h.kernel = std::string(kernel_name(kernel));
  h.width = kernel_width(kernel);
  h.offset.assign(np + 1, 0);
  for (const auto& l : aw)
    for (const auto& [p, w] : l) ++h.offset[static_cast<std::size_t>(p) + 1];
  std::partial_sum(h.offset.begin(), h.offset.end(), h.offset.begin());
  h.atom.resize(static_cast<std::size_t>(h.offset[np]));
  h.weight.resize(h.atom.size());
  std::vector<std::int64_t> fill(h.offset.begin(), h.offset.end() - 1);
  for (std::size_t k = 0; k < aw.size(); ++k)
    for (const auto& [p, w] : aw[k]) {
      const auto c = static_cast<std::size_t>(fill[static_cast<std::size_t>(p)]++);
      h.atom[c] = static_cast<std::int32_t>(k);
      h.weight[c] = w;
    }
  h.mass.assign(np, 0.0);
  for (std::size_t p = 0; p < np; ++p)
    for (auto c = static_cast<std::size_t>(h.offset[p]);
         c < static_cast<std::size_t>(h.offset[p + 1]); ++c)
      h.mass[p] += h.weight[c] * b.mass[static_cast<std::size_t>(h.atom[c])];
  h.points = std::move(pts);
  h.volume = std::move(volume);
  Body out = b;
  out.homogenisation = std::move(h);
  out.kind = body::BodyKind::homogenised;
  return out;
}

}  // namespace

Body homogenise_on_grid(const Body& b, const Kernel& kernel, const GridOptions& g,
                        HomogeniseReport* report) {
  HomogeniseReport rep;
  check_body(b, kernel, rep);
  if (!(g.spacing > 0.0) || !std::isfinite(g.spacing))
    throw InputError("grid spacing must be positive")
        .key("spacing")
        .value(std::to_string(g.spacing))
        .expected("a positive length")
        .fix("give --spacing of the order of the kernel width");
  if (!(g.rotation.transpose() * g.rotation).isApprox(Eigen::Matrix3d::Identity(), 1e-10))
    throw InputError("grid orientation is not a rotation")
        .key("rotation")
        .expected("orthonormal columns");
  const int d = b.dimension;
  const double R = kernel_support(kernel);
  const Eigen::Matrix3d A = g.rotation * g.spacing;
  const Eigen::Matrix3d Ainv = A.inverse();
  const std::size_t n = b.size();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i)
    centroid += Eigen::Vector3d(b.x[3 * i], b.x[3 * i + 1], b.x[3 * i + 2]);
  centroid /= static_cast<double>(n);
  const Eigen::Vector3d origin0 = centroid + A * g.shift;
  // Region: box along periodic directions, atoms ± support along free ones (fractional coords).
  const Eigen::Matrix3d H = b.box.h(), Hinv = b.box.h_inverse();
  const Eigen::Vector3d heights = b.box.heights();
  Eigen::Vector3d smin = Eigen::Vector3d::Constant(INFINITY),
                  smax = Eigen::Vector3d::Constant(-INFINITY);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d s =
        Hinv * (Eigen::Vector3d(b.x[3 * i], b.x[3 * i + 1], b.x[3 * i + 2]) - b.box.lo);
    smin = smin.cwiseMin(s);
    smax = smax.cwiseMax(s);
  }
  for (int k = 0; k < 3; ++k) {
    if (b.box.periodic[static_cast<std::size_t>(k)]) {
      smin[k] = 0.0;
      smax[k] = 1.0;
    } else {
      smin[k] -= R / heights[k];
      smax[k] += R / heights[k];
    }
  }
  Eigen::Vector3d gmin = Eigen::Vector3d::Constant(INFINITY),
                  gmax = Eigen::Vector3d::Constant(-INFINITY);
  for (int corner = 0; corner < 8; ++corner) {
    Eigen::Vector3d s;
    for (int k = 0; k < 3; ++k) s[k] = (corner >> k & 1) ? smax[k] : smin[k];
    const Eigen::Vector3d gc = Ainv * (b.box.lo + H * s - origin0);
    gmin = gmin.cwiseMin(gc);
    gmax = gmax.cwiseMax(gc);
  }
  std::array<std::int64_t, 3> i0{0, 0, 0}, cnt{1, 1, 1};
  for (int k = 0; k < d; ++k) {
    i0[static_cast<std::size_t>(k)] = static_cast<std::int64_t>(std::floor(gmin[k]));
    cnt[static_cast<std::size_t>(k)] =
        static_cast<std::int64_t>(std::ceil(gmax[k])) - i0[static_cast<std::size_t>(k)] + 1;
  }
  const double total =
      static_cast<double>(cnt[0]) * static_cast<double>(cnt[1]) * static_cast<double>(cnt[2]);
  if (total > 5e8)
    throw InputError("grid too large")
        .key("spacing")
        .value(fmt::format("{} ({:.3g} points)", g.spacing, total))
        .expected("a spacing that gives fewer than 5e8 points")
        .fix("use a coarser --spacing");
  std::vector<double> pts;
  std::vector<std::int64_t> gidx;
  for (std::int64_t a = 0; a < cnt[0]; ++a)
    for (std::int64_t bb = 0; bb < cnt[1]; ++bb)
      for (std::int64_t c = 0; c < cnt[2]; ++c) {
        const Eigen::Vector3d x = origin0 + A * Eigen::Vector3d(static_cast<double>(i0[0] + a),
                                                                static_cast<double>(i0[1] + bb),
                                                                static_cast<double>(i0[2] + c));
        const Eigen::Vector3d s = Hinv * (x - b.box.lo);
        bool keep = true;
        for (int k = 0; k < 3; ++k)
          if (b.box.periodic[static_cast<std::size_t>(k)] && (s[k] < 0.0 || s[k] >= 1.0))
            keep = false;
        if (!keep) continue;
        pts.insert(pts.end(), {x[0], x[1], x[2]});
        gidx.push_back((a * cnt[1] + bb) * cnt[2] + c);
      }
  auto aw = atom_weights(b, kernel, pts, true);
  // drop points no atom reaches
  std::vector<std::int32_t> remap(pts.size() / 3, -1);
  for (const auto& l : aw)
    for (const auto& [p, w] : l) remap[static_cast<std::size_t>(p)] = 0;
  std::vector<double> kept;
  std::int32_t next = 0;
  for (std::size_t p = 0; p < remap.size(); ++p)
    if (remap[p] == 0) {
      remap[p] = next++;
      kept.insert(kept.end(), {pts[3 * p], pts[3 * p + 1], pts[3 * p + 2]});
    }
  for (auto& l : aw)
    for (auto& [p, w] : l) p = remap[static_cast<std::size_t>(p)];
  const double vol = measure(A, d);
  std::vector<double> volume(kept.size() / 3, vol);
  Body out = finish(b, kernel, std::move(kept), aw, std::move(volume));
  auto& h = *out.homogenisation;
  const Eigen::Vector3d go =
      origin0 + A * Eigen::Vector3d(static_cast<double>(i0[0]), static_cast<double>(i0[1]),
                                    static_cast<double>(i0[2]));
  h.grid_origin = {go[0], go[1], go[2]};
  h.grid_axes.assign(A.data(), A.data() + 9);  // column-major: columns are the steps
  h.grid_counts = {cnt[0], cnt[1], cnt[2]};
  out.provenance.push_back(
      fmt::format("homogenised: kernel {} width {}, grid spacing {}, {} points", h.kernel, h.width,
                  g.spacing, h.size()));
  log::info("homogenised {} atoms onto {} grid points (kernel {}, width {}, spacing {})", b.size(),
            h.size(), h.kernel, h.width, g.spacing);
  if (report) *report = rep;
  return out;
}

Body homogenise_on_points(const Body& b, const Kernel& kernel, std::vector<double> points,
                          HomogeniseReport* report) {
  HomogeniseReport rep;
  check_body(b, kernel, rep);
  if (points.empty() || points.size() % 3 != 0)
    throw InputError("no continuum points given").key("points").expected("3 coordinates per point");
  const auto aw = atom_weights(b, kernel, points, true);
  const double vatom = b.reference_volume() / static_cast<double>(b.size());
  std::vector<double> volume(points.size() / 3, 0.0);
  for (const auto& l : aw)
    for (const auto& [p, w] : l) volume[static_cast<std::size_t>(p)] += w * vatom;
  Body out = finish(b, kernel, std::move(points), aw, std::move(volume));
  out.provenance.push_back(fmt::format("homogenised: kernel {} width {}, {} given points",
                                       out.homogenisation->kernel, out.homogenisation->width,
                                       out.homogenisation->size()));
  if (report) *report = rep;
  return out;
}

}  // namespace pdcg::coarsen
