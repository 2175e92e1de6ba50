#include "pdcg/solver/cut_cells.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace pdcg::solver {

namespace {

constexpr int kGaussNodes = 20;

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on P_n, computed once).
struct GaussLegendre {
  std::array<double, kGaussNodes> x{}, w{};
  GaussLegendre() {
    const int n = kGaussNodes;
    const double pi = std::acos(-1.0);
    for (int i = 0; i < n; ++i) {
      double t = std::cos(pi * (i + 0.75) / (n + 0.5)), dp = 0;
      for (int it = 0; it < 100; ++it) {
        double p0 = 1, p1 = t;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (t * p1 - p0) / (t * t - 1);
        const double step = p1 / dp;
        t -= step;
        if (std::abs(step) < 1e-16) break;
      }
      x[i] = t;
      w[i] = 2.0 / ((1 - t * t) * dp * dp);
    }
  }
};

const GaussLegendre& gauss() {
  static const GaussLegendre g;
  return g;
}

/// √(R² − X²), as √((R − X)(R + X)): no cancellation for |X| near R.
double half_chord(double X, double R) { return std::sqrt(std::max(0.0, (R - X) * (R + X))); }

/// ∫ √(R² − X²) dX = ½(X s + R² asin(X/R)), asin as atan2(X, s) (exact near |X| = R,
/// where asin(X/R) loses half the digits of X/R).
double chord_primitive(double X, double R) {
  const double s = half_chord(X, R);
  return 0.5 * (X * s + R * R * std::atan2(X, s));
}

}  // namespace

double disk_rectangle_area(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                           const Eigen::Vector3d& c, double R) {
  if (!(R > 0)) return 0.0;
  const double a = std::max(lo.x() - c.x(), -R), b = std::min(hi.x() - c.x(), R);
  const double y0 = lo.y() - c.y(), y1 = hi.y() - c.y();
  if (!(a < b) || !(y0 < y1) || y0 >= R || y1 <= -R) return 0.0;
  // Breakpoints: where the half-chord s(X) = √(R² − X²) equals |y0| or |y1|.
  std::array<double, 6> bp{};
  int nb = 0;
  bp[nb++] = a;
  bp[nb++] = b;
  for (double y : {y0, y1})
    if (std::abs(y) < R) {
      const double X = half_chord(y, R);
      for (double s : {-X, X})
        if (s > a && s < b) bp[nb++] = s;
    }
  for (int i = 1; i < nb; ++i)  // insertion sort of ≤ 6 values
    for (int j = i; j > 0 && bp[j - 1] > bp[j]; --j) std::swap(bp[j - 1], bp[j]);
  double area = 0.0;
  for (int k = 0; k + 1 < nb; ++k) {
    const double xa = bp[k], xb = bp[k + 1];
    if (!(xb > xa)) continue;
    const double xm = 0.5 * (xa + xb);
    const double s = half_chord(xm, R);
    // On (xa, xb) the top of the clipped chord is y1 or s, the bottom y0 or −s throughout.
    const bool top_flat = s > y1, bottom_flat = -s < y0;
    const double top = top_flat ? y1 : s, bottom = bottom_flat ? y0 : -s;
    if (top <= bottom) continue;
    const double chord = chord_primitive(xb, R) - chord_primitive(xa, R);
    area += (top_flat ? y1 * (xb - xa) : chord) - (bottom_flat ? y0 * (xb - xa) : -chord);
  }
  return std::max(0.0, area);
}

double ball_box_volume(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                       const Eigen::Vector3d& c, double R) {
  if (!(R > 0)) return 0.0;
  const double za = std::max(lo.z() - c.z(), -R), zb = std::min(hi.z() - c.z(), R);
  if (!(za < zb)) return 0.0;
  // Heights (relative to c_z) where the section r(z) = √(R² − z²) passes a radius at which
  // the disk ∩ rectangle changes topology: the distances from the axis to the edge lines and
  // to the corners of the rectangle, and 0 (the axis itself).
  std::vector<double> rho;
  const double dx0 = lo.x() - c.x(), dx1 = hi.x() - c.x(), dy0 = lo.y() - c.y(),
               dy1 = hi.y() - c.y();
  for (double v : {dx0, dx1, dy0, dy1}) rho.push_back(std::abs(v));
  for (double u : {dx0, dx1})
    for (double v : {dy0, dy1}) rho.push_back(std::hypot(u, v));
  std::vector<double> bp{za, zb};
  for (double r : rho)
    if (r < R) {
      const double z = half_chord(r, R);
      for (double s : {-z, z})
        if (s > za && s < zb) bp.push_back(s);
    }
  if (0.0 > za && 0.0 < zb) bp.push_back(0.0);
  std::sort(bp.begin(), bp.end());
  const auto& g = gauss();
  const double pi = std::acos(-1.0);
  Eigen::Vector3d axis = c;
  double vol = 0.0;
  for (std::size_t k = 0; k + 1 < bp.size(); ++k) {
    const double z0 = bp[k], z1 = bp[k + 1];
    if (!(z1 > z0)) continue;
    // z = z0 + (z1 − z0)(1 − cos θ)/2, θ ∈ [0, π]: clusters the nodes at both ends, where the
    // section area has (z − z_b)^{1/2}- and ^{3/2}-type terms; smooth in θ.
    double sum = 0.0;
    for (int q = 0; q < kGaussNodes; ++q) {
      const double th = 0.5 * pi * (g.x[q] + 1.0);
      const double z = z0 + (z1 - z0) * 0.5 * (1.0 - std::cos(th));
      const double dz = (z1 - z0) * 0.5 * std::sin(th) * 0.5 * pi;
      const double r = half_chord(z, R);
      sum += g.w[q] * dz * disk_rectangle_area(lo, hi, axis, r);
    }
    vol += sum;
  }
  return std::max(0.0, vol);
}

double cell_hole_measure(int dimension, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                         const Eigen::Vector3d& c, double R) {
  // Quick answers: the box misses the hole, or lies inside it (all corners inside).
  double near2 = 0.0, far2 = 0.0, box = 1.0;
  for (int a = 0; a < dimension; ++a) {
    const double n = std::clamp(c(a), lo(a), hi(a)) - c(a);
    const double f = std::max(std::abs(lo(a) - c(a)), std::abs(hi(a) - c(a)));
    near2 += n * n;
    far2 += f * f;
    box *= std::max(0.0, hi(a) - lo(a));
  }
  if (near2 >= R * R || box == 0.0) return 0.0;
  if (far2 <= R * R) return box;
  return dimension == 2 ? disk_rectangle_area(lo, hi, c, R) : ball_box_volume(lo, hi, c, R);
}

}  // namespace pdcg::solver
