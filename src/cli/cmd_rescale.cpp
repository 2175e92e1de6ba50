/// `pdcg rescale BODY.h5 --factor EPS | --horizon D -o res.h5` (docs/theory.md §4).
#include <cstdio>

#include "command.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string body, output;
  std::optional<double> factor, horizon;
};

int run(const Options& o) {
  pdcg::io::require_writable_output(o.output, "--output");  // before any computation
  using namespace pdcg;
  if (o.factor.has_value() == o.horizon.has_value())
    throw InputError("give exactly one of --factor and --horizon")
        .key("--factor/--horizon")
        .fix("--factor EPS (ε = δ'/δ) or --horizon D (the new horizon δ')");
  const body::Body b = body::read_body(o.body);
  const double eps = o.factor ? *o.factor : coarsen::epsilon_for_horizon(b, *o.horizon);
  body::Body r = coarsen::rescale(b, eps);
  r.provenance.back() += " (" + pdcg::command_line() + ")";
  body::write_body(r, o.output);
  std::printf("%s: rescaled by %.17g, horizon %.17g -> %.17g\n", o.output.c_str(), eps, b.horizon(),
              r.horizon());
  return 0;
}

pdcg::cli::Registration reg(130, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("rescale", "Rescale the horizon of a PD body (delta' = eps * delta)");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("--factor", o->factor, "Rescaling factor eps > 0");
  sub->add_option("--horizon", o->horizon, "Target horizon (eps = horizon / current horizon)");
  sub->add_option("-o,--output", o->output, "Output model file")->required();
  sub->footer("Example:\n  pdcg rescale body.h5 --factor 4 -o res.h5");
  return [o] { return run(*o); };
});

}  // namespace
