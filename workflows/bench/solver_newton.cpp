// bench_solver_newton: residual+tangent assembly time and linear-solve time per Newton
// iteration of the BA solver (benchmark; docs/performance.md "BA solver").
// A unit square (2D, plane strain) or cube (3D) with n points per edge, m = 3.015, μ = 1,
// K = 10, uniaxial stretch λ = 1.05 in one load step (left face x-fixed + pins, right face
// displaced); times from the solver's own per-step report (summed over the Newton
// iterations, divided by their number), peak RSS from getrusage (= VmHWM), also before the
// Newton run (discretisation + model + solver set-up).
// Usage: bench_solver_newton <dim> <n> [linear=umfpack|cholmod|lu|bicgstab|gmres|gmres-mf]
//        [weak|energy] [tolerance=1e-8]  (a looser tolerance stops after fewer iterations at
//        large sizes; gmres-mf: GMRES with matrix-free products, NewtonOptions::matrix_free)
// Matrix-free rows also report the tangent products (count, seconds per product and per
// Newton iteration) and the bytes of the operator data (packed stencil tangents); for them
// assembly_s_per_it is the residual + per-stencil tangent evaluation (no K).
// (energy: the symmetric energy boundary form, which CHOLMOD can factorise; the weak
// form's tangent is unsymmetric and CHOLMOD is replaced by UMFPACK).
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pdcg/solver/newton.hpp"

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
    std::fprintf(stderr, "usage: %s <dim 2|3> <points per edge> [linear solver]\n", argv[0]);
    return 2;
  }
  const int dim = std::atoi(argv[1]), n = std::atoi(argv[2]);
  double load1 = -1;  // 1-minute load average at the start (the machine is shared)
  if (std::FILE* fl = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(fl, "%lf", &load1) != 1) load1 = -1;
    std::fclose(fl);
  }
  const std::string linear = argc > 3 ? argv[3] : "umfpack";
  const std::string form = argc > 4 ? argv[4] : "weak";
  GridSpec g;
  g.dimension = dim;
  g.spacing = 1.0 / n;
  double t0 = now();
  const auto D = Discretization::grid(g);
  const double t_disc = now() - t0;
  const auto mat =
      make_neo_hookean({1.0, 10.0}, dim == 3 ? Kinematics::three_d : Kinematics::plane_strain);
  t0 = now();
  ModelOptions mo;
  if (form == "energy") mo.boundary = BoundaryForm::energy;
  Model M(D, *mat, mo);
  const double t_model = now() - t0;
  const double dx = g.spacing, xl = 0.5 * dx, xr = 1 - 0.5 * dx, lam = 1.05;
  DisplacementSet left{"left", {}, {}}, pin{"pin", {}, {}}, pin2{"pin2", {}, {}},
      right{"right", {}, {}};
  left.component[0] = [](double) { return 0.0; };
  pin.component[1] = [](double) { return 0.0; };
  if (dim == 3) pin.component[2] = [](double) { return 0.0; };
  pin2.component[1] = [](double) { return 0.0; };
  right.component[0] = [=](double t) { return (lam - 1) * (xr - xl) * t; };
  for (std::size_t i = 0; i < D.size(); ++i) {
    const Vec3& x = D.positions()[i];
    if (x.x() < dx) left.points.push_back(i);
    if (x.x() > 1 - dx) right.points.push_back(i);
    if (x.x() < dx && x.y() < dx && (dim == 2 || x.z() < dx)) pin.points.push_back(i);
    if (dim == 3 && x.x() < dx && x.y() < dx && x.z() > 1 - dx) pin2.points.push_back(i);
  }
  std::vector<DisplacementSet> ds{left, pin, right};
  if (dim == 3) ds.push_back(pin2);
  NewtonOptions opt;
  opt.steps = 1;
  opt.tolerance = argc > 5 ? std::atof(argv[5]) : 1e-8;
  const bool mf = linear == "gmres-mf";
  opt.linear = parse_linear_solver(mf ? "gmres" : linear);
  opt.matrix_free = mf;
  StaticSolver solver(M, ds, {}, opt);
  StepReport last;
  const double rss_before_run = peak_rss_mb();
  t0 = now();
  solver.run([&](const StepReport& r) { last = r; });
  const double t_run = now() - t0;
  const int it = std::max(1, last.iterations);
  std::string history;
  for (double r : last.residual_history) {
    if (!history.empty()) history.append(";");
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3e", r);
    history.append(buf);
  }
  const double peak = peak_rss_mb();
  std::printf(
      "dim=%d n=%d points=%zu bonds=%zu linear=%s form=%s discretization_s=%.3f model_s=%.3f "
      "newton_iterations=%d assembly_s_per_it=%.4f factor_s_per_it=%.4f solve_s_per_it=%.4f "
      "krylov_iterations=%d products=%d product_s=%.4f product_s_per_it=%.3f operator_mb=%.0f "
      "run_s=%.3f rss_before_newton_mb=%.0f peak_rss_mb=%.0f kb_per_point=%.1f load1=%.2f "
      "history=%s\n",
      dim, n, D.size(), D.families().index.size(), linear.c_str(), form.c_str(), t_disc, t_model,
      last.iterations, last.assembly_seconds / it, last.factor_seconds / it,
      (last.solve_seconds - last.factor_seconds) / it, last.krylov_iterations,
      last.operator_products,
      last.operator_products > 0 ? last.product_seconds / last.operator_products : 0.0,
      last.product_seconds / it, static_cast<double>(M.operator_bytes()) / (1 << 20), t_run,
      rss_before_run, peak, 1024.0 * peak / static_cast<double>(D.size()), load1, history.c_str());
  return 0;
}
