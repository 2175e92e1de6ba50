// dispersion::zone_edge: the end of a `--direction` curve (π over the shortest non-zero
// projection of the nearest-neighbour bonds), against the closed forms of the fcc Brillouin
// zone (Γ–X at 2π/a along [100], Γ–L·… at √3π/a along [111]) and a chain (π/h).
#include <gtest/gtest.h>

#include <numbers>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/dispersion/body_dispersion.hpp"

using namespace pdcg;

namespace {

body::Body lj_body(atomistic::Atoms at) {
  const auto spec = atomistic::read_potential_commands_from_string(
      "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n", "lj", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  return body::make_delta_body(at, pot, spec);
}

atomistic::Atoms fcc(int n, double a) {
  atomistic::Atoms at;
  at.box.hi = {n * a, n * a, n * a};
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& b : basis) {
          at.id.push_back(static_cast<std::int64_t>(at.id.size() + 1));
          at.type.push_back(1);
          at.x.insert(at.x.end(), {(i + b[0]) * a, (j + b[1]) * a, (k + b[2]) * a});
        }
  return at;
}

}  // namespace

TEST(ZoneEdge, FccAndChainClosedForms) {
  const double a = 1.5496;
  const body::Body b = lj_body(fcc(3, a));
  // 1e-12 relative: the bond vectors are differences of positions (i + b)·a, round-off only
  EXPECT_NEAR(dispersion::zone_edge(b, 0, {1, 0, 0}), 2 * std::numbers::pi / a, 1e-12 / a);
  EXPECT_NEAR(dispersion::zone_edge(b, 0, Eigen::Vector3d(1, 1, 1).normalized()),
              std::sqrt(3.0) * std::numbers::pi / a, 1e-12 / a);

  atomistic::Atoms chain;
  chain.box.hi = {10 * 1.12, 1, 1};
  chain.box.periodic = {true, false, false};
  for (int i = 0; i < 10; ++i) {
    chain.id.push_back(i + 1);
    chain.type.push_back(1);
    chain.x.insert(chain.x.end(), {1.12 * i, 0.5, 0.5});
  }
  const body::Body c = lj_body(chain);
  EXPECT_NEAR(dispersion::zone_edge(c, 3, {1, 0, 0}), std::numbers::pi / 1.12, 1e-12);
  try {
    (void)dispersion::zone_edge(c, 3, {0, 1, 0}, "direction", "(0, 1, 0)");
    ADD_FAILURE() << "no error for a direction perpendicular to the chain";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "direction: no nearest-neighbour bond has a component along the direction: got "
              "'(0, 1, 0)', expected a direction with a zone edge from the nearest-neighbour "
              "shell. Fix: pass kmax=");
  }
}
