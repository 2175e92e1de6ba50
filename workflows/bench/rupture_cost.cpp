// bench_rupture_cost: "only what a scene asks for" (docs/effects.md). Per-load-step
// cost of the quasi-static BA solver on one pre-cracked plane-stress sheet (Neo-Hookean,
// μ = 1, K = 100, n × n points, m = 3.015, edge crack to x = 0.3 at y = 0.5, top edge
// pulled to u_y = 0.1), in three configurations of the same code path that `pdcg run` uses:
//   elastic   — Model + StaticSolver only (what a scene without `effects` runs);
//   rupture   — plus a Rupture object (criterion bond_stretch, critical 10: no bond ever
//               breaks), its staggered check after every step, i.e. a scene with
//               `effects: [rupture]` whose criterion is never reached;
//   breaking  — the same with critical 1.5, so bonds break at the tip and every step
//               runs staggered passes with local rebuilds.
// Prints one key=value line: the case, per-step wall time, Newton iterations, the arrays
// the rupture machinery allocated (sizes in bytes), peak RSS.
// Usage: bench_rupture_cost <elastic|rupture|breaking> <points per edge> [steps=5]
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "pdcg/core/log.hpp"
#include "pdcg/solver/newton.hpp"
#include "pdcg/solver/rupture.hpp"

namespace {
double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}
double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
}  // namespace

int main(int argc, char** argv) {
  using namespace pdcg::solver;
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s <elastic|rupture|breaking> <points per edge> [steps]\n",
                 argv[0]);
    return 2;
  }
  const std::string mode = argv[1];
  const int n = std::atoi(argv[2]);
  const int steps = argc > 3 ? std::atoi(argv[3]) : 5;
  if (mode != "elastic" && mode != "rupture" && mode != "breaking") {
    std::fprintf(stderr, "unknown case %s\n", mode.c_str());
    return 2;
  }
  pdcg::log::set_level(pdcg::log::Level::warn);
  GridSpec g;
  g.dimension = 2;
  g.spacing = 1.0 / n;
  g.cracks.push_back({Vec3(0.0, 0.5, 0.0), Vec3(0.3, 0.5, 0.0)});
  auto D = Discretization::grid(g);
  const auto mat = make_neo_hookean({1.0, 100.0}, Kinematics::plane_stress);
  Model M(D, *mat);
  const double dx = g.spacing;
  DisplacementSet bottom{"bottom", {}, {}}, pin{"pin", {}, {}}, top{"top", {}, {}};
  bottom.component[1] = [](double) { return 0.0; };
  pin.component[0] = [](double) { return 0.0; };
  top.component[1] = [](double t) { return 0.1 * t; };
  for (std::size_t i = 0; i < D.size(); ++i) {
    const Vec3& x = D.positions()[i];
    if (x.y() < dx) bottom.points.push_back(i);
    if (x.y() > 1 - dx) top.points.push_back(i);
    if (x.y() < dx && x.x() > 1 - dx) pin.points.push_back(i);
  }
  NewtonOptions opt;
  opt.steps = steps;
  opt.tolerance = 1e-8;
  opt.linear = parse_linear_solver("umfpack");
  StaticSolver solver(M, {bottom, pin, top}, {}, opt);
  std::unique_ptr<Rupture> rupture;
  if (mode != "elastic") {
    RuptureOptions ro;
    ro.criterion = RuptureCriterion::bond_stretch;
    ro.critical = mode == "rupture" ? 10.0 : 1.5;
    rupture = std::make_unique<Rupture>(D, M, ro);
  }
  int iterations = 0;
  double stagger_s = 0;
  const double t0 = now();
  solver.run([&](const StepReport& r) {
    iterations += r.iterations;
    if (rupture) {
      const double s0 = now();
      rupture->stagger(solver);
      stagger_s += now() - s0;
    }
  });
  const double run_s = now() - t0;
  const std::size_t directed = D.families().index.size();
  const std::size_t stencils = D.bond_stencils().size();
  // Arrays of the rupture machinery (docs/effects.md): one byte per directed bond (broken
  // flags) and one per BA stencil (ill-posed flags), both only after enable_rupture().
  const std::size_t broken_bytes = D.rupture_enabled() ? directed : 0;
  const std::size_t suppressed_bytes = D.rupture_enabled() ? stencils : 0;
  std::printf(
      "case=%s n=%d points=%zu directed_bonds=%zu bond_stencils=%zu steps=%d "
      "newton_iterations=%d s_per_step=%.4f s_per_iteration=%.4f stagger_s_per_step=%.4f "
      "broken_bonds=%zu anchored=%zu broken_flags_bytes=%zu illposed_flags_bytes=%zu "
      "criterion_values_bytes_per_pass=%zu peak_rss_mb=%.1f\n",
      mode.c_str(), n, D.size(), directed, stencils, steps, iterations, run_s / steps,
      run_s / std::max(1, iterations), stagger_s / steps,
      D.rupture_enabled() ? D.broken_bonds() : 0, M.anchors().size(), broken_bytes,
      // criterion values: one double per directed bond, allocated at the first check and
      // kept (since the dynamic-fracture work; before: two per bond at every pass)
      suppressed_bytes, rupture ? directed * sizeof(double) : std::size_t{0}, peak_rss_mb());
  return 0;
}
