/// \file
/// Private to the atomistic module: parameter files of many-body styles with one entry per
/// element triple (Stillinger–Weber `*.sw`, Tersoff `*.tersoff`), read and mapped to atom
/// types as LAMMPS's PairSW / PairTersoff `coeff`, `read_file` and `setup_params` do:
///   - one `pair_coeff * * FILE el1 … elN` (N = number of atom types; the last such command
///     wins, as each call re-reads the file in LAMMPS);
///   - `#` starts a comment; blank lines are skipped; an entry is the three element names
///     followed by its values, continued over as many lines as it takes (TextFileReader::
///     next_line(nparams));
///   - entries naming an element that is not mapped are skipped unparsed;
///   - every triple of mapped elements needs exactly one entry ("Potential file is missing an
///     entry" / "has duplicate entry" in LAMMPS);
///   - a `UNITS:` tag on the first line is checked against the `units` command; metal ↔ real
///     are converted by LAMMPS's factor 23.060549 (utils::get_conversion_factor), other
///     mismatches refused.
/// Every failure is an InputError naming the file and line (or the pair_coeff command).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "pdcg/atomistic/potential.hpp"
#include "pdcg/core/error.hpp"

namespace pdcg::atomistic::detail {

struct TripleFormat {
  std::string_view style;               ///< LAMMPS style name ("sw")
  std::string_view label;               ///< name in messages ("Stillinger-Weber")
  std::vector<std::string_view> names;  ///< names of the values after the three elements
};

struct TripleTable {
  std::string file;                   ///< resolved path of the parameter file
  long coeff_line = 0;                ///< line of the pair_coeff command in the spec's source
  std::vector<std::string> elements;  ///< mapped elements in order of first appearance
  std::vector<int> element_of_type;   ///< [t], t = 1..ntypes: 0-based element (index 0 unused)
  std::size_t nvalues = 0;
  /// nvalues numbers per element triple (i, j, k), at ((i·ne + j)·ne + k)·nvalues
  std::vector<double> values;
  std::vector<long> line;  ///< first line of the entry of each triple
  /// Energy conversion factor from the file's UNITS tag to the spec's units (1 if none).
  double energy_factor = 1.0;

  int nelements() const { return static_cast<int>(elements.size()); }
  std::size_t index(int i, int j, int k) const {
    const auto ne = elements.size();
    return (static_cast<std::size_t>(i) * ne + static_cast<std::size_t>(j)) * ne +
           static_cast<std::size_t>(k);
  }
  const double* entry(int i, int j, int k) const {
    return values.data() + index(i, j, k) * nvalues;
  }
  /// "Si C C" for messages.
  std::string triple_name(int i, int j, int k) const;
  /// The entry index of each type triple (ti, tj, tk), t = 1..ntypes, at
  /// (ti·(ntypes+1) + tj)·(ntypes+1) + tk (0 where a type is 0).
  std::vector<int> type_triple_index(int ntypes) const;
};

/// Reads the parameter file of the (last) pair_coeff command of `spec` for a style whose
/// entries hold `format.names.size()` values after the three element names.
TripleTable read_triple_table(const PotentialSpec& spec, const TripleFormat& format);

/// Calls entry(i, j, k, v, p) for every element triple (i, j, k) of the table, i slowest: v its
/// values, p its parameter slot in params (resized to one slot per triple).
template <class Param, class Entry>
void for_each_entry(const TripleTable& table, std::vector<Param>& params, Entry&& entry) {
  const int ne = table.nelements();
  params.resize(table.values.size() / table.nvalues);
  for (int i = 0; i < ne; ++i)
    for (int j = 0; j < ne; ++j)
      for (int k = 0; k < ne; ++k)
        entry(i, j, k, table.entry(i, j, k), params[table.index(i, j, k)]);
}

/// "Illegal pair_style STYLE command" about the argument `value` of the spec's pair_style line.
InputError pair_style_argument_error(const PotentialSpec& spec, std::string_view style,
                                     const std::string& value, std::string_view expected);

/// An InputError about the value `name` of the entry (i, j, k), naming the file and its line.
InputError entry_error(const TripleTable& table, int i, int j, int k, std::string problem);

}  // namespace pdcg::atomistic::detail
