/// \file
/// Residual and consistent tangent of the correspondence model on a
/// Discretization (docs/theory.md §6).
///
/// Energy part (variational). With energy stencils S (BA bonds, or points for
/// the classical model) of weights w_S,
///   Π(u) = Σ_S w_S Ψ(F_S(u)),   F_S = I + Σ_{m∈S} u_m ⊗ G_S^m,
///   Q_k  = ∂Π/∂u_k = Σ_{S∋k} w_S P(F_S) G_S^k,
///   ∂Q_ka/∂u_nb = Σ_{S∋k,n} w_S Σ_JL A_aJbL(F_S) G_S^kJ G_S^nL   (symmetric).
///
/// Weak-form boundary term (after Madenci et al., CMAME 337 (2018) 598–631, and
/// the seed). For a constant stress P the discrete energy gives Q_k = P b_k with
///   b_k = Σ_{S∋k} w_S G_S^k,
/// a discrete ∮ n dS smeared over a layer of thickness ~δ under the surface
/// (b_k = 0 exactly in the interior because Σ_m G^m = 0 there). The continuum
/// boundary integral ∮ (P n)·δu dS is, instead, carried by the surface points
/// with their face vectors s_k. The weak form replaces the smeared boundary
/// term by the surface one:
///   f_k = Q_k − P(F̄_k) e_k,   e_k = b_k − s_k,
/// with F̄_k the PDDO gradient on the point family. One stress per point times
/// e_k does not conserve linear momentum (Σ_k f_k = −Σ_k P(F̄_k) e_k ≠ 0 unless P
/// is uniform), so the correction is applied as a bond flux: e_k = Σ_l h_kl with
/// h_kl = −h_lk on the short bonds of the boundary layer (minimum norm, from a
/// graph Laplacian solved once), and
///   f_k = Q_k − Σ_l ½ (P(F̄_k) + P(F̄_l)) h_kl.
/// Every pair term enters two rows with opposite signs, so Σ_k f_k = 0 for every
/// state (docs/solver.md §3, "Force balance"). The correction vanishes in the
/// interior (no flux there); for any homogeneous deformation f_k = P s_k exactly,
/// so a uniform state whose stress meets the tractions is an exact discrete
/// solution (patch test), boundary layer included. The price: the tangent is
/// unsymmetric in the boundary-layer rows (UMFPACK / LU).
///
/// Equilibrium: f(u) = f_ext (applied tractions t* times face areas).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/material.hpp"

namespace pdcg::solver {

enum class Correspondence { bond_associated, classical };
enum class BoundaryForm {
  weak,   ///< Q − P(F̄) e (default; passes the homogeneous patch test)
  energy  ///< Q only (variational, symmetric tangent; boundary layer at free edges)
};

struct ModelOptions {
  Correspondence correspondence = Correspondence::bond_associated;
  BoundaryForm boundary = BoundaryForm::weak;
};

/// Row-major sparse matrix of the full system (d·N × d·N, dof = d·point + component).
using SparseRow = Eigen::SparseMatrix<double, Eigen::RowMajor, int>;

class Model {
 public:
  Model(const Discretization& body, const Material& material, ModelOptions options = {});

  const Discretization& body() const { return *body_; }
  const Material& material() const { return *material_; }
  const ModelOptions& options() const { return opt_; }
  int dimension() const { return d_; }
  std::size_t dofs() const { return static_cast<std::size_t>(d_) * body_->size(); }
  /// True when the tangent is symmetric (energy boundary form).
  bool symmetric() const { return opt_.boundary == BoundaryForm::energy; }

  /// Π(u) (energy part only; after restrict_evaluation this process's stencils only). NaN if
  /// some F_S is inadmissible.
  double energy(const Eigen::VectorXd& u) const;
  /// Internal force f(u). Returns false if some F is inadmissible.
  bool internal_force(const Eigen::VectorXd& u, Eigen::VectorXd& f) const;
  /// Internal force and its tangent K = ∂f/∂u (K gets its pattern, fixed by the body, on the
  /// first call; later calls refill its values in place). One fused sweep over the energy
  /// stencils scatters f and stores w_S A(F_S) packed by major symmetry (as the matrix-free
  /// operator); the row gather then reads the packed tangents, no per-stencil stress is
  /// kept. Throws NumericalError if a stencil tangent lacks major symmetry.
  bool internal_force_and_tangent(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseRow& K) const;

