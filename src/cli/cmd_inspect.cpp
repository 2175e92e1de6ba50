/// `pdcg inspect FILE [--json]`: what a LAMMPS dump or data file holds —
/// atoms, frames, types and masses, box, periodicity, columns.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "command.hpp"
#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/atomistic/dump_reader.hpp"

namespace {

using namespace pdcg::atomistic;

struct Options {
  std::string path;
  bool json = false;
};

struct TypeInfo {
  std::int64_t count = 0;
  double mass = std::nan("");
};

/// Everything `inspect` reports, from either kind of file.
struct Summary {
  std::string kind;  // "dump" or "data"
  bool compressed = false;
  std::int64_t natoms = 0;
  std::size_t nframes = 0;
  std::int64_t first_step = 0, last_step = 0;
  Box box;
  std::vector<std::string> columns;
  std::map<int, TypeInfo> types;
  std::string units, atom_style, title;
  std::map<std::string, std::int64_t> counts;
  std::vector<std::string> sections;
  bool natoms_varies = false;
  std::string no_types;  ///< why `types` is empty (zero atoms, no type column)
};

void collect_types(const Atoms& a, Summary& s) {
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.type.empty()) break;
    auto& t = s.types[a.type[i]];
    ++t.count;
    if (std::isnan(t.mass)) t.mass = a.mass_of(i);
  }
  for (int t = 1; t <= a.ntypes; ++t) {  // declared types without atoms
    auto& ti = s.types[t];
    if (std::isnan(ti.mass) && static_cast<std::size_t>(t) < a.type_mass.size())
      ti.mass = a.type_mass[static_cast<std::size_t>(t)];
  }
}

Summary summarize(const std::string& path) {
  Summary s;
  if (detect_atom_file_kind(path) == AtomFileKind::dump) {
    DumpReader dump(path);
    s.kind = "dump";
    s.compressed = dump.compressed();
    s.nframes = dump.nframes();
    s.first_step = dump.info(0).timestep;
    s.last_step = dump.info(s.nframes - 1).timestep;
    s.natoms = dump.info(0).natoms;
    for (std::size_t n = 1; n < s.nframes; ++n)
      if (dump.info(n).natoms != s.natoms) s.natoms_varies = true;
    s.box = dump.info(0).box;
    s.columns = dump.columns();
    s.units = dump.units();
    collect_types(dump.frame(0), s);  // types and masses from the first frame only
    if (s.natoms == 0)
      s.no_types = fmt::format(
          "none: frame 0 (timestep {}) has zero atoms ({}:{}: ITEM: NUMBER "
          "OF ATOMS 0)",
          s.first_step, path, dump.info(0).natoms_line);
    else if (s.types.empty())
      s.no_types = fmt::format("(no type column: {}:{}: ITEM: ATOMS {})", path,
                               dump.info(0).atoms_line - 1, fmt::join(s.columns, " "));
  } else {
    const DataFile d = read_data(path);
    s.kind = "data";
    s.compressed = d.compressed;
    s.nframes = 1;
    s.natoms = static_cast<std::int64_t>(d.atoms.size());
    s.box = d.atoms.box;
    s.columns = d.columns;
    s.atom_style = d.style == AtomStyle::unknown ? "" : std::string(to_string(d.style));
    s.title = d.title;
    s.counts = d.counts;
    s.sections = d.sections;
    collect_types(d.atoms, s);
    if (s.types.empty())
      s.no_types = s.natoms == 0 ? fmt::format("none: {} has zero atoms", path)
                                 : std::string("(no type column)");
  }
  return s;
}

std::string json_string(std::string_view v) {
  std::string out = "\"";
  for (const char c : v) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20)
          out += fmt::format("\\u{:04x}", static_cast<unsigned>(c));
        else
          out += c;
    }
  }
  return out + "\"";
}
std::string json_number(double v) { return std::isfinite(v) ? fmt::format("{}", v) : "null"; }
std::string json_strings(const std::vector<std::string>& v) {
  std::vector<std::string> q;
  for (const auto& s : v) q.push_back(json_string(s));
  return fmt::format("[{}]", fmt::join(q, ", "));
}

