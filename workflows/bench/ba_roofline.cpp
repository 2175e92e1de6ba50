// bench_ba_roofline: throughput of the BA residual evaluation and of the tangent assembly
// against the machine's measured roofline (docs/performance.md), and the bytes the BA solver holds
// per point / per BA family term (docs/performance.md, "Memory"). Driven by
// workflows/bench/roofline.sh.
//
//   bench_ba_roofline triad <threads> [MiB per array = 256]   STREAM-like triad a = b + s·c
//   bench_ba_roofline fma <threads>                            FMA peak (AVX2+FMA if present)
//   bench_ba_roofline ba <dim> <n per edge> [reps = 5] [tangent = 1]
//   bench_ba_roofline roof <dim> <n per edge> [rounds = 5] [reps = 5]  triad and residual
//                                                  alternating in one process (one thread)
//
// One line of key=value pairs per run. Times are the minimum over `reps` repetitions (the
// machine is shared: the minimum is the least disturbed run).
//
// A "BA family term" is one (BA stencil, member) pair: stencil B_ij of bond (i, j) holds the
// points {i, j} ∪ (H_i ∩ H_j), each with its PDDO weight G^m (d doubles). terms = Σ_ij |B_ij|.
//
// Analytic counts per term (the minimum any implementation must do / move; the same numbers
// are used before and after an optimisation, so achieved rates compare like with like):
//   flops  : F_S = I + Σ_m u_m ⊗ G^m      d² FMA  = 2d² flops
//            f_m += (w_S P_S) G^m          d² FMA  = 2d² flops
//            → 4d² per term (2D: 16, 3D: 36). The constitutive update P(F_S) once per
//            stencil (≈ 10² flops, i.e. 2–7 per term) is NOT counted: achieved GFLOP/s is a
//            lower bound.
//   bytes  : the stencil data are far larger than the caches and must stream from memory
//            once per evaluation: member index (4 B) + G^m (8d B) per term, plus weight and
//            offset (16 B) per stencil, plus u read and f written (2 · 8d B) per point
//            (u and f themselves stay in cache within a stencil: members are neighbours).
//            → bytes = terms·(4 + 8d) + stencils·16 + points·16d.
//   AI = flops / bytes ≈ 0.76 flop/B (2D), 1.27 flop/B (3D): memory bound on any machine
//   with peak/bandwidth above ~1.3 flop/B, so the bound is AI × bandwidth.
// Tangent assembly: counted in terms of the same family terms (it also needs, per term and
// member row, the d²×d² stencil tangent contracted with G^k and G^n: the "term" rate
// is the comparable throughput; its flop count is implementation specific and not given).
//
// Memory: a counting malloc (live bytes via malloc_usable_size) measures what the
// Discretization, the Model and the tangent hold after construction and first use.
#include <malloc.h>
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "live_bytes.hpp"
#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/model.hpp"

namespace {
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}
void set_threads(int t) {
#ifdef _OPENMP
  omp_set_num_threads(t);
#else
  (void)t;
#endif
}
int threads() {
#ifdef _OPENMP
  return omp_get_max_threads();
#else
  return 1;
#endif
}

// ---------------------------------------------------------------- STREAM-like triad
int triad(int nthreads, std::size_t mib) {
  set_threads(nthreads);
  const std::size_t n = mib * 1024 * 1024 / sizeof(double);
  auto* a = static_cast<double*>(std::malloc(n * sizeof(double)));
  auto* b = static_cast<double*>(std::malloc(n * sizeof(double)));
  auto* c = static_cast<double*>(std::malloc(n * sizeof(double)));
  // First touch by the threads that use the pages (static schedule, as in the kernel).
#pragma omp parallel for schedule(static)
  for (std::size_t i = 0; i < n; ++i) {
    a[i] = 0.0;
    b[i] = 1.0;
    c[i] = 2.0;
  }
  const double s = 3.0;
  double best = 1e300;
  for (int rep = 0; rep < 10; ++rep) {
    const double t0 = now();
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
    best = std::min(best, now() - t0);
  }
  // STREAM convention: 3 arrays × 8 B per element (the write-allocate read is not counted).
  const double gbs = 3.0 * 8.0 * static_cast<double>(n) / best / 1e9;
  std::printf("probe=triad threads=%d mib_per_array=%zu best_s=%.5f gbs=%.2f check=%.1f\n",
              nthreads, mib, best, gbs, a[n / 2]);
  std::free(a);
  std::free(b);
  std::free(c);
  return 0;
}

