// Helpers shared by the body commands (atoms2pd, forces, energy): reading configurations and
// frame ranges, parsing matrices, bringing deformed positions onto the body's images.
#pragma once

#include <fmt/format.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/configurations.hpp"
#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::cli::body_util {

/// n numbers from an option value ("1 0 0 0 1 0 0 0 1").
inline std::vector<double> numbers(const std::string& text, std::size_t n,
                                   std::string_view option) {
  std::string t = text;
  for (auto& c : t)
    if (c == ',') c = ' ';
  const auto tok = split_blanks(t);
  if (tok.size() != n)
    throw InputError("wrong number of values")
        .source(option)
        .value(text)
        .expected(fmt::format("{} numbers separated by blanks", n));
  std::vector<double> v;
  for (auto s : tok) v.push_back(parse_double(s, {option, 0, option}));
  return v;
}

/// A deformation gradient from an option value: 9 numbers, row-major F11 F12 F13 F21 … F33,
/// with det F > 0.
inline Eigen::Matrix3d deformation_gradient(const std::string& text, std::string_view option) {
  const auto v = numbers(text, 9, option);
  Eigen::Matrix3d F;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) F(r, c) = v[static_cast<std::size_t>(3 * r + c)];
  if (!(F.determinant() > 0.0))
    throw InputError("deformation gradient with det F ≤ 0")
        .source(option)
        .value(fmt::format("{} (det F = {:.6g})", text, F.determinant()))
        .expected("det F > 0 (row-major F11 F12 F13 F21 … F33)")
        .fix("the identity is \"1 0 0 0 1 0 0 0 1\"");
  return F;
}

/// Frame selection and reading: the library's (atomistic/configurations.hpp), with the CLI's
/// option names --frame and --frames.
using FrameRange = atomistic::FrameSelection;

inline FrameRange parse_frames(const std::optional<std::int64_t>& frame, const std::string& frames,
                               std::int64_t nframes, const std::string& source) {
  return atomistic::select_frames(frame, frames, nframes, source);
}

inline std::vector<atomistic::Atoms> read_configurations(const std::string& path,
                                                         const std::optional<std::int64_t>& frame,
                                                         const std::string& frames,
                                                         std::string* units,
                                                         const atomistic::FrameNeeds& needs = {}) {
  return atomistic::read_configurations(path, frame, frames, units, needs);
}

/// "p p f" for a periodicity.
inline std::string boundary_text(const std::array<bool, 3>& periodic) {
  return fmt::format("{} {} {}", periodic[0] ? 'p' : 'f', periodic[1] ? 'p' : 'f',
                     periodic[2] ? 'p' : 'f');
}

/// The periodicity a body is built with and whether anything stated it.
struct Periodicity {
  std::array<bool, 3> periodic{true, true, true};
  bool assumed = false;  ///< nothing stated it: LAMMPS's default p p p for a data file
};

/// Periodicity of the configuration `input` (its box's flags: the dump header's, or the data
/// reader's all-periodic default), decided as LAMMPS users write it: `--boundary` (the option
/// text, empty if not given) wins, then the `boundary` command of the commands file (as in a
/// LAMMPS deck, where read_dump keeps the script's boundary), then the dump header's
/// ITEM: BOX BOUNDS flags; a data file says nothing, so without the first two LAMMPS's default
/// p p p is assumed (and checked for overlapping images when the body is built). A source that
/// wins over a different statement says so in a warning.
inline Periodicity resolve_periodicity(const std::string& input,
                                       const std::array<bool, 3>& file_periodic,
                                       const atomistic::PotentialSpec& spec,
                                       const std::string& option) {
  const bool from_dump = atomistic::detect_atom_file_kind(input) != atomistic::AtomFileKind::data;
  Periodicity out;
  std::string stated;  // who said the current value
  if (from_dump) {
    out.periodic = file_periodic;
    stated = fmt::format("the dump header of {} (ITEM: BOX BOUNDS, {})", input,
                         boundary_text(file_periodic));
  }
  if (spec.periodic) {
    if (!stated.empty() && *spec.periodic != out.periodic)
      log::warn("`boundary {}` ({}:{}) wins over {}", spec.boundary, spec.source,
                spec.boundary_line, stated);
    out.periodic = *spec.periodic;
    stated = fmt::format("`boundary {}` ({}:{})", spec.boundary, spec.source, spec.boundary_line);
  }
  if (!option.empty()) {
    const auto p = atomistic::parse_boundary(option, "--boundary", 0, "--boundary");
    if (!stated.empty() && p != out.periodic)
      log::warn("--boundary \"{}\" wins over {}", option, stated);
    out.periodic = p;
    stated = "--boundary";
  }
  out.assumed = stated.empty();
  if (out.assumed)
    log::debug(
        "{}: a data file does not say which directions are periodic; LAMMPS's default "
        "`boundary p p p` applies (give `boundary` in the commands file or --boundary)",
        input);
  return out;
}

/// Deformed positions for a body from a configuration with the same atom ids: sorted by id,
/// and along periodic directions moved by whole box vectors of the deformed box so that every
/// atom sits on the image the body's families assume (fractional displacement < ½).
inline std::vector<double> deformed_positions(const body::Body& b, atomistic::Atoms a,
                                              const std::string& source, Eigen::Matrix3d& h_y) {
  atomistic::sort_by_id(a, source);
  if (a.id != b.id) {
    std::string detail = fmt::format("{} atoms", a.size());
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
      if (a.id[i] != b.id[i]) {
        detail += fmt::format(", first differing id {} (body has {})", a.id[i], b.id[i]);
        break;
      }
    throw InputError("deformed configuration does not hold the body's atoms")
        .source(source)
        .key("id")
        .value(detail)
        .expected(fmt::format("the {} atom ids of the body", b.size()))
        .fix(
            "dump the same atoms (dump custom ... id type x y z) as the configuration the body was "
            "built from");
  }
  h_y = b.periodic() ? a.box.h() : b.families.h;
  if (b.periodic()) {
    const Eigen::Matrix3d Hx_inv = b.box.h_inverse(), Hy_inv = h_y.inverse();
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Eigen::Vector3d sx =
          Hx_inv * (Eigen::Vector3d(b.x[3 * i], b.x[3 * i + 1], b.x[3 * i + 2]) - b.box.lo);
      Eigen::Vector3d y(a.x[3 * i], a.x[3 * i + 1], a.x[3 * i + 2]);
      const Eigen::Vector3d sy = Hy_inv * (y - a.box.lo);
      Eigen::Vector3d m = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k)
        if (b.box.periodic[static_cast<std::size_t>(k)]) m[k] = std::round(sx[k] - sy[k]);
      y += h_y * m;
      for (int k = 0; k < 3; ++k) a.x[3 * i + static_cast<std::size_t>(k)] = y[k];
    }
  }
  return a.x;
}

}  // namespace pdcg::cli::body_util
