#include "pdcg/atomistic/dump_reader.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <mutex>
#include <optional>

#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"
#include "text_source.hpp"

namespace pdcg::atomistic {

namespace {

using detail::ByteSource;
using detail::LineReader;

/// A line holding one non-negative integer only (the atom count that starts an xyz frame).
bool is_count(std::string_view line) {
  const auto t = trim(line);
  return !t.empty() && t.size() < 20 &&
         std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
}
constexpr const char* kXyzFix =
    "an xyz file has no box, no atom ids and element names instead of types; write a text dump "
    "instead: `dump 1 all custom N traj.dump id type x y z` (or `dump 1 all atom N traj.dump`), "
    "or a data file (write_data)";
constexpr std::int64_t kMaxImage = std::numeric_limits<int>::max();
bool is_item(std::string_view line) { return line.size() >= 5 && line.compare(0, 5, "ITEM:") == 0; }
bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

/// Where one column of `ITEM: ATOMS` goes.
enum class Dest : std::uint8_t { skip, id, type, mol, charge, mass, pos, image, vel, force, extra };
struct ColumnPlan {
  Dest dest = Dest::skip;
  int component = 0;       ///< 0..2 for vectors
  std::string extra_name;  ///< for Dest::extra
};
enum class PositionKind { none, unwrapped, wrapped, scaled_unwrapped, scaled };
bool is_scaled(PositionKind k) {
  return k == PositionKind::scaled || k == PositionKind::scaled_unwrapped;
}
bool is_wrapped(PositionKind k) { return k == PositionKind::wrapped || k == PositionKind::scaled; }

/// Position columns in the order of preference (see the header).
constexpr std::array<std::pair<PositionKind, std::array<const char*, 3>>, 4> kPositionKinds{{
    {PositionKind::unwrapped, {"xu", "yu", "zu"}},
    {PositionKind::wrapped, {"x", "y", "z"}},
    {PositionKind::scaled_unwrapped, {"xsu", "ysu", "zsu"}},
    {PositionKind::scaled, {"xs", "ys", "zs"}},
}};
constexpr std::array<const char*, 3> kAxisColumns{"x (or xu, xs, xsu)", "y (or yu, ys, ysu)",
                                                  "z (or zu, zs, zsu)"};

/// Which column gives the position along each axis: the first complete set of one kind, else
/// per axis the first of its columns in the same order.
struct PositionChoice {
  std::array<PositionKind, 3> kind{PositionKind::none, PositionKind::none, PositionKind::none};
  std::array<std::size_t, 3> column{0, 0, 0};
  bool has(std::size_t k) const { return kind[k] != PositionKind::none; }
  bool complete() const { return has(0) && has(1) && has(2); }
  bool any_scaled() const { return is_scaled(kind[0]) || is_scaled(kind[1]) || is_scaled(kind[2]); }
  /// One kind for all three axes.
  bool uniform() const { return complete() && kind[0] == kind[1] && kind[1] == kind[2]; }
  /// Fractional columns need a complete set of one kind in a tilted box (x = lo + H s mixes axes).
  bool usable_in(const Box& b) const { return !(b.triclinic() && any_scaled() && !uniform()); }
};

PositionChoice choose_positions(const std::vector<std::string>& cols) {
  auto find = [&](std::string_view name) -> std::optional<std::size_t> {
    for (std::size_t j = 0; j < cols.size(); ++j)
      if (cols[j] == name) return j;
    return std::nullopt;
  };
  PositionChoice c;
  for (const auto& [kind, names] : kPositionKinds) {
    const auto i = find(names[0]), j = find(names[1]), k = find(names[2]);
    if (i && j && k) {
      c.kind = {kind, kind, kind};
      c.column = {*i, *j, *k};
      return c;
    }
  }
  for (std::size_t axis = 0; axis < 3; ++axis)
    for (const auto& [kind, names] : kPositionKinds)
      if (auto j = find(names[axis])) {
        c.kind[axis] = kind;
        c.column[axis] = *j;
        break;
      }
  return c;
}

struct FramePlan {
  std::vector<ColumnPlan> columns;
  PositionChoice position;  ///< the axes whose columns are read into Atoms::x (none: x empty)
  bool has_id = false, has_type = false, has_mol = false, has_charge = false, has_mass = false;
  bool has_image = false, has_vel = false, has_force = false;
  std::vector<std::string> extra_names;
};

/// `positions`: the position columns to read into Atoms::x (an empty choice keeps them all in
/// Atoms::extra by name).
FramePlan make_plan(const std::vector<std::string>& cols, std::string_view source,
                    const PositionChoice& positions) {
  FramePlan plan;
  plan.columns.resize(cols.size());
  auto find = [&](std::string_view name) -> std::optional<std::size_t> {
    for (std::size_t j = 0; j < cols.size(); ++j)
      if (cols[j] == name) return j;
    return std::nullopt;
  };
  auto find3 = [&](std::string_view a, std::string_view b,
                   std::string_view c) -> std::optional<std::array<std::size_t, 3>> {
    const auto i = find(a), j = find(b), k = find(c);
    if (i && j && k) return std::array<std::size_t, 3>{*i, *j, *k};
    return std::nullopt;
  };
  auto assign3 = [&](const std::array<std::size_t, 3>& idx, Dest d) {
    for (int k = 0; k < 3; ++k) plan.columns[idx[static_cast<std::size_t>(k)]] = {d, k, {}};
  };
  plan.position = positions;
  for (std::size_t k = 0; k < 3; ++k)
    if (positions.has(k)) plan.columns[positions.column[k]] = {Dest::pos, static_cast<int>(k), {}};
  if (auto idx = find3("ix", "iy", "iz")) {
    plan.has_image = true;
    assign3(*idx, Dest::image);
  }
  if (auto idx = find3("vx", "vy", "vz")) {
    plan.has_vel = true;
    assign3(*idx, Dest::vel);
  }
  if (auto idx = find3("fx", "fy", "fz")) {
    plan.has_force = true;
    assign3(*idx, Dest::force);
  }
  const std::array<std::pair<const char*, Dest>, 5> scalars{{{"id", Dest::id},
                                                             {"type", Dest::type},
                                                             {"mol", Dest::mol},
                                                             {"q", Dest::charge},
                                                             {"mass", Dest::mass}}};
  for (const auto& [name, dest] : scalars)
    if (auto j = find(name)) {
      plan.columns[*j] = {dest, 0, {}};
      if (dest == Dest::id) plan.has_id = true;
      if (dest == Dest::type) plan.has_type = true;
      if (dest == Dest::mol) plan.has_mol = true;
      if (dest == Dest::charge) plan.has_charge = true;
      if (dest == Dest::mass) plan.has_mass = true;
    }
  // Everything else, and second occurrences of a name, go to `extra`.
  for (std::size_t j = 0; j < cols.size(); ++j) {
    auto& c = plan.columns[j];
    const bool taken = c.dest != Dest::skip && find(cols[j]) == j;
    if (taken) continue;
    c = {};
    if (cols[j] == "element") {
      log::debug("{}: column 'element' (element names) is not numeric; skipped", source);
      continue;
    }
    std::string name = cols[j];
    while (std::find(plan.extra_names.begin(), plan.extra_names.end(), name) !=
           plan.extra_names.end())
      name.append(1, '#').append(std::to_string(j + 1));
    c.dest = Dest::extra;
    c.component = static_cast<int>(plan.extra_names.size());
    plan.extra_names.push_back(name);
  }
  return plan;
}

/// A column's storage while parsing: base pointer and stride in elements.
struct Sink {
  enum Kind : std::uint8_t { skip, f64, i64, i32 } kind = skip;
  void* base = nullptr;
  std::size_t stride = 1;
  bool positive = false;  ///< i32 values must be >= 1 (atom types)
};

}  // namespace

struct DumpReader::Impl {
  std::string path;
  std::unique_ptr<ByteSource> src;
  std::unique_ptr<LineReader> lines;
  std::deque<DumpFrameInfo> frames;  // deque: references stay valid as the index grows
  std::deque<std::vector<std::string>> column_sets;
  std::string units;
  bool complete = false;            // every frame indexed
  std::uint64_t resume_offset = 0;  // where indexing continues
  long resume_line = 1;
  mutable std::mutex mutex;