// ---------------------------------------------------------------- FMA peak
#if defined(__x86_64__)
__attribute__((target("avx2,fma"))) double fma_avx2(long iters) {
  // 12 independent accumulators (latency 4 × 2 pipes on current cores, with margin).
  __m256d acc[12];
  for (int k = 0; k < 12; ++k) acc[k] = _mm256_set1_pd(1.0 + 1e-3 * k);
  const __m256d x = _mm256_set1_pd(0.999999), y = _mm256_set1_pd(1e-7);
  for (long i = 0; i < iters; ++i)
    for (int k = 0; k < 12; ++k) acc[k] = _mm256_fmadd_pd(acc[k], x, y);
  __m256d s = acc[0];
  for (int k = 1; k < 12; ++k) s = _mm256_add_pd(s, acc[k]);
  double out[4];
  _mm256_storeu_pd(out, s);
  return out[0] + out[1] + out[2] + out[3];
}
#endif

int fma_peak(int nthreads) {
  set_threads(nthreads);
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) {
    std::printf("probe=fma threads=%d gflops=nan isa=none\n", nthreads);
    return 0;
  }
  const long iters = 20'000'000;  // per thread: 12·4·2·iters flops ≈ 1.9 GFLOP
  double best = 1e300, sink = 0;
  for (int rep = 0; rep < 7; ++rep) {
    const double t0 = now();
#pragma omp parallel reduction(+ : sink)
    sink += fma_avx2(iters);
    best = std::min(best, now() - t0);
  }
  const double flops = 12.0 * 4 * 2 * static_cast<double>(iters) * nthreads;
  std::printf("probe=fma threads=%d isa=avx2+fma best_s=%.4f gflops=%.2f check=%.3g\n", nthreads,
              best, flops / best / 1e9, sink);
#else
  std::printf("probe=fma threads=%d gflops=nan isa=none\n", nthreads);
#endif
  return 0;
}

