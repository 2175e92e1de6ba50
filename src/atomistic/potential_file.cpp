#include "pdcg/atomistic/potential_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "pdcg/config.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::atomistic {

namespace fs = std::filesystem;

namespace {

struct Command {
  std::string text;  ///< joined, comment stripped
  long line = 0;     ///< first physical line
};

/// Splits text into commands: comments (`#` outside quotes) removed, `&` continuation joined.
std::vector<Command> split_commands(std::string_view text) {
  std::vector<Command> out;
  std::string pending;
  long pending_line = 0;
  long lineno = 0;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view raw = text.substr(pos, end - pos);
    ++lineno;
    // strip comment outside quotes
    char quote = 0;
    std::size_t cut = raw.size();
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const char c = raw[i];
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '#') {
        cut = i;
        break;
      }
    }
    std::string_view body = trim(raw.substr(0, cut));
    const bool continued = !body.empty() && body.back() == '&';
    if (continued) body = trim(body.substr(0, body.size() - 1));
    if (pending.empty() && !body.empty()) pending_line = lineno;
    if (!body.empty()) {
      if (!pending.empty()) pending += ' ';
      pending += body;
    }
    if (!continued && !pending.empty()) {
      out.push_back({pending, pending_line});
      pending.clear();
    }
    if (end == text.size()) break;
    pos = end + 1;
  }
  if (!pending.empty()) out.push_back({pending, pending_line});
  return out;
}

std::vector<std::string> words_of(std::string_view s) {
  std::vector<std::string> w;
  for (auto v : split_blanks(s)) {
    std::string t(v);
    if (t.size() >= 2 && (t.front() == '"' || t.front() == '\'') && t.back() == t.front())
      t = t.substr(1, t.size() - 2);
    w.push_back(std::move(t));
  }
  return w;
}

bool is_number(std::string_view s) {
  if (s.empty()) return false;
  char* end = nullptr;
  const std::string t(s);
  std::strtod(t.c_str(), &end);
  return end == t.c_str() + t.size();
}

