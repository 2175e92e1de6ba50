/// \file
/// Reading the LAMMPS commands that define an interaction model.
///
/// Users write potentials as LAMMPS commands: either a short file with only those commands or
/// a full input deck. The reader follows LAMMPS's input syntax
/// (https://docs.lammps.org/Commands_parse.html):
/// `#` starts a comment (outside quotes), a trailing `&` continues a command on the next line,
/// words are separated by blanks. Accepted commands: `units`, `atom_style`, `mass`,
/// `pair_style`, `pair_coeff`, `pair_modify`, `bond_style`, `bond_coeff`, `special_bonds`,
/// and `boundary` (the periodicity of the configuration, PotentialSpec::periodic).
/// `create_box N …` and `read_data FILE` (its header's "atom types") only give the number of
/// atom types; every other command is ignored and listed in one log note.
///
/// Units (https://docs.lammps.org/units.html): without a `units` command the style is lj, as in
/// LAMMPS. A potential file whose first line carries a `UNITS:` tag (all of LAMMPS's
/// distributed files do) is checked as utils::open_potential does: the same units, or metal ↔
/// real, which the native EAM styles convert as LAMMPS does (energies × 23.060549); any other
/// combination is an InputError naming the file, its units and the fix.
///
/// Potential files named in `pair_coeff` are looked up like LAMMPS does (utils::open_potential):
/// the path as given, then the file name inside $LAMMPS_POTENTIALS, then inside
/// PDCG_LAMMPS_POTENTIALS_DIR (pdcg/config.hpp, Debian: /usr/share/lammps/potentials).
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic {

/// The most atom types pdcg accepts from a configuration or a stored body: per-type-pair tables
/// hold (ntypes+1)² entries per coefficient, 10⁸ for 10⁴ types.
inline constexpr int kMaxAtomTypes = 10000;

/// Reads the potential commands of `path`. `ntypes` > 0 fixes the number of atom types (e.g.
/// from the data file); 0 infers it (create_box/read_data, else the largest type named in
/// mass/pair_coeff, else the element count of a `pair_coeff * * file el1 el2 …`).
/// Throws InputError (file:line, command, bad token) on malformed numbers, type ranges
/// outside 1..ntypes, unknown special_bonds keywords and missing potential files.
PotentialSpec read_potential_commands(const std::string& path, int ntypes = 0);

/// Same, from text; `source` names it in messages (and resolves relative paths of
/// read_data against the current directory).
PotentialSpec read_potential_commands_from_string(std::string_view text,
                                                  std::string_view source = "<string>",
                                                  int ntypes = 0);

/// Checks every pair_coeff/bond_coeff/mass type range of `spec` against `ntypes` (the count the
/// configuration declares) and sets spec.ntypes. Throws InputError naming the file and line of
/// the first command with a type outside 1..ntypes.
void check_atom_types(PotentialSpec& spec, int ntypes);

/// Periodicity of the three arguments of a LAMMPS `boundary` command (Domain::set_boundary):
/// each is one of p, f, s, m or a lo/hi pair of them (e.g. "fs"); p is periodic and must then
/// be on both sides. `text` holds the three arguments ("p p f"). Throws InputError naming
/// `source`, `line` and `key` for anything else.
std::array<bool, 3> parse_boundary(std::string_view text, std::string_view source, long line,
                                   std::string_view key);

/// Unit style a potential file declares in its first non-blank line (`UNITS: metal`, as
/// LAMMPS's utils::get_potential_units reads it); empty if it declares none.
std::string potential_file_units(const std::string& path);

/// Finds a potential file as LAMMPS does; nullopt if none of the places holds it.
std::optional<std::string> find_potential_file(std::string_view name);

/// Parses a LAMMPS type range ("3", "*", "*2", "2*", "1*3") against ntypes into [lo, hi].
/// Throws InputError (with `where`) if malformed or outside 1..ntypes.
void parse_type_range(std::string_view token, int ntypes, int& lo, int& hi, std::string_view source,
                      long line, std::string_view command);

/// The potential file a pair_coeff line names, resolved (empty if the style takes no file).
/// For styles whose coefficients start with a file name (many-body styles, `pair_coeff * *
/// FILE …`), the first non-numeric coefficient is the file.
std::string coeff_file_argument(const PotentialSpec& spec, const CoeffLine& coeff);

/// True when pdcg was built with embedded LAMMPS (PDCG_ENABLE_LAMMPS).
bool lammps_available();

/// True for pair styles pdcg evaluates natively (force states available).
bool native_pair_style(std::string_view style);
/// True for bond styles pdcg evaluates natively.
bool native_bond_style(std::string_view style);
/// The native pair styles, comma separated, for messages ("lj/cut, morse, …").
std::string native_pair_style_names();
/// The native bond styles, comma separated.
std::string native_bond_style_names();

/// Throws InputError (naming the pair_style/bond_style line) when `spec` uses a style that is
/// neither native nor available through embedded LAMMPS (`lammps_enabled` false).
void require_supported_styles(const PotentialSpec& spec, bool lammps_enabled = lammps_available());

}  // namespace pdcg::atomistic
