#include "pdcg/atomistic/configurations.hpp"

#include <fmt/format.h>

#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::atomistic {

FrameSelection select_frames(const std::optional<std::int64_t>& frame, const std::string& frames,
                             std::int64_t nframes, const std::string& source,
                             const FrameOptionNames& names) {
  if (frame && !frames.empty())
    throw InputError(fmt::format("give one of {} and {}", names.frame, names.frames))
        .key(names.frame + "/" + names.frames);
  auto fix = [&](std::int64_t v) { return v < 0 ? v + nframes : v; };
  FrameSelection r;
  if (frame) {
    r.first = fix(*frame);
    r.last = r.first + 1;
  } else if (!frames.empty()) {
    // The one frame-range syntax of pdcg (docs/cli.md): A:B[:S], B inclusive.
    const auto fr =
        pdcg::parse_frame_range(frames, static_cast<std::size_t>(nframes), names.frames);
    r.first = static_cast<std::int64_t>(fr.first);
    r.last = static_cast<std::int64_t>(fr.last) + 1;
    r.step = static_cast<std::int64_t>(fr.stride);
  }
  if (r.first < 0 || r.first >= nframes || r.last > nframes || r.last <= r.first)
    throw InputError("frame range out of bounds")
        .source(source)
        .key(frame ? names.frame : names.frames)
        .value(frame ? std::to_string(*frame) : frames)
        .expected(fmt::format("frames within 0..{} (the file holds {} frame{})", nframes - 1,
                              nframes, nframes == 1 ? "" : "s"))
        .fix("count frames from 0; negative numbers count from the end");
  return r;
}

std::vector<Atoms> read_configurations(const std::string& path,
                                       const std::optional<std::int64_t>& frame,
                                       const std::string& frames, std::string* units,
                                       const FrameNeeds& needs, const FrameOptionNames& names) {
  std::vector<Atoms> out;
  if (units) units->clear();
  if (detect_atom_file_kind(path) == AtomFileKind::data) {
    (void)select_frames(frame, frames, 1, path, names);
    out.push_back(read_data_file(path));
    return out;
  }
  DumpReader dump(path);
  if (units) *units = dump.units();
  const auto r =
      select_frames(frame, frames, static_cast<std::int64_t>(dump.nframes()), path, names);
  for (std::int64_t f = r.first; f < r.last; f += r.step)
    out.push_back(dump.frame(static_cast<std::size_t>(f), needs));
  return out;
}

}  // namespace pdcg::atomistic
