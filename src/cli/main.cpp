/// pdcg — command-line entry point.
///
/// Exit codes: 0 success, 1 runtime or numerical failure, 2 bad input or
/// usage. Messages go to stderr; results to files or stdout.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <map>
#include <string>

#include "command.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::cli {
std::vector<Entry>& registry() {
  static std::vector<Entry> r;
  return r;
}
}  // namespace pdcg::cli

int main(int argc, char** argv) {
  using namespace pdcg;
  set_command_line(argc, argv);
  // A file beyond the file size limit (`ulimit -f`, RLIMIT_FSIZE) raises SIGXFSZ, whose default
  // action kills the process without a word. Ignored, the write fails with EFBIG instead and
  // the writer reports it like a full disk: the file, the OS error, the fix (docs/formats.md).
  std::signal(SIGXFSZ, SIG_IGN);

  CLI::App app{
      "pdcg — coarse-grain atoms into peridynamics.\n"
      "Reads LAMMPS dumps, data files and potentials; builds peridynamic bodies whose forces\n"
      "equal the MD forces; homogenises, rescales, checks dispersion; runs a bond-associated\n"
      "correspondence continuum solver. Documentation: docs/README.md",
      "pdcg"};
  app.require_subcommand(1);
  app.fallthrough();
  bool verbose = false, quiet = false;
  app.add_flag("-v,--verbose", verbose, "More log output (debug level)");
  app.add_flag("-q,--quiet", quiet, "Only warnings and errors on stderr");
  app.footer("Run 'pdcg <command> --help' for the options of a command and an example.");

  auto& entries = cli::registry();
  std::stable_sort(entries.begin(), entries.end(),
                   [](const cli::Entry& a, const cli::Entry& b) { return a.order < b.order; });
  std::map<std::string, cli::Runner> runners;
  for (auto& e : entries) {
    const auto before = app.get_subcommands({}).size();
    cli::Runner r = e.setup(app);
    auto subs = app.get_subcommands({});
    if (subs.size() > before) runners[subs.back()->get_name()] = std::move(r);
  }

  // A first positional argument that is not a command gets a helpful message
  // instead of CLI11's generic "arguments were not expected".
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (!a.empty() && a[0] == '-') continue;
    if (runners.count(a) == 0) {
      std::string names;
      for (const auto& [n, r] : runners) names += (names.empty() ? "" : ", ") + n;
      std::fprintf(stderr,
                   "pdcg: unknown command '%s'. Valid commands: %s.\n"
                   "Run 'pdcg --help' for one line on each.\n",
                   a.c_str(), names.c_str());
      return 2;
    }
    break;
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "pdcg: %s\nRun 'pdcg --help' or 'pdcg <command> --help'.\n", e.what());
    return 2;
  }

  if (verbose && quiet) {
    std::fprintf(stderr, "pdcg: --verbose and --quiet contradict each other; give one.\n");
    return 2;
  }
  if (verbose) log::set_level(log::Level::debug);
  if (quiet) log::set_level(log::Level::warn);

  try {
    for (auto* sub : app.get_subcommands()) return runners.at(sub->get_name())();
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "pdcg: error: %s\n", e.what());
    return 2;
  } catch (const NumericalError& e) {
    std::fprintf(stderr, "pdcg: numerical failure: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pdcg: error: %s\n", e.what());
    return 1;
  }
}