  /// Indexes frames until frame `wanted` is known or the file ends.
  void index_until(std::size_t wanted);
  /// Frame n; with `needs`, positions are read when the needed axes are present (require()
  /// has checked that), else only when all three are.
  Atoms parse(std::size_t n, const FrameNeeds* needs);
  void require(std::size_t n, const FrameNeeds& needs) const;

  [[noreturn]] void fail_at(long line, std::string problem, std::string_view value,
                            std::string_view expected, std::string_view fix) const {
    InputError e(std::move(problem));
    e.source(path).line(line);
    if (!value.empty()) e.value(value);
    if (!expected.empty()) e.expected(expected);
    if (!fix.empty()) e.fix(fix);
    throw e;
  }
};

void DumpReader::Impl::index_until(std::size_t wanted) {
  if (complete || frames.size() > wanted) return;
  LineReader& r = *lines;
  r.seek(resume_offset, resume_line);
  std::string_view line;
  std::vector<std::string_view> tok;
  tok.reserve(16);

  // Reads the value line after an ITEM line.
  auto value_line = [&](std::string_view item) -> std::string_view {
    if (!r.next(line) || is_item(line))
      fail_at(r.line_number(), fmt::format("truncated frame: no value after 'ITEM: {}'", item), {},
              fmt::format("the value of ITEM: {} on the next line", item),
              "the file was cut short; regenerate it or drop the incomplete frame");
    return line;
  };

  std::uint64_t off = r.offset();
  bool have = r.next(line);
  while (have) {
    if (trim(line).empty()) {  // tolerated between frames
      off = r.offset();
      have = r.next(line);
      continue;
    }
    if (!is_item(line)) {
      if (frames.empty() && is_count(line))
        fail_at(r.line_number(), "an xyz file (dump xyz) is not read",
                std::string(line.substr(0, 60)),
                "a LAMMPS text dump starting with 'ITEM: TIMESTEP'", kXyzFix);
      if (frames.empty())
        fail_at(r.line_number(), "not a LAMMPS dump file", std::string(line.substr(0, 60)),
                "'ITEM: TIMESTEP' (or ITEM: UNITS / ITEM: TIME) on the first line",
                "give a text dump written by 'dump atom' or 'dump custom'");
      fail_at(r.line_number(), "expected the start of a frame", std::string(line.substr(0, 60)),
              "'ITEM: TIMESTEP'",
              "the previous frame has more atom lines than its ITEM: NUMBER OF ATOMS says, or "
              "the file is corrupt");
    }
    DumpFrameInfo fi;
    fi.offset = off;
    fi.line = r.line_number();
    fi.time = std::numeric_limits<double>::quiet_NaN();
    bool got_step = false, got_natoms = false, got_box = false;
    std::vector<std::string> cols;
    for (;;) {  // `line` is an ITEM line of this frame's header
      const long item_line = r.line_number();
      const std::string_view item = trim(line.substr(5));
      if (item == "TIMESTEP") {
        const std::string_view v = trim(value_line(item));
        fi.timestep = parse_int(v, {path, r.line_number(), "TIMESTEP"});
        got_step = true;
      } else if (item == "NUMBER OF ATOMS") {
        const std::string_view v = trim(value_line(item));
        fi.natoms = parse_int(v, {path, r.line_number(), "NUMBER OF ATOMS"});
        fi.natoms_line = r.line_number();
        if (fi.natoms < 0)
          fail_at(r.line_number(), "negative number of atoms", v, "a count >= 0", {});
        got_natoms = true;
      } else if (item.substr(0, 10) == "BOX BOUNDS") {
        split_blanks(item.substr(10), tok);
        bool triclinic = false;
        std::vector<std::string_view> flags;
        for (auto t : tok) {
          if (t == "xy" || t == "xz" || t == "yz") {
            triclinic = true;
          } else if (t == "abc" || t == "origin") {
            fail_at(item_line, "general triclinic box (ITEM: BOX BOUNDS abc origin) not supported",
                    std::string(item), "an orthogonal or restricted triclinic box",
                    "write the dump with a restricted triclinic box (the LAMMPS default)");
          } else {
            flags.push_back(t);
          }
        }
        if (!flags.empty() && flags.size() != 3)
          fail_at(item_line, "boundary flags", std::string(item),
                  "three boundary flags, e.g. 'pp pp ff'", {});
        for (std::size_t k = 0; k < flags.size(); ++k) {
          const auto f = flags[k];
          const bool ok = f.size() == 2 &&
                          std::string_view("pfsm").find(f[0]) != std::string_view::npos &&
                          std::string_view("pfsm").find(f[1]) != std::string_view::npos;
          if (!ok)
            fail_at(item_line, "unknown boundary flag", f, "two of p, f, s, m (e.g. pp, fs)", {});
          fi.box.periodic[k] = f == "pp";
        }
        std::array<double, 3> lo_b{}, hi_b{}, tilt{};
        static constexpr std::array<const char*, 3> axis{"x bounds", "y bounds", "z bounds"};
        for (std::size_t k = 0; k < 3; ++k) {
          const bool got = r.next(line);
          if (!got || is_item(line))
            fail_at(r.line_number(), fmt::format("ITEM: BOX BOUNDS has {} of 3 lines", k),
                    got ? std::string(line.substr(0, 60)) : std::string("end of file"),
                    triclinic ? "3 lines 'lo_bound hi_bound tilt' (x, y, z; a 2D box too)"
                              : "3 lines 'lo hi' (x, y, z; a 2D box too)",
                    "the file was cut short or is not a LAMMPS dump; LAMMPS writes three box "
                    "lines in every frame");
          const std::string_view v = line;
          split_blanks(v, tok);
          const std::size_t want = triclinic ? 3 : 2;
          if (tok.size() != want)
            fail_at(r.line_number(), fmt::format("box line has {} values", tok.size()), v,
                    triclinic ? "3 values: lo_bound hi_bound tilt" : "2 values: lo hi",
                    "the BOX BOUNDS header and its three lines disagree; the file is corrupt");
          lo_b[k] = parse_double(tok[0], {path, r.line_number(), axis[k]});
          hi_b[k] = parse_double(tok[1], {path, r.line_number(), axis[k]});
          if (triclinic) tilt[k] = parse_double(tok[2], {path, r.line_number(), "tilt"});
        }
        Box& b = fi.box;
        if (triclinic) {
          // Bounding box -> box (https://docs.lammps.org/Howto_triclinic.html).
          const double xy = tilt[0], xz = tilt[1], yz = tilt[2];
          b.xy = xy;
          b.xz = xz;
          b.yz = yz;
          b.lo.x() = lo_b[0] - std::min({0.0, xy, xz, xy + xz});
          b.hi.x() = hi_b[0] - std::max({0.0, xy, xz, xy + xz});
          b.lo.y() = lo_b[1] - std::min(0.0, yz);
          b.hi.y() = hi_b[1] - std::max(0.0, yz);
        } else {
          b.lo.x() = lo_b[0];
          b.hi.x() = hi_b[0];
          b.lo.y() = lo_b[1];
          b.hi.y() = hi_b[1];
        }
        b.lo.z() = lo_b[2];
        b.hi.z() = hi_b[2];
        for (int k = 0; k < 3; ++k)
          if (!(b.hi[k] > b.lo[k]))
            fail_at(item_line + 1 + k, "empty box", fmt::format("{} {}", b.lo[k], b.hi[k]),
                    "hi > lo in every direction", {});
        got_box = true;
      } else if (item == "UNITS") {
        units = std::string(trim(value_line(item)));
      } else if (item == "TIME") {
        fi.time = parse_double(trim(value_line(item)), {path, r.line_number(), "TIME"});
      } else if (item.substr(0, 5) == "ATOMS") {
        split_blanks(item.substr(5), tok);
        cols.assign(tok.begin(), tok.end());
        if (cols.empty())
          fail_at(item_line, "ITEM: ATOMS names no columns", std::string(line),
                  "column names, e.g. 'ITEM: ATOMS id type x y z'",
                  "very old dumps without names are not supported; rewrite with dump custom");
        break;
      } else {
        fail_at(item_line, "unknown ITEM: section", std::string(line),
                "one of ITEM: UNITS, TIME, TIMESTEP, NUMBER OF ATOMS, BOX BOUNDS, ATOMS",
                "the file is not a LAMMPS text dump or is corrupt");
      }
      if (!r.next(line))
        fail_at(r.line_number(), "truncated frame: file ends inside a frame header", {},
                "'ITEM: ATOMS ...' followed by the atom lines",
                "the file was cut short; regenerate it or drop the incomplete frame");
      if (!is_item(line))
        fail_at(r.line_number(), "expected an ITEM: line in the frame header",
                std::string(line.substr(0, 60)),
                "the next 'ITEM: ...' line of the header (TIMESTEP, NUMBER OF ATOMS, BOX BOUNDS, "
                "ATOMS)",
                "a header line is missing; the file is corrupt");
    }
    const char* missing = !got_step     ? "TIMESTEP"
                          : !got_natoms ? "NUMBER OF ATOMS"
                          : !got_box    ? "BOX BOUNDS"
                                        : nullptr;
    if (missing)
      fail_at(r.line_number(), fmt::format("missing 'ITEM: {}' section", missing), "ITEM: ATOMS",
              fmt::format("'ITEM: {}' before 'ITEM: ATOMS' in every frame", missing),
              "the frame header is incomplete; the file is corrupt or not a LAMMPS dump");
    std::size_t set = 0;
    while (set < column_sets.size() && column_sets[set] != cols) ++set;
    if (set == column_sets.size()) column_sets.push_back(std::move(cols));
    fi.column_set = set;
    fi.atoms_offset = r.offset();
    fi.atoms_line = r.line_number() + 1;
    // Skip the atom lines, checking that there are as many as declared.
    for (std::int64_t i = 0; i < fi.natoms; ++i) {
      if (!r.next(line) || is_item(line))
        fail_at(r.line_number(),
                fmt::format("truncated frame {} (timestep {}): {} of {} atom lines", frames.size(),
                            fi.timestep, i, fi.natoms),
                {}, fmt::format("{} atom lines after line {}", fi.natoms, fi.atoms_line - 1),
                "the file was cut short (run killed, disk full?); regenerate it or drop the "
                "incomplete frame");
    }
    frames.push_back(fi);
    resume_offset = r.offset();
    resume_line = r.line_number() + 1;
    if (frames.size() > wanted) return;
    off = r.offset();
    have = r.next(line);
  }
  complete = true;
  if (frames.empty())
    fail_at(0, "empty dump file", {}, "at least one frame", "give a non-empty LAMMPS text dump");
}

void DumpReader::Impl::require(std::size_t n, const FrameNeeds& needs) const {
  const DumpFrameInfo& fi = frames[n];
  const auto& cols = column_sets[fi.column_set];
  const long atoms_item = fi.atoms_line - 1;  // the line of ITEM: ATOMS
  const std::string header = fmt::format("ITEM: ATOMS {}", fmt::join(cols, " "));
  constexpr const char* kFix =
      "write the dump with the columns it needs, e.g. `dump 1 all custom 100 traj.dump id type x "
      "y z` (or `dump 1 all atom 100 traj.dump`)";
  if (needs.atoms && fi.natoms == 0)
    fail_at(fi.natoms_line,
            fmt::format("{} needs atoms, but frame {} (timestep {}) has zero atoms",
                        needs.operation, n, fi.timestep),
            "ITEM: NUMBER OF ATOMS 0", "at least one atom",
            "select a frame with atoms (--frame), or check the dump group");
  const PositionChoice pos = choose_positions(cols);
  std::vector<std::string> missing;
  for (std::size_t k = 0; k < 3; ++k)
    if (needs.position[k] && !pos.has(k)) missing.emplace_back(kAxisColumns[k]);
  if (needs.type && std::find(cols.begin(), cols.end(), "type") == cols.end())
    missing.emplace_back("type");
  if (needs.id && std::find(cols.begin(), cols.end(), "id") == cols.end())
    missing.emplace_back("id");
  if (!missing.empty())
    fail_at(atoms_item,
            fmt::format("{} needs column{} {} that frame {} (timestep {}) does not have",
                        needs.operation, missing.size() == 1 ? "" : "s", fmt::join(missing, ", "),
                        n, fi.timestep),
            header, fmt::format("ITEM: ATOMS with {}", fmt::join(missing, ", ")), kFix);
  const bool positions = needs.position[0] || needs.position[1] || needs.position[2];
  if (positions && !pos.usable_in(fi.box))
    fail_at(atoms_item,
            fmt::format("frame {} (timestep {}) mixes fractional and other position columns in "
                        "a tilted box",
                        n, fi.timestep),
            header,
            "in a triclinic box, fractional positions as a complete set (xs ys zs or xsu ysu zsu)",
            kFix);
}

Atoms DumpReader::Impl::parse(std::size_t n, const FrameNeeds* needs) {
  const DumpFrameInfo& fi = frames[n];
  const auto& cols = column_sets[fi.column_set];
  // A column pdcg reads that appears twice (`ITEM: ATOMS id x x y z`) is ambiguous: the two may
  // hold different quantities. Refused rather than taking the first (other names are kept as
  // extra columns, the second renamed name#N).
  static constexpr std::array<const char*, 26> kRead{
      "id", "type", "mol", "q",   "mass", "x",  "y",  "z",  "xu", "yu", "zu", "xs", "ys",
      "zs", "xsu",  "ysu", "zsu", "ix",   "iy", "iz", "vx", "vy", "vz", "fx", "fy", "fz"};
  for (const char* name : kRead)
    if (std::count(cols.begin(), cols.end(), name) > 1)
      fail_at(fi.atoms_line - 1,
              fmt::format("column '{}' appears more than once in ITEM: ATOMS of frame {} "
                          "(timestep {})",
                          name, n, fi.timestep),
              fmt::format("ITEM: ATOMS {}", fmt::join(cols, " ")), "each column once",
              "write the dump with each column once (e.g. `dump 1 all custom 100 traj.dump id "
              "type x y z`); pdcg does not guess which of the two is meant");
  PositionChoice pos = choose_positions(cols);
  // Read positions when they can give Atoms::x: all three axes (or, for an operation, the axes
  // it needs), and fractional columns only as one complete set in a tilted box.
  bool read_pos = pos.complete();
  if (needs) {
    read_pos = true;
    for (std::size_t k = 0; k < 3; ++k)
      if (needs->position[k] && !pos.has(k)) read_pos = false;
    read_pos = read_pos && (pos.has(0) || pos.has(1) || pos.has(2));
  }
  if (!pos.usable_in(fi.box)) read_pos = false;
  if (!read_pos) pos = PositionChoice{};
  const FramePlan plan = make_plan(cols, path, pos);
  const std::size_t N = static_cast<std::size_t>(fi.natoms);

  Atoms a;
  a.timestep = fi.timestep;
  a.box = fi.box;
  a.id.resize(N);
  if (plan.has_type) a.type.resize(N);
  if (read_pos) {
    // axes without a column (not needed by the caller): the box centre
    a.x.resize(3 * N);
    const Eigen::Vector3d centre = 0.5 * (fi.box.lo + fi.box.hi);
    for (std::size_t i = 0; i < N; ++i)
      for (std::size_t k = 0; k < 3; ++k)
        if (!pos.has(k)) a.x[3 * i + k] = centre[static_cast<Eigen::Index>(k)];
  }
  if (plan.has_image) a.image.resize(3 * N);
  if (plan.has_vel) a.v.resize(3 * N);
  if (plan.has_force) a.f.resize(3 * N);
  if (plan.has_mol) a.molecule.resize(N);
  if (plan.has_charge) a.charge.resize(N);
  if (plan.has_mass) a.mass.resize(N);
  std::vector<std::vector<double>*> extra;
  for (const auto& name : plan.extra_names) {
    auto& col = a.extra[name];
    col.resize(N);
    extra.push_back(&col);
  }

  std::vector<Sink> sinks(cols.size());
  for (std::size_t j = 0; j < cols.size(); ++j) {
    const auto& c = plan.columns[j];
    const auto k = static_cast<std::size_t>(c.component);
    Sink& s = sinks[j];
    // column k of an N×3 array; null for a frame of zero atoms (nullptr + k is undefined)
    auto at = [](auto& v, std::size_t off) { return v.empty() ? nullptr : v.data() + off; };
    switch (c.dest) {
      case Dest::skip:
        s = {Sink::skip, nullptr, 1};
        break;
      case Dest::id:
        s = {Sink::i64, a.id.data(), 1};
        break;
      case Dest::type:
        s = {Sink::i32, a.type.data(), 1, true};
        break;
      case Dest::mol:
        s = {Sink::i64, a.molecule.data(), 1};
        break;
      case Dest::charge:
        s = {Sink::f64, a.charge.data(), 1};
        break;
      case Dest::mass:
        s = {Sink::f64, a.mass.data(), 1};
        break;
      case Dest::pos:
        s = {Sink::f64, at(a.x, k), 3};
        break;
      case Dest::image:
        s = {Sink::i32, at(a.image, k), 3};
        break;
      case Dest::vel:
        s = {Sink::f64, at(a.v, k), 3};
        break;
      case Dest::force:
        s = {Sink::f64, at(a.f, k), 3};
        break;
      case Dest::extra:
        s = {Sink::f64, extra[k]->data(), 1};
        break;
    }
  }

  LineReader& r = *lines;
  r.seek(fi.atoms_offset, fi.atoms_line);
  std::string_view line;
  const std::size_t ncols = cols.size();
  auto bad = [&](std::size_t j, const char* p, const char* e, bool integer) {
    const char* q = p;
    while (q < e && !blank(*q)) ++q;
    const std::string_view token(p, static_cast<std::size_t>(q - p));
    const TextLocation where{path, r.line_number(), cols[j]};
    if (integer) (void)parse_int(token, where);
    (void)parse_double(token, where);  // throws with the precise reason
    fail_at(r.line_number(), "bad value", token, "a number", {});
  };
  for (std::size_t i = 0; i < N; ++i) {
    if (!r.next(line))
      fail_at(r.line_number(), "file changed while reading: atom lines missing", {}, {},
              "do not modify a dump while it is being read");
    const char* p = line.data();
    const char* const e = p + line.size();
    for (std::size_t j = 0; j < ncols; ++j) {
      while (p < e && blank(*p)) ++p;
      if (p == e)
        fail_at(r.line_number(),
                fmt::format("atom line has {} values, ITEM: ATOMS declares {} columns", j, ncols),
                std::string(line.substr(0, 80)),
                fmt::format("{} values (missing: {} ...)", ncols, cols[j]),
                "the line was cut short or the header does not match the data");
      const Sink& s = sinks[j];
      switch (s.kind) {
        case Sink::f64: {
          double v = 0.0;
          const auto [ptr, ec] = std::from_chars(p + (*p == '+'), e, v);
          if (ec != std::errc() || (ptr != e && !blank(*ptr)) || !std::isfinite(v))
            bad(j, p, e, false);
          static_cast<double*>(s.base)[i * s.stride] = v;
          p = ptr;
          break;
        }
        case Sink::i64:
        case Sink::i32: {
          std::int64_t v = 0;
          const auto [ptr, ec] = std::from_chars(p + (*p == '+'), e, v);
          if (ec != std::errc() || (ptr != e && !blank(*ptr))) bad(j, p, e, true);
          if (s.kind == Sink::i64) {
            static_cast<std::int64_t*>(s.base)[i * s.stride] = v;
          } else {
            if (v > std::numeric_limits<int>::max() || v < (s.positive ? 1 : -kMaxImage))
              fail_at(r.line_number(), s.positive ? "atom type out of range" : "value out of range",
                      std::string_view(p, static_cast<std::size_t>(ptr - p)),
                      s.positive ? "an atom type >= 1" : "an image flag that fits an int",
                      fmt::format("check column '{}'; the file may be corrupt", cols[j]));
            static_cast<int*>(s.base)[i * s.stride] = static_cast<int>(v);
          }
          p = ptr;
          break;
        }
        case Sink::skip:
          while (p < e && !blank(*p)) ++p;
          break;
      }
    }
    while (p < e && blank(*p)) ++p;
    if (p != e)
      fail_at(
          r.line_number(),
          fmt::format("atom line has more values than the {} columns ITEM: ATOMS declares", ncols),
          std::string(line.substr(0, 80)), fmt::format("{} values", ncols),
          "the header does not match the data; the file is corrupt");
  }

  if (!plan.has_id) {
    log::debug("{}: no 'id' column; atoms numbered 1..N in file order", path);
    for (std::size_t i = 0; i < N; ++i) a.id[i] = static_cast<std::int64_t>(i + 1);
  }

  // Positions to Cartesian, unwrapped where possible (see the header).
  const Box& b = a.box;
  const Eigen::Vector3d l = b.lengths();
  const PositionChoice& pc = plan.position;
  if (pc.uniform() && is_scaled(pc.kind[0])) {
    // x = lo + H s, H upper triangular.
    for (std::size_t i = 0; i < N; ++i) {
      double* x = a.x.data() + 3 * i;
      const double s0 = x[0], s1 = x[1], s2 = x[2];
      x[0] = b.lo.x() + l.x() * s0 + b.xy * s1 + b.xz * s2;
      x[1] = b.lo.y() + l.y() * s1 + b.yz * s2;
      x[2] = b.lo.z() + l.z() * s2;
    }
  } else {
    // A set mixed per axis: fractional columns only in an orthogonal box (usable_in), where
    // each axis maps on its own.
    for (std::size_t k = 0; k < 3; ++k)
      if (is_scaled(pc.kind[k])) {
        const auto e = static_cast<Eigen::Index>(k);
        for (std::size_t i = 0; i < N; ++i) a.x[3 * i + k] = b.lo[e] + l[e] * a.x[3 * i + k];
      }
  }
  if (plan.has_image && read_pos) {
    // x ← x + H·image (LAMMPS Domain::unmap), row by row for the wrapped axes.
    const std::array<bool, 3> wrapped{is_wrapped(pc.kind[0]), is_wrapped(pc.kind[1]),
                                      is_wrapped(pc.kind[2])};
    for (std::size_t i = 0; i < N; ++i) {
      double* x = a.x.data() + 3 * i;
      const int* m = a.image.data() + 3 * i;
      if (wrapped[0]) x[0] += l.x() * m[0] + b.xy * m[1] + b.xz * m[2];
      if (wrapped[1]) x[1] += l.y() * m[1] + b.yz * m[2];
      if (wrapped[2]) x[2] += l.z() * m[2];
    }
  }

  try {
    sort_by_id(a, path);
  } catch (const InputError& err) {
    // Name both lines: ids are still in file order (sort_by_id checks before permuting).
    const std::int64_t dup = std::stoll(err.bad_value());
    long first = 0, second = 0;
    for (std::size_t i = 0; i < N && !second; ++i)
      if (a.id[i] == dup) (first ? second : first) = fi.atoms_line + static_cast<long>(i);
    throw InputError(fmt::format("duplicate atom id in frame {} (timestep {})", n, fi.timestep))
        .source(path)
        .line(second)
        .key("id")
        .value(err.bad_value())
        .expected(fmt::format("each atom id once per frame (id {} is also on line {})", dup, first))
        .fix(
            "the file merges two systems or is corrupt; renumber the atoms (LAMMPS reset_atoms "
            "id / reset_atom_ids)");
  }
  return a;
}

DumpReader::DumpReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->src = ByteSource::open(path);
  impl_->lines = std::make_unique<LineReader>(*impl_->src);
  impl_->index_until(0);
}
DumpReader::~DumpReader() = default;
DumpReader::DumpReader(DumpReader&&) noexcept = default;
DumpReader& DumpReader::operator=(DumpReader&&) noexcept = default;

