/// \file
/// One body from configurations: the assembly `pdcg atoms2pd` and the Python module share
/// (docs/bodies.md §1–2). A delta body of the first frame, or a statistical body of all frames
/// (Gaussian fit, isotropic width, temperature estimate, or empirical), with the families
/// rebuilt at the mean positions when several frames are given.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/potential.hpp"
#include "pdcg/body/body.hpp"

namespace pdcg::body {

/// How the caller's user spells an option (messages name it): the command line writes
/// "--family-cutoff", the Python module "family_cutoff=".
enum class OptionSpelling { command_line, python };

/// What to build. `statistics` empty: a delta body of frames[0]; "gaussian" or "empirical":
/// a statistical body (docs/theory.md §2).
struct BodyRequest {
  DeltaBodyOptions delta;               ///< dimension, source, periodicity_assumed
  std::optional<double> family_cutoff;  ///< family radius ≥ the potential's cutoff
  std::string statistics;               ///< "", "gaussian", "empirical"
  std::optional<double> width;          ///< isotropic Gaussian width (one frame)
  /// Gaussian widths of a local-harmonic (Einstein) estimate at this temperature, in the
  /// temperature unit of the potential's unit style (einstein_statistics; one frame).
  std::optional<double> temperature;
  std::optional<int> order;             ///< Gauss–Hermite points per dimension
  std::optional<std::int64_t> samples;  ///< joint samples (any potential)
  std::string provenance;               ///< appended to the body's first provenance line
  OptionSpelling spelling = OptionSpelling::command_line;
};

/// Builds the body: frames[0] is the reference configuration (families, masses, types); all
/// frames carry the same box periodicity (the caller resolved it). Throws InputError for an
/// unknown statistics name, a family cutoff below the potential's, options that do not go
/// together (order and samples; width, temperature or several frames), cubature with a
/// many-body potential, too few frames, and (from the statistics) frames that do not match.
Body build_body(std::span<const atomistic::Atoms> frames,
                std::shared_ptr<const atomistic::Potential> potential,
                const atomistic::PotentialSpec& spec, const BodyRequest& request);

}  // namespace pdcg::body
