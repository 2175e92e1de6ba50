#include "pdcg/body/statistics.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "lindemann.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parallel.hpp"
#include "pdcg/core/units.hpp"
#include "statistics_impl.hpp"

namespace pdcg::body {

void gauss_hermite(int n, std::vector<double>& nodes, std::vector<double>& weights) {
  if (n < 1 || n > 64)
    throw InputError("Gauss–Hermite order out of range")
        .key("order")
        .value(std::to_string(n))
        .expected("1..64 points per dimension")
        .fix("orders 3..10 are usual");
  // Golub–Welsch: Jacobi matrix of the probabilists' Hermite polynomials He_n
  // (recurrence z He_k = He_{k+1} + k He_{k−1}): off-diagonal √k, zero diagonal.
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k) J(k, k - 1) = J(k - 1, k) = std::sqrt(static_cast<double>(k));
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(J);
  nodes.resize(static_cast<std::size_t>(n));
  weights.resize(static_cast<std::size_t>(n));
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    nodes[static_cast<std::size_t>(i)] = es.eigenvalues()[i];
    const double v = es.eigenvectors()(0, i);
    weights[static_cast<std::size_t>(i)] = v * v;  // times ∫ N(0,1) = 1
    sum += v * v;
  }
  for (auto& w : weights) w /= sum;  // exact normalisation (eigenvectors are unit up to round-off)
}

Statistics isotropic_gaussian(const Body& body, double width) {
  if (!(width >= 0.0) || !std::isfinite(width))
    throw InputError("statistical width must be non-negative")
        .key("width")
        .value(std::to_string(width))
        .expected("σ ≥ 0 (a length, e.g. √(k_B T / k) for a harmonic well)");
  Statistics s;
  s.form = Statistics::Form::gaussian;
  s.covariance.assign(6 * body.size(), 0.0);
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (int a = 0; a < body.dimension; ++a) C(a, a) = width * width;
  for (std::size_t i = 0; i < body.size(); ++i) s.set_covariance(i, C);
  return s;
}

namespace {

/// Displacements of every atom in every frame relative to the body's positions (minimum image
/// along periodic directions), checked ids. Returns S×3N.
std::vector<std::vector<double>> displacements(const Body& body,
                                               std::span<const atomistic::Atoms> frames,
                                               bool covariance) {
  if (frames.size() < 2)
    throw InputError("statistical densities need several frames")
        .key("frames")
        .value(std::to_string(frames.size()))
        .expected("at least 2 frames")
        .fix("give a frame range A:B with B > A");
  if (covariance && frames.size() <= static_cast<std::size_t>(body.dimension))
    // S frames give a covariance of rank ≤ S − 1: singular in d dimensions when S ≤ d
    throw InputError("too few frames for a covariance")
        .key("frames")
        .value(std::to_string(frames.size()))
        .expected(fmt::format("more than {} frames (S frames give a covariance of rank at most "
                              "S − 1; a {}-D covariance needs S > {}); tens to hundreds of "
                              "uncorrelated frames for a width to a few per cent",
                              body.dimension, body.dimension, body.dimension))
        .fix("give a longer frame range, or --statistics empirical");
  std::vector<std::vector<double>> out;
  const Eigen::Matrix3d h0 = body.box.h();
  for (std::size_t f = 0; f < frames.size(); ++f) {
    atomistic::Atoms a = frames[f];
    atomistic::sort_by_id(a);
    if (a.id != body.id)
      throw InputError("frame does not hold the body's atoms")
          .key("frame " + std::to_string(f))
          .value(std::to_string(a.size()) + " atoms")
          .expected(std::to_string(body.size()) + " atoms with the same ids as the reference frame")
          .fix("use frames of the same trajectory");
    if (!a.type.empty() && a.type != body.type) {
      std::size_t i = 0;
      while (a.type[i] == body.type[i]) ++i;
      throw InputError("frame gives an atom another type than the reference frame")
          .key(fmt::format("frame {}, atom id {}", f, a.id[i]))
          .value(fmt::format("type {}", a.type[i]))
          .expected(fmt::format("type {} (the reference frame's)", body.type[i]))
          .fix("use frames of one trajectory (the same atoms, the same types)");
    }
    // The densities are of positions in one box: frames of a fluctuating box (NPT, fix deform)
    // have no common reference positions. Dumps write box bounds with 16 digits.
    // Free directions (shrink-wrapped boxes of a cluster) may change: only the periodic edge
    // vectors and their origins are compared.
    const Eigen::Matrix3d hf = a.box.h();
    const double tol = 1e-10 * h0.norm();  // round-off of 17-digit box bounds, with margin
    bool same = true;
    for (int c = 0; c < 3; ++c)
      if (body.box.periodic[static_cast<std::size_t>(c)])
        same = same && (hf.col(c) - h0.col(c)).norm() <= tol &&
               std::abs(a.box.lo[c] - body.box.lo[c]) <= tol;
    if (!same)
      throw InputError("frame has another box than the reference frame")
          .key(fmt::format("frame {}", f))
          .value(fmt::format("edge lengths {:.10g} {:.10g} {:.10g}", hf.col(0).norm(),
                             hf.col(1).norm(), hf.col(2).norm()))
          .expected(fmt::format("the reference box, edge lengths {:.10g} {:.10g} {:.10g}",
                                h0.col(0).norm(), h0.col(1).norm(), h0.col(2).norm()))
          .fix(
              "sample at constant volume (NVT or NVE, no barostat or fix deform), or build one "
              "body per box");
    std::vector<double> d(3 * body.size());
    for (std::size_t i = 0; i < body.size(); ++i) {
      Eigen::Vector3d v(a.x[3 * i] - body.x[3 * i], a.x[3 * i + 1] - body.x[3 * i + 1],
                        a.x[3 * i + 2] - body.x[3 * i + 2]);
      if (body.periodic()) v = body.box.minimum_image(v);
      for (int k = 0; k < 3; ++k) d[3 * i + static_cast<std::size_t>(k)] = v[k];
    }
    out.push_back(std::move(d));
  }
  return out;
}

/// Moves the body's reference positions to new means (family topology unchanged; the reference
/// bonds ξ_b = x_j − x_k + H n_b follow, as they are derived from the positions).
void move_means(Body& body, const std::vector<double>& mean) { body.x = mean; }

}  // namespace

