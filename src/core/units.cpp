#include "pdcg/core/units.hpp"

#include <limits>

#include "pdcg/core/error.hpp"

namespace pdcg {

UnitStyle parse_unit_style(std::string_view name, std::string_view where) {
  if (name == "none") return UnitStyle::none;
  if (name == "lj") return UnitStyle::lj;
  if (name == "metal") return UnitStyle::metal;
  if (name == "real") return UnitStyle::real;
  if (name == "si") return UnitStyle::si;
  throw InputError("unknown unit style")
      .source(where)
      .key("units")
      .value(name)
      .expected("one of none, lj, metal, real, si")
      .fix("use the LAMMPS unit style the data was produced with");
}

std::string_view to_string(UnitStyle style) {
  switch (style) {
    case UnitStyle::none: return "none";
    case UnitStyle::lj: return "lj";
    case UnitStyle::metal: return "metal";
    case UnitStyle::real: return "real";
    case UnitStyle::si: return "si";
  }
  return "none";
}

UnitConstants unit_constants(UnitStyle style) {
  // Values of LAMMPS src/update.cpp (force->mvv2e, force->ftm2v, force->boltz, force->nktv2p);
  // pressure units from https://docs.lammps.org/units.html (1 bar = 1e5 Pa, 1 atm = 101325 Pa).
  switch (style) {
    case UnitStyle::metal:
      return {1.0364269e-4, 1.0 / 1.0364269e-4, 8.617343e-5, 1.6021765e6, 1e-4};
    case UnitStyle::real:
      return {48.88821291 * 48.88821291, 1.0 / 48.88821291 / 48.88821291, 0.0019872067, 68568.415,
              1.01325e-4};
    case UnitStyle::si:
      return {1.0, 1.0, 1.3806504e-23, 1.0, 1e-9};
    case UnitStyle::lj:
    case UnitStyle::none:
      return {1.0, 1.0, 1.0, 1.0, 0.0};
  }
  return {1.0, 1.0, 1.0, 1.0, 0.0};
}

UnitNames unit_names(UnitStyle style) {
  switch (style) {
    case UnitStyle::metal:
      return {"eV",     "Angstrom",   "eV/Angstrom",   "ps",
              "rad/ps", "1/Angstrom", "eV/Angstrom^3", "bar"};
    case UnitStyle::real:
      return {"kcal/mol", "Angstrom",   "kcal/mol/Angstrom",   "fs",
              "rad/fs",   "1/Angstrom", "kcal/mol/Angstrom^3", "atm"};
    case UnitStyle::si:
      return {"J", "m", "N", "s", "rad/s", "1/m", "J/m^3", "Pa"};
    case UnitStyle::lj:
      return {"reduced (epsilon)",         "reduced (sigma)",
              "reduced (epsilon/sigma)",   "reduced (tau)",
              "reduced (1/tau)",           "reduced (1/sigma)",
              "reduced (epsilon/sigma^3)", "reduced (epsilon/sigma^3)"};
    case UnitStyle::none:
      break;
  }
  return {"none", "none", "none", "none", "none", "none", "none", "none"};
}

double energy_density_to_gpa(UnitStyle style) {
  const UnitConstants c = unit_constants(style);
  if (!(c.pressure_to_gpa > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return c.nktv2p * c.pressure_to_gpa;
}

}  // namespace pdcg
