/// \file
/// The quasi-static Newton solver and explicit dynamics on several MPI processes with PETSc
/// (docs/scale-out.md).
///
/// Points are partitioned by recursive coordinate bisection (partition_points); each process
/// evaluates the energy stencils centred at its points and the weak-form rows of its points
/// (Model::restrict_evaluation), adds its partial forces into a distributed PETSc vector and
/// its partial tangent into a MatMPIAIJ of the free dofs (ADD_VALUES, rows owned elsewhere
/// sent by PETSc's stash), and KSP solves (MUMPS, GAMG, hypre). The Newton logic is
/// StaticSolver's own, run on replicated vectors (solver::Distribution).
///
/// This header does not include PETSc or MPI: the library links them privately.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pdcg/solver/explicit.hpp"
#include "pdcg/solver/newton.hpp"

namespace pdcg::parallel {

/// True when this process was started by mpirun/mpiexec (OpenMPI, MPICH, PMIx environment).
bool launched_by_mpirun();

/// PETSc's version ("3.18.5") and the MPI library's (MPI_Get_library_version, first line).
std::string petsc_version();
std::string mpi_library_version();

/// PetscInitialize / PetscFinalize. `options`: PETSc options ("-ksp_rtol 1e-12 …"), added to
/// those of the environment variable PETSC_OPTIONS.
class Session {
 public:
  explicit Session(const std::string& options = {});
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// Aborts every process (MPI_Abort) with the exit code: one process's error must not leave
  /// the others waiting in a collective call.
  [[noreturn]] static void abort(int code);

 private:
  int rank_ = 0, size_ = 1;
};

/// Owner process of every point: recursive coordinate bisection. A set of points going to
/// `parts` processes is cut across its longest bounding-box extent at the point count
/// n·⌊parts/2⌋/parts (the lower part to the first ⌊parts/2⌋ processes), by the order of
/// (coordinate, point index) — deterministic, the same on every process. Throws InputError
/// if there are fewer points than processes.
std::vector<int> partition_points(const std::vector<solver::Vec3>& x, int dimension, int parts);

/// Partitions the model's points over the processes of PETSC_COMM_WORLD, restricts its
/// evaluation to this process's stencils and rows, and returns the Distribution the
/// StaticSolver takes (NewtonOptions::distribution). `linear` is mumps, gamg or hypre.
std::shared_ptr<solver::Distribution> distribute(solver::Model& model, solver::LinearSolver linear);

/// Explicit dynamics on the processes of PETSC_COMM_WORLD (docs/scale-out.md §6): the same
/// partition; on several processes a second Model on the model's body evaluates this process's
/// stencils and weak rows, and the forces are summed over the processes through a ghosted PETSc
/// vector (on one process the whole model evaluates, nothing is exchanged). `model` (the whole
/// one) is not changed; the result is given to ExplicitSolver::set_force_exchange and must
/// outlive its use.
std::unique_ptr<solver::ForceExchange> distribute_explicit(const solver::Model& model);

/// The module's entry points as one table, for the `pdcg` executable, which loads the module
/// only when a run uses it (dlopen: linked, PETSc and its libraries cost every start of the
/// executable ~45 ms of CPU and 16 MB; docs/scale-out.md §1). C linkage: `pdcg_parallel_api`.
struct Api {
  std::string (*petsc_version)();
  std::string (*mpi_library_version)();
  /// new Session(options); rank and size set
  void* (*session_begin)(const std::string& options, int* rank, int* size);
  void (*session_end)(void* session);
  void (*abort)(int code);  ///< MPI_Abort; does not return
  std::shared_ptr<solver::Distribution> (*distribute)(solver::Model& model,
                                                      solver::LinearSolver linear);
  std::unique_ptr<solver::ForceExchange> (*distribute_explicit)(const solver::Model& model);
};

}  // namespace pdcg::parallel

extern "C" const pdcg::parallel::Api* pdcg_parallel_api();
