#include "pdcg/core/units.hpp"

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
  // Values of LAMMPS src/update.cpp (force->mvv2e, force->ftm2v, force->boltz).
  switch (style) {
    case UnitStyle::metal: return {1.0364269e-4, 1.0 / 1.0364269e-4, 8.617343e-5};
    case UnitStyle::real: return {48.88821291 * 48.88821291, 1.0 / 48.88821291 / 48.88821291, 0.0019872067};
    case UnitStyle::si: return {1.0, 1.0, 1.3806504e-23};
    case UnitStyle::lj:
    case UnitStyle::none: return {1.0, 1.0, 1.0};
  }
  return {1.0, 1.0, 1.0};
}

}  // namespace pdcg
