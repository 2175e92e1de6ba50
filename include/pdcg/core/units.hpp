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
  /// energy/volume -> pressure unit (LAMMPS nktv2p): eV/Å³ -> bar (metal), kcal/mol/Å³ -> atm
  /// (real), 1 for si, lj and none.
  double nktv2p;
  /// pressure unit -> GPa: 1e-4 (bar, metal), 1.01325e-4 (atm, real), 1e-9 (Pa, si); 0 for lj
  /// and none (reduced units have no GPa value).
  double pressure_to_gpa;
};
UnitConstants unit_constants(UnitStyle style);

/// Names of the units of a style (https://docs.lammps.org/units.html), ASCII, for output
/// headers: lj and none give "reduced" for every quantity ("reduced (epsilon/sigma^3)" …).
struct UnitNames {
  std::string_view energy;          ///< "eV" (metal), "kcal/mol" (real), "J" (si)
  std::string_view length;          ///< "Angstrom", "Angstrom", "m"
  std::string_view force;           ///< "eV/Angstrom", "kcal/mol/Angstrom", "N"
  std::string_view time;            ///< "ps", "fs", "s"
  std::string_view frequency;       ///< angular frequency ω: "rad/ps", "rad/fs", "rad/s"
  std::string_view wavenumber;      ///< κ: "1/Angstrom", "1/Angstrom", "1/m"
  std::string_view energy_density;  ///< "eV/Angstrom^3", "kcal/mol/Angstrom^3", "J/m^3"
  std::string_view pressure;        ///< "bar", "atm", "Pa"
};
UnitNames unit_names(UnitStyle style);

/// Energy per volume of `style` in GPa (energy_density · nktv2p · pressure_to_gpa); NaN for lj
/// and none. metal: 1 eV/Å³ = 160.21765 GPa; real: 1 kcal/mol/Å³ = 6.9476 GPa.
double energy_density_to_gpa(UnitStyle style);

}  // namespace pdcg