bool is_integer(std::string_view s) {
  if (s.empty()) return false;
  for (char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

/// "N atom types" from a data file header (0 if not found / unreadable).
int data_file_ntypes(const std::string& path) {
  std::ifstream in(path);
  if (!in) return 0;
  std::string line;
  int count = 0;
  for (int n = 0; n < 200 && std::getline(in, line); ++n) {
    if (n == 0) continue;  // title line
    auto w = words_of(line.substr(0, line.find('#')));
    if (w.size() >= 3 && w[1] == "atom" && w[2] == "types" && is_integer(w[0]))
      return std::stoi(w[0]);
    if (w.size() == 1 && !is_number(w[0])) break;  // first section header
    ++count;
  }
  return 0;
}

/// Largest explicit type index in a range token (0 if only wildcards).
int max_type_in(std::string_view token) {
  int m = 0;
  std::size_t i = 0;
  while (i < token.size()) {
    if (token[i] >= '0' && token[i] <= '9') {
      std::size_t j = i;
      while (j < token.size() && token[j] >= '0' && token[j] <= '9') ++j;
      m = std::max(m, std::atoi(std::string(token.substr(i, j - i)).c_str()));
      i = j;
    } else {
      ++i;
    }
  }
  return m;
}

/// Pair styles whose pair_coeff starts with `* * FILE` or `I J FILE` (tabulated/many-body).
bool style_takes_file(std::string_view style) {
  // styles whose first non-numeric coefficient is not a file (element or model names)
  static const std::set<std::string, std::less<>> no_file{"kim",
                                                          "python",
                                                          "mliap",
                                                          "lj/cut",
                                                          "morse",
                                                          "zero",
                                                          "lj/cut/coul/cut",
                                                          "lj/cut/coul/long",
                                                          "lj/expand",
                                                          "soft",
                                                          "yukawa",
                                                          "born",
                                                          "buck",
                                                          "coul/cut",
                                                          "lj96/cut",
                                                          "mie/cut",
                                                          "gauss",
                                                          "beck",
                                                          "lj/smooth/linear",
                                                          "lj/gromacs"};
  return !no_file.count(style);
}

bool is_eam_style(std::string_view style) {
  return style == "eam" || style == "eam/alloy" || style == "eam/fs";
}

/// The units of every potential file named by pair_coeff against spec.units, as LAMMPS's
/// utils::open_potential / PotentialFileReader: a file's `UNITS:` tag must equal the unit
/// style, except metal ↔ real, which LAMMPS converts for the styles that support it (the
/// native EAM styles convert exactly as LAMMPS, build_eam_tables). A file without a tag is
/// used as it is, as LAMMPS does; for EAM files (DYNAMO tables are in eV and Å) that is worth a
/// warning when the units are not metal.
void check_file_units(const PotentialSpec& spec) {
  const std::string units(to_string(spec.units));
  const std::string where =
      spec.units_line > 0
          ? fmt::format("`units {}` ({}:{})", units, spec.source, spec.units_line)
          : fmt::format("no `units` command in {}: LAMMPS's default lj", spec.source);
  std::set<std::string> seen;
  for (const auto& c : spec.pair_coeff) {
    const std::string name = coeff_file_argument(spec, c);
    if (name.empty() || !seen.insert(name).second) continue;
    const auto path = find_potential_file(name);
    if (!path) continue;  // reported where the file is read
    const std::string tag = potential_file_units(*path);
    const std::string style =
        spec.pair_style.rfind("hybrid", 0) == 0 && !c.args.empty() ? c.args[0] : spec.pair_style;
    if (tag.empty()) {
      if (is_eam_style(style) && spec.units != UnitStyle::metal)
        log::warn(
            "{}:{}: {} declares no units (no UNITS: tag); EAM (DYNAMO) tables are in eV and "
            "Angstrom, i.e. `units metal`, but {} — LAMMPS uses the numbers as they are, so does "
            "pdcg",
            spec.source, c.line_number, name, where);
      continue;
    }
    if (tag == units) continue;
    const bool convertible =
        (tag == "metal" && units == "real") || (tag == "real" && units == "metal");
    if (convertible) {
      if (is_eam_style(style))
        log::debug("{}:{}: converting {} from {} to {} units (energies x {}), as LAMMPS does",
                   spec.source, c.line_number, name, tag, units,
                   tag == "metal" ? "23.060549" : "1/23.060549");
      continue;  // other styles: LAMMPS converts or refuses (embedded LAMMPS reports it)
    }
    throw InputError("potential file requires " + tag + " units but " + units + " units are in use")
        .source(spec.source)
        .line(c.line_number)
        .key("pair_coeff")
        .value(fmt::format("{} (UNITS: {}); {}", name, tag, where))
        .expected(fmt::format("`units {}`{}", tag,
                              tag == "metal"  ? " (or real, which LAMMPS converts to)"
                              : tag == "real" ? " (or metal, which LAMMPS converts to)"
                                              : ""))
        .fix(spec.units_line > 0
                 ? fmt::format("change line {} of {} to `units {}`", spec.units_line, spec.source,
                               tag)
                 : fmt::format("add `units {}` to {} (before pair_style)", tag, spec.source));
  }
}

}  // namespace

bool lammps_available() { return PDCG_ENABLE_LAMMPS != 0; }

std::optional<std::string> find_potential_file(std::string_view name) {
  if (name.empty()) return std::nullopt;
  std::error_code ec;
  const fs::path given{std::string(name)};
  if (fs::is_regular_file(given, ec)) return given.string();
  const fs::path base = given.filename();
  if (const char* env = std::getenv("LAMMPS_POTENTIALS"); env && *env) {
    const fs::path p = fs::path(env) / base;
    if (fs::is_regular_file(p, ec)) return p.string();
  }
  const fs::path p = fs::path(PDCG_LAMMPS_POTENTIALS_DIR) / base;
  if (fs::is_regular_file(p, ec)) return p.string();
  return std::nullopt;
}

std::array<bool, 3> parse_boundary(std::string_view text, std::string_view source, long line,
                                   std::string_view key) {
  const auto w = split_blanks(text);
  auto bad = [&](std::string_view problem, std::string_view value) {
    return InputError(std::string(problem))
        .source(source)
        .line(line)
        .key(key)
        .value(value)
        .expected(
            "three boundary styles, one per direction x y z: p (periodic), f, s or m "
            "(non-periodic), or a lo/hi pair such as fs; e.g. \"p p f\"")
        .fix("see https://docs.lammps.org/boundary.html");
  };
  if (w.size() != 3) throw bad("a boundary needs three styles", text);
  std::array<bool, 3> periodic{};
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string_view f = w[k];
    if (f.empty() || f.size() > 2) throw bad("bad boundary style", f);
    for (char c : f)
      if (c != 'p' && c != 'f' && c != 's' && c != 'm') throw bad("bad boundary style", f);
    const char lo = f[0], hi = f.size() == 2 ? f[1] : f[0];
    // Domain::set_boundary: "Both sides of boundary must be periodic"
    if ((lo == 'p') != (hi == 'p')) throw bad("both sides of a periodic boundary must be p", f);
    periodic[k] = lo == 'p';
  }
  return periodic;
}

