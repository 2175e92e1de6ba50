/// \file
/// The units comment line of the CSV files of `pdcg run` (docs/formats.md). Private to the
/// scene module.
#pragma once

#include <string>

#include "pdcg/scene/scene.hpp"

namespace pdcg::scene {

/// "# units: …\n": the first line of reactions.csv (dynamic = false) or series.csv (true).
/// It starts with '#' so that CSV readers skip it (pandas comment='#', numpy comments='#').
std::string csv_units_comment(const Scene& s, bool dynamic);

}  // namespace pdcg::scene
