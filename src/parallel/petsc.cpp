// pdcg::parallel: partition, ownership, ghosts and the PETSc assembly and solve of the
// distributed quasi-static Newton run, and the force exchange of distributed explicit dynamics
// (docs/scale-out.md).
#include "pdcg/parallel/petsc.hpp"

#include <fmt/format.h>
#include <mpi.h>
#include <petscksp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <numeric>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/solver/explicit.hpp"

namespace pdcg::parallel {

using solver::LinearSolver;
using solver::Model;
using solver::SparseRow;
using solver::Vec3;

namespace {

void check(PetscErrorCode ierr, const char* what) {
  if (ierr == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(ierr, &text, nullptr);
  throw Error(fmt::format("PETSc: {} failed (error {}: {})", what, static_cast<int>(ierr),
                          text ? text : "unknown"));
}

void rcb(const std::vector<Vec3>& x, int dim, std::vector<int>::iterator b,
         std::vector<int>::iterator e, int first_part, int parts, std::vector<int>& owner) {
  if (parts == 1) {
    for (auto it = b; it != e; ++it) owner[static_cast<std::size_t>(*it)] = first_part;
    return;
  }
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (auto it = b; it != e; ++it) {
    lo = lo.cwiseMin(x[static_cast<std::size_t>(*it)]);
    hi = hi.cwiseMax(x[static_cast<std::size_t>(*it)]);
  }
  int axis = 0;
  for (int a = 1; a < dim; ++a)
    if (hi(a) - lo(a) > hi(axis) - lo(axis)) axis = a;
  const int left = parts / 2;
  const auto n = e - b;
  const auto cut = b + n * left / parts;
  std::nth_element(b, cut, e, [&](int p, int q) {
    const double xp = x[static_cast<std::size_t>(p)](axis),
                 xq = x[static_cast<std::size_t>(q)](axis);
    return xp < xq || (xp == xq && p < q);
  });
  rcb(x, dim, b, cut, first_part, left, owner);
  rcb(x, dim, cut, e, first_part + left, parts - left, owner);
}

/// Throws InputError naming the PETSc options nothing used (skip_viewers: not those read only
/// when KSPSolve ends or at PetscFinalize, -ksp_view, -log_view and the like); `expected` says
/// what the run reads.
void refuse_unused_options(bool skip_viewers, const std::string& expected);

class PetscDistribution final : public solver::Distribution {
 public:
  /// with_matrix false: the force sum only (explicit dynamics), no tangent pattern read
  PetscDistribution(Model& model, LinearSolver linear, bool with_matrix = true);
  ~PetscDistribution() override;
  /// Entries exchanged by one sum(): sent (ghost points' partial sums to their owners) and
  /// received (the points owned elsewhere, by the copy to every process), over all processes.
  struct Traffic {
    long long ghost_entries = 0, copy_entries = 0;
  };
  Traffic traffic() const;
  /// This process's points (increasing index: their PETSc order), and the points its
  /// stencils and weak rows write (owned and ghost points, increasing index).
  const std::vector<int>& owned_points() const { return owned_points_; }
  const std::vector<int>& touched_points() const { return touched_; }
  /// Position of point k in the PETSc order (process by process).
  PetscInt petsc_position(int k) const { return point_at_[static_cast<std::size_t>(k)]; }
  int rank() const override { return rank_; }
  int size() const override { return size_; }
  bool owns_point(int k) const override { return owner_[static_cast<std::size_t>(k)] == rank_; }
  void sum(Eigen::VectorXd& v) override;
  void sum_scalars(Eigen::VectorXd& v) override;
  void setup(const std::vector<int>& free_index, const SparseRow& K) override;
  bool solve(const SparseRow& K, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
             solver::StepReport& rep) override;

 private:
  /// Throws InputError naming the PETSc options nothing used (skip_viewers: not those read
  /// only when KSPSolve ends, -ksp_view and the like).
  void check_options_left(bool skip_viewers);
  void assemble(const SparseRow& K);

  MPI_Comm comm_ = PETSC_COMM_WORLD;
  int rank_ = 0, size_ = 1, d_ = 2;
  std::size_t npoints_ = 0;
  LinearSolver linear_;
  std::vector<int> owner_;          // point -> process
  std::vector<int> point_order_;    // PETSc order of the points (process by process)
  std::vector<PetscInt> point_at_;  // point -> its position in point_order_
  std::vector<int> touched_;        // owned + ghost points (this process's partial sums)
  std::size_t ghosts_written_ = 0;  // of touched_: owned by other processes
  // full adjacency rows of the owned points, in original point order
  std::vector<std::int64_t> adj_off_;
  std::vector<int> adj_idx_;
  std::vector<int> owned_points_;
  std::vector<Vec3> positions_;
  // dof vectors (all d·N dofs, PETSc order)
  Vec fdist_ = nullptr, fall_ = nullptr;
  VecScatter fscatter_ = nullptr;
  // free system
  std::vector<int> free_index_;        // dof -> StaticSolver's free index or −1
  std::vector<PetscInt> free_global_;  // StaticSolver's free index -> PETSc row
  std::vector<PetscInt> dof_row_;      // dof -> PETSc row (free) or −1
  PetscInt row_begin_ = 0, row_end_ = 0;
  Mat A_ = nullptr;
  Vec b_ = nullptr, x_ = nullptr, xall_ = nullptr;
  VecScatter xscatter_ = nullptr;
  KSP ksp_ = nullptr;
  MatNullSpace near_null_ = nullptr;
  bool options_checked_ = false;
  PetscInt n_unused_ = 0;
  std::vector<PetscInt> cols_;
  std::vector<PetscScalar> vals_;
};

PetscDistribution::PetscDistribution(Model& model, LinearSolver linear, bool with_matrix)
    : d_(model.dimension()),
      npoints_(model.body().size()),
      linear_(linear),
      positions_(model.body().positions()) {
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
  const auto& body = model.body();
  owner_ = partition_points(body.positions(), d_, size_);
  // PETSc order: process by process, each process's points in their original order.
  point_order_.resize(npoints_);
  std::iota(point_order_.begin(), point_order_.end(), 0);
  std::stable_sort(point_order_.begin(), point_order_.end(), [&](int p, int q) {
    return owner_[static_cast<std::size_t>(p)] < owner_[static_cast<std::size_t>(q)];
  });
  point_at_.resize(npoints_);
  for (std::size_t i = 0; i < npoints_; ++i)
    point_at_[static_cast<std::size_t>(point_order_[i])] = static_cast<PetscInt>(i);
  std::vector<char> owned(npoints_, 0);
  for (std::size_t k = 0; k < npoints_; ++k)
    if (owner_[k] == rank_) {
      owned[k] = 1;
      owned_points_.push_back(static_cast<int>(k));
    }
  // The tangent's row pattern of the owned points (for the preallocation) from the
  // unrestricted model: every stencil and weak row of every process adds to those rows.
  if (with_matrix) {
    const solver::Csr& adj = model.point_adjacency();
    adj_off_.assign(1, 0);
    for (int k : owned_points_) {
      adj_idx_.insert(adj_idx_.end(), adj.index.begin() + adj.begin(static_cast<std::size_t>(k)),
                      adj.index.begin() + adj.end(static_cast<std::size_t>(k)));
      adj_off_.push_back(static_cast<std::int64_t>(adj_idx_.size()));
    }
  }
  model.restrict_evaluation(owned);
  // Ghosts: points read or written by this process's stencils and weak rows that another
  // process owns (members of the owned stencils; the point families of the weak points whose
  // stresses the owned weak rows read).
  std::vector<char> touched(npoints_, 0);
  for (int k : owned_points_) touched[static_cast<std::size_t>(k)] = 1;
  const solver::Stencils& S = model.evaluated_stencils();
  for (int m : S.index) touched[static_cast<std::size_t>(m)] = 1;
  std::vector<char> read = touched;  // + the families the weak rows read
  {
    const auto& weak = model.weak_points();
    const auto& flux = model.flux();
    const solver::Stencils& P = body.point_stencils();
    for (std::size_t w = 0; w < weak.size(); ++w) {
      if (!owned[static_cast<std::size_t>(weak[w])]) continue;
      for (auto c = flux.begin(w); c < flux.end(w); ++c) {
        const int l = weak[static_cast<std::size_t>(flux.index[static_cast<std::size_t>(c)])];
        for (auto r = P.offsets[static_cast<std::size_t>(l)];
             r < P.offsets[static_cast<std::size_t>(l) + 1]; ++r)
          read[static_cast<std::size_t>(P.index[static_cast<std::size_t>(r)])] = 1;
      }
    }
  }
  ghosts_written_ = 0;
  std::size_t ghosts_read = 0;
  std::size_t& ghosts_written = ghosts_written_;
  for (std::size_t k = 0; k < npoints_; ++k) {
    if (touched[k]) touched_.push_back(static_cast<int>(k));
    if (!owned[k]) {
      ghosts_written += touched[k] != 0;
      ghosts_read += read[k] != 0;
    }
  }
  log::debug("process {}/{}: {} points, {} energy stencils, ghost points: {} written, {} read",
             rank_, size_, owned_points_.size(), S.size(), ghosts_written, ghosts_read);
  // The force vector over all dofs (PETSc order), and its copy on every process.
  check(VecCreateMPI(comm_, static_cast<PetscInt>(d_ * owned_points_.size()),
                     static_cast<PetscInt>(d_ * npoints_), &fdist_),
        "VecCreateMPI");
  check(VecScatterCreateToAll(fdist_, &fscatter_, &fall_), "VecScatterCreateToAll");
}

PetscDistribution::~PetscDistribution() {
  VecDestroy(&fdist_);
  VecDestroy(&fall_);
  VecScatterDestroy(&fscatter_);
  MatDestroy(&A_);
  VecDestroy(&b_);
  VecDestroy(&x_);
  VecDestroy(&xall_);
  VecScatterDestroy(&xscatter_);
  KSPDestroy(&ksp_);
  MatNullSpaceDestroy(&near_null_);
}

void PetscDistribution::sum(Eigen::VectorXd& v) {
  // This process's partial sums live on its owned and ghost points only: those are added
  // (ADD_VALUES; entries of other processes' points go through PETSc's stash), then the
  // assembled vector is copied to every process (the same bits everywhere).
  check(VecZeroEntries(fdist_), "VecZeroEntries");
  cols_.resize(static_cast<std::size_t>(d_));
  for (int k : touched_) {
    for (int a = 0; a < d_; ++a)
      cols_[static_cast<std::size_t>(a)] = d_ * point_at_[static_cast<std::size_t>(k)] + a;
    check(VecSetValues(fdist_, d_, cols_.data(), v.data() + static_cast<std::ptrdiff_t>(d_) * k,
                       ADD_VALUES),
          "VecSetValues");
  }
  check(VecAssemblyBegin(fdist_), "VecAssemblyBegin");
  check(VecAssemblyEnd(fdist_), "VecAssemblyEnd");
  check(VecScatterBegin(fscatter_, fdist_, fall_, INSERT_VALUES, SCATTER_FORWARD), "VecScatter");
  check(VecScatterEnd(fscatter_, fdist_, fall_, INSERT_VALUES, SCATTER_FORWARD), "VecScatter");
  const PetscScalar* all = nullptr;
  check(VecGetArrayRead(fall_, &all), "VecGetArrayRead");
  for (std::size_t k = 0; k < npoints_; ++k)
    for (int a = 0; a < d_; ++a)
      v[static_cast<Eigen::Index>(d_ * k + a)] = all[d_ * point_at_[k] + a];
  check(VecRestoreArrayRead(fall_, &all), "VecRestoreArrayRead");
}

PetscDistribution::Traffic PetscDistribution::traffic() const {
  long long mine[2] = {static_cast<long long>(d_ * ghosts_written_),
                       static_cast<long long>(d_ * (npoints_ - owned_points_.size()))};
  long long all[2] = {0, 0};
  MPI_Allreduce(mine, all, 2, MPI_LONG_LONG, MPI_SUM, comm_);
  return {all[0], all[1]};
}

void PetscDistribution::sum_scalars(Eigen::VectorXd& v) {
  Eigen::VectorXd out(v.size());
  MPI_Allreduce(v.data(), out.data(), static_cast<int>(v.size()), MPI_DOUBLE, MPI_SUM, comm_);
  v = out;
}

void PetscDistribution::setup(const std::vector<int>& free_index, const SparseRow& K) {
  free_index_ = free_index;
  const std::size_t n = free_index.size();
  // PETSc rows of the free dofs: process by process, point by point (PETSc point order).
  dof_row_.assign(n, -1);
  std::size_t nfree = 0;
  for (std::size_t k : std::vector<std::size_t>(point_order_.begin(), point_order_.end()))
    for (int a = 0; a < d_; ++a)
      if (free_index[d_ * k + a] >= 0) dof_row_[d_ * k + a] = static_cast<PetscInt>(nfree++);
  free_global_.assign(nfree, -1);
  row_begin_ = -1;
  row_end_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (dof_row_[i] < 0) continue;
    free_global_[static_cast<std::size_t>(free_index[i])] = dof_row_[i];
    if (owner_[i / static_cast<std::size_t>(d_)] == rank_) {
      if (row_begin_ < 0 || dof_row_[i] < row_begin_) row_begin_ = dof_row_[i];
      row_end_ = std::max(row_end_, dof_row_[i] + 1);
    }
  }
  PetscInt nlocal = row_begin_ < 0 ? 0 : row_end_ - row_begin_;
  {  // the first row of this process when it has no free dof: after the previous processes'
    PetscInt before = 0;
    MPI_Exscan(&nlocal, &before, 1, MPIU_INT, MPI_SUM, comm_);
    if (rank_ == 0) before = 0;
    if (row_begin_ < 0) row_begin_ = row_end_ = before;
    if (row_begin_ != before)
      throw Error("internal error: the free rows of a process are not contiguous");
  }
  // Preallocation per owned row from the full pattern adjacency: d free columns per
  // adjacent point, in this process's column block or not.
  std::vector<PetscInt> dnz(static_cast<std::size_t>(nlocal), 0),
      onz(static_cast<std::size_t>(nlocal), 0);
  for (std::size_t i = 0; i < owned_points_.size(); ++i) {
    const int k = owned_points_[i];
    PetscInt diag = 0, off = 0;
    for (auto q = adj_off_[i]; q < adj_off_[i + 1]; ++q)
      for (int b = 0; b < d_; ++b) {
        const PetscInt c =
            dof_row_[static_cast<std::size_t>(d_ * adj_idx_[static_cast<std::size_t>(q)] + b)];
        if (c < 0) continue;
        if (c >= row_begin_ && c < row_end_)
          ++diag;
        else
          ++off;
      }
    for (int a = 0; a < d_; ++a) {
      const PetscInt r = dof_row_[static_cast<std::size_t>(d_ * k + a)];
      if (r < 0) continue;
      dnz[static_cast<std::size_t>(r - row_begin_)] = diag;
      onz[static_cast<std::size_t>(r - row_begin_)] = off;
    }
  }
  const auto nglobal = static_cast<PetscInt>(nfree);
  check(MatCreateAIJ(comm_, nlocal, nlocal, nglobal, nglobal, 0, dnz.data(), 0, onz.data(), &A_),
        "MatCreateAIJ");
  check(MatSetOption(A_, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
  check(MatCreateVecs(A_, &x_, &b_), "MatCreateVecs");
  check(VecScatterCreateToAll(x_, &xscatter_, &xall_), "VecScatterCreateToAll");
  check(KSPCreate(comm_, &ksp_), "KSPCreate");
  PC pc;
  check(KSPGetPC(ksp_, &pc), "KSPGetPC");
  switch (linear_) {
    case LinearSolver::mumps:
      check(KSPSetType(ksp_, KSPPREONLY), "KSPSetType");
      check(PCSetType(pc, PCLU), "PCSetType");
      check(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS), "PCFactorSetMatSolverType");
      break;
    case LinearSolver::gamg:
    case LinearSolver::hypre: {
      // The weak-form tangent is unsymmetric: GMRES. Relative tolerance 1e-12 (docs/scale-out.md).
      check(KSPSetType(ksp_, KSPGMRES), "KSPSetType");
      check(KSPGMRESSetRestart(ksp_, 100), "KSPGMRESSetRestart");
      check(KSPSetTolerances(ksp_, 1e-12, 1e-300, PETSC_DEFAULT, 5000), "KSPSetTolerances");
      if (linear_ == LinearSolver::hypre) {
        check(PCSetType(pc, PCHYPRE), "PCSetType");
        check(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
      } else {
        check(PCSetType(pc, PCGAMG), "PCSetType");
        // Near-null space: the rigid-body modes restricted to the free dofs (the eliminated
        // ones are not unknowns), orthonormalised (Gram–Schmidt, the same on every process).
        const int nmodes = d_ == 2 ? 3 : 6;
        std::vector<Eigen::VectorXd> modes(static_cast<std::size_t>(nmodes),
                                           Eigen::VectorXd::Zero(nglobal));
        const auto& x = positions_;
        for (std::size_t k = 0; k < npoints_; ++k)
          for (int a = 0; a < d_; ++a) {
            const PetscInt r = dof_row_[d_ * k + a];
            if (r < 0) continue;
            modes[static_cast<std::size_t>(a)][r] = 1.0;  // translations
            const Vec3& p = x[k];
            // rotations: e_z × x (2D); e_x × x, e_y × x, e_z × x (3D)
            if (d_ == 2) {
              modes[2][r] = a == 0 ? -p(1) : p(0);
            } else {
              const Vec3 ax[3] = {Vec3::UnitX().cross(p), Vec3::UnitY().cross(p),
                                  Vec3::UnitZ().cross(p)};
              for (int m = 0; m < 3; ++m) modes[static_cast<std::size_t>(3 + m)][r] = ax[m](a);
            }
          }
        std::vector<Vec> vecs(static_cast<std::size_t>(nmodes));
        for (int m = 0; m < nmodes; ++m) {
          auto& v = modes[static_cast<std::size_t>(m)];
          for (int q = 0; q < m; ++q)
            v -= v.dot(modes[static_cast<std::size_t>(q)]) * modes[static_cast<std::size_t>(q)];
          v /= v.norm();
          check(VecDuplicate(x_, &vecs[static_cast<std::size_t>(m)]), "VecDuplicate");
          PetscScalar* a = nullptr;
          check(VecGetArray(vecs[static_cast<std::size_t>(m)], &a), "VecGetArray");
          for (PetscInt r = row_begin_; r < row_end_; ++r) a[r - row_begin_] = v[r];
          check(VecRestoreArray(vecs[static_cast<std::size_t>(m)], &a), "VecRestoreArray");
        }
        check(MatNullSpaceCreate(comm_, PETSC_FALSE, nmodes, vecs.data(), &near_null_),
              "MatNullSpaceCreate");
        for (auto& v : vecs) VecDestroy(&v);
        check(MatSetNearNullSpace(A_, near_null_), "MatSetNearNullSpace");
      }
      break;
    }
    default:
      throw Error("internal error: the distributed run needs mumps, gamg or hypre");
  }
  check(KSPSetFromOptions(ksp_), "KSPSetFromOptions");
  // Unknown options are refused before the run begins: what KSPSetFromOptions left is
  // looked at again after setting the solver up with the tangent at u = 0 (factorisation
  // options, -mat_mumps_*, are read there), which costs a factorisation only when such
  // options are given; the options read at the end of a solve are checked after the first.
  PetscBool any_left = PETSC_FALSE;
  check(PetscOptionsAllUsed(nullptr, &n_unused_), "PetscOptionsAllUsed");
  any_left = n_unused_ > 0 ? PETSC_TRUE : PETSC_FALSE;
  if (any_left) {
    assemble(K);
    check(KSPSetOperators(ksp_, A_, A_), "KSPSetOperators");
    check(KSPSetUp(ksp_), "KSPSetUp");
    check_options_left(true);
  }
}

void PetscDistribution::assemble(const SparseRow& K) {
  // Assembly: this process's partial rows (its stencils' members and its weak rows), free
  // rows and columns, added into the distributed matrix; rows of other processes' points go
  // through PETSc's stash to their owners.
  check(MatZeroEntries(A_), "MatZeroEntries");
  const int* outer = K.outerIndexPtr();
  const int* inner = K.innerIndexPtr();
  const double* val = K.valuePtr();
  for (int k : touched_)
    for (int a = 0; a < d_; ++a) {
      const int r = d_ * k + a;
      const PetscInt row = dof_row_[static_cast<std::size_t>(r)];
      if (row < 0) continue;
      cols_.clear();
      vals_.clear();
      for (auto q = outer[r]; q < outer[r + 1]; ++q) {
        const PetscInt c = dof_row_[static_cast<std::size_t>(inner[q])];
        if (c < 0) continue;
        cols_.push_back(c);
        vals_.push_back(val[q]);
      }
      if (!cols_.empty())
        check(MatSetValues(A_, 1, &row, static_cast<PetscInt>(cols_.size()), cols_.data(),
                           vals_.data(), ADD_VALUES),
              "MatSetValues");
    }
  check(MatAssemblyBegin(A_, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check(MatAssemblyEnd(A_, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
}

bool PetscDistribution::solve(const SparseRow& K, const Eigen::VectorXd& rhs, Eigen::VectorXd& dx,
                              solver::StepReport& rep) {
  assemble(K);
  // rhs: replicated; each process writes its rows
  {
    PetscScalar* b = nullptr;
    check(VecGetArray(b_, &b), "VecGetArray");
    for (std::size_t i = 0; i < free_global_.size(); ++i) {
      const PetscInt r = free_global_[i];
      if (r >= row_begin_ && r < row_end_) b[r - row_begin_] = rhs[static_cast<Eigen::Index>(i)];
    }
    check(VecRestoreArray(b_, &b), "VecRestoreArray");
  }
  const auto ts = std::chrono::steady_clock::now();
  check(KSPSetOperators(ksp_, A_, A_), "KSPSetOperators");
  check(KSPSolve(ksp_, b_, x_), "KSPSolve");
  KSPConvergedReason reason;
  check(KSPGetConvergedReason(ksp_, &reason), "KSPGetConvergedReason");
  PetscInt its = 0;
  check(KSPGetIterationNumber(ksp_, &its), "KSPGetIterationNumber");
  rep.krylov_iterations += static_cast<int>(its);
  rep.factor_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - ts).count();
  if (!options_checked_) {
    options_checked_ = true;
    check_options_left(false);
  }
  if (reason < 0) {
    log::warn("PETSc KSP ({}) did not converge: reason {} after {} iterations",
              solver::to_string(linear_), KSPConvergedReasons[reason], its);
    return false;
  }
  check(VecScatterBegin(xscatter_, x_, xall_, INSERT_VALUES, SCATTER_FORWARD), "VecScatter");
  check(VecScatterEnd(xscatter_, x_, xall_, INSERT_VALUES, SCATTER_FORWARD), "VecScatter");
  const PetscScalar* xa = nullptr;
  check(VecGetArrayRead(xall_, &xa), "VecGetArrayRead");
  dx.resize(static_cast<Eigen::Index>(free_global_.size()));
  for (std::size_t i = 0; i < free_global_.size(); ++i)
    dx[static_cast<Eigen::Index>(i)] = xa[free_global_[i]];
  check(VecRestoreArrayRead(xall_, &xa), "VecRestoreArrayRead");
  return true;
}

void PetscDistribution::check_options_left(bool skip_viewers) {
  refuse_unused_options(skip_viewers,
                        fmt::format("options of the KSP/PC of solver.linear: {} (-ksp_*, -pc_*, "
                                    "-mat_mumps_*; list them with -help)",
                                    solver::to_string(linear_)));
}

void refuse_unused_options(bool skip_viewers, const std::string& expected) {
  PetscInt n = 0;
  char** names = nullptr;
  char** values = nullptr;
  check(PetscOptionsLeftGet(nullptr, &n, &names, &values), "PetscOptionsLeftGet");
  std::vector<std::string> left;
  for (PetscInt i = 0; i < n; ++i) {
    const std::string name = names[i];
    bool late = false;  // read when a solve ends or at PetscFinalize
    for (const char* p : {"ksp_view", "ksp_converged_reason", "pc_view", "mat_view", "vec_view",
                          "log_view", "options_", "help", "malloc", "memory_view", "info"})
      late = late || name.rfind(p, 0) == 0;
    if (!(skip_viewers && late)) left.push_back("-" + name);
  }
  PetscOptionsLeftRestore(nullptr, &n, &names, &values);
  if (!left.empty())
    throw InputError(fmt::format("PETSc option{} not used by the solver: {}",
                                 left.size() == 1 ? "" : "s", fmt::join(left, " ")))
        .key("--petsc-options / PETSC_OPTIONS")
        .value(fmt::format("{}", fmt::join(left, " ")))
        .expected(expected)
        .fix("correct or remove the option");
}

/// Explicit dynamics on several processes (docs/scale-out.md §6). The whole Model stays with
/// the ExplicitSolver (the stable step, the rupture criterion, the outputs); the force is
/// evaluated by a second Model on the same body restricted to this process's stencils and
/// weak rows (the partition and ownership of PetscDistribution), and summed over the processes
/// through a ghosted PETSc vector: its local form is [owned points | ghost points], a reverse
/// ghost update adds the ghosts' partial sums into their owners' entries, and the assembled
/// vector is copied to every process. Broken bonds: the body and its broken flags are replicated,
/// and every process decides the same bonds from the same bits of u; after each break event the
/// restricted stencils are copied again from the rebuilt body and the broken counts are
/// compared across the processes.
class PetscForceExchange final : public solver::ForceExchange {
 public:
  explicit PetscForceExchange(const Model& whole) : whole_(&whole), d_(whole.dimension()) {
    int processes = 1;
    MPI_Comm_size(PETSC_COMM_WORLD, &processes);
    if (processes == 1) {
      // one process: the whole model is its part; no second Model, nothing to exchange
      log::info("explicit dynamics on 1 MPI process: the whole model, nothing exchanged");
      refuse_explicit_options();
      return;
    }
    part_ = std::make_unique<Model>(whole.body(), whole.material(), whole.options());
    sum_ = std::make_unique<PetscDistribution>(*part_, LinearSolver::mumps, false);
    const std::size_t n = whole.body().size();
    owned_.assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) owned_[k] = sum_->owns_point(static_cast<int>(k)) ? 1 : 0;
    // The index sets of the exchange: owned points (local entries [0, d·owned)), ghost points
    // (the points this process's stencils write that others own; local entries after them).
    owned_points_ = sum_->owned_points();
    std::vector<PetscInt> ghost_rows;
    for (int k : sum_->touched_points())
      if (!owned_[static_cast<std::size_t>(k)]) {
        ghost_points_.push_back(k);
        for (int a = 0; a < d_; ++a) ghost_rows.push_back(d_ * sum_->petsc_position(k) + a);
      }
    check(VecCreateGhost(PETSC_COMM_WORLD, static_cast<PetscInt>(d_ * owned_points_.size()),
                         PETSC_DECIDE, static_cast<PetscInt>(ghost_rows.size()), ghost_rows.data(),
                         &force_),
          "VecCreateGhost");
    check(VecScatterCreateToAll(force_, &to_all_, &force_all_), "VecScatterCreateToAll");
    position_.resize(n);
    for (std::size_t k = 0; k < n; ++k) position_[k] = sum_->petsc_position(static_cast<int>(k));
    const auto t = sum_->traffic();
    const auto bytes =
        (t.ghost_entries + t.copy_entries) * static_cast<long long>(sizeof(PetscScalar));
    log::info(
        "explicit dynamics on {} MPI processes: per force evaluation {} partial sums of ghost "
        "points sent to their owners, {} entries copied to the processes that do not own them "
        "(≈ {} kB over all processes)",
        sum_->size(), t.ghost_entries, t.copy_entries, (bytes + 512) / 1024);
    refuse_explicit_options();
  }
  PetscForceExchange(const PetscForceExchange&) = delete;
  PetscForceExchange& operator=(const PetscForceExchange&) = delete;
  ~PetscForceExchange() override {
    VecDestroy(&force_);
    VecDestroy(&force_all_);
    VecScatterDestroy(&to_all_);
    // this process's own times (no collective call here: a destructor may run while another
    // process has stopped with an error)
    if (evaluations_ > 0)
      log::info(
          "explicit dynamics, process {}/{}: {} force evaluations, {:.3g} ms each ({:.3g} ms "
          "of CPU) for its stencils, {:.3g} ms for the admissibility vote and the sum over the "
          "processes",
          sum_ ? sum_->rank() : 0, sum_ ? sum_->size() : 1, evaluations_,
          1e3 * evaluate_seconds_ / evaluations_, 1e3 * evaluate_cpu_seconds_ / evaluations_,
          1e3 * exchange_seconds_ / evaluations_);
  }
  bool internal_force(const Eigen::VectorXd& u, Eigen::VectorXd& f) override {
    using clock = std::chrono::steady_clock;
    const auto t0 = clock::now();
    const double c0 = cpu_seconds();
    const int mine = (part_ ? *part_ : *whole_).internal_force(u, f) ? 1 : 0;
    evaluate_cpu_seconds_ += cpu_seconds() - c0;
    const auto t1 = clock::now();
    int all = mine;
    if (sum_) {
      MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MIN, PETSC_COMM_WORLD);
      if (all) sum(f);
    }
    ++evaluations_;
    evaluate_seconds_ += std::chrono::duration<double>(t1 - t0).count();
    exchange_seconds_ += std::chrono::duration<double>(clock::now() - t1).count();
    return all != 0;
  }
  void stencils_rebuilt() override {
    if (!part_) return;  // the whole model reads the body's stencils themselves
    part_->restrict_evaluation(owned_);
    // the rupture driver cut the flux between separated pieces in the whole model
    // (Rupture::commit, docs/solver.md §3 "Pieces"); this process's part evaluates the forces
    part_->cut_flux_between_pieces();
    const auto& body = part_->body();
    const long long mine[2] = {static_cast<long long>(body.broken_bonds()),
                               -static_cast<long long>(body.broken_bonds())};
    long long ext[2] = {0, 0};  // max, −min
    MPI_Allreduce(mine, ext, 2, MPI_LONG_LONG, MPI_MAX, PETSC_COMM_WORLD);
    if (ext[0] != -ext[1])
      throw Error(
          fmt::format("internal error: the processes broke different bonds ({} to {} broken bonds)",
                      -ext[1], ext[0]));
  }
  /// f: this process's partial sums (on its owned and ghost points) → the sum over the
  /// processes, the same bits on every process.
  void sum(Eigen::VectorXd& f) {
    Vec local = nullptr;
    check(VecGhostGetLocalForm(force_, &local), "VecGhostGetLocalForm");
    PetscScalar* x = nullptr;
    check(VecGetArray(local, &x), "VecGetArray");
    std::size_t e = 0;
    for (const auto* points : {&owned_points_, &ghost_points_})
      for (int k : *points)
        for (int a = 0; a < d_; ++a) x[e++] = f[static_cast<Eigen::Index>(d_) * k + a];
    check(VecRestoreArray(local, &x), "VecRestoreArray");
    check(VecGhostRestoreLocalForm(force_, &local), "VecGhostRestoreLocalForm");
    // reverse ghost update: the ghosts' partial sums added into their owners' entries
    check(VecGhostUpdateBegin(force_, ADD_VALUES, SCATTER_REVERSE), "VecGhostUpdateBegin");
    check(VecGhostUpdateEnd(force_, ADD_VALUES, SCATTER_REVERSE), "VecGhostUpdateEnd");
    // the assembled force to every process (the replicated state, docs/scale-out.md §6)
    check(VecScatterBegin(to_all_, force_, force_all_, INSERT_VALUES, SCATTER_FORWARD),
          "VecScatter");
    check(VecScatterEnd(to_all_, force_, force_all_, INSERT_VALUES, SCATTER_FORWARD), "VecScatter");
    const PetscScalar* all = nullptr;
    check(VecGetArrayRead(force_all_, &all), "VecGetArrayRead");
    for (std::size_t k = 0; k < position_.size(); ++k)
      for (int a = 0; a < d_; ++a)
        f[static_cast<Eigen::Index>(d_ * k + a)] = all[d_ * position_[k] + a];
    check(VecRestoreArrayRead(force_all_, &all), "VecRestoreArrayRead");
  }
  double energy(const Eigen::VectorXd& u) override {
    if (!part_) return whole_->energy(u);
    const double mine = part_->energy(u);
    double all = 0;
    MPI_Allreduce(&mine, &all, 1, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD);
    return all;
  }

 private:
  const Model* whole_;
  std::unique_ptr<Model> part_;  // this process's stencils (null on one process)
  // partition, ownership, ghosts (its force sum is the Newton run's); null on one process
  std::unique_ptr<PetscDistribution> sum_;
  int d_ = 2;
  std::vector<char> owned_;
  std::vector<int> owned_points_, ghost_points_;  // the index sets of the exchange
  std::vector<PetscInt> position_;                // point -> PETSc position
  Vec force_ = nullptr, force_all_ = nullptr;     // ghosted; its copy on every process
  VecScatter to_all_ = nullptr;
  // Explicit dynamics reads no PETSc option: one given is a mistake, refused before the run
  static void refuse_explicit_options() {
    refuse_unused_options(true,
                          "no PETSc options: explicit dynamics uses no PETSc solver (viewers "
                          "such as -log_view are accepted)");
  }
  // CPU time of this process (all its threads): the work, whatever the machine's load
  static double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  }
  long evaluations_ = 0;
  double evaluate_seconds_ = 0, evaluate_cpu_seconds_ = 0, exchange_seconds_ = 0;
};

}  // namespace

bool launched_by_mpirun() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(v)) return true;
  return false;
}

std::string petsc_version() {
  return fmt::format("{}.{}.{}", PETSC_VERSION_MAJOR, PETSC_VERSION_MINOR, PETSC_VERSION_SUBMINOR);
}

std::string mpi_library_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int len = 0;
  MPI_Get_library_version(text, &len);  // allowed before MPI_Init
  std::string s(text, static_cast<std::size_t>(std::max(0, len)));
  if (const auto nl = s.find_first_of("\n,"); nl != std::string::npos) s.resize(nl);
  return s;
}

