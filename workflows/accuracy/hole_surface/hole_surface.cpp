// Diagnosis driver (docs/accuracy-cost.md §1, "Cause of the lateral-strain error"): the plate
// with a hole of a pdcg scene, with the grid's surface vectors s_k (mode 0; the staircase until
// Discretization::grid took the true circle itself, docs/solver.md §2) or with
// s_k of the hole's points replaced by the exact ∫ n dS of the true circle (mode 1: the hole's
// surface points sorted by angle, each owning the arc between the mid-angles to its neighbours,
// s_k = −R (sin b − sin a, cos a − cos b); Σ s_k over the hole stays 0).
//   hole_surface SCENE U_IN OUT MODE R           internal force at the given field U_IN (2N numbers)
//   hole_surface SCENE -    OUT MODE R d         solve: left column u_x = 0, pin nearest (0,0)
//                                                u_y = 0, right column u_x = d, one load step
// OUT: x y V f_x f_y s_x s_y u_x u_y per point. Built by build.sh against a pdcg build dir.
#include "pdcg/scene/scene.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg/solver/newton.hpp"
#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
int main(int argc, char** argv) {
  using namespace pdcg;
  auto s = scene::load_scene(argv[1]);
  const int mode = std::atoi(argv[4]);
  const double R = std::atof(argv[5]), cx = 0.5, cy = 0.5;
  auto grid = scene::make_discretization(s);
  std::vector<solver::Vec3> x = grid.positions(), surf = grid.surface();
  std::vector<double> vol = grid.volumes();
  if (mode == 1) {
    std::vector<int> hole;
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double r = std::hypot(x[i][0] - cx, x[i][1] - cy);
      if (r < 0.3 && std::hypot(surf[i][0], surf[i][1]) > 0) hole.push_back(int(i));
    }
    std::vector<double> th(hole.size());
    for (std::size_t k = 0; k < hole.size(); ++k) th[k] = std::atan2(x[hole[k]][1] - cy, x[hole[k]][0] - cx);
    std::vector<int> o(hole.size());
    std::iota(o.begin(), o.end(), 0);
    std::sort(o.begin(), o.end(), [&](int a, int b) { return th[a] < th[b]; });
    const int n = int(o.size());
    for (int k = 0; k < n; ++k) {
      double tp = th[o[(k - 1 + n) % n]], t = th[o[k]], tn = th[o[(k + 1) % n]];
      if (tp > t) tp -= 2 * M_PI;
      if (tn < t) tn += 2 * M_PI;
      const double a = 0.5 * (tp + t), b = 0.5 * (t + tn);
      auto& sk = surf[hole[o[k]]];
      sk[0] = -R * (std::sin(b) - std::sin(a));
      sk[1] = -R * (std::cos(a) - std::cos(b));
    }
  }
  solver::DiscretizationOptions dopt;
  dopt.horizon_factor = s.horizon_factor;
  dopt.horizon = s.horizon_value;
  auto body = solver::Discretization::from_points(2, x, vol, surf, grid.spacing(), {}, dopt);
  auto mat = scene::make_material(s);
  solver::Model model(body, *mat, s.model);
  const auto N = body.size();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(2 * N), f;
  if (argc > 6) {  // solve: left u_x = 0, pin u_y = 0 at the point nearest (0,0), right u_x = d t
    const double d = std::atof(argv[6]);
    solver::DisplacementSet L{"left", {}, {}}, P{"pin", {}, {}}, Rt{"right", {}, {}};
    int pin = 0;
    for (std::size_t i = 0; i < N; ++i) {
      if (x[i][0] < 1e-9) L.points.push_back(int(i));
      if (x[i][0] > 1 - 1e-9) Rt.points.push_back(int(i));
      if (std::hypot(x[i][0], x[i][1]) < std::hypot(x[pin][0], x[pin][1])) pin = int(i);
    }
    P.points = {pin};
    L.component[0] = [](double) { return 0.0; };
    P.component[1] = [](double) { return 0.0; };
    Rt.component[0] = [d](double t) { return d * t; };
    solver::NewtonOptions no;
    no.steps = 1;
    no.tolerance = 1e-10;
    solver::StaticSolver ss(model, {L, P, Rt}, {}, no);
    ss.run();
    u = ss.displacement();
  } else {
    std::ifstream in(argv[2]);
    for (std::size_t i = 0; i < 2 * N; ++i) in >> u[i];
  }
  model.internal_force(u, f);
  std::ofstream out(argv[3]);
  out.precision(17);
  for (std::size_t i = 0; i < N; ++i)
    out << x[i][0] << ' ' << x[i][1] << ' ' << vol[i] << ' ' << f[2 * i] << ' ' << f[2 * i + 1] << ' '
        << surf[i][0] << ' ' << surf[i][1] << ' ' << u[2 * i] << ' ' << u[2 * i + 1] << '\n';
}
