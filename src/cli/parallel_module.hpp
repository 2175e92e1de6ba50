/// The `pdcg` executable's access to pdcg::parallel (PETSc + MPI, docs/scale-out.md): the
/// module is loaded with dlopen when a run uses it, so that every other start of the executable
/// does not load PETSc and its libraries (docs/scale-out.md §1). A static build links it.
#pragma once

#include <cstdlib>

#include "pdcg/config.hpp"

#if PDCG_HAVE_PETSC
#include "pdcg/parallel/petsc.hpp"

namespace pdcg::cli {

/// True when this process was started by mpirun/mpiexec (OpenMPI, MPICH, PMIx environment).
inline bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}

/// The module's entry points; throws pdcg::Error naming the library if it cannot be loaded.
const parallel::Api& parallel_module();

/// PetscInitialize … PetscFinalize.
class ParallelSession {
 public:
  explicit ParallelSession(const std::string& options)
      : api_(parallel_module()), session_(api_.session_begin(options, &rank_, &size_)) {}
  ~ParallelSession() { api_.session_end(session_); }
  ParallelSession(const ParallelSession&) = delete;
  ParallelSession& operator=(const ParallelSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  [[noreturn]] void abort(int code) const {
    api_.abort(code);
    std::_Exit(code);
  }

 private:
  const parallel::Api& api_;
  int rank_ = 0, size_ = 1;
  void* session_;
};

}  // namespace pdcg::cli
#endif