std::string potential_file_units(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    const auto w = split_blanks(line);
    if (w.empty()) continue;  // TextFileReader::next_line skips blank lines
    for (std::size_t i = 0; i + 1 < w.size(); ++i)
      if (w[i] == "UNITS:") return std::string(w[i + 1]);
    return {};
  }
  return {};
}

void parse_type_range(std::string_view token, int ntypes, int& lo, int& hi, std::string_view source,
                      long line, std::string_view command) {
  auto bad = [&](std::string_view problem) {
    return InputError(std::string(problem))
        .source(source)
        .line(line)
        .key(command)
        .value(token)
        .expected(ntypes > 0 ? "an atom type or range (N, *, *N, N*, M*N) within 1.." +
                                   std::to_string(ntypes)
                             : std::string("an atom type or range (N, *, *N, N*, M*N)"))
        .fix("use the atom types of the data file (its header's 'atom types' count)");
  };
  const auto star = token.find('*');
  auto num = [&](std::string_view s) -> int {
    if (!is_integer(s)) throw bad("malformed atom type");
    return std::atoi(std::string(s).c_str());
  };
  if (star == std::string_view::npos) {
    lo = hi = num(token);
  } else {
    if (token.find('*', star + 1) != std::string_view::npos) throw bad("malformed atom type range");
    const auto a = token.substr(0, star), b = token.substr(star + 1);
    lo = a.empty() ? 1 : num(a);
    hi = b.empty() ? ntypes : num(b);
    if (b.empty() && ntypes <= 0) throw bad("wildcard type range needs the number of atom types");
  }
  if (lo < 1 || (ntypes > 0 && hi > ntypes) || hi < lo) throw bad("unknown atom type");
}

std::string coeff_file_argument(const PotentialSpec& spec, const CoeffLine& c) {
  std::string style = spec.pair_style;
  std::size_t first = 0;
  if (style == "hybrid" || style == "hybrid/overlay" || style == "hybrid/scaled") {
    if (c.args.empty()) return {};
    style = c.args[0];
    first = 1;
  }
  if (!style_takes_file(style) || c.args.size() <= first) return {};
  const std::string& tok = c.args[first];
  if (is_number(tok) || tok == "NULL") return {};
  return tok;
}

void check_atom_types(PotentialSpec& spec, int ntypes) {
  int lo, hi;
  for (const auto& c : spec.pair_coeff) {
    parse_type_range(c.i, ntypes, lo, hi, spec.source, c.line_number, "pair_coeff");
    parse_type_range(c.j, ntypes, lo, hi, spec.source, c.line_number, "pair_coeff");
    // `pair_coeff * * FILE el1 … elN`: one element (or NULL) per atom type
    if (c.i == "*" && c.j == "*" && !coeff_file_argument(spec, c).empty()) {
      const std::size_t first = (spec.pair_style.rfind("hybrid", 0) == 0) ? 2 : 1;
      const auto nel = c.args.size() >= first ? static_cast<long>(c.args.size() - first) : 0L;
      const bool mapped = spec.pair_style.rfind("eam/", 0) == 0 || spec.pair_style == "tersoff" ||
                          spec.pair_style == "sw" || spec.pair_style.rfind("tersoff/", 0) == 0;
      if (mapped && nel != ntypes)
        throw InputError(
            "pair_coeff maps a different number of atom types than the configuration has")
            .source(spec.source)
            .line(c.line_number)
            .key("pair_coeff")
            .value(c.line)
            .expected(std::to_string(ntypes) +
                      " element names (or NULL) after the file, one per atom type")
            .fix("list one element per atom type of the data file");
    }
  }
  for (const auto& c : spec.bond_coeff) {
    // bond types are not atom types; only check the syntax
    if (!is_integer(c.i) && c.i.find('*') == std::string::npos)
      throw InputError("malformed bond type")
          .source(spec.source)
          .line(c.line_number)
          .key("bond_coeff")
          .value(c.i)
          .expected("a bond type or range");
  }
  // masses: replay the mass commands (in order, later ones win) against the type count
  std::vector<double> mass(static_cast<std::size_t>(ntypes + 1),
                           std::numeric_limits<double>::quiet_NaN());
  for (const std::string& line : spec.lines) {
    const auto w = words_of(line);
    if (w.size() < 3 || w[0] != "mass") continue;
    parse_type_range(w[1], ntypes, lo, hi, spec.source, 0, line);
    const double m = std::strtod(w[2].c_str(), nullptr);  // validated when read
    for (int t = lo; t <= hi; ++t) mass[static_cast<std::size_t>(t)] = m;
  }
  spec.ntypes = ntypes;
  spec.type_mass = std::move(mass);
}