const std::string& DumpReader::path() const { return impl_->path; }
bool DumpReader::compressed() const { return impl_->src->compressed(); }
std::size_t DumpReader::nframes() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->index_until(std::numeric_limits<std::size_t>::max() - 1);
  return impl_->frames.size();
}
const std::vector<std::string>& DumpReader::columns() const { return columns(0); }
const std::vector<std::string>& DumpReader::columns(std::size_t n) const {
  const std::size_t set = info(n).column_set;
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->column_sets[set];
}
std::vector<std::vector<std::string>> DumpReader::column_sets() const {
  (void)nframes();
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return {impl_->column_sets.begin(), impl_->column_sets.end()};
}
const DumpFrameInfo& DumpReader::info(std::size_t n) const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->index_until(n);
  if (n >= impl_->frames.size())
    throw InputError("frame index out of range")
        .source(impl_->path)
        .value(std::to_string(n))
        .expected(fmt::format("0 .. {} (the dump has {} frames)", impl_->frames.size() - 1,
                              impl_->frames.size()));
  return impl_->frames[n];
}
const std::string& DumpReader::units() const { return impl_->units; }

Atoms DumpReader::frame(std::size_t n) const {
  (void)info(n);  // range check
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->parse(n, nullptr);
}
Atoms DumpReader::frame(std::size_t n, const FrameNeeds& needs) const {
  (void)info(n);  // range check
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->require(n, needs);
  return impl_->parse(n, &needs);
}
void DumpReader::require(std::size_t n, const FrameNeeds& needs) const {
  (void)info(n);  // range check
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->require(n, needs);
}
std::array<std::string, 3> DumpReader::position_columns(std::size_t n) const {
  const auto& cols = columns(n);
  const PositionChoice pc = choose_positions(cols);
  std::array<std::string, 3> out;
  for (std::size_t k = 0; k < 3; ++k)
    if (pc.has(k)) out[k] = cols[pc.column[k]];
  return out;
}

