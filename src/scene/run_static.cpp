// run_scene: the checks of the output directory, the body, the material and the boundary
// sets, then the quasi-static run (Newton load steps, staggered rupture) or run_dynamic.
#include <fmt/format.h>

#include <sstream>

#include "checks.hpp"
#include "csv_units.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/progress.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/scene/scene.hpp"
#include "results.hpp"

namespace pdcg::scene {

using solver::Vec3;

void run_scene(const Scene& s, const std::optional<std::filesystem::path>& out_override) {
  RunOptions o;
  o.output = out_override;
  run_scene(s, o);
}

namespace {
// Distributed runs (docs/scale-out.md): what is not implemented on several processes is
// refused before any work, naming the scene key and the fix.
void refuse_distributed(const Scene& s, const RunOptions& ro) {
  auto refuse = [&](const std::string& what, const std::string& key) {
    throw InputError(fmt::format("{} is not implemented on several MPI processes ({} processes)",
                                 what, ro.processes))
        .source(s.source.string())
        .key(key)
        .fix("run on one process (without mpirun), or drop " + key);
  };
  if (ro.restart) refuse("restart from a checkpoint", "--restart");
  // explicit dynamics runs on several processes, with dynamic fracture (docs/scale-out.md §6);
  // the quasi-static rupture and the other effects do not
  if (s.rupture && !s.inertia) refuse("rupture of a quasi-static run", "effects");
  for (const auto& e : s.effects)
    if (e != "inertia" && e != "rupture" && e != "damping") refuse("effect '" + e + "'", "effects");
  if (s.rupture && s.rupture_options.softening != solver::RuptureSoftening::none)
    refuse("the softening failure law", "rupture.softening");
  if (s.newton.matrix_free) refuse("the matrix-free GMRES", "solver.matrix_free");
  if (s.newton.check_stability) refuse("the stability check", "solver.check_stability");
  if (s.checkpoint_every > 0) refuse("checkpointing", "output.checkpoint_every");
  using solver::LinearSolver;
  if (s.newton.linear == LinearSolver::gmres || s.newton.linear == LinearSolver::bicgstab)
    throw InputError(fmt::format("solver.linear: {} is a serial solver; on several MPI processes "
                                 "the linear solve is PETSc's",
                                 solver::to_string(s.newton.linear)))
        .source(s.source.string())
        .key("solver.linear")
        .value(solver::to_string(s.newton.linear))
        .expected("mumps, gamg or hypre (cholmod, umfpack and lu become mumps)")
        .fix("set solver.linear: gamg or hypre (iterative) or mumps (direct)");
}
}  // namespace

void run_scene(const Scene& s, const RunOptions& ro) {
  if (ro.processes > 1) try {
      refuse_distributed(s, ro);
    } catch (InputError& e) {
      throw with_line(s, e);
    }
  // Only rank 0 writes (outputs, checks of the directory); every process runs the same logic.
  const bool writer = ro.rank == 0;
  const std::filesystem::path dir =
      ro.restart ? *ro.restart : (ro.output ? *ro.output : s.output_directory);
  std::optional<Restart> restart;
  if (ro.restart) restart = load_checkpoint(s, dir);
  // Before any computation the output directory is checked: it exists or can be created, and
  // takes a file (docs/formats.md). Directories this check creates are removed again if the
  // scene's set-up is refused below, so that a refused scene leaves nothing behind
  // (docs/solver.md §6); scene.resolved.yaml is written once everything is checked.
  const char* dir_option = ro.restart ? "--restart" : ro.output ? "--output" : "output.directory";
  // Only the writer creates and removes them: another process removing the directory it
  // has just created (on a refusal it reached first) made the writer's check fail.
  std::vector<std::filesystem::path> created;  // directories the check creates, outermost last
  if (writer) {
    std::error_code ec;
    for (auto p = std::filesystem::absolute(dir, ec);
         !ec && !p.empty() && !std::filesystem::exists(p, ec) && p != p.parent_path();
         p = p.parent_path())
      created.push_back(p);
  }
  if (writer) io::require_writable_directory(dir, dir_option);
  if (const int n = writer ? io::remove_stale_temporaries(dir) : 0)
    log::info("removed {} temporary file{} left in {} by a killed run", n, n == 1 ? "" : "s",
              dir.string());
  bool outputs_begun = false;
  struct RemoveCreatedOnRefusal {
    const std::vector<std::filesystem::path>& dirs;
    const bool& begun;
    ~RemoveCreatedOnRefusal() {
      if (begun) return;
      std::error_code ec;
      for (const auto& p : dirs) std::filesystem::remove(p, ec);  // only removes empty ones
    }
  } remove_created{created, outputs_begun};
  auto begin_outputs = [&] {
    outputs_begun = true;
    if (!writer) return;
    io::AtomicTextFile f(dir / "scene.resolved.yaml");
    f.stream() << resolved_yaml(s);
    f.commit();
  };
  auto body = make_discretization(s);
  log::info("body: {} points, spacing {}, horizon {}", body.size(), body.spacing(), body.horizon());
  const auto material = make_material(s);
  log::info("material: {}", material->name());
  solver::Model model(body, *material, s.model);
  std::vector<solver::DisplacementSet> dsets;
  std::vector<solver::TractionSet> tsets;
  for (const auto& bc : s.boundary) {
    auto pts = select(s, body, bc);
    log::info("boundary '{}': {} points", bc.name, pts.size());
    if (bc.is_traction) {
      auto v = bc.value;
      tsets.push_back({bc.name, std::move(pts), [v](double t) {
                         return Vec3(v[0] ? v[0](t) : 0.0, v[1] ? v[1](t) : 0.0,
                                     v[2] ? v[2](t) : 0.0);
                       }});
    } else {
      solver::DisplacementSet ds{bc.name, std::move(pts), {}};
      ds.component = bc.value;
      if (bc.grip_surface) ds.surface_offset = surface_grip_offsets(s, body, bc, ds.points);
      dsets.push_back(std::move(ds));
    }
  }
  checks::boundary_sets(s, body, dsets);
  if (s.inertia) {
    run_dynamic(s, dir, restart, body, model, *material, std::move(dsets), std::move(tsets),
                begin_outputs, ro);
    return;
  }
  solver::NewtonOptions nopt = s.newton;
  nopt.steps = s.steps;
  if (ro.distribute) {
    using solver::LinearSolver;
    if (!solver::is_petsc_solver(nopt.linear)) {
      log::info("{} MPI processes: solver.linear {} → mumps (PETSc's MUMPS LU)", ro.processes,
                solver::to_string(nopt.linear));
      nopt.linear = LinearSolver::mumps;
    }
    nopt.distribution = ro.distribute(model, nopt.linear);
  }
  std::unique_ptr<solver::StaticSolver> solver_ptr;
  try {
    solver_ptr = std::make_unique<solver::StaticSolver>(model, dsets, tsets, nopt);
  } catch (InputError& e) {
    throw with_line(s, e);
  }
  solver::StaticSolver& solver = *solver_ptr;
  // Rupture: only when the scene lists it (no broken flags, no checks otherwise).
  std::unique_ptr<solver::Rupture> rupture;
  if (s.rupture) {
    rupture = std::make_unique<solver::Rupture>(body, model, s.rupture_options);
    if (s.rupture_options.criterion == solver::RuptureCriterion::fracture_energy)
      log::info(
          "rupture: fracture_energy, G_c = {:.6g}: a bond breaks when the work done on it "
          "exceeds ψ_c (V_iφ̂_ijV_j + V_jφ̂_jiV_i), ψ_c = G_c/(β_d δ) = {:.6g}; staggered "
          "re-equilibration at fixed load",
          s.rupture_options.fracture_energy, rupture->critical_energy_density());
    else
      log::info("rupture: {} > {} breaks a bond; staggered re-equilibration at fixed load",
                solver::to_string(s.rupture_options.criterion), s.rupture_options.critical);
  }
  const bool griffith =
      rupture && s.rupture_options.criterion == solver::RuptureCriterion::fracture_energy;
  // the run parts of the listed effects that have one (registered effects; effect.hpp)
  const RunContext context{s, dir, body, model, *material, dsets, false};
  const auto runs = attach_effects(s, context);
  begin_outputs();
  const int d = s.dimension;
  const std::size_t N = body.size();
  std::vector<std::pair<int, double>> written;
  std::ostringstream csv;
  const char* axes[3] = {"x", "y", "z"};
  int first = 1;
  if (restart) {
    if (restart->kind != "static")
      throw InputError("the checkpoint is of a dynamic run").source(restart->file.string());
    solver.prepare_restart();  // pattern analysis on the model of a fresh start
    if (rupture) {
      const auto pairs = restart->h5->read_int("rupture/broken");
      const auto ap = restart->h5->read_int("rupture/anchor_points");
      rupture->restore(pairs, std::vector<int>(ap.begin(), ap.end()),
                       restart->vec("rupture/anchor_targets"),
                       restart->h5->exists("rupture/point_stencils_off")
                           ? restart->h5->read_int("rupture/point_stencils_off")
                           : std::vector<std::int64_t>{});
      // the residual scale's floor after separation (older checkpoints: re-derived)
      if (restart->h5->exists("rupture/peak_force"))
        rupture->restore_peak_force(restart->vec("rupture/peak_force").at(0));
      if (griffith)
        rupture->restore_work(restart->vec("rupture/work"), restart->vec("rupture/work_psi"),
                              restart->h5->attribute_double("/", "dissipated_energy"));
    }
    for (const auto& [name, run] : runs) run->restore(*restart->h5, "effects/" + name);
    // the balance's normaliser, the largest load so far (absent from checkpoints written
    // before it was stored: the restarted run then normalises by its own loads only)
    double peak_load = 0.0;
    if (restart->h5->has_attribute("/", "peak_load"))
      peak_load = restart->h5->attribute_double("/", "peak_load");
    else
      log::warn(
          "{}: no peak_load in this checkpoint (written by an earlier pdcg); the logged force "
          "balance is normalised by the loads of the restarted steps only",
          restart->file.string());
    solver.restore(vec_of(restart->vec("state/u")), vec_of(restart->vec("state/f")), restart->t,
                   static_cast<int>(restart->h5->attribute_int("/", "solver_step")), peak_load);
    csv << restart->series;
    written = restart->written;
    first = static_cast<int>(restart->step) + 1;
  } else {
    csv << csv_units_comment(s, false) << "step,t";
    for (const auto& ds : dsets)  // reactions of the prescribed components only
      for (int a = 0; a < d; ++a)
        if (ds.component[a]) csv << "," << ds.name << "_f" << axes[a];
    if (rupture) csv << ",broken_bonds";
    if (griffith) csv << ",dissipated_energy";
    for (const auto& [name, run] : runs)
      for (const auto& col : run->columns()) csv << "," << col;
    csv << "\n";
    csv << "0,0";
    for (std::size_t i = 0; i < dsets.size(); ++i)
      for (int a = 0; a < d; ++a)
        if (dsets[i].component[a]) csv << ",0";
    if (rupture) csv << ",0";
    if (griffith) csv << ",0";
    csv << effect_values(runs, {0, 0.0, solver.displacement(), nullptr}, "{:.10g}");
    csv << "\n";
  }
  auto write_csv = [&] {
    if (!writer) return;
    io::AtomicTextFile f(dir / "reactions.csv");
    f.stream() << csv.str();
    f.commit();
  };
  write_csv();
  int counter = 0;
  auto on_step = [&](const solver::StepReport& rep) {
    if (rupture) rupture->stagger(solver);  // re-equilibrate at this load until no bond breaks
    csv << rep.step << "," << fmt::format("{:.10g}", rep.t);
    for (std::size_t i = 0; i < dsets.size(); ++i) {
      const Vec3 r = solver.reaction(i);
      for (int a = 0; a < d; ++a)
        if (dsets[i].component[a]) csv << "," << fmt::format("{:.10g}", r(a));
    }
    if (rupture) csv << "," << body.broken_bonds();
    if (griffith) csv << "," << fmt::format("{:.10g}", rupture->dissipated_energy());
    csv << effect_values(runs, {rep.step, rep.t, solver.displacement(), nullptr}, "{:.10g}");
    csv << "\n";
    write_csv();
    ++counter;
    const bool last = rep.t >= 1.0 - 1e-12;
    if (counter % s.output_every != 0 && !last) return;
    if (!writer) return;
    write_fields(dir, s, body, model, *material, solver.displacement(), nullptr, s.rupture,
                 rep.step, [&](io::H5Writer& h5) {
                   h5.attribute("/", "step", static_cast<std::int64_t>(rep.step));
                   h5.attribute("/", "load_factor", rep.t);
                   h5.attribute("/", "newton_iterations",
                                static_cast<std::int64_t>(rep.iterations));
                   h5.attribute("/", "residual", rep.residual);
                   for (const auto& [name, run] : runs)
                     run->write_fields(h5, {rep.step, rep.t, solver.displacement(), nullptr});
                 });
    written.emplace_back(rep.step, rep.t);
    write_xdmf(dir, N, written, s.rupture);
  };
  // Nominal load steps t = k/steps; a checkpoint after every checkpoint_every of them.
  auto progress_text = [&] {
    return rupture ? fmt::format("t = {:.4g}, {} bonds broken", solver.load_factor(),
                                 body.broken_bonds())
                   : fmt::format("t = {:.4g}", solver.load_factor());
  };
  Progress progress("load steps", static_cast<std::uint64_t>(s.steps));
  for (int k = first; k <= s.steps; ++k) {
    solver.advance_to(static_cast<double>(k) / s.steps, on_step);
    if (s.checkpoint_every > 0 && (k % s.checkpoint_every == 0 || k == s.steps)) {
      auto h5 = begin_checkpoint(s, dir, "static", k, solver.load_factor(), csv.str(), written);
      h5->write("state/u", std_of(solver.displacement()));
      h5->write("state/f", std_of(solver.internal_force()));
      h5->attribute("/", "solver_step", static_cast<std::int64_t>(solver.step()));
      h5->attribute("/", "peak_load", solver.peak_load());
      if (rupture) {
        h5->write("rupture/broken", rupture->broken_pairs());
        const auto po = body.suppressed_point_stencils();
        h5->write("rupture/point_stencils_off", std::vector<std::int64_t>(po.begin(), po.end()));
        const auto& ap = model.anchors();
        h5->write("rupture/anchor_points", std::vector<std::int64_t>(ap.begin(), ap.end()));
        h5->write("rupture/anchor_targets", model.anchor_targets());
        h5->write("rupture/peak_force", std::vector<double>{rupture->peak_force()});
        if (griffith) {
          h5->write("rupture/work", rupture->bond_work());
          h5->write("rupture/work_psi", rupture->bond_work_last_psi());
          h5->attribute("/", "dissipated_energy", rupture->dissipated_energy());
        }
      }
      for (const auto& [name, run] : runs) run->checkpoint(*h5, "effects/" + name);
      finish_checkpoint(*h5, dir, k);
    }
    progress.update(static_cast<std::uint64_t>(k), progress_text());
  }
  progress.finish(progress_text());
  log::info("done: {} steps, results in {}", counter, dir.string());
}

}  // namespace pdcg::scene
