/// `pdcg run scene.yaml [-o DIR | --restart DIR]`: quasi-static (Newton) or explicit dynamic
/// run of a scene.
#include <memory>
#include <optional>

#include "command.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/scene/scene.hpp"

namespace {

struct Options {
  std::string scene;
  std::string out;
  std::string restart;
};

pdcg::cli::Registration reg(80, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("run", "Run a continuum scene (bond-associated correspondence, Newton)");
  auto opts = std::make_shared<Options>();
  sub->add_option("scene", opts->scene, "Scene file (YAML)")->required();
  sub->add_option("-o,--output", opts->out, "Output directory (overrides output.directory)");
  sub->add_option("--restart", opts->restart,
                  "Continue the run in DIR from its last checkpoint (output.checkpoint_every)");
  sub->footer(
      "Writes results_NNNN.h5 per output step, results.xdmf (open in ParaView),\n"
      "reactions.csv (dynamic runs: series.csv) and scene.resolved.yaml.\n"
      "Examples:\n  pdcg run plate.yaml -o out/plate\n"
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
    pdcg::scene::run_scene(s, ro);
    return 0;
  };
});

}  // namespace
