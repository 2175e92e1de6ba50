/// \file
/// Private to the atomistic module: the sweep over short lists that the many-body kernels of
/// sw and tersoff share (Potential::manybody_forces; docs/dynamics.md, "Native three-body and
/// bond-order styles"): per centre i, each listed partner j within a cutoff with its
/// separation Y = y_j − y_i, whether i owns the pair, and the force gathered on i added once
/// after the centre. Inline templates: the callbacks inline into each kernel; nothing is
/// allocated.
#pragma once

#include <cstdint>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic::detail {

/// A centre i of the sweep.
struct SweepCentre {
  int type = 0;  ///< i's atom type
  /// Force gathered on i, added to f[3i..3i+3) after the centre.
  double f[3] = {0.0, 0.0, 0.0};
  /// Partners the kernel kept (its own short arrays), 0 at each centre.
  std::int64_t kept = 0;
};

/// For each centre k0 ≤ i < k1 of the short lists: partner(c, j, dx, dy, dz, rsq, owned) for
/// each partner j on i's list with rsq = |Y|² < cutsq, Y = (dx, dy, dz) = y_j − y_i, in list
/// order (`owned`: the pair's term is i's to evaluate); then centre(c); then c.f is added to
/// f. A partner callback returns false when the kernel cannot go on (a short array is full):
/// the sweep stops there and returns false. Returns true otherwise.
template <class Partner, class Centre>
inline bool sweep_short_lists(const ShortLists& s, std::int64_t k0, std::int64_t k1,
                              const double* y, double cutsq, double* f, Partner&& partner,
                              Centre&& centre) {
  for (std::int64_t i = k0; i < k1; ++i) {
    SweepCentre c;
    c.type = s.type[i];
    const double xi = y[3 * i], yi = y[3 * i + 1], zi = y[3 * i + 2];
    const std::int32_t* nb = s.neighbor + s.offset[i];
    const std::int32_t cnt = s.count[i], own = s.owned[i];
    for (std::int32_t q = 0; q < cnt; ++q) {
      const std::int32_t j = nb[q];
      const double dx = y[3 * j] - xi, dy = y[3 * j + 1] - yi, dz = y[3 * j + 2] - zi;
      const double rsq = dx * dx + dy * dy + dz * dz;
      if (rsq >= cutsq) continue;
      if (!partner(c, j, dx, dy, dz, rsq, q < own)) return false;
    }
    centre(c);
    f[3 * i] += c.f[0];
    f[3 * i + 1] += c.f[1];
    f[3 * i + 2] += c.f[2];
  }
  return true;
}

/// A pair term's forces with g = (dE/dr)/r and Y = (dx, dy, dz) = y_j − y_i:
/// f_i += g Y (into the centre's c.f), f_j −= g Y.
inline void add_pair_force(SweepCentre& c, double* f, std::int32_t j, double g, double dx,
                           double dy, double dz) {
  c.f[0] += g * dx;
  c.f[1] += g * dy;
  c.f[2] += g * dz;
  f[3 * j] -= g * dx;
  f[3 * j + 1] -= g * dy;
  f[3 * j + 2] -= g * dz;
}

/// Appends partner j and its Y = (dx, dy, dz) to the kernel's short arrays of the centre
/// (sj[c.kept], sd[3 c.kept ..]); returns its slot, or −1 when the arrays hold `capacity`
/// partners already (nothing written).
inline std::int64_t keep_partner(SweepCentre& c, std::int32_t j, double dx, double dy, double dz,
                                 std::int32_t* sj, double* sd, std::int64_t capacity) {
  const std::int64_t ns = c.kept;
  if (ns == capacity) return -1;
  sj[ns] = j;
  sd[3 * ns] = dx;
  sd[3 * ns + 1] = dy;
  sd[3 * ns + 2] = dz;
  c.kept = ns + 1;
  return ns;
}

}  // namespace pdcg::atomistic::detail