Statistics gaussian_from_frames(Body& body, std::span<const atomistic::Atoms> frames) {
  const auto d = displacements(body, frames, true);
  const std::size_t n = body.size();
  const double S = static_cast<double>(d.size());
  std::vector<double> mean(3 * n, 0.0);
  Statistics s;
  s.form = Statistics::Form::gaussian;
  s.covariance.assign(6 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (const auto& f : d) m += Eigen::Vector3d(f[3 * i], f[3 * i + 1], f[3 * i + 2]);
    m /= S;
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (const auto& f : d) {
      const Eigen::Vector3d v = Eigen::Vector3d(f[3 * i], f[3 * i + 1], f[3 * i + 2]) - m;
      C += v * v.transpose();
    }
    C /= S;  // moments of the empirical distribution (same second moment as the empirical form)
    for (int a = 0; a < 3; ++a)
      mean[3 * i + static_cast<std::size_t>(a)] =
          body.x[3 * i + static_cast<std::size_t>(a)] + m[a];
    s.set_covariance(i, C);
  }
  move_means(body, mean);
  return s;
}

Statistics einstein_statistics(const Body& body, double temperature, std::string_view where) {
  if (!(temperature >= 0.0) || !std::isfinite(temperature))
    throw InputError("temperature must be non-negative")
        .key(where)
        .value(fmt::format("{}", temperature))
        .expected(fmt::format("T ≥ 0 in the temperature unit of units {}", to_string(body.units)));
  if (!body.potential)
    throw InputError("body has no potential").fix("build the body with a potential");
  const UnitConstants uc = unit_constants(body.units);
  const double kT = uc.boltz * temperature;
  const auto& fam = body.families;
  const auto& pot = *body.potential;
  const std::size_t n = body.size();
  const int d = body.dimension;
  // H_k = Σ_bc c_b c_c K_bc (own family; c_b = −1, or 0 for a periodic image of k itself,
  // which moves with k) + Σ over families holding k as a partner of K_bb. Serial: bonds add
  // to their partner's H (not a hot loop: once per body).
  std::vector<Eigen::Matrix3d> H(n, Eigen::Matrix3d::Zero());
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  std::vector<double> K, work;
  atomistic::FamilyGather gather;
  for (std::size_t i = 0; i < n; ++i) {
    const auto b0 = static_cast<std::size_t>(fam.offset[i]);
    const std::size_t m = static_cast<std::size_t>(fam.offset[i + 1]) - b0;
    if (m == 0) continue;
    K.resize(9 * m * m);
    work.resize(atomistic::Potential::tangent_workspace(static_cast<std::int64_t>(m)));
    const atomistic::FamilyState f = gather(fam, body.type, body.x, fam.h, i);
    for (std::size_t b = 0; b < m; ++b)
      nearest[i] = std::min(nearest[i], Eigen::Map<const Eigen::Vector3d>(f.bond + 3 * b).norm());
    pot.force_state_tangent(f, K.data(), work.data());
    auto block = [&](std::size_t j, std::size_t l) {
      return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(K.data() +
                                                                            9 * (j * m + l));
    };
    for (std::size_t j = 0; j < m; ++j) {
      const auto pj = static_cast<std::size_t>(fam.neighbor[b0 + j]);
      if (pj == i) continue;  // an image of k: moves with k, the bond does not change
      H[pj] += block(j, j);
      for (std::size_t l = 0; l < m; ++l)
        if (static_cast<std::size_t>(fam.neighbor[b0 + l]) != i) H[i] += block(j, l);
    }
  }
  Statistics s;
  s.form = Statistics::Form::gaussian;
  s.covariance.assign(6 * n, 0.0);
  std::vector<double> ratio(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::MatrixXd h = H[i].topLeftCorner(d, d);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(h);
    if (!(es.eigenvalues().minCoeff() > 0.0))
      throw InputError("an atom is not in a harmonic well at its reference position")
          .key(fmt::format("{}: atom id {}", where, body.id[i]))
          .value(
              fmt::format("smallest eigenvalue of ∂²U/∂x_k² = {:.6g}", es.eigenvalues().minCoeff()))
          .expected("a positive-definite local Hessian (a minimum of the energy)")
          .fix(
              "relax the configuration first (LAMMPS minimize), or fit the widths to frames "
              "(--frames A:B)");
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    C.topLeftCorner(d, d) = kT * h.inverse();
    s.set_covariance(i, C);
    if (std::isfinite(nearest[i]) && nearest[i] > 0.0) ratio[i] = std::sqrt(C.trace()) / nearest[i];
  }
  std::vector<double> sorted = ratio;
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2),
                   sorted.end());
  const double lindemann = n ? sorted[n / 2] : 0.0;  // median over the atoms
  const std::string unit_hint = detail::temperature_unit_hint(body.units);
  detail::require_below_melting(lindemann, temperature, body.units, where,
                                "rms displacement (median over the atoms)");
  if (lindemann > 0.10)
    log::warn(
        "{} {}: rms displacement {:.3g} of the nearest-neighbour distance, near melting "
        "(Lindemann ≈ 0.10–0.15): the local-harmonic widths are a poor estimate there",
        where, temperature, lindemann);
  else if (temperature > 0.0 && body.units != UnitStyle::lj && lindemann < 1e-3)
    log::warn("{} {}: rms displacement only {:.3g} of the nearest-neighbour distance; {}", where,
              temperature, lindemann, unit_hint);
  return s;
}

