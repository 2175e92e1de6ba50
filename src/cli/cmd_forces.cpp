/// `pdcg forces BODY.h5 [--deformed DUMP [--frame N]] -o forces.csv`: PD internal force per point,
/// f_k = Σ_j (t_kj − t_jk), at the reference configuration or at the positions of a dump with
/// the same atom ids. CSV header `id,fx,fy,fz`.
#include <fmt/format.h>

#include <cstdio>

#include "body_cli_util.hpp"
#include "command.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string body, deformed, output;
  std::optional<std::int64_t> frame;
};

int run(const Options& o) {
  pdcg::io::require_writable_output(o.output, "--output");  // before any computation
  using namespace pdcg;
  namespace bu = cli::body_util;
  const body::Body b = body::read_body(o.body);
  body::Evaluator ev(b);
  body::Evaluation e;
  if (o.deformed.empty()) {
    if (o.frame) throw InputError("--frame needs --deformed").key("--frame");
    e = ev.reference();
  } else {
    atomistic::FrameNeeds needs;  // positions x y z and ids (matched with the body's atoms)
    needs.id = true;
    needs.operation = "pdcg forces --deformed";
    auto conf = bu::read_configurations(o.deformed, o.frame, "", nullptr, needs);
    Eigen::Matrix3d hy;
    const auto y = bu::deformed_positions(b, std::move(conf.front()), o.deformed, hy);
    e = ev.deformed(y, hy);
  }
  io::AtomicTextFile out(o.output);
  auto& s = out.stream();
  s << "id,fx,fy,fz\n";
  for (std::size_t i = 0; i < b.size(); ++i)
    s << fmt::format("{},{:.17g},{:.17g},{:.17g}\n", b.id[i], e.forces[3 * i], e.forces[3 * i + 1],
                     e.forces[3 * i + 2]);
  out.commit();
  std::fprintf(stderr, "%s: forces on %zu points, energy %.17g\n", o.output.c_str(), b.size(),
               e.energy);
  return 0;
}

pdcg::cli::Registration reg(110, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand("forces", "PD internal force per point (CSV id,fx,fy,fz)");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("--deformed", o->deformed, "Dump (or data file) with the same atom ids");
  sub->add_option("--frame", o->frame, "Frame of the deformed dump (default 0)");
  sub->add_option("-o,--output", o->output, "Output CSV")->required();
  sub->footer("Example:\n  pdcg forces body.h5 --deformed dump.lammpstrj -o forces.csv");
  return [o] { return run(*o); };
});

}  // namespace
