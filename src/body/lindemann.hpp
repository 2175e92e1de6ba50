// The melting check shared by the temperature estimates (statistics.cpp) and the quasi-harmonic
// free energy (quasi_harmonic.cpp). Lindemann (1910): crystals melt when the rms displacement
// reaches ≈ 0.10–0.15 of the nearest-neighbour distance; a temperature given in the wrong
// units (kelvin in units lj) lands far beyond.
#pragma once

#include <fmt/format.h>

#include <string>
#include <string_view>

#include "pdcg/core/error.hpp"
#include "pdcg/core/units.hpp"

namespace pdcg::body::detail {

/// What a temperature means in these units, for messages.
inline std::string temperature_unit_hint(UnitStyle units) {
  return units == UnitStyle::lj
             ? "in units lj the temperature is k_B T/ε (LJ fcc melts near 0.7): a temperature in "
               "kelvin belongs to units metal or real"
             : fmt::format("in units {} the temperature is in kelvin", to_string(units));
}

/// Throws InputError (key `key`) when `lindemann`, the rms displacement over the
/// nearest-neighbour distance (`how` says how it was estimated), exceeds 0.15.
inline void require_below_melting(double lindemann, double temperature, UnitStyle units,
                                  std::string_view key, std::string_view how) {
  if (lindemann <= 0.15) return;
  throw InputError("temperature beyond melting for this crystal")
      .key(std::string(key))
      .value(fmt::format("{} (units {}): {} {:.3g} of the nearest-neighbour distance", temperature,
                         to_string(units), how, lindemann))
      .expected(
          "a crystal below melting: rms displacement < 0.15 of the nearest-neighbour distance "
          "(Lindemann)")
      .fix(temperature_unit_hint(units));
}

}  // namespace pdcg::body::detail
