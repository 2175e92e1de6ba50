#include "pdcg/dispersion/trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "pdcg/core/error.hpp"

namespace pdcg::dispersion {

namespace {
const char* axis_name(int a) { return a == 0 ? "x" : a == 1 ? "y" : "z"; }
}  // namespace

LatticePlanes find_planes(const std::vector<double>& ref, const atomistic::Box& box, int axis,
                          const std::string& source) {
  const auto a = static_cast<std::size_t>(axis);
  if (!box.periodic[a])
    throw InputError("the box is not periodic along the wave axis")
        .source(source)
        .key("--axis")
        .value(axis_name(axis))
        .expected("a periodic direction (a wave needs a periodic lattice of planes)")
        .fix("use a periodic axis or a trajectory from a periodic run");
  if (box.triclinic())
    throw InputError("measured dispersion needs an orthogonal box")
        .source(source)
        .value(fmt::format("tilt {} {} {}", box.xy, box.xz, box.yz))
        .expected("xy = xz = yz = 0");
  const std::size_t n = ref.size() / 3;
  const double L = box.hi[axis] - box.lo[axis];
  std::vector<double> c(n);
  for (std::size_t i = 0; i < n; ++i) {
    double s = (ref[3 * i + a] - box.lo[axis]) / L;
    s -= std::floor(s);
    c[i] = s * L;
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t p, std::size_t q) { return c[p] < c[q]; });
  // A new plane starts where the gap exceeds a tolerance small against the lattice spacing:
  // 1e-3 of the mean spacing of n atoms, or a tenth of the largest gap (the wrap gap counted),
  // whichever is larger. The time-averaged positions of a thermal crystal scatter within a
  // plane (measured: 32 atoms of a (100) plane of fcc LJ at T* = 0.4, 2000 frames, over
  // ±0.003 of a spacing 0.79 — more than 1e-3 L/∛n = 0.0016, which split planes), never by a
  // tenth of the spacing while it is a crystal (the atom-leaves-its-plane check below is at ½).
  double max_gap = n ? c[order.front()] + L - c[order.back()] : L;
  for (std::size_t k = 1; k < n; ++k) max_gap = std::max(max_gap, c[order[k]] - c[order[k - 1]]);
  const double tol =
      std::max(1e-3 * L / std::max<double>(1.0, std::cbrt(static_cast<double>(n))), 0.1 * max_gap);
  LatticePlanes lp;
  lp.plane_of_atom.assign(n, 0);
  std::vector<double> first;  // first coordinate of each plane
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = order[k];
    if (k == 0 || c[i] - c[order[k - 1]] > tol) first.push_back(c[i]);
    lp.plane_of_atom[i] = static_cast<int>(first.size() - 1);
  }
  // The last plane may be the first one seen across the boundary.
  if (first.size() > 1 && first.front() + L - c[order.back()] <= tol) {
    const int last = static_cast<int>(first.size() - 1);
    for (auto& p : lp.plane_of_atom)
      if (p == last) p = 0;
    first.pop_back();
  }
  lp.planes = first.size();
  if (lp.planes < 2)
    throw InputError("all atoms lie in one lattice plane normal to the wave axis")
        .source(source)
        .key("--axis")
        .value(fmt::format("{} ({} atoms, 1 plane)", axis_name(axis), n))
        .expected(
            "an axis along which the atoms are spread over several lattice planes (a chain: its "
            "direction)")
        .fix(
            "choose the lattice direction of the wave as --axis (the chain direction for a 1D "
            "chain)");
  lp.spacing = L / static_cast<double>(lp.planes);
  for (std::size_t p = 0; p < lp.planes; ++p) {
    const double expect = first[0] + static_cast<double>(p) * lp.spacing;
    if (std::abs(first[p] - expect) > 0.05 * lp.spacing)
      throw InputError("lattice planes normal to the axis are not evenly spaced")
          .source(source)
          .key("--axis")
          .value(fmt::format("plane {} at {:.6g}, expected {:.6g} (spacing {:.6g})", p, first[p],
                             expect, lp.spacing))
          .expected("a perfect lattice (time-averaged positions) along the axis")
          .fix(
              "pick a lattice direction as the axis, or a trajectory of a crystal without defects");
  }
  return lp;
}

