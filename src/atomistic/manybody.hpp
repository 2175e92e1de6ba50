/// \file
/// Private to the atomistic module: native three-body and bond-order styles (sw, tersoff) as
/// PD constitutive models, for the style registry (make_potential). docs/potentials.md,
/// "Three-body and bond-order styles", gives ψ_k, the force states and the tangents.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <memory>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic::detail {

/// `pair_style sw [threebody on|off]` (PairSW).
std::unique_ptr<Potential> make_stillinger_weber(const PotentialSpec& spec);
/// `pair_style tersoff [shift δ]` (PairTersoff).
std::unique_ptr<Potential> make_tersoff(const PotentialSpec& spec);

/// The centre's and the partners' types of the family are all within 1..ntypes.
inline bool family_types_valid(const FamilyState& f, int ntypes) {
  if (f.type < 1 || f.type > ntypes) return false;
  for (std::int64_t b = 0; b < f.size; ++b)
    if (f.neighbor_type[b] < 1 || f.neighbor_type[b] > ntypes) return false;
  return true;
}

/// The outputs of one family evaluation: the force state t (3n values) and, with kTangent,
/// the tangent K (9n²).
template <bool kTangent>
struct FamilyOutput {
  double* t;
  double* K;
  std::int64_t n;
  /// The start of an evaluation of family f: zeroes t (and K); false when a type of f is
  /// outside 1..ntypes (the caller returns poison()).
  bool start(const FamilyState& f, int ntypes) const {
    std::fill(t, t + 3 * n, 0.0);
    if constexpr (kTangent) std::fill(K, K + 9 * n * n, 0.0);
    return family_types_valid(f, ntypes);
  }
  /// NaN in t (and K), and NaN to return as ψ_k: a family the style cannot evaluate.
  double poison() const {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::fill(t, t + 3 * n, nan);
    if constexpr (kTangent) std::fill(K, K + 9 * n * n, nan);
    return nan;
  }
};

/// The near list of a family: the bonds b, in order, that a style's filter keeps, each with a
/// value the filter computes from |Y_b|² (|Y_b|² itself, or a shifted length r̃ = |Y_b| + δ).
template <std::int64_t kMax>
struct NearBonds {
  std::int64_t bond[kMax];
  double value[kMax];
  std::int64_t size = 0;
  /// Fills the list from family f: bond b is kept when keep(|Y_b|², v) is true, with value v.
  /// False when more than kMax bonds are kept (the caller returns FamilyOutput::poison()).
  template <class Keep>
  bool collect(const FamilyState& f, Keep&& keep) {
    size = 0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      double v;
      if (!keep(rsq, v)) continue;
      if (size == kMax) return false;
      bond[size] = b;
      value[size++] = v;
    }
    return true;
  }
};

}  // namespace pdcg::atomistic::detail
