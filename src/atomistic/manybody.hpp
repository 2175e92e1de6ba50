/// \file
/// Private to the atomistic module: native three-body and bond-order styles (sw, tersoff) as
/// PD constitutive models, for the style registry (make_potential). docs/potentials.md,
/// "Three-body and bond-order styles", gives ψ_k, the force states and the tangents.
#pragma once

#include <memory>

#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic::detail {

/// `pair_style sw [threebody on|off]` (PairSW).
std::unique_ptr<Potential> make_stillinger_weber(const PotentialSpec& spec);
/// `pair_style tersoff [shift δ]` (PairTersoff).
std::unique_ptr<Potential> make_tersoff(const PotentialSpec& spec);

}  // namespace pdcg::atomistic::detail
