#include "pdcg/atomistic/data_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"
#include "text_source.hpp"

namespace pdcg::atomistic {

AtomStyle atom_style_from_string(std::string_view n) {
  if (n == "atomic") return AtomStyle::atomic;
  if (n == "charge") return AtomStyle::charge;
  if (n == "bond") return AtomStyle::bond;
  if (n == "angle") return AtomStyle::angle;
  if (n == "molecular") return AtomStyle::molecular;
  if (n == "full") return AtomStyle::full;
  return AtomStyle::unknown;
}

std::string_view to_string(AtomStyle s) {
  switch (s) {
    case AtomStyle::atomic:
      return "atomic";
    case AtomStyle::charge:
      return "charge";
    case AtomStyle::bond:
      return "bond";
    case AtomStyle::angle:
      return "angle";
    case AtomStyle::molecular:
      return "molecular";
    case AtomStyle::full:
      return "full";
    case AtomStyle::unknown:
      break;
  }
  return "unknown";
}

std::vector<std::string> atom_style_columns(AtomStyle s) {
  switch (s) {
    case AtomStyle::atomic:
      return {"id", "type", "x", "y", "z"};
    case AtomStyle::charge:
      return {"id", "type", "q", "x", "y", "z"};
    case AtomStyle::bond:
    case AtomStyle::angle:
    case AtomStyle::molecular:
      return {"id", "mol", "type", "x", "y", "z"};
    case AtomStyle::full:
      return {"id", "mol", "type", "q", "x", "y", "z"};
    case AtomStyle::unknown:
      break;
  }
  return {};
}

namespace {

using detail::ByteSource;
using detail::LineReader;

/// Header count keywords (the words after the number).
constexpr std::array<std::string_view, 19> kCountKeywords{"atoms",
                                                          "bonds",
                                                          "angles",
                                                          "dihedrals",
                                                          "impropers",
                                                          "atom types",
                                                          "bond types",
                                                          "angle types",
                                                          "dihedral types",
                                                          "improper types",
                                                          "extra bond per atom",
                                                          "extra angle per atom",
                                                          "extra dihedral per atom",
                                                          "extra improper per atom",
                                                          "extra special per atom",
                                                          "ellipsoids",
                                                          "lines",
                                                          "triangles",
                                                          "bodies"};

/// Section keyword → header count(s) that give its number of lines.
std::int64_t section_lines(std::string_view s, const std::map<std::string, std::int64_t>& c,
                           bool& known) {
  auto get = [&](const char* k) -> std::int64_t {
    const auto it = c.find(k);
    return it == c.end() ? 0 : it->second;
  };
  known = true;
  if (s == "Atoms" || s == "Velocities") return get("atoms");
  if (s == "Masses" || s == "Pair Coeffs" || s == "Atom Type Labels") return get("atom types");
  if (s == "Bond Type Labels") return get("bond types");
  if (s == "Angle Type Labels") return get("angle types");
  if (s == "Dihedral Type Labels") return get("dihedral types");
  if (s == "Improper Type Labels") return get("improper types");
  if (s == "PairIJ Coeffs") return get("atom types") * (get("atom types") + 1) / 2;
  if (s == "Bonds") return get("bonds");
  if (s == "Angles") return get("angles");
  if (s == "Dihedrals") return get("dihedrals");
  if (s == "Impropers") return get("impropers");
  if (s == "Bond Coeffs") return get("bond types");
  if (s == "Angle Coeffs" || s == "BondBond Coeffs" || s == "BondAngle Coeffs")
    return get("angle types");
  if (s == "Dihedral Coeffs" || s == "MiddleBondTorsion Coeffs" || s == "EndBondTorsion Coeffs" ||
      s == "AngleTorsion Coeffs" || s == "AngleAngleTorsion Coeffs" || s == "BondBond13 Coeffs")
    return get("dihedral types");
  if (s == "Improper Coeffs" || s == "AngleAngle Coeffs") return get("improper types");
  if (s == "Ellipsoids") return get("ellipsoids");
  if (s == "Lines") return get("lines");
  if (s == "Triangles") return get("triangles");
  known = false;
  return 0;
}

constexpr const char* kKnownSections =
    "Atoms, Velocities, Masses, Bonds, Angles, Dihedrals, Impropers, Pair Coeffs, PairIJ Coeffs, "
    "Bond Coeffs, Angle Coeffs, Dihedral Coeffs, Improper Coeffs, BondBond Coeffs, BondAngle "
    "Coeffs, MiddleBondTorsion Coeffs, EndBondTorsion Coeffs, AngleTorsion Coeffs, "
    "AngleAngleTorsion Coeffs, BondBond13 Coeffs, AngleAngle Coeffs, Ellipsoids, Lines, Triangles, "
    "Atom/Bond/Angle/Dihedral/Improper Type Labels";

/// Splits a line into its content (before '#') and its comment (after '#'), both trimmed.
std::string_view strip_comment(std::string_view line, std::string_view* comment = nullptr) {
  const auto hash = line.find('#');
  if (comment)
    *comment = hash == std::string_view::npos ? std::string_view{} : trim(line.substr(hash + 1));
  return trim(line.substr(0, hash));
}

bool starts_alpha(std::string_view s) {
  return !s.empty() && ((s[0] >= 'A' && s[0] <= 'Z') || (s[0] >= 'a' && s[0] <= 'z'));
}

class Parser {
 public:
  Parser(const std::string& path, AtomStyle hint)
      : path_(path), hint_(hint), src_(ByteSource::open(path)), r_(*src_, std::size_t{4} << 20) {}