Statistics empirical_from_frames(Body& body, std::span<const atomistic::Atoms> frames) {
  const auto d = displacements(body, frames, false);
  const std::size_t n = body.size();
  std::vector<double> mean(3 * n, 0.0);
  for (const auto& f : d)
    for (std::size_t c = 0; c < 3 * n; ++c) mean[c] += f[c] / static_cast<double>(d.size());
  Statistics s;
  s.form = Statistics::Form::empirical;
  for (const auto& f : d) {
    std::vector<double> pos(3 * n);
    for (std::size_t c = 0; c < 3 * n; ++c) pos[c] = body.x[c] + f[c];
    s.frames.push_back(std::move(pos));
  }
  for (std::size_t c = 0; c < 3 * n; ++c) mean[c] += body.x[c];
  move_means(body, mean);
  return s;
}

void make_statistical(Body& body, Statistics s) {
  if (s.form == Statistics::Form::gaussian) {
    if (s.covariance.size() != 6 * body.size())
      throw InputError("covariances do not match the body")
          .key("covariance")
          .value(std::to_string(s.covariance.size() / 6))
          .expected(std::to_string(body.size()) +
                    " symmetric 3×3 matrices (6 values each: the upper triangle)");
    if (s.method == Statistics::Method::cubature) {
      if (s.order < 1 || s.order > 64)
        throw InputError("Gauss–Hermite order out of range")
            .key("order")
            .value(std::to_string(s.order))
            .expected("1..64");
      if (!body.potential->pairwise())
        throw InputError("Gauss–Hermite cubature needs a pair potential")
            .key("order")
            .value(body.potential->style())
            .expected("a pair potential (lj/cut, morse, …)")
            .fix("use sampling (--samples N) for many-body potentials");
    } else if (s.samples < 1) {
      throw InputError("sample count must be positive")
          .key("samples")
          .value(std::to_string(s.samples));
    }
  } else {
    if (s.frames.empty())
      throw InputError("empirical statistics without frames")
          .key("frames")
          .expected("at least 2 frames");
    for (const auto& f : s.frames)
      if (f.size() != 3 * body.size())
        throw InputError("frame size does not match the body")
            .key("frames")
            .value(std::to_string(f.size() / 3));
  }
  body.statistics = std::move(s);
  body.kind = BodyKind::statistical;
  body.provenance.push_back(
      std::string("statistical densities: ") +
      (body.statistics->form == Statistics::Form::gaussian
           ? (body.statistics->method == Statistics::Method::cubature
                  ? "gaussian, Gauss–Hermite order " + std::to_string(body.statistics->order)
                  : "gaussian, " + std::to_string(body.statistics->samples) + " samples")
           : "empirical, " + std::to_string(body.statistics->frames.size()) + " frames"));
}