void print_json(const std::string& path, const Summary& s) {
  const Box& b = s.box;
  std::string o = "{\n";
  o += fmt::format("  \"file\": {},\n  \"kind\": \"{}\",\n  \"compressed\": {},\n",
                   json_string(path), s.kind, s.compressed);
  o += fmt::format("  \"natoms\": {},\n  \"nframes\": {},\n", s.natoms, s.nframes);
  if (s.kind == "dump") {
    o += fmt::format("  \"timesteps\": [{}, {}],\n  \"natoms_varies\": {},\n", s.first_step,
                     s.last_step, s.natoms_varies);
    if (!s.units.empty()) o += fmt::format("  \"units\": {},\n", json_string(s.units));
  } else {
    o += fmt::format("  \"title\": {},\n  \"atom_style\": {},\n", json_string(s.title),
                     json_string(s.atom_style));
    std::vector<std::string> c;
    for (const auto& [k, v] : s.counts) c.push_back(fmt::format("{}: {}", json_string(k), v));
    o += fmt::format("  \"counts\": {{{}}},\n  \"sections\": {},\n", fmt::join(c, ", "),
                     json_strings(s.sections));
  }
  o += fmt::format(
      "  \"box\": {{\"lo\": [{}, {}, {}], \"hi\": [{}, {}, {}], \"tilt\": [{}, {}, {}], "
      "\"periodic\": [{}, {}, {}], \"triclinic\": {}}},\n",
      json_number(b.lo.x()), json_number(b.lo.y()), json_number(b.lo.z()), json_number(b.hi.x()),
      json_number(b.hi.y()), json_number(b.hi.z()), json_number(b.xy), json_number(b.xz),
      json_number(b.yz), b.periodic[0], b.periodic[1], b.periodic[2], b.triclinic());
  o += fmt::format("  \"columns\": {},\n", json_strings(s.columns));
  std::vector<std::string> t;
  for (const auto& [type, info] : s.types)
    t.push_back(fmt::format("{{\"type\": {}, \"count\": {}, \"mass\": {}}}", type, info.count,
                            json_number(info.mass)));
  o += fmt::format("  \"types\": [{}]\n}}\n", fmt::join(t, ", "));
  std::fputs(o.c_str(), stdout);
}

void print_text(const std::string& path, const Summary& s) {
  const Box& b = s.box;
  if (s.kind == "dump") {
    std::printf("%s: LAMMPS dump%s, %zu frame%s, timesteps %lld .. %lld%s\n", path.c_str(),
                s.compressed ? " (gzip)" : "", s.nframes, s.nframes == 1 ? "" : "s",
                static_cast<long long>(s.first_step), static_cast<long long>(s.last_step),
                s.units.empty() ? "" : fmt::format(", units {}", s.units).c_str());
    std::printf("  atoms:    %lld%s\n", static_cast<long long>(s.natoms),
                s.natoms_varies ? " in frame 0 (varies between frames)" : "");
  } else {
    std::printf("%s: LAMMPS data file%s, atom style %s\n  title:    %s\n", path.c_str(),
                s.compressed ? " (gzip)" : "", s.atom_style.empty() ? "?" : s.atom_style.c_str(),
                s.title.c_str());
    std::printf("  atoms:    %lld\n", static_cast<long long>(s.natoms));
    std::string c;
    for (const auto& [k, v] : s.counts) c += fmt::format("{}{} {}", c.empty() ? "" : ", ", v, k);
    std::printf("  header:   %s\n  sections: %s\n", c.c_str(),
                fmt::format("{}", fmt::join(s.sections, ", ")).c_str());
  }
  std::string types;
  for (const auto& [type, info] : s.types)
    types += fmt::format("{}{}: {} atoms{}", types.empty() ? "" : "; ", type, info.count,
                         std::isfinite(info.mass) ? fmt::format(", mass {}", info.mass) : "");
  std::printf("  types:    %s\n", types.empty() ? s.no_types.c_str() : types.c_str());
  std::printf("  box:      lo (%s)  hi (%s)\n",
              fmt::format("{}, {}, {}", b.lo.x(), b.lo.y(), b.lo.z()).c_str(),
              fmt::format("{}, {}, {}", b.hi.x(), b.hi.y(), b.hi.z()).c_str());
  if (b.triclinic()) std::printf("  tilt:     xy %g  xz %g  yz %g\n", b.xy, b.xz, b.yz);
  std::printf(
      "  periodic: %s %s %s%s\n", b.periodic[0] ? "p" : "f", b.periodic[1] ? "p" : "f",
      b.periodic[2] ? "p" : "f",
      s.kind == "data" ? " (a data file does not say; LAMMPS takes it from 'boundary')" : "");
  std::printf("  columns:  %s\n", fmt::format("{}", fmt::join(s.columns, " ")).c_str());
}

pdcg::cli::Registration reg(100, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand(
      "inspect", "Summarise a LAMMPS dump or data file (atoms, frames, types, box, columns)");
  auto opts = std::make_shared<Options>();
  sub->add_option("file", opts->path, "A LAMMPS text dump or data file (plain or gzip)")
      ->required();
  sub->add_flag("--json", opts->json, "Print one JSON object instead of text");
  sub->footer(
      "Examples:\n  pdcg inspect traj.lammpstrj.gz\n  pdcg inspect system.data --json\n"
      "JSON keys: file, kind, compressed, natoms, nframes, box{lo,hi,tilt,periodic,triclinic},\n"
      "columns, types[{type,count,mass}]; dumps add timesteps, natoms_varies, units;\n"
      "data files add title, atom_style, counts, sections.");
  return [opts] {
    const Summary s = summarize(opts->path);
    if (opts->json)
      print_json(opts->path, s);
    else
      print_text(opts->path, s);
    return 0;
  };
});

}  // namespace
