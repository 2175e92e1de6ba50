/// `pdcg atoms2pd --input FILE [--frame N | --frames A:B[:S]] --potential FILE
///   --density delta|statistical [--statistics gaussian|empirical] [--order N | --samples N]
///   [--width W | --temperature T] [--dimension D] [--boundary "p p f"] -o body.h5`
/// Builds a PD body from atoms (docs/theory.md §1–2). Periodicity: --boundary, else the
/// commands file's `boundary`, else the dump header, else (data file) LAMMPS's default p p p,
/// checked for overlapping images (docs/atomistic-input.md, "Periodicity").
#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

#include "body_cli_util.hpp"
#include "command.hpp"
#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/build.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string input, potential, density = "delta", statistics = "gaussian", frames, output,
                                boundary;
  std::optional<std::int64_t> frame, samples;
  std::optional<int> order;
  std::optional<double> width, temperature, family_cutoff;
  int dimension = 3;
};

int run(const Options& o) {
  using namespace pdcg;
  namespace bu = cli::body_util;
  io::require_writable_output(o.output, "--output");  // before any computation
  if (o.density != "delta" && o.density != "statistical")
    throw InputError("unknown density")
        .source("--density")
        .value(o.density)
        .expected("delta or statistical");
  if (o.statistics != "gaussian" && o.statistics != "empirical")
    throw InputError("unknown statistics")
        .source("--statistics")
        .value(o.statistics)
        .expected("gaussian or empirical");
  const bool statistical = o.density == "statistical";
  if (!statistical && (o.order || o.samples || o.width || o.temperature || !o.frames.empty()))
    throw InputError(
        "--order, --samples, --width, --temperature and --frames belong to statistical densities")
        .source("--density")
        .value("delta")
        .fix("add --density statistical, or drop those options");
  if (o.order && o.samples)
    throw InputError("give one of --order and --samples").key("--order/--samples");
  std::string dump_units;
  atomistic::FrameNeeds needs;  // positions x y z, types; ids to match atoms across frames
  needs.type = true;
  needs.id = !o.frames.empty();
  needs.operation = "pdcg atoms2pd";
  std::vector<atomistic::Atoms> frames =
      bu::read_configurations(o.input, o.frame, o.frames, &dump_units, needs);
  atomistic::Atoms& ref = frames.front();
  int ntypes = ref.ntypes;
  constexpr int kMaxTypes = atomistic::kMaxAtomTypes;  // per-type-pair tables grow as types²
  if (ntypes > kMaxTypes)
    throw InputError("too many atom types declared")
        .source(o.input)
        .key("atom types")
        .value(std::to_string(ntypes))
        .expected(fmt::format("at most {} types (per-type-pair tables grow as types²)", kMaxTypes))
        .fix("declare only the types the configuration uses (`N atom types` of the data file)");
  if (ntypes == 0 && !ref.type.empty()) {
    // a dump does not declare its type count: the largest type stands for it
    const auto top = std::max_element(ref.type.begin(), ref.type.end());
    ntypes = *top;
    if (ntypes > kMaxTypes)
      throw InputError("atom type too large for a dump without a declared type count")
          .source(o.input)
          .key(fmt::format("type of atom id {}",
                           ref.id[static_cast<std::size_t>(top - ref.type.begin())]))
          .value(std::to_string(ntypes))
          .expected(fmt::format("types numbered 1..N with N <= {} (LAMMPS numbers types 1..N)",
                                kMaxTypes))
          .fix("renumber the types (LAMMPS `set type`), or give a data file");
  }
  atomistic::PotentialSpec spec = atomistic::read_potential_commands(o.potential, ntypes);
  const bu::Periodicity periodicity =
      bu::resolve_periodicity(o.input, ref.box.periodic, spec, o.boundary);
  for (auto& f : frames) f.box.periodic = periodicity.periodic;
  if (!dump_units.empty() && dump_units != to_string(spec.units))
    throw InputError("the dump and the potential use different units")
        .source(o.input)
        .key("ITEM: UNITS")
        .value(dump_units)
        .expected(fmt::format("'{}' (the `units` of {})", to_string(spec.units), o.potential))
        .fix("use the potential file the trajectory was produced with");
  atomistic::take_type_charges(spec, ref);  // data-file charges for embedded LAMMPS, per type
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  body::BodyRequest request;
  request.delta.dimension = o.dimension;
  request.delta.source = o.input;
  request.delta.periodicity_assumed = periodicity.assumed;
  request.family_cutoff = o.family_cutoff;
  if (statistical) request.statistics = o.statistics;
  request.width = o.width;
  request.temperature = o.temperature;
  request.order = o.order;
  request.samples = o.samples;
  request.provenance = fmt::format(" (potential {}, {})", o.potential, pdcg::command_line());
  request.spelling = body::OptionSpelling::command_line;
  const body::Body b = body::build_body(frames, pot, spec, request);
  body::write_body(b, o.output);
  std::printf("%s: %s body, %zu points, %zu bonds, horizon %.10g, potential %s\n", o.output.c_str(),
              std::string(body::to_string(b.kind)).c_str(), b.size(), b.families.bonds(),
              b.horizon(), pot->style().c_str());
  return 0;
}

pdcg::cli::Registration reg(100, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand("atoms2pd", "Build a peridynamic body from atoms and a potential");
  auto o = std::make_shared<Options>();
  sub->add_option("--input", o->input, "LAMMPS dump or data file")->required();
  sub->add_option("--frame", o->frame,
                  "Frame of a dump (0-based; negative from the end; default 0)");
  sub->add_option(
      "--frames", o->frames,
      "Frames A:B[:S] for statistical densities (B inclusive, 0-based, negative from the end)");
  sub->add_option("--potential", o->potential, "LAMMPS commands defining the interaction")
      ->required();
  sub->add_option("--density", o->density, "delta | statistical (default delta)");
  sub->add_option("--statistics", o->statistics, "gaussian | empirical (default gaussian)");
  sub->add_option("--order", o->order, "Gauss–Hermite points per dimension (pair potentials)");
  sub->add_option("--samples", o->samples, "Samples for the expected energy (any potential)");
  sub->add_option("--width", o->width, "Isotropic Gaussian width (one frame)");
  sub->add_option("--temperature", o->temperature,
                  "Gaussian widths of a local-harmonic (Einstein) estimate at T (one relaxed "
                  "frame; T in the unit style's temperature unit: k_B T/epsilon in lj, K in "
                  "metal and real; docs/temperature.md)");
  sub->add_option(
      "--family-cutoff", o->family_cutoff,
      "Family radius (default: the potential cutoff); a skin keeps pairs that come within the "
      "cutoff in deformed configurations");
  sub->add_option("--dimension", o->dimension, "Dimension of the body (1, 2, 3; default 3)");
  sub->add_option("--boundary", o->boundary,
                  "Periodicity x y z as LAMMPS's boundary command, e.g. \"p p f\" (p periodic; "
                  "f, s, m free); wins over a boundary command and the dump header");
  sub->add_option("-o,--output", o->output, "Output model file")->required();
  sub->footer(
      "Examples:\n  pdcg atoms2pd --input dump.lammpstrj --frame 0 --potential lj.in --density "
      "delta -o body.h5\n"
      "  pdcg atoms2pd --input dump.lammpstrj --frames 10:59 --potential lj.in --density "
      "statistical --order 4 -o stat.h5");
  return [o] { return run(*o); };
});

}  // namespace