Session::Session(const std::string& options) {
  check(PetscInitializeNoArguments(), "PetscInitialize");
  // Errors come back as codes (turned into exceptions with PETSc's message), no trace dump.
  PetscPushErrorHandler(PetscReturnErrorHandler, nullptr);
  if (!options.empty()) check(PetscOptionsInsertString(nullptr, options.c_str()), "PETSc options");
  MPI_Comm_rank(PETSC_COMM_WORLD, &rank_);
  MPI_Comm_size(PETSC_COMM_WORLD, &size_);
}

Session::~Session() { PetscFinalize(); }

void Session::abort(int code) {
  MPI_Abort(PETSC_COMM_WORLD, code);
  std::_Exit(code);
}

std::vector<int> partition_points(const std::vector<Vec3>& x, int dimension, int parts) {
  if (parts < 1) throw Error("internal error: partition into no parts");
  if (x.size() < static_cast<std::size_t>(parts))
    throw InputError(fmt::format("the body has {} point{} for {} MPI processes: the partition "
                                 "would leave a process without points",
                                 x.size(), x.size() == 1 ? "" : "s", parts))
        .key("mpirun -n")
        .value(std::to_string(parts))
        .expected(fmt::format("at most {} processes", x.size()))
        .fix("run on fewer processes (mpirun -n ≤ the number of points), or refine the grid");
  std::vector<int> owner(x.size(), -1), idx(x.size());
  std::iota(idx.begin(), idx.end(), 0);
  rcb(x, dimension, idx.begin(), idx.end(), 0, parts, owner);
  return owner;
}

std::shared_ptr<solver::Distribution> distribute(Model& model, LinearSolver linear) {
  return std::make_shared<PetscDistribution>(model, linear);
}

std::unique_ptr<solver::ForceExchange> distribute_explicit(const Model& model) {
  return std::make_unique<PetscForceExchange>(model);
}

}  // namespace pdcg::parallel

extern "C" const pdcg::parallel::Api* pdcg_parallel_api() {
  using namespace pdcg::parallel;
  static const Api api{
      &petsc_version,
      &mpi_library_version,
      [](const std::string& options, int* rank, int* size) -> void* {
        auto* s = new Session(options);
        *rank = s->rank();
        *size = s->size();
        return s;
      },
      [](void* s) { delete static_cast<Session*>(s); },
      &Session::abort,
      &distribute,
      &distribute_explicit,
  };
  return &api;
}