namespace detail {

namespace {

/// 3×d factor A with A Aᵀ = C restricted to the first d directions (eigen-decomposition of the
/// zero-padded block, robust for singular C such as σ = 0; fixed size: allocates nothing). The
/// columns are ordered by decreasing eigenvalue, so the first d carry the whole block.
Eigen::Matrix3d factor_of(const Eigen::Matrix3d& C, int d) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  M.topLeftCorner(d, d) = C.topLeftCorner(d, d);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(M);
  Eigen::Matrix3d A;
  for (int c = 0; c < 3; ++c)
    A.col(c) = es.eigenvectors().col(2 - c) * std::sqrt(std::max(0.0, es.eigenvalues()[2 - c]));
  return A;
}

Eigen::Matrix3d cov_of(const Statistics& s, std::size_t i) { return s.covariance_of(i); }

/// Shared sampling/empirical accumulation: evaluates the whole body at sample positions ys and
/// adds weight·ψ_k, weight·t_b. One fused parallel loop over atoms (bonds of atom k are built
/// in k's slice of the scratch arrays); no allocation.
/// With `du_dg` (9, row-major, accumulated): + weight·Σ_b t_b ⊗ ξ_b^s, ξ_b^s the bond of the
/// sample's reference positions xs (box H of the body).
double accumulate_sample(const Body& body, std::span<const double> ys, const Eigen::Matrix3d& h_y,
                         double weight, std::span<double> psi_out, std::span<double> t_out,
                         Scratch& sc, std::span<const double> xs = {}, double* du_dg = nullptr) {
  const auto& fam = body.families;
  const auto& pot = *body.potential;
  double total = 0.0;
  double acc[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  ParallelExceptions errors;  // a potential may refuse a sampled configuration
#pragma omp parallel for schedule(static) reduction(+ : total, acc[:9])
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(body.size()); ++ii)
    errors.capture([&] {
      const auto i = static_cast<std::size_t>(ii);
      const auto b0 = static_cast<std::size_t>(fam.offset[i]),
                 b1 = static_cast<std::size_t>(fam.offset[i + 1]);
      // per-thread family buffers, grown once per thread to the largest family
      thread_local std::vector<double> yb, tb;
      if (yb.size() < 3 * (b1 - b0)) {
        yb.resize(3 * (b1 - b0));
        tb.resize(3 * (b1 - b0));
      }
      for (std::size_t b = b0; b < b1; ++b) {
        const Eigen::Vector3d v = atomistic::bond_vector(fam, ys, h_y, i, b);
        for (int k = 0; k < 3; ++k) yb[3 * (b - b0) + static_cast<std::size_t>(k)] = v[k];
      }
      const atomistic::FamilyState f =
          atomistic::family_state(fam, i, body.type[i], sc.ntype.data() + b0, yb.data());
      const double psi = pot.force_state(f, tb.data());
      psi_out[i] += weight * psi;
      for (std::size_t c = 3 * b0; c < 3 * b1; ++c) t_out[c] += weight * tb[c - 3 * b0];
      total += weight * psi;
      if (du_dg) {
        for (std::size_t b = b0; b < b1; ++b) {
          const Eigen::Vector3d xi = atomistic::bond_vector(fam, xs, fam.h, i, b);
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c)
              acc[3 * r + c] += weight * tb[3 * (b - b0) + static_cast<std::size_t>(r)] * xi[c];
        }
      }
    });
  errors.rethrow();
  if (du_dg)
    for (int c = 0; c < 9; ++c) du_dg[c] += acc[c];
  return total;
}