// ---------------------------------------------------------------- BA kernels
int ba(int dim, int n, int reps, bool tangent) {
  using namespace pdcg::solver;
  GridSpec g;
  g.dimension = dim;
  g.spacing = 1.0 / n;
  const long long live0 = live_bytes;
  double t0 = now();
  const auto D = Discretization::grid(g);
  const double t_disc = now() - t0;
  const long long live_disc = live_bytes - live0;
  const auto mat =
      make_neo_hookean({1.0, 10.0}, dim == 3 ? Kinematics::three_d : Kinematics::plane_strain);
  const Stencils& S = D.bond_stencils();
  const std::size_t N = D.size(), ns = S.size(), terms = S.index.size();
  const std::size_t pterms = D.point_stencils().index.size(), bonds = D.families().index.size();
  // Tangent work grows with member pairs: row k of K sums, per stencil holding k, all its
  // members n (d×d blocks): pairs = Σ_S |S|².
  double pairs = 0;
  for (std::size_t s = 0; s < ns; ++s) {
    const auto m = static_cast<double>(S.offsets[s + 1] - S.offsets[s]);
    pairs += m * m;
  }
  // u: a homogeneous stretch plus a small random field (admissible everywhere).
  Eigen::VectorXd u(dim * N), f(dim * N);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (std::size_t i = 0; i < N; ++i)
    for (int a = 0; a < dim; ++a)
      u[dim * i + a] = 0.05 * D.positions()[i](a) * (a == 0 ? 1 : -0.3) + 0.01 * g.spacing * U(rng);
  const long long live1 = live_bytes;
  t0 = now();
  const Model M(D, *mat);
  const double t_model = now() - t0;
  const long long live_model = live_bytes - live1;
  // Residual.
  const long long live2 = live_bytes;
  if (!M.internal_force(u, f)) {
    std::fprintf(stderr, "inadmissible deformation\n");
    return 1;
  }
  const long long live_res = live_bytes - live2;
  double t_res = 1e300;
  for (int r = 0; r < reps; ++r) {
    t0 = now();
    M.internal_force(u, f);
    t_res = std::min(t_res, now() - t0);
  }
  const Eigen::VectorXd f_res = f;
  // Tangent assembly (residual + K).
  double t_tan = std::nan(""), fdiff = std::nan("");
  long long live_tan = 0;
  long long nnz = 0;
  std::size_t store = 0;  // of which the per-stencil tangents (packed w_S A_S) and scratch
  if (tangent) {
    SparseRow K;
    const long long live3 = live_bytes;
    M.internal_force_and_tangent(u, f, K);
    live_tan = live_bytes - live3;
    store = M.operator_bytes();
    nnz = K.nonZeros();
    t_tan = 1e300;
    // (the tangent is 10–100× slower than the residual: fewer repetitions)
    for (int r = 0; r < std::max(1, reps / 3); ++r) {
      t0 = now();
      M.internal_force_and_tangent(u, f, K);
      t_tan = std::min(t_tan, now() - t0);
    }
    fdiff = (f - f_res).norm() / f_res.norm();  // the two paths agree (round-off)
  }
  const double d = dim;
  const double flops = 4 * d * d * static_cast<double>(terms);
  const double bytes = static_cast<double>(terms) * (4 + 8 * d) + 16.0 * static_cast<double>(ns) +
                       16.0 * d * static_cast<double>(N);
  // Data the Discretization must hold (each array once, at its element size, no slack):
  // BA stencils: index 4 + G 8d per term, weight 8 + offset 8 per stencil; point stencils:
  // index 4 + G 8d per term, offset 8 per point; families: index 4 per bond, offset 8 per
  // point; per point x, surface (2 × 24 B) and volume 8 B.
  const double min_disc = static_cast<double>(terms + pterms) * (4 + 8 * d) +
                          16.0 * static_cast<double>(ns) + 4.0 * static_cast<double>(bonds) +
                          (8 + 8 + 56) * static_cast<double>(N);
  // Residual evaluation must hold, beyond the body: u and f (8d B each per point) and a
  // per-stencil P (8d² B) if stresses are stored (the fused kernel needs none).
  // Tangent: the matrix K (values 8 B + column 4 B per nonzero, row offsets 4 B per row).
  const double min_k = 12.0 * static_cast<double>(nnz) + 4.0 * d * static_cast<double>(N);
  std::printf(
      "dim=%d n=%d threads=%d points=%zu bonds=%zu stencils=%zu terms=%zu point_terms=%zu "
      "terms_per_point=%.1f members_per_stencil=%.2f discretization_s=%.3f model_s=%.3f "
      "residual_s=%.6g tangent_s=%.6g residual_terms_per_s=%.4g tangent_terms_per_s=%.4g "
      "flops_per_term=%.0f bytes_per_term=%.3f residual_gflops=%.3f residual_gbs=%.3f "
      "tangent_vs_residual_rel_f=%.2e pairs=%.0f tangent_pairs_per_s=%.4g "
      "disc_bytes=%lld disc_min_bytes=%.0f model_bytes=%lld residual_scratch_bytes=%lld "
      "tangent_bytes=%lld tangent_store_bytes=%zu k_nnz=%lld k_min_bytes=%.0f peak_rss_mb=%.0f\n",
      dim, n, threads(), N, bonds, ns, terms, pterms, static_cast<double>(terms) / N,
      static_cast<double>(terms) / ns, t_disc, t_model, t_res, t_tan, terms / t_res, terms / t_tan,
      flops / terms, bytes / terms, flops / t_res / 1e9, bytes / t_res / 1e9, fdiff, pairs,
      pairs / t_tan, live_disc, min_disc, live_model, live_res, live_tan, store, nnz, min_k,
      peak_rss_mb());
  return 0;
}

