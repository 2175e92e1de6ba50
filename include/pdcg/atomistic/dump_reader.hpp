/// \file
/// Reader for LAMMPS text dump files (`dump atom`, `dump custom`, plain or
/// gzip-compressed), https://docs.lammps.org/dump.html.
///
/// A frame is
/// \verbatim
///   [ITEM: UNITS / ITEM: TIME ...]          (optional, dump_modify units/time)
///   ITEM: TIMESTEP
///   <step>
///   ITEM: NUMBER OF ATOMS
///   <N>
///   ITEM: BOX BOUNDS [xy xz yz] <b_x> <b_y> <b_z>     (b = pp, ff, fs, sm, ...)
///   <xlo_bound> <xhi_bound> [xy]
///   <ylo_bound> <yhi_bound> [xz]
///   <zlo_bound> <zhi_bound> [yz]
///   ITEM: ATOMS <column names>
///   N lines, one value per column
/// \endverbatim
///
/// The reader keeps an index: for every frame, the byte offset (uncompressed
/// offset for gzip) and line number of its atom lines plus its header
/// (timestep, N, box, columns). The index grows lazily in one forward pass —
/// the constructor indexes frame 0, info(n)/frame(n) index up to frame n,
/// nframes() to the end of the file — and atom lines are only counted while
/// indexing. frame(n) then seeks to its atom lines and parses only those N
/// lines: random access without parsing any other frame.
/// For gzip the offsets are uncompressed offsets; while indexing, the reader
/// records an access point every 4 MiB of text (compressed offset, bit offset,
/// last 32 KiB of output: the method of zlib's examples/zran.c), so frame(n)
/// restarts decompression at most 4 MiB before the frame, in any order.
///
/// Triclinic boxes: a dump stores the bounding box; the box itself is
/// (Howto_triclinic.html, "Output of the triclinic box")
///   xlo = xlo_bound − min(0, xy, xz, xy + xz),  xhi = xhi_bound − max(0, xy, xz, xy + xz),
///   ylo = ylo_bound − min(0, yz),               yhi = yhi_bound − max(0, yz),
///   zlo = zlo_bound,                            zhi = zhi_bound.
/// A direction is periodic when its boundary flag is `pp`.
///
/// Positions: one complete set of x/y/z-like columns is chosen, in this order:
///  - `xu yu zu` (unwrapped, Cartesian),
///  - `x y z` (wrapped), plus `ix iy iz` when present: x ← x + H·image,
///  - `xsu ysu zsu` (unwrapped, fractional): x = lo + H·s,
///  - `xs ys zs` (wrapped, fractional), x = lo + H·s, plus image flags as above,
/// where H = [a b c] is the box matrix of box.hpp. Atoms::x therefore holds
/// unwrapped positions whenever the dump allows it; the image flags are kept in
/// Atoms::image when the dump has `ix iy iz`. Position columns of the other
/// kinds stay available by name in Atoms::extra. Without a complete set, each
/// axis takes the first of its own columns found in the same order (x from
/// `xu`, `x`, `xsu`, `xs`; y, z alike), so `xs yu zu` is complete too (a tilted
/// box accepts fractional columns only as a complete `xs ys zs` / `xsu ysu zsu`
/// set). frame(n) gives an empty Atoms::x unless all three axes are present;
/// frame(n, needs) gives positions when the axes `needs` asks for are present,
/// with any other, absent axis at the box centre, and refuses the frame with an
/// InputError naming the missing columns otherwise.
///
/// Other columns: `id`, `type`, `mol` → molecule, `q` → charge, `mass`,
/// `vx vy vz` → v, `fx fy fz` → f (each vector only when all three are
/// present), anything else (e.g. `c_pe`, `v_foo`, `f_1[2]`, `proc`) → extra,
/// by name. The non-numeric `element` column is skipped with a note.
/// Every frame is sorted by atom id (duplicate ids are an InputError).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/box.hpp"

