#include "pdcg/solver/perturb.hpp"

#include <fmt/format.h>

#include <random>

#include "pdcg/core/error.hpp"

namespace pdcg::solver {

Discretization perturbed_grid(const GridSpec& spec, double amplitude, std::uint64_t seed,
                              const DiscretizationOptions& opt) {
  if (!(amplitude >= 0.0 && amplitude < 0.5))
    throw InputError("grid perturbation amplitude out of range")
        .key("perturbation")
        .value(fmt::format("{}", amplitude))
        .expected("a fraction of the spacing in [0, 0.5)")
        .fix("use e.g. 0.25 (±25% of the spacing)");
  const Discretization regular = Discretization::grid(spec, opt);
  std::vector<Vec3> x = regular.positions();
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> r(-1.0, 1.0);
  const double a = amplitude * spec.spacing;
  for (auto& p : x)
    for (int c = 0; c < spec.dimension; ++c) p[c] += a * r(rng);
  return Discretization::from_points(spec.dimension, std::move(x), regular.volumes(),
                                     regular.surface(), spec.spacing, spec.cracks, opt);
}

}  // namespace pdcg::solver
