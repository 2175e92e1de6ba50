/// `pdcg atoms2pd --input FILE [--frame N | --frames A:B[:S]] --potential FILE
///   --density delta|statistical [--statistics gaussian|empirical] [--order N | --samples N]
///   [--width W] [--dimension D] [--boundary "p p f"] -o body.h5`
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
#include "pdcg/body/model_file.hpp"
#include "pdcg/body/statistics.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string input, potential, density = "delta", statistics = "gaussian", frames, output,
                                boundary;
  std::optional<std::int64_t> frame, samples;
  std::optional<int> order;
  std::optional<double> width, family_cutoff;
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
  if (!statistical && (o.order || o.samples || o.width || !o.frames.empty()))
    throw InputError("--order, --samples, --width and --frames belong to statistical densities")
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
  // per-type-pair tables hold (ntypes+1)² entries per coefficient: 10⁴ types are 10⁸
  constexpr int kMaxTypes = 10000;
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
  body::DeltaBodyOptions opt;
  opt.dimension = o.dimension;
  opt.source = o.input;
  opt.periodicity_assumed = periodicity.assumed;
  if (o.family_cutoff) {
    if (!(*o.family_cutoff >= pot->cutoff()))
      throw InputError("family cutoff below the potential's cutoff")
          .source("--family-cutoff")
          .value(fmt::format("{}", *o.family_cutoff))
          .expected(fmt::format("at least the potential cutoff {}", pot->cutoff()))
          .fix("omit --family-cutoff, or give the cutoff plus a skin");
    opt.cutoff = *o.family_cutoff;
  }
  body::Body b = body::make_delta_body(ref, pot, spec, opt);
  b.potential_files = body::embed_potential_files(b.potential_spec);
  b.provenance.back() += fmt::format(" (potential {}, {})", o.potential, pdcg::command_line());
  if (statistical) {
    body::Statistics s;
    if (o.statistics == "empirical") {
      s = body::empirical_from_frames(b, frames);
    } else if (o.width) {
      if (frames.size() > 1)
        throw InputError("give --width or several frames, not both").key("--width");
      s = body::isotropic_gaussian(b, *o.width);
    } else {
      if (frames.size() < 2)
        throw InputError("gaussian densities need a width or several frames")
            .key("--statistics gaussian")
            .fix("give --frames A:B (mean and covariance per atom) or --width W (isotropic)");
      s = body::gaussian_from_frames(b, frames);
    }
    if (o.samples) {
      s.method = body::Statistics::Method::sampling;
      s.samples = *o.samples;
    } else {
      s.method =
          pot->pairwise() ? body::Statistics::Method::cubature : body::Statistics::Method::sampling;
      if (o.order) s.order = *o.order;
      if (o.order && !pot->pairwise())
        throw InputError("Gauss–Hermite cubature needs a pair potential")
            .key("--order")
            .value(pot->style())
            .fix("use --samples N for many-body potentials");
    }
    if (frames.size() > 1) {
      // families of the mean configuration (not of the first frame): rebuild the delta body at
      // the means the statistics moved the points to
      atomistic::Atoms mean = ref;
      atomistic::sort_by_id(mean, o.input);
      mean.x = b.x;
      auto files = std::move(b.potential_files);
      auto prov = std::move(b.provenance);
      b = body::make_delta_body(mean, pot, spec, opt);
      b.potential_files = std::move(files);
      b.provenance = std::move(prov);
      b.provenance.push_back(
          fmt::format("families rebuilt at the mean positions of {} frames", frames.size()));
    }
    body::make_statistical(b, std::move(s));
  }
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
