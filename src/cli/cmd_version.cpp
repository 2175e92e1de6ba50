/// `pdcg version`: versions of pdcg and of the libraries it was built with.
#include <SuiteSparse_config.h>
#include <cholmod.h>
#include <fftw3.h>
#include <fmt/format.h>
#include <omp.h>
#include <spdlog/version.h>
#include <umfpack.h>

#include <cstdio>

#include "command.hpp"
#include "pdcg/config.hpp"
#include "pdcg/core/version.hpp"
#include "pdcg/io/hdf5.hpp"

#if PDCG_ENABLE_LAMMPS
#include <library.h>
#endif
#include "parallel_module.hpp"

namespace {

std::string embedded_lammps_version() {
#if PDCG_ENABLE_LAMMPS
  // The version is a property of a LAMMPS instance; a throw-away one with no
  // log and no screen output costs a few milliseconds.
  const char* args[] = {"pdcg", "-log", "none", "-screen", "none", "-nocite"};
  // LAMMPS sets the OpenMP thread count to 1 when OMP_NUM_THREADS is unset; restore ours.
  const int threads = pdcg::omp_max_threads();
  void* lmp = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
  omp_set_num_threads(threads);
  if (!lmp) return "unavailable (liblammps failed to start)";
  const int v = ::lammps_version(lmp);
  lammps_close(lmp);
  return std::to_string(v);
#else
  return "not enabled (PDCG_ENABLE_LAMMPS=OFF)";
#endif
}

int run() {
  std::printf("pdcg        %s\n", pdcg::version().c_str());
  std::printf("Eigen       %s\n", pdcg::eigen_version().c_str());
  std::printf("FFTW        %s\n", fftw_version);
  std::printf("HDF5        %s\n", pdcg::io::hdf5_version().c_str());
  std::printf("LAMMPS      %s\n", embedded_lammps_version().c_str());
  std::printf("SuiteSparse %d.%d.%d (CHOLMOD %d.%d.%d, UMFPACK %d.%d.%d)\n",
              SUITESPARSE_MAIN_VERSION, SUITESPARSE_SUB_VERSION, SUITESPARSE_SUBSUB_VERSION,
              CHOLMOD_MAIN_VERSION, CHOLMOD_SUB_VERSION, CHOLMOD_SUBSUB_VERSION,
              UMFPACK_MAIN_VERSION, UMFPACK_SUB_VERSION, UMFPACK_SUBSUB_VERSION);
  std::printf("fmt         %d\nspdlog      %d.%d.%d\n", FMT_VERSION, SPDLOG_VER_MAJOR,
              SPDLOG_VER_MINOR, SPDLOG_VER_PATCH);
  std::printf("OpenMP      %d threads\n", pdcg::omp_max_threads());
#if PDCG_HAVE_PETSC
  std::printf("PETSc       %s\n", pdcg::cli::parallel_module().petsc_version().c_str());
  std::printf("MPI         %s\n", pdcg::cli::parallel_module().mpi_library_version().c_str());
#else
  std::printf("PETSc       not enabled (PDCG_ENABLE_PETSC=OFF or PETSc not found)\n");
#endif
  return 0;
}

pdcg::cli::Registration reg(1000, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand("version", "Print the versions of pdcg and its libraries");
  sub->footer("Example:\n  pdcg version");
  return [] { return run(); };
});

}  // namespace
