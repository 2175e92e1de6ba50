/// `pdcg run scene.yaml [-o DIR]`: static BA correspondence solve of a scene.
#include <memory>
#include <optional>

#include "command.hpp"
#include "pdcg/scene/scene.hpp"

namespace {

struct Options {
  std::string scene;
  std::string out;
};

pdcg::cli::Registration reg(80, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("run", "Run a continuum scene (bond-associated correspondence, Newton)");
  auto opts = std::make_shared<Options>();
  sub->add_option("scene", opts->scene, "Scene file (YAML)")->required();
  sub->add_option("-o,--output", opts->out, "Output directory (overrides output.directory)");
  sub->footer(
      "Writes results_NNNN.h5 per output step, results.xdmf (open in ParaView),\n"
      "reactions.csv and scene.resolved.yaml.\n"
      "Example:\n  pdcg run plate.yaml -o out/plate");
  return [opts] {
    const auto s = pdcg::scene::load_scene(opts->scene);
    std::optional<std::filesystem::path> out;
    if (!opts->out.empty()) out = opts->out;
    pdcg::scene::run_scene(s, out);
    return 0;
  };
});

}  // namespace
