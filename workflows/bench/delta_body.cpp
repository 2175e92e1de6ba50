// bench_delta_body: time and peak memory of building a delta body (families by cell lists, CSR)
// from N LJ atoms (fcc, ρ = 0.8442, lj/cut 2.5), and of one evaluation of energies, force
// states and PD forces. Usage: bench_delta_body [cells_per_edge=63]  (63 → 1,000,188 atoms).
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"

namespace {
double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;  // kB on Linux
}
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

int main(int argc, char** argv) {
  using namespace pdcg;
  const int n = argc > 1 ? std::atoi(argv[1]) : 63;
  const double a = std::cbrt(4.0 / 0.8442);
  atomistic::Atoms at;
  at.box.hi = {n * a, n * a, n * a};
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  at.id.reserve(4ull * n * n * n);
  at.x.reserve(12ull * n * n * n);
  std::int64_t id = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& b : basis) {
          at.id.push_back(++id);
          at.type.push_back(1);
          at.x.insert(at.x.end(),
                      {(i + b[0] + 0.1) * a, (j + b[1] + 0.1) * a, (k + b[2] + 0.1) * a});
        }
  const auto spec = atomistic::read_potential_commands_from_string(
      "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n", "bench", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  const double rss0 = peak_rss_mb();
  const double t0 = now();
  body::Body b = body::make_delta_body(at, pot, spec);
  const double t1 = now();
  const double rss1 = peak_rss_mb();
  body::Evaluator ev(b);
  const double t2 = now();
  const auto e = ev.reference();
  const double t3 = now();
  const double N = static_cast<double>(b.size());
  std::printf("atoms %zu, bonds %zu (%.1f per atom)\n", b.size(), b.families.bonds(),
              b.families.bonds() / N);
  std::printf(
      "build delta body: %.2f s (%.2f us/atom); peak RSS %.0f MB before, %.0f MB after: %.0f "
      "bytes/atom\n",
      t1 - t0, 1e6 * (t1 - t0) / N, rss0, rss1, (rss1 - rss0) * 1048576.0 / N);
  std::printf(
      "evaluator setup %.2f s; one evaluation (psi, t, f): %.2f s, energy/atom %.6f; peak RSS %.0f "
      "MB\n",
      t2 - t1, t3 - t2, e.energy / N, peak_rss_mb());
  return 0;
}
