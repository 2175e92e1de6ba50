/// \file
/// Dispersion curves as CSV (`kappa,omega_1,…` or `kappa,omega,…`) and their comparison.
#pragma once

#include <string>
#include <vector>

namespace pdcg::dispersion {

struct Curves {
  std::vector<double> kappa;
  std::vector<std::string> names;          ///< branch column names
  std::vector<std::vector<double>> omega;  ///< per branch, one value per κ
};

/// Reads a CSV with a `kappa` column and one or more columns whose names start with `omega`
/// (columns named omega_ref… are skipped). Throws InputError naming file, line and column.
Curves read_curves(const std::string& path, const std::string& option = "--compare");

/// Linear interpolation of branch b at κ; NaN outside the tabulated range.
double interpolate(const Curves& curves, std::size_t branch, double kappa);

}  // namespace pdcg::dispersion
