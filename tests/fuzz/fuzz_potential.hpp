/// \file
/// Builds the potential of a fuzzed spec and evaluates one small family, so that the
/// numbers read from a fuzzed file also reach the evaluation (splines, cutoffs).
#pragma once

#include <algorithm>
#include <cmath>
#include <string_view>
#include <vector>

#include "pdcg/atomistic/potentials.hpp"

namespace pdcg::fuzz {

/// The pair styles make_potential builds natively; any other style would start embedded
/// LAMMPS (a build with PDCG_ENABLE_LAMMPS=ON), whose errors end the process inside
/// liblammps and which is not what these harnesses test: such a spec counts as refused.
inline bool native_style(std::string_view ps) {
  for (std::string_view s :
       {"", "lj/cut", "morse", "zero", "eam", "eam/alloy", "eam/fs", "sw", "tersoff"})
    if (ps == s) return true;
  return false;
}

inline void build_and_evaluate(const atomistic::PotentialSpec& spec) {
  if (!native_style(spec.pair_style)) return;
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
