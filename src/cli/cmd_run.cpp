/// `pdcg run scene.yaml [-o DIR | --restart DIR]`: quasi-static (Newton) or explicit dynamic
/// run of a scene.
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <thread>

#include "command.hpp"
#include "parallel_module.hpp"
#include "pdcg/config.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/scene/scene.hpp"
#if PDCG_HAVE_PETSC
#include "pdcg/core/log.hpp"
#endif

namespace {

struct Options {
  std::string scene;
  std::string out;
  std::string restart;
  std::string petsc_options;
};

pdcg::cli::Registration reg(80, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("run", "Run a continuum scene (bond-associated correspondence, Newton)");
  auto opts = std::make_shared<Options>();
  sub->add_option("scene", opts->scene, "Scene file (YAML)")->required();
  sub->add_option("-o,--output", opts->out, "Output directory (overrides output.directory)");
  sub->add_option("--restart", opts->restart,
                  "Continue the run in DIR from its last checkpoint (output.checkpoint_every)");
  sub->add_option("--petsc-options", opts->petsc_options,
                  "PETSc options of the distributed solve, e.g. \"-ksp_rtol 1e-10\" "
                  "(also: environment variable PETSC_OPTIONS; docs/scale-out.md)");
  sub->footer(
      "Writes results_NNNN.h5 per output step, results.xdmf (open in ParaView),\n"
      "reactions.csv (dynamic runs: series.csv) and scene.resolved.yaml.\n"
      "Under mpirun (PETSc build) the quasi-static run and explicit dynamics are split over the\n"
      "processes; rank 0 writes the outputs (docs/scale-out.md).\n"
      "Examples:\n  pdcg run plate.yaml -o out/plate\n"
      "  mpirun -n 2 pdcg run plate.yaml -o out/plate   # two processes, MUMPS\n"
      "  pdcg run bar.yaml --restart out/bar   # continue a killed run from its last checkpoint");
  return [opts] {
    const auto s = pdcg::scene::load_scene(opts->scene);
    pdcg::scene::RunOptions ro;
    if (!opts->out.empty()) ro.output = opts->out;
    if (!opts->restart.empty()) {
      if (ro.output)
        throw pdcg::InputError("--restart continues the run in its own directory")
            .key("--output")
            .value(opts->out)
            .fix("give --restart DIR alone");
      ro.restart = opts->restart;
    }
#if PDCG_HAVE_PETSC
    // PETSc is started only for a run under mpirun or a scene that asks for its solvers: a
    // serial run of a serial scene does not touch MPI (it behaves exactly as without PETSc).
    if (pdcg::cli::launched_by_mpirun() || pdcg::solver::is_petsc_solver(s.newton.linear) ||
        !opts->petsc_options.empty()) {
      const pdcg::cli::ParallelSession session(opts->petsc_options);
      const pdcg::parallel::Api& api = pdcg::cli::parallel_module();
      ro.processes = session.size();
      ro.rank = session.rank();
      // one log, rank 0's (every process runs the same logic and meets the same warnings)
      if (session.rank() != 0) pdcg::log::set_level(pdcg::log::Level::error);
      ro.distribute = [&api](pdcg::solver::Model& m, pdcg::solver::LinearSolver l) {
        return api.distribute(m, l);
      };
      ro.distribute_explicit = [&api](const pdcg::solver::Model& m) {
        return api.distribute_explicit(m);
      };
      if (session.size() == 1) {
        pdcg::scene::run_scene(s, ro);
        return 0;
      }
      // Several processes: an error on one must not leave the others waiting in a collective
      // call, so the process that meets it stops all (MPI_Abort, with the exit code of the
      // serial run). Most errors (a bad scene) meet every process at once: rank 0 prints and
      // aborts at once, the others wait a second first, so the message is printed once; an
      // error of another process alone is still printed, a second later.
      const auto fail = [&](const char* kind, const char* what, int code) {
        if (session.rank() != 0) std::this_thread::sleep_for(std::chrono::seconds(1));
        std::fprintf(stderr, "pdcg: %s: %s\n", kind, what);
        std::fflush(stderr);
        session.abort(code);
      };
      try {
        pdcg::scene::run_scene(s, ro);
      } catch (const pdcg::InputError& e) {
        fail("error", e.what(), 2);
      } catch (const pdcg::NumericalError& e) {
        fail("numerical failure", e.what(), 1);
      } catch (const std::exception& e) {
        fail("error", e.what(), 1);
      }
      return 0;
    }
#else
    if (!opts->petsc_options.empty())
      throw pdcg::InputError("this pdcg is built without PETSc")
          .key("--petsc-options")
          .fix("build with PETSc (cmake -DPDCG_ENABLE_PETSC=ON; docs/scale-out.md)");
#endif
    pdcg::scene::run_scene(s, ro);
    return 0;
  };
});

}  // namespace
