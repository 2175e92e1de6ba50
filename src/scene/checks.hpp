/// \file
/// Checks of a scene before anything runs or is written (docs/solver.md §6):
///  - numbers(): every numeric key a scene reads, from the rules the components declare (type,
///    sign, range, finite);
///  - key_lines(): the line of every key, for errors raised after parsing;
///  - consistency(): contradictions visible in the parsed scene (empty regions, a point region
///    with bounds, values that are not finite at the load factors or times the run visits);
///  - boundary_sets(): contradictions on the discretised body (two conditions fixing the same
///    dof to different values, a point region far from the body, initial velocities that are
///    not finite at a point).
/// Private to the scene module.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/scene/component.hpp"
#include "pdcg/scene/scene.hpp"
#include "pdcg/solver/newton.hpp"

namespace YAML {
class Node;
}

namespace pdcg::scene::checks {

/// Checks every numeric key of `rules` that the scene gives, in order. Throws InputError with
/// file, line, key, the bad value and the accepted range.
void numbers(const YAML::Node& root, const std::string& file, const std::vector<NumberRule>& rules);

/// "key.path" → 1-based line, for every key of the scene (boundary items as boundary[NAME],
/// NAME = the item's name or set<index>; other list items as key[index]).
std::map<std::string, long> key_lines(const YAML::Node& root);

/// Line of `key` in the scene (or of its nearest enclosing key); 0 if unknown.
long line_of(const Scene& s, const std::string& key);

/// An InputError of the scene file naming `key` and its line.
InputError error(const Scene& s, const std::string& key, const std::string& problem);

/// Contradictions of the parsed scene (before the body is built).
void consistency(const Scene& s);

/// Contradictions on the body, before any output is created.
void boundary_sets(const Scene& s, const solver::Discretization& body,
                   const std::vector<solver::DisplacementSet>& dsets);

}  // namespace pdcg::scene::checks
