/// `pdcg info FILE.h5`: what a pdcg file holds, in a few lines.
#include <fmt/format.h>

#include <cstdio>
#include <functional>

#include "command.hpp"
#include "pdcg/io/hdf5.hpp"

namespace {

int run(const std::string& path) {
  pdcg::io::H5Reader file(path);
  const auto& info = file.info();
  std::printf("%s: %s (schema %d), units %s, written by pdcg %s\n", path.c_str(),
              info.format.c_str(), info.schema_version,
              std::string(pdcg::to_string(info.units)).c_str(), info.pdcg_version.c_str());
  std::printf("  command: %s\n", info.command_line.c_str());
  if (info.format == "pdcg-body") {  // a PD body: what it is, in two lines (docs/bodies.md)
    const auto bonds = file.exists("families/neighbor") ? file.dims("families/neighbor").at(0) : 0;
    std::printf("  %s body, dimension %lld, %lld points, %zu bonds, horizon %g, epsilon %g\n",
                file.attribute_string("/", "kind").c_str(),
                static_cast<long long>(file.attribute_int("/", "dimension")),
                static_cast<long long>(file.attribute_int("/", "points")), bonds,
                file.attribute_double("/families", "horizon"), file.attribute_double("/", "epsilon"));
    std::printf("  potential %s", file.attribute_string("/potential", "style").c_str());
    if (file.exists("statistics"))
      std::printf("; statistics %s", file.attribute_string("/statistics", "form").c_str());
    if (file.exists("homogenisation"))
      std::printf("; homogenised onto %zu points (kernel %s, width %g)", file.dims("homogenisation/volume").at(0),
                  file.attribute_string("/homogenisation", "kernel").c_str(),
                  file.attribute_double("/homogenisation", "width"));
    std::printf("\n");
  }
  // A short tree: groups and datasets with their shapes, two levels deep.
  std::function<void(const std::string&, int)> walk = [&](const std::string& group, int depth) {
    for (const auto& name : file.list(group)) {
      const std::string p = (group == "/" ? "" : group) + "/" + name;
      bool is_group = true;
      try {
        (void)file.list(p);
      } catch (...) {
        is_group = false;
      }
      if (is_group) {
        std::printf("  %*s%s/\n", 2 * depth, "", name.c_str());
        if (depth < 2) walk(p, depth + 1);
      } else {
        const auto d = file.dims(p);
        std::string shape;
        for (auto x : d) shape += (shape.empty() ? "" : "x") + std::to_string(x);
        std::printf("  %*s%s [%s]\n", 2 * depth, "", name.c_str(),
                    shape.empty() ? "scalar" : shape.c_str());
      }
    }
  };
  walk("/", 0);
  return 0;
}

pdcg::cli::Registration reg(900, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand("info", "Show what a pdcg HDF5 file holds");
  auto path = std::make_shared<std::string>();
  sub->add_option("file", *path, "A pdcg HDF5 file (model or results)")->required();
  sub->footer("Example:\n  pdcg info body.h5");
  return [path] { return run(*path); };
});

}  // namespace
