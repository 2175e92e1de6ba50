#include "pdcg/dispersion/closed_form.hpp"

#include <cmath>

#include "pdcg/core/error.hpp"

namespace pdcg::dispersion {

double chain_omega(double kappa, double mass, double spacing, std::span<const double> mu) {
  if (!(mass > 0)) throw InputError("mass must be positive").key("mass").value(std::to_string(mass));
  double w2 = 0.0;
  for (std::size_t n = 0; n < mu.size(); ++n)
    w2 += 2.0 * mu[n] * (1.0 - std::cos(static_cast<double>(n + 1) * kappa * spacing));
  return std::sqrt(std::max(w2, 0.0) / mass);
}

double constant_micromodulus_omega(double kappa, double density, double c, double delta) {
  if (!(density > 0)) throw InputError("density must be positive").key("density").value(std::to_string(density));
  // ∫_{−δ}^{δ} (1 − cos κξ) dξ = 2(δ − sin(κδ)/κ); series near κ = 0 avoids cancellation.
  const double x = kappa * delta;
  double integral;
  if (std::abs(x) < 1e-3)
    integral = 2.0 * delta * (x * x / 6.0 - x * x * x * x / 120.0);
  else
    integral = 2.0 * (delta - std::sin(x) / kappa);
  return std::sqrt(std::max(c * integral, 0.0) / density);
}

double chain_long_wave_speed(double mass, double spacing, std::span<const double> mu) {
  double s = 0.0;
  for (std::size_t n = 0; n < mu.size(); ++n) s += mu[n] * static_cast<double>((n + 1) * (n + 1));
  return spacing * std::sqrt(s / mass);
}

}  // namespace pdcg::dispersion