  DataFile run();

 private:
  [[noreturn]] void fail(long line, std::string problem, std::string_view value,
                         std::string_view expected, std::string_view fix) const {
    InputError e(std::move(problem));
    e.source(path_).line(line);
    if (!value.empty()) e.value(value);
    if (!expected.empty()) e.expected(expected);
    if (!fix.empty()) e.fix(fix);
    throw e;
  }
  /// Next non-blank, non-comment line's content; false at end of file.
  bool next_content(std::string_view& content, std::string_view* comment = nullptr) {
    std::string_view line;
    while (r_.next(line)) {
      content = strip_comment(line, comment);
      if (!content.empty()) return true;
    }
    return false;
  }
  /// Reads the n data lines of `section` into tok_ one at a time via `fn(i)`.
  template <class Fn>
  void for_section_lines(std::string_view section, std::int64_t n, Fn&& fn);

  /// An xyz file (`dump xyz`: a count line, a comment line, then `name x y z` lines) is
  /// refused by name; a data file whose title is a number reads on.
  void refuse_xyz(std::string_view first);
  void header(std::string_view& first_section, std::string_view& first_comment, bool& more);
  void read_atoms(std::int64_t n, std::string_view style_comment);
  void read_masses(std::int64_t n);
  void read_velocities(std::int64_t n);
  void read_bonds(std::int64_t n);
  std::size_t index_of(std::int64_t id, long line, std::string_view section) const;
  double num(std::size_t k, const char* field) const {
    return parse_double(tok_[k], {path_, r_.line_number(), field});
  }
  std::int64_t integer(std::size_t k, const char* field) const {
    return parse_int(tok_[k], {path_, r_.line_number(), field});
  }