  /// Matrix-free tangent (docs/solver.md §4, "Matrix-free GMRES"). Internal force f(u) (as
  /// internal_force) and, per energy stencil, the weighted material tangent w_S A(F_S) packed
  /// by its major symmetry A_aJbL = A_bLaJ (hyperelastic materials: d²(d²+1)/2 doubles, 45 in
  /// 3D, 10 in 2D, instead of the d⁴ the row gather reads), plus, per weak point l, the
  /// tangent Ā_l = A(F̄_l) of the boundary correction. K is never assembled and
  /// neither the reverse point → stencil index nor the matrix pattern is built. Returns
  /// false if some F is inadmissible. Throws NumericalError if a stencil tangent lacks major
  /// symmetry (a material not derived from an energy).
  bool internal_force_and_operator(const Eigen::VectorXd& u, Eigen::VectorXd& f) const;
  /// out = K v with K = ∂f/∂u at the state of the last internal_force_and_operator call,
  /// without K: one fused sweep over the energy stencils,
  ///   out_k = Σ_{S∋k} (w_S A_S : δF_S) G_S^k,   δF_S = Σ_{m∈S} v_m ⊗ G_S^m,
  /// then −Σ_l (Ā_l : δF̄_l) c_kl on the weak rows and κ v_k on the anchors. Private force
  /// arrays per thread, static schedule, no allocation after the first call. v and out are
  /// full (d·N) vectors; out is resized if needed.
  void apply_tangent(const Eigen::VectorXd& v, Eigen::VectorXd& out) const;
  /// Bytes of the matrix-free operator's data (packed tangents, weak-point tangents).
  std::size_t operator_bytes() const;

  /// Point deformation gradients: weighted mean of the energy stencils centred
  /// at each point (BA: Σ_j φ̂_ij V_j F_ij; classical: F_i). 3×3 with the
  /// in-plane block filled (2D: F₃₃ = 1). Always over every stencil (restrict_evaluation
  /// does not apply: u is complete on every process).
  std::vector<Mat3> point_deformation_gradients(const Eigen::VectorXd& u) const;
  /// PDDO gradient on the point family, F̄_k (used by the weak form).
  std::vector<Mat3> point_family_gradients(const Eigen::VectorXd& u) const;
  /// e_k = b_k − s_k of the weak form (zero in the interior).
  const std::vector<Vec3>& boundary_defect() const { return defect_; }
  /// The bond flux of the defect: for weak row w (point weak_points()[w]), entries
  /// c ∈ [flux().begin(w), flux().end(w)) pair the weak point flux().index[c] (its
  /// position in weak_points()) with the coefficient flux_coefficients()[c] of its stress:
  /// f_k −= Σ_c P(F̄_l) c_kl; the first entry is the row's own point (½ Σ_l h_kl), the
  /// others ½ h_kl.
  const Csr& flux() const { return corr_; }
  const std::vector<Vec3>& flux_coefficients() const { return corr_coef_; }
  const std::vector<int>& weak_points() const { return weak_points_; }
  /// b_k = Σ_S w_S G_S^k.
  const std::vector<Vec3>& smeared_normals() const { return smeared_; }

  /// Gershgorin row sums of the tangent at u for the rows of the given points:
  /// sums[d·i + a] = Σ_n |K_(d·points[i]+a),n| over the columns n with skip_column[n] == 0
  /// (skip_column empty: all columns). The same entries as internal_force_and_tangent, built
  /// row by row without assembling K (explicit dynamics re-estimates the stable step on the
  /// rows that rebuilt stencils touch; allocates, not for per-step use). False if some F
  /// is inadmissible.
  bool tangent_row_abs_sums(const Eigen::VectorXd& u, const std::vector<int>& points,
                            const std::vector<char>& skip_column, std::vector<double>& sums) const;

  /// Rupture only: points that no stencil couples any more (every stencil that
  /// held them is broken or ill-posed) would leave zero rows in K. They are
  /// parked at their displacement u⁰ at the moment they were cut loose by a
  /// spring f_k = κ (u_k − u⁰_k) (energy ½κ|u_k − u⁰_k|²) that exerts no force on
  /// any other point. Empty (and not looked at per bond) without rupture. A NaN target
  /// component has no spring (a pin in the other components only).
  /// The weak-form flux's pair terms between points of different pieces (no chain of live
  /// stencils connects them) are dropped from both rows, whatever holds the pieces (docs/
  /// solver.md §3, "Pieces"): nothing pulls a piece across a complete cut, so an anchored
  /// piece's springs — no reaction of any set — carry no force at equilibrium, and a piece
  /// held by grips loads them with its own forces only. Rupture calls this after every commit.
  void set_anchors(std::vector<int> points, std::vector<double> targets, double stiffness);
  /// Drops the flux's pair terms between different pieces of the current stencils (what
  /// set_anchors does after setting the anchors): for runs without anchors (explicit
  /// dynamics), after every rebuild, so that a restore (which calls set_anchors) gives the
  /// same model.
  void cut_flux_between_pieces();
  const std::vector<int>& anchors() const { return anchor_points_; }