AtomFileKind detect_atom_file_kind(const std::string& path) {
  auto src = ByteSource::open(path);
  LineReader r(*src, std::size_t{1} << 16);
  std::string_view line;
  while (r.next(line)) {
    const auto t = trim(line);
    if (t.empty()) continue;
    return t.substr(0, 5) == "ITEM:" ? AtomFileKind::dump : AtomFileKind::data;
  }
  return AtomFileKind::data;
}

Atoms read_atoms(const std::string& path, long frame) {
  if (detect_atom_file_kind(path) == AtomFileKind::data) {
    if (frame != 0 && frame != -1)
      throw InputError("a data file holds one configuration")
          .source(path)
          .key("frame")
          .value(std::to_string(frame))
          .expected("frame 0 or -1 (last)");
    return read_data_file(path);
  }
  DumpReader dump(path);
  const long n = static_cast<long>(dump.nframes());
  const long k = frame < 0 ? n + frame : frame;
  if (k < 0 || k >= n)
    throw InputError("frame index out of range")
        .source(path)
        .key("frame")
        .value(std::to_string(frame))
        .expected(fmt::format("0 .. {} or -1 .. -{} (the dump has {} frames)", n - 1, n, n));
  return dump.frame(static_cast<std::size_t>(k));
}

}  // namespace pdcg::atomistic
