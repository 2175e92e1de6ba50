/// \file
/// Homogenisation kernels φ(q) (docs/theory.md §3, docs/bodies.md). A kernel is a small value
/// type (aggregate with its width as only member) with a name, width(), support() and a radial
/// shape operator()(r); adding one is one struct plus its entry in the Kernel variant below. Shapes
/// are not normalised: homogenisation normalises the discrete weights per atom (Σ_p w_kp = 1),
/// which is what conserves mass and energy on any set of continuum points.
#pragma once

#include <cmath>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace pdcg::coarsen {

/// φ = 1 for r < R.
struct TopHat {
  static constexpr std::string_view name = "top-hat";
  double radius = 1.0;  ///< width = R
  double width() const { return radius; }
  double support() const { return radius; }
  double operator()(double r) const { return r < radius ? 1.0 : 0.0; }
};

/// φ = exp(−r²/2σ²) for r < 3σ (truncated Gaussian).
struct TruncatedGaussian {
  static constexpr std::string_view name = "gaussian";
  double sigma = 1.0;  ///< width = σ
  double width() const { return sigma; }
  double support() const { return 3.0 * sigma; }
  double operator()(double r) const {
    return r < 3.0 * sigma ? std::exp(-0.5 * r * r / (sigma * sigma)) : 0.0;
  }
};

/// Cubic B-spline (Monaghan & Lattanzio 1985) with support R = 2h, q = 2r/R:
/// φ = 1 − 1.5q² + 0.75q³ (q < 1), 0.25(2 − q)³ (1 ≤ q < 2).
struct CubicBSpline {
  static constexpr std::string_view name = "cubic-bspline";
  double radius = 1.0;  ///< width = support radius R
  double width() const { return radius; }
  double support() const { return radius; }
  double operator()(double r) const {
    const double q = 2.0 * r / radius;
    if (q < 1.0) return 1.0 - 1.5 * q * q + 0.75 * q * q * q;
    if (q < 2.0) return 0.25 * (2.0 - q) * (2.0 - q) * (2.0 - q);
    return 0.0;
  }
};

/// Wendland C2 (Wendland 1995, d ≤ 3): φ = (1 − q)⁴(4q + 1), q = r/R < 1.
struct WendlandC2 {
  static constexpr std::string_view name = "wendland-c2";
  double radius = 1.0;  ///< width = support radius R
  double width() const { return radius; }
  double support() const { return radius; }
  double operator()(double r) const {
    const double q = r / radius;
    if (q >= 1.0) return 0.0;
    const double a = 1.0 - q;
    return a * a * a * a * (4.0 * q + 1.0);
  }
};

using Kernel = std::variant<TopHat, TruncatedGaussian, CubicBSpline, WendlandC2>;

/// Kernel by name ("top-hat", "gaussian", "cubic-bspline", "wendland-c2") and width (see each
/// struct). Throws InputError naming the choices for an unknown name or a non-positive width.
Kernel make_kernel(std::string_view name, double width);
std::vector<std::string> kernel_names();
std::string_view kernel_name(const Kernel& k);
double kernel_width(const Kernel& k);
inline double kernel_support(const Kernel& k) {
  return std::visit([](const auto& v) { return v.support(); }, k);
}

}  // namespace pdcg::coarsen
