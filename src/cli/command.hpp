/// \file
/// Subcommand registry of the `pdcg` executable.
///
/// Each cmd_<name>.cpp defines one subcommand and registers it with a static
/// `Registration` object, so adding a command touches no other file:
/// \code
///   namespace {
///   pdcg::cli::Registration reg(50, [](CLI::App& app) -> pdcg::cli::Runner {
///     auto* sub = app.add_subcommand("forces", "PD internal force per point");
///     auto opts = std::make_shared<Options>();
///     sub->add_option("body", opts->body, "...")->required();
///     sub->footer("Example:\n  pdcg forces body.h5 -o forces.csv");
///     return [opts] { return run(*opts); };   // exit code
///   });
///   }
/// \endcode
/// Runners throw pdcg::InputError (exit 2) or pdcg::NumericalError (exit 1);
/// main() prints one clear message for either.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace pdcg::cli {

/// Runs the command after parsing; returns the process exit code.
using Runner = std::function<int()>;
/// Adds the subcommand to `app` and returns what to run when it is chosen.
using Setup = std::function<Runner(CLI::App& app)>;

struct Entry {
  int order;  ///< position in `pdcg --help`
  Setup setup;
};

std::vector<Entry>& registry();

struct Registration {
  Registration(int order, Setup setup) { registry().push_back({order, std::move(setup)}); }
};

}  // namespace pdcg::cli
