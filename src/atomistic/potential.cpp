#include "pdcg/atomistic/potential.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace pdcg::atomistic {

void Potential::force_state_tangent(const FamilyState& f, double* K, double* work) const {
  const std::int64_t n = f.size;
  const auto n3 = static_cast<std::size_t>(3 * n);
  double* y = work;            // perturbed copy of the bonds
  double* tp = work + n3;      // t at Y + s e
  double* tm = work + 2 * n3;  // t at Y − s e
  std::memcpy(y, f.bond, n3 * sizeof(double));
  FamilyState g = f;
  g.bond = y;
  for (std::int64_t m = 0; m < n; ++m) {
    const double* ym = f.bond + 3 * m;
    const double len = std::sqrt(ym[0] * ym[0] + ym[1] * ym[1] + ym[2] * ym[2]);
    const double s = 6e-6 * std::max(1.0, len);
    for (int b = 0; b < 3; ++b) {
      const auto idx = static_cast<std::size_t>(3 * m + b);
      y[idx] = f.bond[idx] + s;
      force_state(g, tp);
      y[idx] = f.bond[idx] - s;
      force_state(g, tm);
      y[idx] = f.bond[idx];
      for (std::int64_t j = 0; j < n; ++j)
        for (int a = 0; a < 3; ++a)
          K[static_cast<std::size_t>((j * n + m) * 9 + 3 * a + b)] =
              (tp[3 * j + a] - tm[3 * j + a]) / (2.0 * s);
    }
  }
}

double Potential::half_pair_forces(const HalfFamilies&, std::int64_t, std::int64_t, const double*,
                                   double*) const {
  throw std::logic_error("half_pair_forces: no pair kernel for " + style());
}

double Potential::manybody_forces(const ShortLists&, std::int64_t, std::int64_t, const double*,
                                  double*, bool&) const {
  throw std::logic_error("manybody_forces: no many-body kernel for " + style());
}

}  // namespace pdcg::atomistic