// ---------------------------------------------------------------- same-process roofline
// `roof`: the residual and the triad probe alternate in one process, `rounds` times (one
// thread): each round runs the triad (best of 5 passes over 3 × 256 MiB) and then the residual
// (minimum of `reps` calls). The best triad and the best residual over the rounds give the
// fraction of the bound at the best bandwidth seen; the fraction within each round (the probe
// and the kernel a few ms apart, under the same load) is printed too, with its best over the
// rounds. Prints one line per round and a summary line.
int roof(int dim, int n, int rounds, int reps) {
  using namespace pdcg::solver;
  set_threads(1);
  GridSpec g;
  g.dimension = dim;
  g.spacing = 1.0 / n;
  const auto D = Discretization::grid(g);
  const auto mat =
      make_neo_hookean({1.0, 10.0}, dim == 3 ? Kinematics::three_d : Kinematics::plane_strain);
  const Stencils& S = D.bond_stencils();
  const std::size_t N = D.size(), ns = S.size(), terms = S.index.size();
  Eigen::VectorXd u(dim * N), f(dim * N);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  for (std::size_t i = 0; i < N; ++i)
    for (int a = 0; a < dim; ++a)
      u[dim * i + a] = 0.05 * D.positions()[i](a) * (a == 0 ? 1 : -0.3) + 0.01 * g.spacing * U(rng);
  const Model M(D, *mat);
  if (!M.internal_force(u, f)) {
    std::fprintf(stderr, "inadmissible deformation\n");
    return 1;
  }
  const double d = dim;
  const double bytes = static_cast<double>(terms) * (4 + 8 * d) + 16.0 * static_cast<double>(ns) +
                       16.0 * d * static_cast<double>(N);
  const std::size_t m = 256ull * 1024 * 1024 / sizeof(double);
  std::vector<double> a(m, 0.0), b(m, 1.0), c(m, 2.0);
  double best_bw = 0, best_t = 1e300, best_round = 0;
  const double bpt = bytes / static_cast<double>(terms);
  for (int round = 0; round < rounds; ++round) {
    double tt = 1e300;
    for (int rep = 0; rep < 5; ++rep) {
      const double t0 = now();
      for (std::size_t i = 0; i < m; ++i) a[i] = b[i] + 3.0 * c[i];
      tt = std::min(tt, now() - t0);
    }
    const double bw = 24.0 * static_cast<double>(m) / tt / 1e9;
    double tr = 1e300;
    for (int r = 0; r < reps; ++r) {
      const double t0 = now();
      M.internal_force(u, f);
      tr = std::min(tr, now() - t0);
    }
    best_bw = std::max(best_bw, bw);
    best_t = std::min(best_t, tr);
    // fraction of the bound within the round (probe and kernel a few ms apart)
    const double frac = terms / tr / (bw * 1e9 / bpt);
    best_round = std::max(best_round, frac);
    std::printf(
        "round=%d triad_gbs=%.2f residual_s=%.6g residual_terms_per_s=%.4g fraction=%.3f "
        "check=%.1f\n",
        round, bw, tr, terms / tr, frac, a[m / 2]);
  }
  const double bound = best_bw * 1e9 / (bytes / terms);  // terms/s
  std::printf(
      "roof dim=%d n=%d points=%zu terms=%zu bytes_per_term=%.3f best_triad_gbs=%.2f "
      "best_residual_s=%.6g best_terms_per_s=%.4g bound_terms_per_s=%.4g fraction=%.3f "
      "one_over=%.2f best_round_fraction=%.3f\n",
      dim, n, N, terms, bytes / terms, best_bw, best_t, terms / best_t, bound,
      terms / best_t / bound, bound / (terms / best_t), best_round);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // PDCG_SOLVER_SCALAR=1: the portable sweep, the peer of the AVX2 one (roofline.sh)
  if (const char* e = std::getenv("PDCG_SOLVER_SCALAR"); e && *e && std::string(e) != "0")
    pdcg::solver::set_vector_kernels(false);
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "triad" && argc > 2)
    return triad(std::atoi(argv[2]), argc > 3 ? std::strtoul(argv[3], nullptr, 10) : 256);
  if (mode == "fma" && argc > 2) return fma_peak(std::atoi(argv[2]));
  if (mode == "ba" && argc > 3)
    return ba(std::atoi(argv[2]), std::atoi(argv[3]), argc > 4 ? std::atoi(argv[4]) : 5,
              argc > 5 ? std::atoi(argv[5]) != 0 : true);
  if (mode == "roof" && argc > 3)
    return roof(std::atoi(argv[2]), std::atoi(argv[3]), argc > 4 ? std::atoi(argv[4]) : 5,
                argc > 5 ? std::atoi(argv[5]) : 5);
  std::fprintf(stderr,
               "usage: %s triad <threads> [MiB] | fma <threads> | ba <dim> <n> [reps] [tangent] | "
               "roof <dim> <n> [rounds] [reps]\n",
               argv[0]);
  return 2;
}
