/// \file
/// LAMMPS unit styles. pdcg keeps every quantity in the unit style of its
/// input (as LAMMPS does) and records the style in every file it writes.
/// See https://docs.lammps.org/units.html for the definitions.
#pragma once

#include <string>
#include <string_view>

namespace pdcg {

enum class UnitStyle { none, lj, metal, real, si };

/// Parses "none|lj|metal|real|si"; throws InputError naming `where` otherwise.
UnitStyle parse_unit_style(std::string_view name, std::string_view where = {});
std::string_view to_string(UnitStyle style);

/// Conversion constants of a unit style (LAMMPS's force->* values).
struct UnitConstants {
  /// mass*velocity^2 -> energy (LAMMPS mvv2e)
  double mvv2e;
  /// force*time^2/mass -> distance (LAMMPS ftm2v, as 1/ftm2v in force->ftm2v)
  double ftm2v;
  /// Boltzmann constant in energy/temperature units
  double boltz;
};
UnitConstants unit_constants(UnitStyle style);

}  // namespace pdcg
