#include "csv_units.hpp"

#include <fmt/format.h>

namespace pdcg::scene {

std::string csv_units_comment(const Scene& s, bool dynamic) {
  // The scene has no unit system of its own: its numbers are in the units its moduli (or the
  // model file's energies and lengths) and its lengths are given in.
  const std::string style = std::string(to_string(s.units));
  const std::string system =
      s.units == UnitStyle::none
          ? "none (model units: those of the scene's lengths, moduli and density)"
          : fmt::format(
                "{} (lengths in the distance unit of LAMMPS units {}; stresses in the unit "
                "of the moduli, or energy/length^3 of a Cauchy–Born model file)",
                style, style);
  const std::string per = s.dimension == 2 ? " per unit thickness" : "";
  const std::string force =
      s.dimension == 2 ? "force = stress × length per unit thickness" : "force = stress × length^2";
  if (!dynamic)
    return fmt::format(
        "# units: {}; step: load step (count); t: load factor (dimensionless, 0..1); "
        "<set>_f<axis>: reaction on the set along a prescribed axis, {}\n",
        system, force);
  return fmt::format(
      "# units: {}; step: time step (count); t: time = length × sqrt(density/stress); kinetic, "
      "internal, total, total_verlet: energy = stress × length^{}{}; <set>_f<axis>: reaction on "
      "the set along a prescribed axis, {}; damping_coefficient: 1/time; broken_bonds: count\n",
      system, s.dimension, per, force);
}

}  // namespace pdcg::scene
