/// \file
/// Configurations from a LAMMPS atom file, whichever kind it is (docs/cli.md, "Frames"): one
/// frame or a range of frames of a dump, or the one configuration of a data file. The file kind
/// is told from the content (detect_atom_file_kind). Used by the CLI (`--frame`, `--frames`) and
/// the Python module (`frame=`, `frames=`).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/dump_reader.hpp"

namespace pdcg::atomistic {

/// Frames [first, last) with stride `step` (0-based indices into the file).
struct FrameSelection {
  std::int64_t first = 0, last = 1, step = 1;
};

/// Names of the two selection options in messages ("--frame"/"--frames" for the CLI).
struct FrameOptionNames {
  std::string frame = "--frame";
  std::string frames = "--frames";
};

/// Frame selection: `frame` (one frame, negative counts from the end as in Python), or `frames`
/// in the one frame-range syntax of pdcg, A:B[:S] with B inclusive (core/parse.hpp,
/// parse_frame_range), or neither (frame 0). Throws InputError naming `source` and the option
/// when both are given or the selection is outside 0..nframes−1.
FrameSelection select_frames(const std::optional<std::int64_t>& frame, const std::string& frames,
                             std::int64_t nframes, const std::string& source,
                             const FrameOptionNames& names = {});

/// Frames of a dump or the configuration of a data file (for which the selection must name
/// frame 0 or −1). A dump frame must hold what `needs` asks for (by default positions along x,
/// y, z and at least one atom), else InputError. `units`, when given, receives the dump's
/// `ITEM: UNITS` value (empty for a data file or a dump without one).
std::vector<Atoms> read_configurations(const std::string& path,
                                       const std::optional<std::int64_t>& frame,
                                       const std::string& frames, std::string* units,
                                       const FrameNeeds& needs = {},
                                       const FrameOptionNames& names = {});

}  // namespace pdcg::atomistic