void require_supported_styles(const PotentialSpec& spec, bool lammps_enabled) {
  if (!spec.pair_style.empty() && !native_pair_style(spec.pair_style) && !lammps_enabled)
    throw InputError("pair style needs embedded LAMMPS, which this build does not have")
        .source(spec.source)
        .line(spec.pair_style_line)
        .key("pair_style")
        .value(spec.pair_style)
        .expected("a native style (" + native_pair_style_names() + ")")
        .fix("rebuild pdcg with -DPDCG_ENABLE_LAMMPS=ON (liblammps), or use a native style");
  if (!spec.bond_style.empty() && !native_bond_style(spec.bond_style) && !lammps_enabled)
    throw InputError("bond style needs embedded LAMMPS, which this build does not have")
        .source(spec.source)
        .line(spec.bond_style_line)
        .key("bond_style")
        .value(spec.bond_style)
        .expected("a native bond style (" + native_bond_style_names() + ")")
        .fix("rebuild pdcg with -DPDCG_ENABLE_LAMMPS=ON (liblammps), or use a native style");
}

PotentialSpec read_potential_commands_from_string(std::string_view text, std::string_view source,
                                                  int ntypes) {
  PotentialSpec spec;
  spec.source = std::string(source);
  std::map<std::string, int> ignored;  // command -> count
  int deck_ntypes = 0;
  int max_type = 0;
  int element_count = 0;
  struct MassCmd {
    std::string range;
    double value;
    long line;
  };
  std::vector<MassCmd> masses, charges;  // `mass`, `set type T charge Q`

  auto err = [&](const Command& c, std::string_view cmd, std::string problem) {
    InputError e(std::move(problem));
    e.source(spec.source).line(c.line).key(cmd);
    return e;
  };

  for (const Command& c : split_commands(text)) {
    const auto w = words_of(c.text);
    if (w.empty()) continue;
    const std::string& cmd = w[0];
    const TextLocation where{spec.source, c.line, cmd};
    auto need = [&](std::size_t n, std::string_view expected) {
      if (w.size() < n)
        throw err(c, cmd, "too few arguments")
            .value(c.text)
            .expected(expected)
            .fix("see https://docs.lammps.org/" + cmd + ".html");
    };
    bool accepted = true;
    static const std::set<std::string, std::less<>> kAccepted{
        "units",       "atom_style", "mass",       "pair_style",    "pair_coeff",
        "pair_modify", "bond_style", "bond_coeff", "special_bonds", "boundary"};
    if (kAccepted.count(cmd) && c.text.find('$') != std::string::npos)
      throw err(c, cmd, "LAMMPS variables are not expanded in potential commands")
          .value(c.text)
          .expected("literal values")
          .fix("replace ${name} or $x by its value");
    if (cmd == "units") {
      need(2, "units STYLE");
      spec.units = parse_unit_style(w[1], spec.source + ":" + std::to_string(c.line));
      spec.units_line = c.line;
    } else if (cmd == "boundary") {
      need(4, "boundary X Y Z");
      std::string args;
      for (std::size_t k = 1; k < w.size(); ++k) args += (k > 1 ? " " : "") + w[k];
      spec.periodic = parse_boundary(args, spec.source, c.line, cmd);
      spec.boundary = args;
      spec.boundary_line = c.line;
      accepted = false;  // the configuration's property, not the interaction's: not replayed
    } else if (cmd == "atom_style") {
      need(2, "atom_style STYLE");
      spec.atom_style = w[1];
    } else if (cmd == "mass") {
      need(3, "mass TYPE VALUE");
      const double m = parse_double(w[2], where);
      if (!(m > 0.0))
        throw err(c, cmd, "mass must be positive").value(w[2]).expected("a positive mass");
      if (w[1].find('*') == std::string::npos) {
        int lo, hi;
        parse_type_range(w[1], 0, lo, hi, spec.source, c.line, cmd);
        max_type = std::max(max_type, hi);
      }
      masses.push_back({w[1], m, c.line});
    } else if (cmd == "pair_style") {
      need(2, "pair_style STYLE ARGS");
      if (w[1] != spec.pair_style) {
        // a different pair_style discards earlier coefficients and modifiers (as LAMMPS does;
        // the same style again only changes its global settings)
        spec.pair_coeff.clear();
        spec.pair_modify.clear();
      }
      spec.pair_style = w[1] == "none" ? std::string() : w[1];
      spec.pair_style_args.assign(w.begin() + 2, w.end());
      spec.pair_style_line = c.line;
    } else if (cmd == "pair_coeff") {
      need(3, "pair_coeff I J ARGS");
      if (spec.pair_style.empty())
        throw err(c, cmd, "pair_coeff before pair_style")
            .value(c.text)
            .expected("a pair_style command first");
      CoeffLine cl;
      cl.i = w[1];
      cl.j = w[2];
      // LAMMPS (Input::pair_coeff) swaps plain numeric types so that I <= J
      if (is_integer(cl.i) && is_integer(cl.j) && std::atoi(cl.j.c_str()) < std::atoi(cl.i.c_str()))
        std::swap(cl.i, cl.j);
      cl.args.assign(w.begin() + 3, w.end());
      cl.line = c.text;
      cl.line_number = c.line;
      int lo, hi;
      for (const auto* tok : {&cl.i, &cl.j}) {
        if (tok->find('*') == std::string::npos)
          parse_type_range(*tok, ntypes, lo, hi, spec.source, c.line, cmd);
        max_type = std::max(max_type, max_type_in(*tok));
      }
      if (ntypes > 0)
        for (const auto* tok : {&cl.i, &cl.j})
          parse_type_range(*tok, ntypes, lo, hi, spec.source, c.line, cmd);
      const std::string file = coeff_file_argument(spec, cl);
      if (!file.empty()) {
        const auto found = find_potential_file(file);
        if (!found)
          throw err(c, cmd, "potential file not found")
              .value(file)
              .expected(
                  std::string(
                      "a readable file: the path as given, or its name in $LAMMPS_POTENTIALS or ") +
                  PDCG_LAMMPS_POTENTIALS_DIR)
              .fix("check the file name, or set LAMMPS_POTENTIALS to the directory holding it");
        if (cl.i == "*" && cl.j == "*") {
          const std::size_t first = spec.pair_style.rfind("hybrid", 0) == 0 ? 2 : 1;
          if (cl.args.size() > first)
            element_count = std::max(element_count, static_cast<int>(cl.args.size() - first));
        }
      }
      spec.pair_coeff.push_back(std::move(cl));
    } else if (cmd == "pair_modify") {
      need(2, "pair_modify KEYWORD VALUE");
      for (std::size_t k = 1; k < w.size(); ++k) {
        if (w[k] == "shift" || w[k] == "tail" || w[k] == "compute" || w[k] == "table" ||
            w[k] == "table/disp" || w[k] == "tabinner" || w[k] == "tabinner/disp" ||
            w[k] == "nofdotr") {
          if (w[k] != "nofdotr" && k + 1 >= w.size())
            throw err(c, cmd, "keyword without value")
                .value(w[k])
                .expected("a value after the keyword");
          if (w[k] == "shift" && w[k + 1] != "yes" && w[k + 1] != "no")
            throw err(c, cmd, "bad shift value").value(w[k + 1]).expected("yes or no");
          if (w[k] != "nofdotr") ++k;
        } else if (w[k] == "mix") {
          if (k + 1 >= w.size() ||
              (w[k + 1] != "geometric" && w[k + 1] != "arithmetic" && w[k + 1] != "sixthpower"))
            throw err(c, cmd, "bad mixing rule")
                .value(k + 1 < w.size() ? w[k + 1] : "")
                .expected("geometric, arithmetic or sixthpower");
          ++k;
        } else if (w[k] == "pair" || w[k] == "special") {
          // hybrid sub-style selection: keep words as written
        }
      }
      spec.pair_modify.insert(spec.pair_modify.end(), w.begin() + 1, w.end());
    } else if (cmd == "bond_style") {
      need(2, "bond_style STYLE ARGS");
      if (w[1] != spec.bond_style) spec.bond_coeff.clear();
      spec.bond_style = w[1] == "none" ? std::string() : w[1];
      spec.bond_style_args.assign(w.begin() + 2, w.end());
      spec.bond_style_line = c.line;
    } else if (cmd == "bond_coeff") {
      need(2, "bond_coeff N ARGS");
      if (spec.bond_style.empty())
        throw err(c, cmd, "bond_coeff before bond_style")
            .value(c.text)
            .expected("a bond_style command first");
      CoeffLine cl;
      cl.i = w[1];
      cl.args.assign(w.begin() + 2, w.end());
      cl.line = c.text;
      cl.line_number = c.line;
      if (!is_integer(cl.i) && cl.i.find('*') == std::string::npos)
        throw err(c, cmd, "malformed bond type")
            .value(cl.i)
            .expected("a bond type (integer) or range");
      spec.bond_coeff.push_back(std::move(cl));
    } else if (cmd == "special_bonds") {
      need(2, "special_bonds KEYWORD VALUES");
      // Force::set_special: every special_bonds command starts from the defaults
      std::array<double, 3> lj{0, 0, 0}, coul{0, 0, 0};
      for (std::size_t k = 1; k < w.size(); ++k) {
        const std::string& key = w[k];
        auto three = [&](std::array<double, 3>& a) {
          if (k + 3 >= w.size())
            throw err(c, cmd, "too few factors")
                .value(key)
                .expected("three factors (1-2 1-3 1-4) after " + key);
          for (int m = 0; m < 3; ++m) {
            const double v =
                parse_double(w[k + 1 + static_cast<std::size_t>(m)], {spec.source, c.line, key});
            if (v < 0.0 || v > 1.0)
              throw err(c, cmd, "special factor outside [0,1]")
                  .value(w[k + 1 + static_cast<std::size_t>(m)])
                  .expected("a factor in [0, 1]");
            a[static_cast<std::size_t>(m)] = v;
          }
          k += 3;
        };
        if (key == "lj/coul") {
          three(lj);
          coul = lj;
        } else if (key == "lj") {
          three(lj);
        } else if (key == "coul") {
          three(coul);
        } else if (key == "amber") {
          lj = {0.0, 0.0, 0.5};
          coul = {0.0, 0.0, 5.0 / 6.0};
        } else if (key == "charmm") {
          lj = coul = {0.0, 0.0, 0.0};
        } else if (key == "dreiding") {
          lj = coul = {0.0, 0.0, 1.0};
        } else if (key == "fene") {
          lj = coul = {0.0, 1.0, 1.0};
        } else if (key == "angle" || key == "dihedral" || key == "one/five") {
          if (k + 1 >= w.size() || (w[k + 1] != "yes" && w[k + 1] != "no"))
            throw err(c, cmd, "keyword needs yes or no")
                .value(key)
                .expected("yes or no after " + key);
          if (w[k + 1] == "yes")
            log::warn("{}:{}: special_bonds {} yes: pdcg finds 1-3/1-4 partners through bonds only",
                      spec.source, c.line, key);
          ++k;
        } else {
          throw err(c, cmd, "unknown special_bonds keyword")
              .value(key)
              .expected(
                  "lj/coul, lj, coul, amber, charmm, dreiding, fene, angle, dihedral, one/five");
        }
      }
      spec.special_lj = lj;
      spec.special_coul = coul;
    } else if (cmd == "set" && w.size() >= 5 && w[1] == "type" && w[3] == "charge") {
      // per-type charges for embedded LAMMPS (atom_style charge/full); other `set` forms are
      // per-atom edits of a configuration and are ignored below
      if (w.size() != 5)
        throw err(c, cmd, "only `set type T charge Q` is supported")
            .value(c.text)
            .expected("set type T charge Q")
            .fix("give each charge its own atom type, or put the charges in the data file");
      charges.push_back({w[2], parse_double(w[4], where), c.line});
    } else if (cmd == "kspace_style" && !(w.size() >= 2 && w[1] == "none")) {
      throw err(c, cmd, "long-range (k-space) electrostatics is not supported")
          .value(c.text)
          .expected("no kspace_style: a pair energy that is a sum over finite families")
          .fix(
              "use a cut-off coulomb pair style (lj/cut/coul/cut, lj/cut/coul/dsf, "
              "coul/wolf, …) or compute this model with LAMMPS itself");
    } else if ((cmd == "angle_style" || cmd == "dihedral_style" || cmd == "improper_style") &&
               !(w.size() >= 2 && (w[1] == "none" || w[1] == "zero"))) {
      throw err(c, cmd, "angle, dihedral and improper terms are not supported")
          .value(c.text)
          .expected("pair and bond styles only (or `" + cmd + " none`)")
          .fix("drop the " + cmd +
               " (its energy would be missing from every result), or "
               "compute this model with LAMMPS itself");
    } else if (cmd == "create_box") {
      accepted = false;
      if (w.size() >= 2 && is_integer(w[1])) deck_ntypes = std::atoi(w[1].c_str());
      ++ignored[cmd];
    } else if (cmd == "read_data") {
      accepted = false;
      if (w.size() >= 2) {
        fs::path p(w[1]);
        if (p.is_relative()) {
          const fs::path dir = fs::path(spec.source).parent_path();
          if (!dir.empty() && fs::exists(dir / p)) p = dir / p;
        }
        if (const int n = data_file_ntypes(p.string()); n > 0) deck_ntypes = n;
      }
      ++ignored[cmd];
    } else {
      accepted = false;
      ++ignored[cmd];
    }
    if (accepted) spec.lines.push_back(c.text);
  }

  if (!ignored.empty()) {
    std::string list;
    for (const auto& [k, n] : ignored)
      list += (list.empty() ? "" : ", ") + k + (n > 1 ? " (" + std::to_string(n) + "x)" : "");
    log::info("{}: ignored commands that do not define the potential: {}", spec.source, list);
  }

  int nt = ntypes > 0 ? ntypes : deck_ntypes > 0 ? deck_ntypes : std::max(max_type, element_count);
  spec.ntypes = nt;
  spec.type_mass.assign(static_cast<std::size_t>(std::max(nt, 0) + 1),
                        std::numeric_limits<double>::quiet_NaN());
  for (const auto& m : masses) {
    // a wildcard needs the type count: without it, check_atom_types applies it later
    if (nt <= 0 && m.range.find('*') != std::string::npos) continue;
    int lo, hi;
    parse_type_range(m.range, nt, lo, hi, spec.source, m.line, "mass");
    if (hi >= static_cast<int>(spec.type_mass.size()))
      spec.type_mass.resize(static_cast<std::size_t>(hi + 1),
                            std::numeric_limits<double>::quiet_NaN());
    for (int t = lo; t <= hi; ++t) spec.type_mass[static_cast<std::size_t>(t)] = m.value;
  }
  for (const auto& q : charges) {
    if (nt <= 0 && q.range.find('*') != std::string::npos) continue;
    int lo, hi;
    parse_type_range(q.range, nt, lo, hi, spec.source, q.line, "set");
    if (hi >= static_cast<int>(spec.type_charge.size()))
      spec.type_charge.resize(static_cast<std::size_t>(hi + 1),
                              std::numeric_limits<double>::quiet_NaN());
    for (int t = lo; t <= hi; ++t) spec.type_charge[static_cast<std::size_t>(t)] = q.value;
  }
  if (nt > 0) check_atom_types(spec, nt);
  check_file_units(spec);
  return spec;
}

PotentialSpec read_potential_commands(const std::string& path, int ntypes) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw InputError("cannot open potential command file")
        .source(path)
        .expected("a readable file with LAMMPS commands (pair_style, pair_coeff, …)")
        .fix("check the path");
  std::ostringstream ss;
  ss << in.rdbuf();
  return read_potential_commands_from_string(ss.str(), path, ntypes);
}

}  // namespace pdcg::atomistic
