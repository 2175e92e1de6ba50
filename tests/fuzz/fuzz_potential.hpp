/// \file
/// Builds the potential of a fuzzed spec and evaluates one small family, so that the
/// numbers read from a fuzzed file also reach the evaluation (splines, cutoffs).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "pdcg/atomistic/potentials.hpp"

namespace pdcg::fuzz {

inline void build_and_evaluate(const atomistic::PotentialSpec& spec) {
  const auto p = atomistic::make_potential(spec);
  const double rc = p->cutoff();
  if (!(rc > 0.0) || !std::isfinite(rc)) return;
  // three partners inside the cutoff, one per type where there are several
  const int nt = std::max(1, p->ntypes());
  const double bond[9] = {0.35 * rc, 0.0, 0.0, 0.0, 0.6 * rc, 0.0, 0.1 * rc, 0.2 * rc, 0.85 * rc};
  const int type[3] = {1, std::min(2, nt), std::min(3, nt)};
  atomistic::FamilyState f;
  f.type = 1;
  f.size = 3;
  f.neighbor_type = type;
  f.bond = bond;
  std::vector<double> t(9);
  (void)p->force_state(f, t.data());
}

}  // namespace pdcg::fuzz
