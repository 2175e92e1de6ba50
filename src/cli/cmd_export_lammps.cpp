/// `pdcg export-lammps BODY.h5 -o DIR [--prefix NAME] [--table-style spline|linear]
///   [--table-tolerance TOL] [--table-inner R] [--temperature T --seed S | --velocities DUMP]
///   [--dt DT] [--steps N]`: a (rescaled) pair or EAM body as LAMMPS input — data file with the
/// points, masses, box and initial velocities, a pair table or setfl file, the pair commands and
/// an input script running the explicit dynamics of `pdcg md` (docs/dynamics.md).
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <optional>

#include "command.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/dynamics/dynamics.hpp"
#include "pdcg/dynamics/lammps_export.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string body, output, prefix = "model", table_style = "spline", velocities, pair = "table";
  double table_tolerance = 1e-10, table_inner = 0.0;
  std::optional<double> temperature, dt;
  std::int64_t seed = 12345, steps = 0;
};

int run(const Options& o) {
  using namespace pdcg;
  dynamics::LammpsExportOptions eo;
  if (o.pair == "table")
    eo.pair_form = dynamics::PairForm::table;
  else if (o.pair == "native")
    eo.pair_form = dynamics::PairForm::native;
  else
    throw InputError("unknown pair form")
        .key("--pair")
        .value(o.pair)
        .expected("table (pair_style table) or native (lj/cut, morse with rescaled coefficients)");
  if (o.table_style == "spline")
    eo.table_style = dynamics::TableStyle::spline;
  else if (o.table_style == "linear")
    eo.table_style = dynamics::TableStyle::linear;
  else
    throw InputError("unknown table style")
        .key("--table-style")
        .value(o.table_style)
        .expected("spline or linear (LAMMPS pair_style table's interpolations)");
  if (!(o.table_tolerance > 0.0) || !std::isfinite(o.table_tolerance) || o.table_tolerance >= 1.0)
    throw InputError("bad table tolerance")
        .key("--table-tolerance")
        .value(fmt::format("{}", o.table_tolerance))
        .expected("a relative error in (0, 1), e.g. 1e-10");
  if (o.table_inner < 0.0 || !std::isfinite(o.table_inner))
    throw InputError("bad inner end of the tables")
        .key("--table-inner")
        .value(fmt::format("{}", o.table_inner))
        .expected("a positive distance (0 = 0.6 × the closest reference pair)");
  if (o.temperature && !o.velocities.empty())
    throw InputError("give one of --temperature and --velocities")
        .key("--temperature/--velocities");
  if (o.temperature && (!(*o.temperature >= 0.0) || !std::isfinite(*o.temperature)))
    throw InputError("bad temperature")
        .key("--temperature")
        .value(fmt::format("{}", *o.temperature))
        .expected("T >= 0");
  if (o.dt && (!(*o.dt > 0.0) || !std::isfinite(*o.dt)))
    throw InputError("bad time step")
        .key("--dt")
        .value(fmt::format("{}", *o.dt))
        .expected("a positive number");
  if (o.steps < 0)
    throw InputError("bad number of steps")
        .key("--steps")
        .value(std::to_string(o.steps))
        .expected("an integer >= 0");
  if (o.prefix.empty() || o.prefix.find('/') != std::string::npos)
    throw InputError("bad file prefix")
        .key("--prefix")
        .value(o.prefix)
        .expected("a file name without '/'");
  io::require_writable_directory(o.output, "-o/--output");  // before any computation

  const body::Body b = body::read_body(o.body);
  dynamics::check_exportable(b, o.body);
  dynamics::check_masses(b, o.body);
  std::vector<double> v;
  if (o.temperature)
    v = dynamics::thermal_velocities(b, *o.temperature, static_cast<std::uint64_t>(o.seed));
  else if (!o.velocities.empty())
    v = dynamics::velocities_from_atoms(b, atomistic::read_atoms(o.velocities, 0), o.velocities);
  const auto limit = dynamics::stable_time_step(b);
  eo.dt = o.dt ? *o.dt : 0.1 * limit.dt_stable;
  if (eo.dt > limit.dt_stable)
    std::fprintf(stderr,
                 "warning: --dt %g is above the stable limit %g of the body (docs/dynamics.md)\n",
                 eo.dt, limit.dt_stable);
  eo.steps = o.steps;
  eo.table_tolerance = o.table_tolerance;
  eo.table_inner = o.table_inner;
  eo.prefix = o.prefix;
  eo.command_line = "pdcg export-lammps " + o.body + " -o " + o.output;
  const auto ex = dynamics::export_lammps(b, v, o.output, eo, o.body);
  std::printf("pair_style %s\n", ex.pair_style.c_str());
  std::printf("closest reference pair %.9g\n", ex.closest_pair);
  for (const auto& t : ex.tables)
    std::printf(
        "table %s: types %d %d, r %.9g .. %.9g, %lld points, error F %.3g E %.3g (tolerance "
        "%.3g)\n",
        t.keyword.c_str(), t.type_i, t.type_j, t.r_lo, t.r_cut, static_cast<long long>(t.points),
        t.force_error, t.energy_error, o.table_tolerance);
  std::printf("atom types %zu, time step %.17g%s\n", ex.lammps_type_mass.size() - 1, eo.dt,
              o.dt ? "" : " (0.1 x the stable limit)");
  for (const auto& f : ex.files) std::printf("wrote %s\n", f.string().c_str());
  return 0;
}

pdcg::cli::Registration reg(155, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("export-lammps", "A pair or EAM body (rescaled or not) as LAMMPS input");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("-o,--output", o->output, "Output directory")->required();
  sub->add_option(
      "--prefix", o->prefix,
      "File names: PREFIX.data, .pair, .table or .eam.setfl, in.PREFIX (default model)");
  sub->add_option(
      "--pair", o->pair,
      "Pair potentials as: table (default; any native pairwise style) or native (lj/cut, morse "
      "with rescaled coefficients, exact)");
  sub->add_option("--table-style", o->table_style,
                  "pair_style table interpolation: spline (default) or linear");
  sub->add_option("--table-tolerance", o->table_tolerance,
                  "Interpolation error bound of forces and energies, relative (default 1e-10)");
  sub->add_option("--table-inner", o->table_inner,
                  "Inner end of the tables (default 0.6 x the closest reference pair)");
  sub->add_option("--temperature", o->temperature,
                  "Initial Gaussian velocities at T, as pdcg md --temperature");
  sub->add_option("--seed", o->seed, "Random seed for --temperature (default 12345)");
  sub->add_option("--velocities", o->velocities,
                  "Initial velocities: dump with vx vy vz and the body's ids");
  sub->add_option("--dt", o->dt, "Time step of the input script (default 0.1 x the stable limit)");
  sub->add_option("--steps", o->steps, "Steps of the input script (default 0; -var steps N)");
  sub->footer(
      "Writes DIR/PREFIX.data, DIR/PREFIX.pair, DIR/PREFIX.table (pair potentials) or\n"
      "DIR/PREFIX.eam.setfl (EAM), DIR/in.PREFIX. Run in DIR: lmp -in in.PREFIX -var steps 1000.\n"
      "Example:\n  pdcg export-lammps coarse.h5 -o lmp --temperature 0.1 --dt 0.005 --steps 1000");
  return [o] { return run(*o); };
});

}  // namespace
