#include "pdcg/core/version.hpp"

#include <Eigen/Core>
#include <fmt/format.h>
#include <omp.h>

namespace pdcg {

std::string version() { return PDCG_VERSION_STRING; }

std::string eigen_version() {
  return fmt::format("{}.{}.{}", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION);
}

int omp_max_threads() { return omp_get_max_threads(); }

}  // namespace pdcg
