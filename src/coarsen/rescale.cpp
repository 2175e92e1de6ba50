#include "pdcg/coarsen/rescale.hpp"

#include <fmt/format.h>

#include <cmath>

#include "pdcg/core/error.hpp"

namespace pdcg::coarsen {

namespace {
void check_epsilon(double eps, std::string_view key) {
  if (!(eps > 0.0) || !std::isfinite(eps))
    throw InputError("rescaling factor must be positive")
        .key(key)
        .value(fmt::format("{}", eps))
        .expected("ε = δ'/δ > 0 (ratio of the new to the old horizon)")
        .fix("give a positive --factor, or a positive --horizon");
}
}  // namespace

double epsilon_for_horizon(const body::Body& b, double horizon) {
  if (!(horizon > 0.0) || !std::isfinite(horizon))
    throw InputError("target horizon must be positive")
        .key("horizon")
        .value(fmt::format("{}", horizon))
        .expected("a positive length")
        .fix(fmt::format("the body's horizon is {}; give a larger one to coarsen", b.horizon()));
  return horizon / b.horizon();
}

body::Body rescale(const body::Body& in, double eps) {
  check_epsilon(eps, "factor");
  body::Body b = in;
  const int d = b.dimension;
  const double md = std::pow(eps, d);
  for (auto& v : b.x) v *= eps;
  b.box.lo *= eps;
  b.box.hi *= eps;
  b.box.xy *= eps;
  b.box.xz *= eps;
  b.box.yz *= eps;
  for (auto& m : b.mass) m *= md;
  b.families.h *= eps;
  b.epsilon = in.epsilon * eps;
  if (b.base_potential) b.potential = body::rescaled_potential(b.base_potential, b.epsilon, d);
  if (b.statistics) {
    for (auto& c : b.statistics->covariance) c *= eps * eps;
    for (auto& f : b.statistics->frames)
      for (auto& v : f) v *= eps;
  }
  if (b.homogenisation) {
    auto& h = *b.homogenisation;
    for (auto& v : h.points) v *= eps;
    for (auto& v : h.volume) v *= md;
    for (auto& v : h.mass) v *= md;
    for (auto& v : h.grid_origin) v *= eps;
    for (auto& v : h.grid_axes) v *= eps;
    h.width *= eps;
  }
  b.kind = body::BodyKind::rescaled;
  b.provenance.push_back(fmt::format("rescaled by ε = {} (total ε = {}), horizon {} → {}", eps,
                                     b.epsilon, in.horizon(), b.horizon()));
  return b;
}

}  // namespace pdcg::coarsen
