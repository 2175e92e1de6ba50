/// `pdcg forces BODY.h5 [--deformed DUMP [--frame N]] -o forces.csv`: PD internal force per point,
/// f_k = Σ_j (t_kj − t_jk), at the reference configuration or at the positions of a dump with
/// the same atom ids. CSV: a `# pdcg forces: units …` line, then `id,fx,fy,fz,pe` (pe = ψ_k, the
/// per-atom energy, LAMMPS's compute pe/atom). Warns when the frame brings pairs within the
/// potential cutoff that the fixed families miss.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "body_cli_util.hpp"
#include "command.hpp"
#include "pdcg/body/lattice.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/units.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string body, deformed, output;
  std::optional<std::int64_t> frame;
};

/// Fixed families: warn when the frame brings pairs within the potential cutoff that are not
/// bonds of the body (their interaction is missing), with the --family-cutoff that keeps them.
void warn_missing_pairs(const pdcg::body::Body& b, const std::vector<double>& y,
                        const pdcg::atomistic::Box& box, const std::string& source) {
  const auto c = pdcg::body::check_families(b, y, box);
  if (c.missing == 0) return;
  // rescaled bodies: the atoms2pd option is in the unrescaled lengths (family radius / ε)
  const double need = c.needed_cutoff / b.epsilon;
  pdcg::log::warn(
      "{}: {} atom pairs are within the potential cutoff {:.6g} in this frame but not in the "
      "body's families (family radius {:.6g}: the reference neighbours), so their interaction "
      "is missing from the forces and energy (e.g. ids {} and {}, {:.6g} apart in the "
      "reference; largest bond length change {:.6g}). Fix: rebuild the body with `pdcg "
      "atoms2pd … --family-cutoff {:.6g}` (or larger){}",
      source, c.missing, c.cutoff, c.family_cutoff, c.example_k, c.example_j, c.needed_cutoff,
      c.max_stretch, std::ceil(need * 1.01 * 1e4) / 1e4,
      b.kind == pdcg::body::BodyKind::delta ? "" : ", then repeat the coarse-graining steps");
}

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
    const atomistic::Box frame_box = conf.front().box;
    Eigen::Matrix3d hy;
    const auto y = bu::deformed_positions(b, std::move(conf.front()), o.deformed, hy);
    e = ev.deformed(y, hy);
    warn_missing_pairs(b, y, frame_box, o.deformed);
  }
  const UnitNames un = unit_names(b.units);
  io::AtomicTextFile out(o.output);
  auto& s = out.stream();
  // units line first (docs/formats.md: CSV files); pe = ψ_k, LAMMPS's compute pe/atom
  s << fmt::format("# pdcg forces: units {}; fx,fy,fz [{}], pe [{}] (per-atom energy psi_k)\n",
                   to_string(b.units), un.force, un.energy);
  s << "id,fx,fy,fz,pe\n";
  for (std::size_t i = 0; i < b.size(); ++i)
    s << fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g}\n", b.id[i], e.forces[3 * i],
                     e.forces[3 * i + 1], e.forces[3 * i + 2], e.psi[i]);
  out.commit();
  std::fprintf(stderr, "%s: forces on %zu points, energy %.17g %s (units %s)\n", o.output.c_str(),
               b.size(), e.energy, std::string(un.energy).c_str(),
               std::string(to_string(b.units)).c_str());
  return 0;
}

pdcg::cli::Registration reg(110, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("forces", "PD internal force and energy per point (CSV id,fx,fy,fz,pe)");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("--deformed", o->deformed, "Dump (or data file) with the same atom ids");
  sub->add_option("--frame", o->frame, "Frame of the deformed dump (default 0)");
  sub->add_option("-o,--output", o->output, "Output CSV")->required();
  sub->footer("Example:\n  pdcg forces body.h5 --deformed dump.lammpstrj -o forces.csv");
  return [o] { return run(*o); };
});

}  // namespace