namespace pdcg::atomistic {

/// What the index knows about one frame without parsing its atom lines.
struct DumpFrameInfo {
  std::int64_t timestep = 0;
  std::int64_t natoms = 0;
  Box box;
  double time = 0.0;               ///< `ITEM: TIME` value; NaN when the dump has none
  std::uint64_t offset = 0;        ///< byte offset (uncompressed) of the frame's first ITEM line
  std::uint64_t atoms_offset = 0;  ///< byte offset of its first atom line
  long line = 0;                   ///< line number of the frame's first ITEM line
  long atoms_line = 0;             ///< line number of its first atom line
  long natoms_line = 0;            ///< line number of its `ITEM: NUMBER OF ATOMS` value
  std::size_t column_set = 0;      ///< index into DumpReader::column_sets()
};

/// What an operation needs from a frame (DumpReader::require, DumpReader::frame(n, needs)).
struct FrameNeeds {
  /// Axes whose positions the operation uses (a 1D trajectory along x needs x only).
  std::array<bool, 3> position{true, true, true};
  bool type = false;  ///< the `type` column
  bool id = false;    ///< the `id` column (atoms matched by id, not by file order)
  bool atoms = true;  ///< at least one atom
  std::string operation = "this operation";  ///< named in the message, e.g. "pdcg atoms2pd"
};

class DumpReader {
 public:
  /// Opens `path` (plain text or gzip, detected from the content) and indexes
  /// its first frame. Indexing (here, and later in nframes(), info(), frame())
  /// throws InputError for anything malformed in a frame header, a truncated
  /// frame (fewer atom lines than `ITEM: NUMBER OF ATOMS` says), or a missing
  /// `ITEM:` section, naming the file and line. A problem in frame k is
  /// reported when the index first reaches frame k.
  explicit DumpReader(const std::string& path);
  ~DumpReader();
  DumpReader(DumpReader&&) noexcept;
  DumpReader& operator=(DumpReader&&) noexcept;

  const std::string& path() const;
  bool compressed() const;
  /// Number of frames (indexes the whole file on the first call).
  std::size_t nframes() const;
  /// Column names of frame 0 (`ITEM: ATOMS ...`).
  const std::vector<std::string>& columns() const;
  /// Column names of frame n (a dump may change its columns between frames).
  const std::vector<std::string>& columns(std::size_t n) const;
  /// The distinct column lists of the file (indexes the whole file).
  std::vector<std::vector<std::string>> column_sets() const;
  const DumpFrameInfo& info(std::size_t n) const;
  /// `ITEM: UNITS` value if the dump has one, else empty.
  const std::string& units() const;

  /// Parses frame n (0-based) into Atoms sorted by id. Throws InputError on a
  /// bad value (non-numeric, NaN/Inf, too few or too many values on a line,
  /// duplicate atom id), naming file and line. Not thread-safe with respect to
  /// concurrent calls on the same reader (it serialises them internally).
  Atoms frame(std::size_t n) const;
  /// Frame n for an operation that needs `needs`: require(n, needs), then the frame with
  /// Atoms::x (3N) holding the needed axes; an axis that is neither needed nor in the dump is
  /// set to the box centre (the same value in every frame).
  Atoms frame(std::size_t n, const FrameNeeds& needs) const;
  /// Throws InputError (file, the line of frame n's `ITEM: ATOMS`, the missing columns, the
  /// dump command to write instead) unless frame n holds what `needs` asks for.
  void require(std::size_t n, const FrameNeeds& needs) const;
  /// The column that gives the position along x, y, z in frame n (e.g. {"xs", "yu", ""}),
  /// empty for an axis without one.
  std::array<std::string, 3> position_columns(std::size_t n) const;
  /// The last frame.
  Atoms last() const { return frame(nframes() - 1); }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Kind of a LAMMPS atom file, told from its content (a dump starts with `ITEM:`).
enum class AtomFileKind { dump, data };
/// Throws InputError when the file cannot be opened.
AtomFileKind detect_atom_file_kind(const std::string& path);

/// One configuration from either kind of file: frame `frame` of a dump
/// (negative counts from the end: −1 is the last frame), or the data file
/// (then `frame` must be 0 or −1).
Atoms read_atoms(const std::string& path, long frame = -1);

}  // namespace pdcg::atomistic