  std::string path_;
  AtomStyle hint_;
  std::unique_ptr<ByteSource> src_;
  LineReader r_;
  std::vector<std::string_view> tok_;
  DataFile out_;
  std::unordered_map<std::int64_t, std::size_t> index_;  // atom id -> position in Atoms order
  std::vector<long> atom_line_;                          // line of each atom
  bool have_atoms_ = false;
};

template <class Fn>
void Parser::for_section_lines(std::string_view section, std::int64_t n, Fn&& fn) {
  std::string_view content;
  for (std::int64_t i = 0; i < n; ++i) {
    const bool got = next_content(content);
    if (!got || starts_alpha(content)) {
      const bool atoms = section == "Atoms";
      fail(r_.line_number(),
           fmt::format("{} section has {} lines, the header declares {}", section, i, n),
           got ? std::string(content.substr(0, 60)) : std::string("end of file"),
           atoms ? fmt::format("{} atom lines ('{} atoms' in the header)", n, n)
                 : fmt::format("{} lines in section {}", n, section),
           atoms ? "atoms are missing: fix the header count or add the missing atoms"
                 : "fix the header count or complete the section");
    }
    split_blanks(content, tok_);
    fn(i);
  }
}

void Parser::header(std::string_view& first_section, std::string_view& comment, bool& more) {
  Box& box = out_.atoms.box;
  box.lo = Eigen::Vector3d::Constant(-0.5);  // LAMMPS defaults when a line is absent
  box.hi = Eigen::Vector3d::Constant(0.5);
  std::string_view content;
  std::array<bool, 3> got_box{false, false, false};
  // LAMMPS takes −0.5 .. 0.5 for an axis without its line, silently; a data file written by
  // hand that forgot one gets a box the atoms may not fit: said once per file.
  auto warn_default_box = [&] {
    static constexpr std::array<const char*, 3> kLines{"xlo xhi", "ylo yhi", "zlo zhi"};
    for (std::size_t k = 0; k < 3; ++k)
      if (!got_box[k])
        log::warn(
            "{}: no '{}' header line: LAMMPS's default {} .. {} is used along {} (add the line "
            "if the atoms lie elsewhere)",
            path_, kLines[k], box.lo[static_cast<Eigen::Index>(k)],
            box.hi[static_cast<Eigen::Index>(k)], "xyz"[k]);
  };
  while (next_content(content, &comment)) {
    split_blanks(content, tok_);
    if (starts_alpha(content)) {  // the first section keyword ends the header
      first_section = content;
      more = true;
      warn_default_box();
      return;
    }
    // "<numbers> <keywords>": split at the first alphabetic token.
    std::size_t nnum = 0;
    while (nnum < tok_.size() && !starts_alpha(tok_[nnum])) ++nnum;
    const std::string_view words =
        nnum < tok_.size()
            ? trim(content.substr(static_cast<std::size_t>(tok_[nnum].data() - content.data())))
            : std::string_view{};
    const long ln = r_.line_number();
    auto need = [&](std::size_t k) {
      if (nnum != k)
        fail(ln, fmt::format("header line '{}' needs {} number(s), has {}", words, k, nnum),
             content, fmt::format("{} number(s) before '{}'", k, words), {});
    };
    auto box_pair = [&](int axis, const char* name) {
      need(2);
      got_box[static_cast<std::size_t>(axis)] = true;
      box.lo[axis] = parse_double(tok_[0], {path_, ln, name});
      box.hi[axis] = parse_double(tok_[1], {path_, ln, name});
      if (!(box.hi[axis] > box.lo[axis]))
        fail(ln, "empty box", content, "hi > lo", "check the box bounds");
    };
    if (words == "xlo xhi") {
      box_pair(0, "xlo xhi");
    } else if (words == "ylo yhi") {
      box_pair(1, "ylo yhi");
    } else if (words == "zlo zhi") {
      box_pair(2, "zlo zhi");
    } else if (words == "xy xz yz") {
      need(3);
      box.xy = parse_double(tok_[0], {path_, ln, "xy"});
      box.xz = parse_double(tok_[1], {path_, ln, "xz"});
      box.yz = parse_double(tok_[2], {path_, ln, "yz"});
    } else if (std::find(kCountKeywords.begin(), kCountKeywords.end(), words) !=
               kCountKeywords.end()) {
      need(1);
      const std::int64_t v = parse_int(tok_[0], {path_, ln, words});
      if (v < 0) fail(ln, "negative count", tok_[0], "a count >= 0", {});
      out_.counts[std::string(words)] = v;
    } else {
      fail(ln, "unknown header line", content,
           "'N atoms', 'N atom types', 'N bonds', 'N bond types', ..., 'xlo xhi', 'ylo yhi', "
           "'zlo zhi', 'xy xz yz', or a section keyword",
           "check the spelling; header lines must come before the first section. (Text dumps "
           "start with 'ITEM:'; xyz files and other formats are not read.)");
    }
  }
  more = false;
  warn_default_box();
}

void Parser::refuse_xyz(std::string_view first) {
  const auto count = trim(first);
  if (count.empty() || count.size() > 18 ||
      !std::all_of(count.begin(), count.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return;
  const std::uint64_t back = r_.offset();
  const long back_line = r_.line_number() + 1;
  std::string_view comment, atom;
  bool xyz = false;
  if (r_.next(comment)) {
    // LAMMPS writes "Atoms. Timestep: N"; other programs write anything on line 2
    xyz = trim(comment).substr(0, 17) == "Atoms. Timestep: ";
    if (!xyz && r_.next(atom)) {
      // a data file has no header line with three numbers after the first token
      const auto tok = split_blanks(atom);
      xyz = tok.size() >= 4;
      for (std::size_t k = 1; xyz && k < 4; ++k) {
        double v = 0.0;
        const auto t = tok[k];
        const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        xyz = ec == std::errc() && ptr == t.data() + t.size();
      }
    }
  }
  if (xyz)
    fail(1, "an xyz file (dump xyz) is not read", std::string(count),
         "a LAMMPS data file (write_data) or a text dump (dump custom / dump atom)",
         "an xyz file has no box, no atom ids and element names instead of types; write a text "
         "dump instead: `dump 1 all custom N traj.dump id type x y z` (or `dump 1 all atom N "
         "traj.dump`), or a data file (write_data)");
  r_.seek(back, back_line);
}

std::size_t Parser::index_of(std::int64_t id, long line, std::string_view section) const {
  const auto it = index_.find(id);
  if (it == index_.end())
    fail(line, fmt::format("{}: atom id not in the Atoms section", section), std::to_string(id),
         "an id listed in Atoms", "the sections disagree; the file is corrupt or hand-edited");
  return it->second;
}

void Parser::read_atoms(std::int64_t n, std::string_view style_comment) {
  Atoms& a = out_.atoms;
  AtomStyle style = AtomStyle::unknown;
  if (!style_comment.empty()) {
    const auto name = split_blanks(style_comment)[0];
    style = atom_style_from_string(name);
    if (style == AtomStyle::unknown)
      fail(r_.line_number(), "unsupported atom style", name,
           "atomic, charge, bond, angle, molecular or full",
           "convert the system to one of these styles (e.g. write_data from a run using "
           "atom_style full)");
    if (hint_ != AtomStyle::unknown && hint_ != style)
      log::warn("{}:{}: the file says 'Atoms # {}', the caller expected {}; using {}", path_,
                r_.line_number(), name, to_string(hint_), name);
  } else {
    style = hint_;
  }
  const auto N = static_cast<std::size_t>(n);
  std::size_t base = 0;
  bool has_mol = false, has_q = false;
  // Arrays grow with the lines read (a header count far beyond the file's lines must fail as
  // a short section, not as a huge allocation).
  std::size_t cap = 0;
  auto grow = [&](std::size_t need) {
    if (need <= cap) return;
    cap = std::min(N, std::max<std::size_t>(2 * cap, 4096));
    a.id.resize(cap);
    a.type.resize(cap);
    a.x.resize(3 * cap);
    atom_line_.resize(cap);
    if (has_mol) a.molecule.resize(cap);
    if (has_q) a.charge.resize(cap);
    if (!a.image.empty()) a.image.resize(3 * cap, 0);
  };
  for_section_lines("Atoms", n, [&](std::int64_t ii) {
    const auto i = static_cast<std::size_t>(ii);
    const long ln = r_.line_number();
    if (style == AtomStyle::unknown) {  // infer from the first line
      switch (tok_.size()) {
        case 5:
        case 8:
          style = AtomStyle::atomic;
          break;
        case 7:
        case 10:
          style = AtomStyle::full;
          break;
        default:
          fail(ln, fmt::format("cannot tell the atom style from {} columns", tok_.size()),
               fmt::format("{}", fmt::join(tok_, " ")),
               "an 'Atoms # <style>' comment, or 5/8 (atomic) or 7/10 (full) columns",
               "add the style after the section keyword, e.g. 'Atoms # bond', or pass the atom "
               "style (6 columns could be charge or bond/molecular)");
      }
    }
    if (i == 0) {
      out_.style = style;
      out_.columns = atom_style_columns(style);
      base = out_.columns.size();
      has_mol = style == AtomStyle::bond || style == AtomStyle::angle ||
                style == AtomStyle::molecular || style == AtomStyle::full;
      has_q = style == AtomStyle::charge || style == AtomStyle::full;
    }
    grow(i + 1);
    if (tok_.size() != base && tok_.size() != base + 3)
      fail(ln, fmt::format("Atoms line has {} values", tok_.size()), std::string(tok_[0]),
           fmt::format("{} values ({}) or {} with image flags ix iy iz (atom style {})", base,
                       fmt::join(out_.columns, " "), base + 3, to_string(style)),
           "check the atom style; the line may be cut short");
    std::size_t k = 0;
    a.id[i] = integer(k++, "id");
    if (a.id[i] <= 0) fail(ln, "atom id must be positive", tok_[0], "an id >= 1", {});
    if (has_mol) a.molecule[i] = integer(k++, "mol");
    const std::int64_t t = integer(k++, "type");
    const auto ntypes = out_.counts.count("atom types") ? out_.counts.at("atom types") : 0;
    if (t < 1 || t > ntypes)
      fail(ln, "atom type out of range", std::to_string(t),
           fmt::format("a type in 1..{} ('{} atom types' in the header)", ntypes, ntypes),
           "fix the type or the 'atom types' header count");
    a.type[i] = static_cast<int>(t);
    if (has_q) a.charge[i] = num(k++, "q");
    static constexpr std::array<const char*, 3> xyz{"x", "y", "z"};
    for (std::size_t c = 0; c < 3; ++c) a.x[3 * i + c] = num(k++, xyz[c]);
    if (tok_.size() == base + 3) {
      if (a.image.empty()) a.image.assign(3 * cap, 0);
      for (int c = 0; c < 3; ++c)
        a.image[3 * i + static_cast<std::size_t>(c)] =
            static_cast<int>(integer(k++, c == 0   ? "ix"
                                          : c == 1 ? "iy"
                                                   : "iz"));
    }
    atom_line_[i] = ln;
    const auto [it, fresh] = index_.emplace(a.id[i], i);
    if (!fresh)
      fail(ln, "duplicate atom id", std::to_string(a.id[i]),
           fmt::format("each atom id once (id {} is also on line {})", a.id[i],
                       atom_line_[it->second]),
           "renumber the atoms (LAMMPS reset_atom_ids) or remove the duplicate");
  });
  if (!a.image.empty()) {
    for (const char* c : {"ix", "iy", "iz"}) out_.columns.emplace_back(c);
    // x ← x + H·image (LAMMPS Domain::unmap)
    const Box& b = a.box;
    const Eigen::Vector3d l = b.lengths();
    for (std::size_t i = 0; i < N; ++i) {
      double* x = a.x.data() + 3 * i;
      const int* m = a.image.data() + 3 * i;
      x[0] += l.x() * m[0] + b.xy * m[1] + b.xz * m[2];
      x[1] += l.y() * m[1] + b.yz * m[2];
      x[2] += l.z() * m[2];
    }
  }
  have_atoms_ = true;
}

void Parser::read_masses(std::int64_t n) {
  Atoms& a = out_.atoms;
  a.type_mass.assign(static_cast<std::size_t>(n + 1), std::numeric_limits<double>::quiet_NaN());
  for_section_lines("Masses", n, [&](std::int64_t) {
    const long ln = r_.line_number();
    if (tok_.size() != 2)
      fail(ln, fmt::format("Masses line has {} values", tok_.size()), std::string(tok_[0]),
           "2 values: type mass", {});
    const std::int64_t t = integer(0, "type");
    if (t < 1 || t > n)
      fail(ln, "atom type out of range", tok_[0], fmt::format("a type in 1..{}", n), {});
    const double m = num(1, "mass");
    if (!(m > 0)) fail(ln, "mass must be positive", tok_[1], "a mass > 0", {});
    a.type_mass[static_cast<std::size_t>(t)] = m;
  });
}

void Parser::read_velocities(std::int64_t n) {
  if (!have_atoms_)
    fail(r_.line_number(), "Velocities before Atoms", "Velocities", "the Atoms section first",
         "move the Atoms section before Velocities (as write_data does)");
  Atoms& a = out_.atoms;
  a.v.assign(3 * a.size(), 0.0);
  std::vector<long> seen(a.size(), 0);
  for_section_lines("Velocities", n, [&](std::int64_t) {
    const long ln = r_.line_number();
    if (tok_.size() != 4)
      fail(ln, fmt::format("Velocities line has {} values", tok_.size()), std::string(tok_[0]),
           "4 values: id vx vy vz", {});
    const std::size_t i = index_of(integer(0, "id"), ln, "Velocities");
    if (seen[i])
      fail(ln, "Velocities: duplicate atom id", tok_[0],
           fmt::format("each atom once (also on line {})", seen[i]), {});
    seen[i] = ln;
    for (std::size_t c = 0; c < 3; ++c)
      a.v[3 * i + c] = num(1 + c, c == 0 ? "vx" : c == 1 ? "vy" : "vz");
  });
}

void Parser::read_bonds(std::int64_t n) {
  if (!have_atoms_)
    fail(r_.line_number(), "Bonds before Atoms", "Bonds", "the Atoms section first",
         "move the Atoms section before Bonds (as write_data does)");
  Atoms& a = out_.atoms;
  const auto nbt = out_.counts.count("bond types") ? out_.counts.at("bond types") : 0;
  a.bonds.reserve(static_cast<std::size_t>(std::min<std::int64_t>(n, 1 << 20)));
  for_section_lines("Bonds", n, [&](std::int64_t) {
    const long ln = r_.line_number();
    if (tok_.size() != 4)
      fail(ln, fmt::format("Bonds line has {} values", tok_.size()), std::string(tok_[0]),
           "4 values: id type atom1 atom2", {});
    Bond b;
    const std::int64_t t = integer(1, "bond type");
    if (t < 1 || t > nbt)
      fail(ln, "bond type out of range", tok_[1],
           fmt::format("a type in 1..{} ('{} bond types' in the header)", nbt, nbt), {});
    b.type = static_cast<int>(t);
    b.atom1 = integer(2, "atom1");
    b.atom2 = integer(3, "atom2");
    (void)index_of(b.atom1, ln, "Bonds");
    (void)index_of(b.atom2, ln, "Bonds");
    a.bonds.push_back(b);
  });
}

DataFile Parser::run() {
  std::string_view line;
  if (!r_.next(line)) fail(1, "empty data file", {}, "a title line, a header and sections", {});
  if (line.find('\0') != std::string_view::npos)
    fail(1, "binary file", "NUL bytes on line 1", "a text LAMMPS data file or text dump",
         "binary dumps and restart files are not read; write a text dump (dump custom) or a "
         "data file (write_data), or convert with LAMMPS's tools/binary2txt");
  out_.title = std::string(trim(line));
  out_.compressed = src_->compressed();
  refuse_xyz(line);
  std::string_view section, comment;
  bool more = false;
  header(section, comment, more);
  out_.atoms.ntypes =
      static_cast<int>(out_.counts.count("atom types") ? out_.counts["atom types"] : 0);
  while (more) {
    const long ln = r_.line_number();
    const std::string name(section);
    const std::string style_comment(comment);
    bool known = false;
    const std::int64_t n = section_lines(name, out_.counts, known);
    if (!known) {
      if (name == "Bodies")
        fail(ln, "section Bodies is not supported", name, "atom styles without bodies", {});
      fail(ln, "unknown section", name, kKnownSections,
           "check the spelling (sections are case-sensitive); a header line after a section, or "
           "a section with more lines than the header declares, also lands here");
    }
    out_.sections.push_back(name);
    if (name == "Atoms") {
      if (have_atoms_)
        fail(ln, "a second Atoms section", name, "one Atoms section",
             "remove the duplicate section (write_data writes one)");
      read_atoms(n, style_comment);
    } else if (name == "Masses") {
      read_masses(n);
    } else if (name == "Velocities") {
      read_velocities(n);
    } else if (name == "Bonds") {
      read_bonds(n);
    } else {
      log::debug("{}:{}: skipping section '{}' ({} lines)", path_, ln, name, n);
      for_section_lines(name, n, [](std::int64_t) {});
    }
    std::string_view content;
    more = next_content(content, &comment);
    if (more) {
      if (!starts_alpha(content))
        fail(r_.line_number(), fmt::format("expected a section keyword after section {}", name),
             std::string(content.substr(0, 60)),
             fmt::format("{} lines in section {} (from the header), then a keyword", n, name),
             "the section has more lines than the header declares; fix the header count");
      section = content;
    }
  }
  const auto natoms = out_.counts.count("atoms") ? out_.counts["atoms"] : 0;
  if (natoms > 0 && !have_atoms_)
    fail(r_.line_number(), "no Atoms section", {},
         fmt::format("an Atoms section with {} lines", natoms), {});
  if (out_.atoms.type_mass.empty() && out_.atoms.ntypes > 0)
    out_.atoms.type_mass.assign(static_cast<std::size_t>(out_.atoms.ntypes + 1),
                                std::numeric_limits<double>::quiet_NaN());
  sort_by_id(out_.atoms, path_);  // ids are unique (checked with line numbers above)
  return std::move(out_);
}

}  // namespace

DataFile read_data(const std::string& path, AtomStyle hint) { return Parser(path, hint).run(); }

Atoms read_data_file(const std::string& path, AtomStyle hint) {
  return read_data(path, hint).atoms;
}

}  // namespace pdcg::atomistic
