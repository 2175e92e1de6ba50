/// \file
/// Reader for LAMMPS data files (the format of `read_data` / `write_data`,
/// https://docs.lammps.org/read_data.html), plain or gzip-compressed.
///
/// Layout: a title line; a header of counts (`N atoms`, `N bonds`, `N atom
/// types`, `N bond types`, angles/dihedrals/impropers and their types, `extra
/// ... per atom`, ...) and box lines (`xlo xhi`, `ylo yhi`, `zlo zhi`, and `xy xz
/// yz` for a triclinic box, which gives the box directly, not a bounding box);
/// then sections, each a keyword line followed by as many lines as the header
/// implies. `#` starts a comment anywhere.
///
/// Read: Masses, Atoms, Velocities, Bonds. Skipped with a debug note (their
/// line counts come from the header): Pair Coeffs, PairIJ Coeffs, Bond/Angle/
/// Dihedral/Improper Coeffs and the class2 cross-term coeffs, Angles,
/// Dihedrals, Impropers, Ellipsoids, Lines, Triangles. Anything else is an
/// InputError ("unknown section").
///
/// Atom styles and their Atoms columns (optionally followed by image flags
/// `ix iy iz`):
///   atomic:              id type x y z
///   charge:              id type q x y z
///   bond/angle/molecular id mol type x y z
///   full:                id mol type q x y z
/// The style is taken from the `Atoms # <style>` comment (write_data writes
/// it); else from the caller's hint; else from the number of columns of the
/// first line (5/8 atomic, 7/10 full; 6 and 9 are ambiguous — an InputError
/// asks for the style).
///
/// Positions: with image flags, Atoms::x holds the unwrapped position
/// x + H·image and Atoms::image the flags (as for dumps). A data file does not
/// say which directions are periodic (that is the `boundary` command); Box::periodic
/// is left at its default (all periodic).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"

namespace pdcg::atomistic {

enum class AtomStyle { unknown, atomic, charge, bond, angle, molecular, full };

/// "atomic" → AtomStyle::atomic, ...; AtomStyle::unknown for anything else.
AtomStyle atom_style_from_string(std::string_view name);
std::string_view to_string(AtomStyle style);
/// Names of the Atoms-section columns of a style (without image flags).
std::vector<std::string> atom_style_columns(AtomStyle style);

/// Everything read from a data file.
struct DataFile {
  Atoms atoms;                           ///< sorted by id
  AtomStyle style = AtomStyle::unknown;  ///< style used for the Atoms section
  std::string title;                     ///< first line
  std::map<std::string, std::int64_t>
      counts;                         ///< header counts by keyword ("atoms", "bond types", ...)
  std::vector<std::string> sections;  ///< section keywords in file order
  std::vector<std::string> columns;   ///< Atoms columns (incl. ix iy iz if present)
  bool compressed = false;            ///< the file was gzip-compressed
};

/// Reads a data file. `hint` is used when the Atoms section has no style
/// comment. Throws InputError naming file and line for: unknown header line or
/// section, a section with fewer lines than the header declares (e.g. missing
/// atoms), wrong number of values on a line, non-numeric or NaN values,
/// duplicate atom ids, types out of range, Velocities or Bonds naming an atom
/// id that is not in Atoms.
DataFile read_data(const std::string& path, AtomStyle hint = AtomStyle::unknown);

/// read_data(path, hint).atoms
Atoms read_data_file(const std::string& path, AtomStyle hint = AtomStyle::unknown);

}  // namespace pdcg::atomistic