/// statistical_force_states, ∂U/∂G accumulated into du_dg (9, row-major) when given.
double statistical_force_states_impl(const Body& body, const Statistics& s,
                                     std::span<const double> y, const Eigen::Matrix3d& h_y,
                                     const Eigen::Matrix3d& G, std::span<double> psi_out,
                                     std::span<double> t_out, Scratch& sc, double* du_dg) {
  const auto& fam = body.families;
  const std::size_t n = body.size(), nb = fam.bonds();
  const int d = body.dimension;
  std::fill(psi_out.begin(), psi_out.end(), 0.0);
  std::fill(t_out.begin(), t_out.end(), 0.0);
  const bool per_sample =
      s.form == Statistics::Form::empirical || s.method == Statistics::Method::sampling;
  sc.ntype.resize(nb);
  for (std::size_t b = 0; b < nb; ++b)
    sc.ntype[b] = body.type[static_cast<std::size_t>(fam.neighbor[b])];
  if (per_sample) sc.ys.resize(3 * n);
  if (per_sample && du_dg) sc.xs.resize(3 * n);
  if (s.form == Statistics::Form::empirical) {
    // y^f = y + G (x^f − x̄): each frame's fluctuation carried by the deformation.
    const double w = 1.0 / static_cast<double>(s.frames.size());
    double e = 0.0;
    for (const auto& f : s.frames) {
      for (std::size_t i = 0; i < n; ++i) {
        const Eigen::Vector3d dx(f[3 * i] - body.x[3 * i], f[3 * i + 1] - body.x[3 * i + 1],
                                 f[3 * i + 2] - body.x[3 * i + 2]);
        const Eigen::Vector3d g = G * dx;
        for (int k = 0; k < 3; ++k)
          sc.ys[3 * i + static_cast<std::size_t>(k)] =
              y[3 * i + static_cast<std::size_t>(k)] + g[k];
      }
      e += accumulate_sample(body, sc.ys, h_y, w, psi_out, t_out, sc, f, du_dg);
    }
    return e;
  }
  // Gaussian: factors of Σ_k (3×d, stored col-major 9 per atom).
  sc.factor.resize(9 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Matrix3d A = factor_of(cov_of(s, i), d);
    std::copy(A.data(), A.data() + 9, sc.factor.data() + 9 * i);
  }
  if (s.method == Statistics::Method::sampling) {
    std::mt19937_64 rng(s.seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    const double w = 1.0 / static_cast<double>(s.samples);
    double e = 0.0;
    for (std::int64_t smp = 0; smp < s.samples; ++smp) {
      for (std::size_t i = 0; i < n; ++i) {
        Eigen::Vector3d z = Eigen::Vector3d::Zero();
        for (int a = 0; a < d; ++a) z[a] = normal(rng);
        const Eigen::Vector3d a = Eigen::Map<const Eigen::Matrix3d>(sc.factor.data() + 9 * i) * z;
        const Eigen::Vector3d g = G * a;
        for (int k = 0; k < 3; ++k) {
          sc.ys[3 * i + static_cast<std::size_t>(k)] =
              y[3 * i + static_cast<std::size_t>(k)] + g[k];
          if (du_dg)
            sc.xs[3 * i + static_cast<std::size_t>(k)] =
                body.x[3 * i + static_cast<std::size_t>(k)] + a[k];
        }
      }
      e += accumulate_sample(body, sc.ys, h_y, w, psi_out, t_out, sc, sc.xs, du_dg);
    }
    return e;
  }
  // Cubature (pair potentials): per bond b = (k → j), Y_b + G A_b z with A_b A_bᵀ = Σ_k + Σ_j,
  // z on the tensor-product Gauss–Hermite grid (order^d nodes).
  if (sc.order != s.order || sc.dim != d) {
    std::vector<double> z1, w1;
    gauss_hermite(s.order, z1, w1);
    const auto m = static_cast<std::size_t>(s.order);
    std::size_t count = 1;
    for (int a = 0; a < d; ++a) count *= m;
    sc.nodes.assign(3 * count, 0.0);
    sc.weights.assign(count, 1.0);
    for (std::size_t c = 0; c < count; ++c) {
      std::size_t r = c;
      for (int a = 0; a < d; ++a) {
        sc.nodes[3 * c + static_cast<std::size_t>(a)] = z1[r % m];
        sc.weights[c] *= w1[r % m];
        r /= m;
      }
    }
    sc.order = s.order;
    sc.dim = d;
  }
  const std::size_t count = sc.weights.size();
  const auto& pot = *body.potential;
  double total = 0.0;
  double acc[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  ParallelExceptions errors;  // a potential may refuse a cubature configuration
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : total, acc[:9])
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii)
    errors.capture([&] {
      const auto i = static_cast<std::size_t>(ii);
      const Eigen::Matrix3d Ci = cov_of(s, i);
      double psi = 0.0;
      for (auto b = static_cast<std::size_t>(fam.offset[i]);
           b < static_cast<std::size_t>(fam.offset[i + 1]); ++b) {
        const auto j = static_cast<std::size_t>(fam.neighbor[b]);
        const Eigen::Matrix3d A = factor_of(Ci + cov_of(s, j), d);
        const Eigen::Matrix3d B = G * A;
        // reference bond of the means (∂U/∂G: Σ w t ⊗ (ξ_b + A z))
        const Eigen::Vector3d xi_b =
            du_dg ? atomistic::bond_vector(fam, body.x, fam.h, i, b) : Eigen::Vector3d::Zero();
        atomistic::FamilyState f;
        f.type = body.type[i];
        f.size = 1;
        f.neighbor_type = sc.ntype.data() + b;
        f.pair_factor = fam.pair_factor.empty() ? nullptr : fam.pair_factor.data() + b;
        f.bond_type = fam.bond_type.empty() ? nullptr : fam.bond_type.data() + b;
        double yb[3], tb[3];
        f.bond = yb;
        const Eigen::Vector3d mean_bond =
            atomistic::bond_vector(fam, y, h_y, i, b);  // Y_b of the means
        double tx = 0, ty = 0, tz = 0, e = 0;
        for (std::size_t c = 0; c < count; ++c) {
          const Eigen::Vector3d z(sc.nodes[3 * c], sc.nodes[3 * c + 1], sc.nodes[3 * c + 2]);
          const Eigen::Vector3d dz = B * z;
          for (int k = 0; k < 3; ++k) yb[k] = mean_bond[k] + dz[k];
          const double w = sc.weights[c];
          e += w * pot.force_state(f, tb);
          tx += w * tb[0];
          ty += w * tb[1];
          tz += w * tb[2];
          if (du_dg) {
            const Eigen::Vector3d xi = xi_b + A * z;
            for (int r = 0; r < 3; ++r)
              for (int cc = 0; cc < 3; ++cc) acc[3 * r + cc] += w * tb[r] * xi[cc];
          }
        }
        t_out[3 * b] = tx;
        t_out[3 * b + 1] = ty;
        t_out[3 * b + 2] = tz;
        psi += e;
      }
      psi_out[i] = psi;
      total += psi;
    });
  errors.rethrow();
  if (du_dg)
    for (int c = 0; c < 9; ++c) du_dg[c] += acc[c];
  return total;
}

}  // namespace

double statistical_force_states(const Body& body, const Statistics& s, std::span<const double> y,
                                const Eigen::Matrix3d& h_y, const Eigen::Matrix3d& G,
                                std::span<double> psi_out, std::span<double> t_out, Scratch& sc,
                                Eigen::Matrix3d* du_dg) {
  double dudg[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  double* dp = du_dg ? dudg : nullptr;
  const double e = statistical_force_states_impl(body, s, y, h_y, G, psi_out, t_out, sc, dp);
  if (du_dg)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) (*du_dg)(r, c) = dudg[3 * r + c];
  return e;
}

}  // namespace detail

}  // namespace pdcg::body