Spectrum measure(const std::vector<atomistic::Atoms>& frames, const TrajectoryOptions& opt) {
  if (frames.empty())
    throw InputError("no frames").source(opt.source).expected("a trajectory with frames");
  const std::size_t n = frames[0].size();
  if (frames[0].x.size() != 3 * n)
    throw InputError("trajectory has no positions")
        .source(opt.source)
        .expected("x y z (or xu/xs) columns");
  const atomistic::Box& box = frames[0].box;
  const auto a = static_cast<std::size_t>(opt.axis), comp = static_cast<std::size_t>(opt.component);
  const Eigen::Vector3d L = box.lengths();
  // Displacements from frame 0 through the minimum image (atoms may wrap), then their means.
  std::vector<double> d(frames.size() * 3 * n), mean(3 * n, 0.0);
  for (std::size_t t = 0; t < frames.size(); ++t) {
    const auto& f = frames[t];
    if (f.size() != n || f.id != frames[0].id)
      throw InputError("frames hold different atoms")
          .source(opt.source)
          .key("frame " + std::to_string(t))
          .value(std::to_string(f.size()) + " atoms")
          .expected(std::to_string(n) + " atoms with the ids of the first frame");
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < 3; ++k) {
        double v = f.x[3 * i + k] - frames[0].x[3 * i + k];
        if (box.periodic[k])
          v -= L[static_cast<Eigen::Index>(k)] * std::round(v / L[static_cast<Eigen::Index>(k)]);
        d[(t * n + i) * 3 + k] = v;
        mean[3 * i + k] += v / static_cast<double>(frames.size());
      }
  }
  std::vector<double> ref(3 * n);
  for (std::size_t i = 0; i < 3 * n; ++i) ref[i] = frames[0].x[i] + mean[i];
  const LatticePlanes lp = find_planes(ref, box, opt.axis, opt.source);
  std::vector<double> u(frames.size() * lp.planes, 0.0), count(lp.planes, 0.0);
  for (std::size_t i = 0; i < n; ++i) count[static_cast<std::size_t>(lp.plane_of_atom[i])] += 1.0;
  // Transverse lattice spacing: (area per atom of a plane over the periodic transverse
  // directions)^(1/p); a chain (no periodic transverse direction) has only its spacing h.
  double across = 1.0;
  int p_across = 0;
  for (std::size_t k = 0; k < 3; ++k)
    if (k != a && box.periodic[k]) {
      across *= L[static_cast<Eigen::Index>(k)];
      ++p_across;
    }
  const double per_plane = static_cast<double>(n) / static_cast<double>(lp.planes);
  const double transverse_spacing =
      p_across == 0 ? lp.spacing
                    : std::pow(across / per_plane, 1.0 / static_cast<double>(p_across));
  for (std::size_t t = 0; t < frames.size(); ++t)
    for (std::size_t i = 0; i < n; ++i) {
      double side2 = 0.0;
      for (std::size_t k = 0; k < 3; ++k)
        if (k != a) side2 += std::pow(d[(t * n + i) * 3 + k] - mean[3 * i + k], 2);
      if (std::sqrt(side2) > 0.5 * transverse_spacing)
        throw InputError("an atom left the wave axis (moved sideways off its lattice site)")
            .source(opt.source)
            .key(fmt::format("atom id {} in frame {}", frames[0].id[i], t))
            .value(fmt::format("{:.4g} from its mean position across the axis {}", std::sqrt(side2),
                               axis_name(opt.axis)))
            .expected(fmt::format("less than half the transverse lattice spacing {:.4g}",
                                  0.5 * transverse_spacing))
            .fix(
                "measure a solid whose atoms vibrate about their sites; for a chain keep the "
                "motion along it "
                "(LAMMPS: fix setforce NULL 0 0) and give the chain direction as --axis");
      const double along = d[(t * n + i) * 3 + a] - mean[3 * i + a];
      if (std::abs(along) > 0.5 * lp.spacing)
        throw InputError("an atom left its lattice plane")
            .source(opt.source)
            .key(fmt::format("atom id {} in frame {}", frames[0].id[i], t))
            .value(
                fmt::format("{:.4g} from its mean position along {}", along, axis_name(opt.axis)))
            .expected(fmt::format("less than half the plane spacing {:.4g}", 0.5 * lp.spacing))
            .fix("measure a solid at a temperature where atoms vibrate about lattice sites");
      const auto p = static_cast<std::size_t>(lp.plane_of_atom[i]);
      u[t * lp.planes + p] += (d[(t * n + i) * 3 + comp] - mean[3 * i + comp]) / count[p];
    }
  return space_time_spectrum(u, frames.size(), lp.planes, lp.spacing, opt.frame_interval,
                             opt.window, opt.min_resolution);
}

}  // namespace pdcg::dispersion
