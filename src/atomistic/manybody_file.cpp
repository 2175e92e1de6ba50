// Element-triple parameter files (sw, tersoff) as LAMMPS's PairSW / PairTersoff read them.
#include "manybody_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <set>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::atomistic::detail {

namespace {

/// utils::get_conversion_factor(ENERGY, METAL2REAL) of LAMMPS.
constexpr double kMetalToReal = 23.060549;

std::string usage(const TripleFormat& f) {
  return fmt::format(
      "pair_coeff * * FILE el1 … elN (one element per atom type), e.g. "
      "'pair_coeff * * Si.{} Si'",
      f.style);
}

/// The UNITS: tag of the first line ("" if none), as utils::open_potential reads it.
std::string units_tag(const std::string& first_line) {
  const auto w = split_blanks(first_line);
  for (std::size_t i = 0; i + 1 < w.size(); ++i)
    if (w[i] == "UNITS:") return std::string(w[i + 1]);
  return {};
}

}  // namespace

std::vector<int> TripleTable::type_triple_index(int ntypes) const {
  const int n1 = ntypes + 1;
  std::vector<int> out(static_cast<std::size_t>(n1 * n1 * n1), 0);
  for (int ti = 1; ti <= ntypes; ++ti)
    for (int tj = 1; tj <= ntypes; ++tj)
      for (int tk = 1; tk <= ntypes; ++tk)
        out[static_cast<std::size_t>((ti * n1 + tj) * n1 + tk)] =
            static_cast<int>(index(element_of_type[static_cast<std::size_t>(ti)],
                                   element_of_type[static_cast<std::size_t>(tj)],
                                   element_of_type[static_cast<std::size_t>(tk)]));
  return out;
}

std::string TripleTable::triple_name(int i, int j, int k) const {
  return elements[static_cast<std::size_t>(i)] + " " + elements[static_cast<std::size_t>(j)] + " " +
         elements[static_cast<std::size_t>(k)];
}

InputError pair_style_argument_error(const PotentialSpec& spec, std::string_view style,
                                     const std::string& value, std::string_view expected) {
  return InputError("Illegal pair_style " + std::string(style) + " command")
      .source(spec.source)
      .line(spec.pair_style_line)
      .key("pair_style " + std::string(style))
      .value(value)
      .expected(expected);
}

InputError entry_error(const TripleTable& t, int i, int j, int k, std::string problem) {
  InputError e(std::move(problem));
  e.source(t.file).line(t.line[t.index(i, j, k)]).key(t.triple_name(i, j, k));
  return e;
}