  /// Distributed evaluation (docs/scale-out.md): restricts every later evaluation to the
  /// energy stencils centred at the points with owned[k] != 0 and to the weak-form rows of
  /// those points. internal_force / internal_force_and_tangent then return this process's
  /// partial sums (f and K over all d·N dofs, nonzero only where its stencils and rows
  /// reach); the sum over the processes of a partition is the unrestricted result (up to
  /// summation order). The evaluation then reads u only at the members of the owned stencils
  /// and at the point families of the weak points whose stresses the owned weak rows read (the
  /// ghost points of docs/scale-out.md §2). The owned stencils are copied into a contiguous set, so
  /// the kernels run unchanged (no mask in the hot loops). Empty: every stencil and row (the
  /// default). Not for rupture (broken stencils are not followed) nor for the matrix-free operator.
  void restrict_evaluation(const std::vector<char>& owned);
  bool restricted() const { return energy_ == &owned_stencils_; }
  /// The energy stencils evaluated (all, or this process's after restrict_evaluation).
  const Stencils& evaluated_stencils() const { return *energy_; }
  /// Point adjacency of the tangent's pattern (CSR over points, sorted): the points n with
  /// K_(k,n) in the pattern (sharing an energy stencil or a weak-form correction with k).
  /// Of the evaluated stencils and rows (restrict_evaluation).
  const Csr& point_adjacency() const {
    build_index();
    return adjacency_;
  }
  const std::vector<double>& anchor_targets() const { return anchor_u_; }

 private:
  Mat3 stencil_gradient(const Stencils& s, std::size_t k, const Eigen::VectorXd& u) const;
  /// Energy part of f (scattered, f must be zero on entry) and the packed weighted stencil
  /// tangents w_S A(F_S) into Apk_ (model_matvec.cpp); throws NumericalError on a tangent
  /// without major symmetry.
  bool energy_force_and_tangents(const Eigen::VectorXd& u, Eigen::VectorXd& f) const;
  bool evaluate_weak_rows(const Eigen::VectorXd& u, bool tangent) const;
  void build_defect_flux();
  /// f_k −= Σ_l P(F̄_l) c_kl for weak row w (Pbar_ filled).
  void subtract_correction(std::size_t w, Eigen::VectorXd& f) const;
  template <int D>
  bool residual_kernel(const Eigen::VectorXd& u, Eigen::VectorXd& f) const;
  void fill_pattern(SparseRow& K) const;
  /// Builds the reverse index, the point adjacency and the pattern size on first use (only
  /// the assembled tangent and the row sums need them; the matrix-free operator does not).
  void build_index() const;
  template <int D>
  bool operator_sweep(const Eigen::VectorXd& u, Eigen::VectorXd& f, double& asym) const;
  template <int D>
  void product_sweep(const Eigen::VectorXd& v, Eigen::VectorXd& out) const;
  template <int D>
  void assemble_rows(Eigen::VectorXd& f, SparseRow& K) const;

  const Discretization* body_;
  std::unique_ptr<Material> material_;
  ModelOptions opt_;
  int d_;
  const Stencils* energy_;            // bond or point stencils (or owned_stencils_)
  Stencils owned_stencils_;           // restrict_evaluation: this process's energy stencils
  std::vector<char> weak_row_owned_;  // per weak row (empty: all rows evaluated)
  std::vector<char> weak_needed_;     // per weak point: its stress P(F̄) is read (empty: all)
  // Reverse index: for each point, the (stencil, member position) pairs holding it (built
  // lazily by build_index(): 8 bytes per stencil member, ≈ 59 kB per 3D point).
  mutable bool indexed_ = false;
  mutable Csr member_of_;
  mutable std::vector<int> member_pos_;
  std::vector<Vec3> smeared_, defect_;
  // Weak-form correction rows: weak_id_[k] = position of point k in weak_points_ (and in
  // Pbar_/Abar_), −1 for interior points (no correction).
  std::vector<int> weak_id_;
  std::vector<int> weak_points_;
  // Bond flux of the defect (build_defect_flux): per weak row, the weak points whose
  // stresses enter it and their coefficients.
  Csr corr_;
  std::vector<Vec3> corr_coef_;
  std::vector<Vec3> corr_base_;  // corr_coef_ of the intact body (set_anchors cuts pairs)
  // Point adjacency of the matrix pattern (sorted, CSR over points).
  mutable Csr adjacency_;
  mutable std::int64_t pattern_nnz_ = 0;  // nonzeros of K (d² per adjacent point pair)
  // Scratch per energy stencil / per point (mutable: filled by evaluations).
  mutable std::vector<Mat3> Pbar_;     // per weak row
  mutable std::vector<Tangent> Abar_;  // per weak row
  // Residual: per-thread force accumulators for threads 1… (thread 0 writes into f).
  mutable std::vector<std::vector<double>> fbuf_;
  mutable std::vector<std::vector<int>> slot_;  // per thread: column slot of each point
  // Stencil tangents of the assembled tangent and of the matrix-free operator
  // (internal_force_and_tangent, internal_force_and_operator / apply_tangent).
  mutable std::vector<double> Apk_;  // per stencil: w_S A_S, upper triangle of d²×d², row-major
  mutable std::vector<double> dPw_;  // per weak point: δP = Ā : δF̄ (apply_tangent scratch)
  mutable std::vector<std::vector<double>> mvbuf_;  // per-thread accumulators (threads 1…)
  std::vector<int> anchor_points_;
  std::vector<double> anchor_u_;  // d per anchored point
  double anchor_k_ = 0.0;
  void add_anchors(const Eigen::VectorXd& u, Eigen::VectorXd& f, SparseRow* K) const;
};

}  // namespace pdcg::solver
