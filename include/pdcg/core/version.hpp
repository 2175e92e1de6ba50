/// \file
/// pdcg version and build information.
#pragma once

#include <string>

#include "pdcg/config.hpp"

namespace pdcg {

/// "0.1.0"
std::string version();
/// Version of Eigen pdcg was compiled with, e.g. "3.4.0".
std::string eigen_version();
/// Number of OpenMP threads a parallel region will use.
int omp_max_threads();

}  // namespace pdcg