TripleTable read_triple_table(const PotentialSpec& spec, const TripleFormat& format) {
  const std::string style(format.style);
  if (spec.pair_coeff.empty())
    throw InputError("no pair_coeff command for pair_style " + style)
        .source(spec.source)
        .line(spec.pair_style_line)
        .key("pair_coeff")
        .expected(usage(format));
  // LAMMPS: each pair_coeff re-reads the file; the last one is in effect. All must be valid.
  for (const CoeffLine& c : spec.pair_coeff) {
    auto bad = [&](std::string problem) {
      return InputError(std::move(problem))
          .source(spec.source)
          .line(c.line_number)
          .key("pair_coeff")
          .value(c.line)
          .expected(usage(format));
    };
    if (c.i != "*" || c.j != "*")
      throw bad("pair_style " + style +
                " takes one pair_coeff with I,J = * * (Incorrect args for "
                "pair coefficients)");
    if (c.args.size() != 1 + static_cast<std::size_t>(spec.ntypes))
      throw bad(
          fmt::format("pair_coeff needs the file and {} element names, one per atom type "
                      "(Incorrect args for pair coefficients)",
                      spec.ntypes));
  }
  const CoeffLine& c = spec.pair_coeff.back();
  TripleTable t;
  t.coeff_line = c.line_number;
  t.nvalues = format.names.size();
  // map[i] = which element the i-th atom type is (PairSW::coeff)
  t.element_of_type.assign(static_cast<std::size_t>(spec.ntypes + 1), -1);
  for (int type = 1; type <= spec.ntypes; ++type) {
    const std::string& el = c.args[static_cast<std::size_t>(type)];
    if (el == "NULL")
      throw InputError(
          "atom type mapped to NULL: LAMMPS accepts NULL only under pair_style "
          "hybrid, which is not native (\"All pair coeffs are not set\")")
          .source(spec.source)
          .line(c.line_number)
          .key("pair_coeff")
          .value(fmt::format("type {} → NULL", type))
          .expected("an element of the parameter file for every atom type")
          .fix("map every type to an element, or run pair_style hybrid through LAMMPS");
    auto it = std::find(t.elements.begin(), t.elements.end(), el);
    if (it == t.elements.end()) {
      t.elements.push_back(el);
      it = t.elements.end() - 1;
    }
    t.element_of_type[static_cast<std::size_t>(type)] = static_cast<int>(it - t.elements.begin());
  }
  const auto found = find_potential_file(c.args[0]);
  if (!found)
    throw InputError("potential file not found")
        .source(spec.source)
        .line(c.line_number)
        .key("pair_coeff")
        .value(c.args[0])
        .expected("a readable " + std::string(format.label) +
                  " file: the path as given, or its name in $LAMMPS_POTENTIALS or the LAMMPS "
                  "potentials directory");
  t.file = *found;
  std::ifstream in(t.file);
  if (!in)
    throw InputError("cannot open " + std::string(format.label) + " potential file")
        .source(t.file)
        .expected("a readable file")
        .fix("check the path and permissions");

  const int ne = t.nelements();
  const std::size_t ntriples =
      static_cast<std::size_t>(ne) * static_cast<std::size_t>(ne) * static_cast<std::size_t>(ne);
  t.values.assign(ntriples * t.nvalues, 0.0);
  t.line.assign(ntriples, 0);
  const std::size_t nwords = 3 + t.nvalues;
  std::set<std::string> file_elements;
  std::vector<std::vector<std::string>> kept_words(ntriples);  // parsed once all are known
  std::string raw, first_line;
  long lineno = 0, entry_line = 0;
  std::vector<std::string> words;
  auto element_index = [&](const std::string& name) {
    const auto it = std::find(t.elements.begin(), t.elements.end(), name);
    return it == t.elements.end() ? -1 : static_cast<int>(it - t.elements.begin());
  };
  while (std::getline(in, raw)) {
    ++lineno;
    if (lineno == 1) first_line = raw;
    const auto hash = raw.find('#');
    const std::string_view body =
        std::string_view(raw).substr(0, hash == std::string::npos ? raw.size() : hash);
    const auto w = split_blanks(body);
    if (w.empty()) continue;
    if (words.empty()) entry_line = lineno;
    for (auto v : w) words.emplace_back(v);
    if (words.size() < nwords) continue;  // the entry continues on the next line
    if (words.size() != nwords)
      throw InputError(fmt::format("{} potential file entry has {} words, expected {} (three "
                                   "elements and {} values)",
                                   format.label, words.size(), nwords, t.nvalues))
          .source(t.file)
          .line(entry_line)
          .key(words[0] + " " + words[1] + " " + words[2])
          .expected(fmt::format("{} values after the elements", t.nvalues))
          .fix(
              "each entry is 3 element names followed by its values; a value is missing or "
              "two entries run together");
    for (std::size_t e = 0; e < 3; ++e) file_elements.insert(words[e]);
    const int i = element_index(words[0]), j = element_index(words[1]), k = element_index(words[2]);
    if (i >= 0 && j >= 0 && k >= 0) {  // else an element not mapped: skipped (LAMMPS)
      const std::size_t q = t.index(i, j, k);
      if (t.line[q] != 0)
        throw InputError(fmt::format("{} potential file has a duplicate entry (first on line {})",
                                     format.label, t.line[q]))
            .source(t.file)
            .line(entry_line)
            .key(t.triple_name(i, j, k))
            .expected("one entry per element triple")
            .fix("delete one of the two entries");
      t.line[q] = entry_line;
      kept_words[q] = std::move(words);
    }
    words.clear();
  }
  if (!words.empty())
    throw InputError(fmt::format("{} potential file ends inside an entry: {} of {} words "
                                 "(Incorrect format in {} potential file)",
                                 format.label, words.size(), nwords, format.style))
        .source(t.file)
        .line(entry_line)
        .key(words.size() >= 3 ? words[0] + " " + words[1] + " " + words[2] : words[0])
        .expected(fmt::format("3 element names and {} values", t.nvalues))
        .fix("the file is truncated: restore the missing values");

  // unit conversion (utils::open_potential + PotentialFileReader)
  const std::string file_units = units_tag(first_line);
  const std::string units(to_string(spec.units));
  if (!file_units.empty() && file_units != units) {
    if (file_units == "metal" && units == "real") {
      t.energy_factor = kMetalToReal;
    } else if (file_units == "real" && units == "metal") {
      t.energy_factor = 1.0 / kMetalToReal;
    } else {
      throw InputError(fmt::format("{} potential file requires {} units but {} units are in use",
                                   format.style, file_units, units))
          .source(t.file)
          .line(1)
          .key("UNITS:")
          .value(file_units)
          .expected(units + " (or metal/real, which are converted)")
          .fix("use 'units " + file_units + "' in the potential commands");
    }
    log::warn("{}: converting {} potential in {} units to {} units (factor {})", t.file,
              format.style, file_units, units, t.energy_factor);
  }

  // every mapped element must appear; every triple needs its entry (setup_params)
  for (const std::string& el : t.elements)
    if (!file_elements.count(el)) {
      std::string list;
      for (const auto& f : file_elements) list += (list.empty() ? "" : " ") + f;
      throw InputError("element not in the " + std::string(format.label) + " potential file")
          .source(spec.source)
          .line(c.line_number)
          .key("pair_coeff")
          .value(el)
          .expected("one of the file's elements: " + list + " (" + t.file + ")")
          .fix("map the atom types to elements of the file, or use a file for " + el);
    }
  for (int i = 0; i < ne; ++i)
    for (int j = 0; j < ne; ++j)
      for (int k = 0; k < ne; ++k) {
        const std::size_t q = t.index(i, j, k);
        if (t.line[q] == 0)
          throw InputError("potential file is missing an entry for an element triple")
              .source(t.file)
              .key(style)
              .value(t.triple_name(i, j, k))
              .expected(fmt::format("an entry '{} …' for every triple of the mapped elements",
                                    t.triple_name(i, j, k)))
              .fix("add the entry to the file, or map fewer elements in pair_coeff (line " +
                   std::to_string(c.line_number) + " of " + spec.source + ")");
        const auto& w = kept_words[q];
        for (std::size_t v = 0; v < t.nvalues; ++v) {
          const std::string field = t.triple_name(i, j, k) + " " + std::string(format.names[v]);
          t.values[q * t.nvalues + v] = parse_double(w[3 + v], {t.file, t.line[q], field});
        }
      }
  return t;
}

}  // namespace pdcg::atomistic::detail
