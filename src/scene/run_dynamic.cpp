// Explicit dynamics of a scene (effects: [inertia]; docs/effects.md): velocity Verlet with
// optional damping and dynamic fracture, series.csv, fields and checkpoints.
#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "csv_units.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/progress.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/solver/explicit.hpp"
#include "results.hpp"

namespace pdcg::scene {

using solver::Vec3;

void run_dynamic(const Scene& s, const std::filesystem::path& dir,
                 const std::optional<Restart>& restart, solver::Discretization& body,
                 solver::Model& model, const solver::Material& material,
                 std::vector<solver::DisplacementSet> dsets, std::vector<solver::TractionSet> tsets,
                 const std::function<void()>& begin_outputs, const RunOptions& ro) {
  const int d = s.dimension;
  // Several processes (docs/scale-out.md §6): every process steps the same replicated state;
  // the forces come from the force exchange (this process's stencils, summed), and rank 0
  // alone writes.
  const bool writer = ro.rank == 0;
  const std::size_t N = body.size();
  if (restart && restart->kind != "dynamic")
    throw InputError("the checkpoint is of a quasi-static run").source(restart->file.string());
  solver::ExplicitOptions eo;
  eo.density = s.density;
  eo.time_step = s.time_step;
  eo.safety = s.safety;
  eo.allow_unstable = s.allow_unstable;
  if (s.damping_type == "viscous") {
    eo.damping_type = solver::ExplicitDamping::viscous;
    eo.damping = s.damping_coefficient;
  } else if (s.damping_type == "adaptive-dynamic-relaxation") {
    eo.damping_type = solver::ExplicitDamping::adaptive;
  }
  std::unique_ptr<solver::ExplicitSolver> ex;
  try {
    // tractions: nominal t*(t) with t the time, as the displacement values of dynamic scenes
    ex = std::make_unique<solver::ExplicitSolver>(model, dsets, std::move(tsets), eo);
  } catch (InputError& e) {
    throw with_line(s, e);  // e.g. a time step above the stable limit: refused, nothing written
  }
  std::unique_ptr<solver::ForceExchange> exchange;
  if (ro.distribute_explicit) {
    try {
      exchange = ro.distribute_explicit(model);
    } catch (InputError& e) {
      throw with_line(s, e);  // e.g. a PETSc option explicit dynamics does not read
    }
    ex->set_force_exchange(exchange.get());
  }
  // Π(u): the model's, or summed over the processes' stencils
  auto energy = [&](const Eigen::VectorXd& u) {
    return exchange ? exchange->energy(u) : model.energy(u);
  };
  begin_outputs();
  // Steps: auto → Δt = end_time / ⌈end_time / (safety Δt_crit)⌉ (ends exactly at end_time,
  // still ≤ safety Δt_crit); a given Δt is kept and the last step may pass end_time.
  const double dt0 = ex->time_step();
  long steps = static_cast<long>(std::ceil(s.end_time / dt0 * (1 - 1e-12)));
  if (!(s.time_step > 0)) ex->shorten_time_step(s.end_time / static_cast<double>(steps));
  double dt = ex->time_step();
  const double dt_start = dt;
  double dt_min = dt;
  // Dynamic fracture (docs/effects.md §3c): only when the scene lists rupture.
  std::unique_ptr<solver::Rupture> rupture;
  if (s.rupture) {
    rupture = std::make_unique<solver::Rupture>(body, model, s.rupture_options);
    ex->attach_rupture(rupture.get());
    if (s.rupture_options.criterion == solver::RuptureCriterion::fracture_energy)
      log::info(
          "dynamic fracture: fracture_energy, G_c = {:.6g} (ψ_c = {:.6g}; checked every {} "
          "step{})",
          s.rupture_options.fracture_energy, rupture->critical_energy_density(),
          s.rupture_options.check_every, s.rupture_options.check_every == 1 ? "" : "s");
    else
      log::info("dynamic fracture: {} > {} breaks a bond (checked every {} step{})",
                solver::to_string(s.rupture_options.criterion), s.rupture_options.critical,
                s.rupture_options.check_every, s.rupture_options.check_every == 1 ? "" : "s");
  }
  const bool griffith =
      rupture && s.rupture_options.criterion == solver::RuptureCriterion::fracture_energy;
  const RunContext context{s, dir, body, model, material, dsets, true};
  const auto runs = attach_effects(s, context);
  log::info("explicit dynamics: {} steps of {:.6g} to t = {:.6g} (stable limit {:.6g}, {:.3g}×)",
            steps, dt, s.end_time, ex->stable_limit(), dt / ex->stable_limit());
  // initial velocity (free components only; prescribed ones follow ū(t))
  bool any_v = false;
  for (int a = 0; a < d; ++a) any_v = any_v || static_cast<bool>(s.initial_velocity[a]);
  if (any_v && !restart) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(model.dofs());
    for (std::size_t k = 0; k < N; ++k) {
      const double x[3] = {body.positions()[k](0), body.positions()[k](1), body.positions()[k](2)};
      for (int a = 0; a < d; ++a)
        if (s.initial_velocity[a]) v[d * k + a] = s.initial_velocity[a](x);
    }
    for (const auto& ds : dsets)
      for (int p : ds.points)
        for (int a = 0; a < d; ++a)
          if (ds.component[a]) v[d * p + a] = 0.0;
    ex->set_velocity(v);
  }
  const char* axes[3] = {"x", "y", "z"};
  std::ostringstream csv;
  std::vector<std::pair<int, double>> written;
  long first = 1;
  if (restart) {
    solver::ExplicitSolver::State st;
    st.u = vec_of(restart->vec("state/u"));
    st.v = vec_of(restart->vec("state/v"));
    st.a = vec_of(restart->vec("state/a"));
    st.f = vec_of(restart->vec("state/f"));
    if (restart->h5->exists("state/f_prev")) st.f_prev = vec_of(restart->vec("state/f_prev"));
    st.t = restart->t;
    st.c = restart->h5->attribute_double("/", "damping_coefficient");
    st.dt = restart->h5->attribute_double("/", "time_step");
    st.crit = restart->h5->attribute_double("/", "stable_limit");
    st.steps = static_cast<long>(restart->h5->attribute_int("/", "solver_steps"));
    steps = static_cast<long>(restart->h5->attribute_int("/", "steps_planned"));
    if (rupture)
      rupture->restore(restart->h5->read_int("rupture/broken"), {}, {},
                       restart->h5->read_int("rupture/point_stencils_off"));
    if (griffith)
      rupture->restore_work(restart->vec("rupture/work"), restart->vec("rupture/work_psi"),
                            restart->h5->attribute_double("/", "dissipated_energy"));
    if (st.u.size() != static_cast<Eigen::Index>(model.dofs()))
      throw InputError("the checkpoint does not fit the scene's body")
          .source(restart->file.string());
    ex->restore(st);
    for (const auto& [name, run] : runs) run->restore(*restart->h5, "effects/" + name);
    dt = ex->time_step();
    csv << restart->series;
    written = restart->written;
    first = restart->step + 1;
  } else {
    csv << csv_units_comment(s, true) << "step,t,kinetic,internal,total,total_verlet";
    for (const auto& ds : dsets)  // reactions of the prescribed components only
      for (int a = 0; a < d; ++a)
        if (ds.component[a]) csv << "," << ds.name << "_f" << axes[a];
    if (!s.damping_type.empty()) csv << ",damping_coefficient";
    if (rupture) csv << ",broken_bonds";
    if (griffith) csv << ",dissipated_energy";
    for (const auto& [name, run] : runs)
      for (const auto& col : run->columns()) csv << "," << col;
    csv << "\n";
  }
  auto sample = [&](long n) {
    const double ek = ex->kinetic_energy(), ei = energy(ex->displacement());
    // total_verlet: ½ v_{n−½}·M v_{n+½} + Π, the energy velocity Verlet conserves exactly for
    // a linear system (E_kin + Π oscillates by O((ωΔt)²) around it; docs/effects.md)
    csv << n << ","
        << fmt::format("{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}", ex->time(), ek, ei, ek + ei,
                       ex->modified_kinetic_energy() + ei);
    for (std::size_t i = 0; i < dsets.size(); ++i) {
      const Vec3 r = ex->reaction(i);
      for (int a = 0; a < d; ++a)
        if (dsets[i].component[a]) csv << "," << fmt::format("{:.17g}", r(a));
    }
    if (!s.damping_type.empty()) csv << "," << fmt::format("{:.17g}", ex->damping_coefficient());
    if (rupture) csv << "," << body.broken_bonds();
    if (griffith) csv << "," << fmt::format("{:.17g}", rupture->dissipated_energy());
    csv << effect_values(runs, {n, ex->time(), ex->displacement(), &ex->velocity()}, "{:.17g}");
    csv << "\n";
    return ek + ei;
  };
  auto write_series = [&] {
    if (!writer) return;
    io::AtomicTextFile f(dir / "series.csv");
    f.stream() << csv.str();
    f.commit();
  };
  auto write_step = [&](long n) {
    if (!writer) return;
    write_fields(dir, s, body, model, material, ex->displacement(), &ex->velocity(), s.rupture,
                 static_cast<int>(n), [&](io::H5Writer& h5) {
                   h5.attribute("/", "step", static_cast<std::int64_t>(n));
                   h5.attribute("/", "time", ex->time());
                   for (const auto& [name, run] : runs)
                     run->write_fields(h5, {n, ex->time(), ex->displacement(), &ex->velocity()});
                 });
    written.emplace_back(static_cast<int>(n), ex->time());
    write_xdmf(dir, N, written, s.rupture, true);
    write_series();
  };
  double E0 = 0.0;
  if (!restart) {
    E0 = sample(0);
    write_step(0);
  } else {
    E0 = ex->kinetic_energy() + energy(ex->displacement());
  }
  Progress progress("steps", static_cast<std::uint64_t>(steps));
  const long progress_every = std::max(1L, steps / 2000);
  double E = E0;
  std::size_t break_events = 0;
  for (long n = first; n <= steps; ++n) {
    try {
      ex->step();
      if (rupture && ex->last_rupture().broken > 0) {
        const auto& p = ex->last_rupture();
        if (body.broken_bonds() == p.broken)
          log::info("dynamic fracture: first bonds break at step {} (t = {:.6g}): {} bonds", n,
                    ex->time(), p.broken);
        ++break_events;
        log::debug(
            "step {} t = {:.6g}: {} bonds broke ({} with an inverted stencil; {} in total), {} "
            "stencils rebuilt, {} ill-posed stencils off",
            n, ex->time(), p.broken, p.inverted, body.broken_bonds(), p.rebuilt,
            body.suppressed_stencils());
      }
      if (rupture && ex->time_step() != dt) {
        // rebuilt stencils changed the stable limit: the remaining time in steps of the new
        // size (auto: shortened to end exactly at end_time)
        const double rest = s.end_time - ex->time();
        const long k =
            rest <= 1e-12 * s.end_time
                ? 0L  // end_time reached: this step is the last
                : std::max(1L, static_cast<long>(std::ceil(rest / ex->time_step() * (1 - 1e-12))));
        if (!(s.time_step > 0) && k > 0) ex->shorten_time_step(rest / static_cast<double>(k));
        dt = ex->time_step();
        dt_min = std::min(dt_min, dt);
        steps = n + k;
      }
    } catch (const NumericalError& e) {
      write_series();  // the series up to the failure, for the diagnosis
      throw NumericalError(
          fmt::format("{} (step {}; Δt = {:.6g} is {:.3g}× the stable limit {:.6g})", e.what(), n,
                      dt, dt / ex->stable_limit(), ex->stable_limit()));
    }
    const bool last = n == steps;
    if (n % s.series_every == 0 || last) E = sample(n);
    if (!std::isfinite(E) || !ex->displacement().allFinite())
      throw NumericalError(fmt::format(
          "explicit dynamics diverged at step {} (t = {:.6g}): energy {} — the time step {:.6g} "
          "is {:.3g}× the stable limit {:.6g}",
          n, ex->time(), E, dt, dt / ex->stable_limit(), ex->stable_limit()));
    if (n % s.output_every == 0 || last) write_step(n);
    if (s.checkpoint_every > 0 && (n % s.checkpoint_every == 0 || last)) {
      if (n % s.output_every != 0 && !last) write_series();
      auto h5 = begin_checkpoint(s, dir, "dynamic", n, ex->time(), csv.str(), written);
      const auto st = ex->state();
      h5->write("state/u", std_of(st.u));
      h5->write("state/v", std_of(st.v));
      h5->write("state/a", std_of(st.a));
      h5->write("state/f", std_of(st.f));
      if (st.f_prev.size() > 0) h5->write("state/f_prev", std_of(st.f_prev));
      h5->attribute("/", "damping_coefficient", st.c);
      h5->attribute("/", "time_step", st.dt);
      h5->attribute("/", "stable_limit", st.crit);
      h5->attribute("/", "solver_steps", static_cast<std::int64_t>(st.steps));
      h5->attribute("/", "steps_planned", static_cast<std::int64_t>(steps));
      if (rupture) {
        h5->write("rupture/broken", rupture->broken_pairs());
        const auto po = body.suppressed_point_stencils();
        h5->write("rupture/point_stencils_off", std::vector<std::int64_t>(po.begin(), po.end()));
        if (griffith) {
          h5->write("rupture/work", rupture->bond_work());
          h5->write("rupture/work_psi", rupture->bond_work_last_psi());
          h5->attribute("/", "dissipated_energy", rupture->dissipated_energy());
        }
      }
      for (const auto& [name, run] : runs) run->checkpoint(*h5, "effects/" + name);
      finish_checkpoint(*h5, dir, n);
    }
    if (n % progress_every == 0)  // formatting the line allocates: not every step
      progress.update(static_cast<std::uint64_t>(n),
                      fmt::format("t = {:.4g}, E = {:.6g} ({:+.2e}){}", ex->time(), E,
                                  E0 != 0 ? (E - E0) / std::abs(E0) : 0.0,
                                  rupture ? fmt::format(", {} bonds broken", body.broken_bonds())
                                          : std::string()));
  }
  progress.finish(rupture
                      ? fmt::format("t = {:.4g}, {} bonds broken", ex->time(), body.broken_bonds())
                      : fmt::format("t = {:.4g}", ex->time()));
  write_series();
  if (rupture)
    log::info("dynamic fracture: {} bonds broken in {} break events, {} ill-posed stencils off{}",
              body.broken_bonds(), break_events, body.suppressed_stencils(),
              dt != dt_start ? fmt::format("; time step at the end {:.6g} (start {:.6g}, smallest "
                                           "{:.6g}, stable limit {:.6g})",
                                           dt, dt_start, dt_min, ex->stable_limit())
                             : std::string());
  log::info(
      "done: {} steps to t = {:.6g}; total energy {:.10g} (start {:.10g}, change {:.3e}); "
      "results in {}",
      steps, ex->time(), E, E0, E0 != 0 ? (E - E0) / std::abs(E0) : 0.0, dir.string());
}

}  // namespace pdcg::scene
