/// `pdcg md BODY.h5 --steps N --dt DT [--temperature T --seed S | --velocities DUMP]
///   [--dump FILE --every K] [--thermo CSV] [--force-unstable] [--kernels auto|general]`:
/// explicit dynamics of a body's points (fixed-family MD for a delta body; the coarse
/// surrogate for a rescaled one), velocity
/// Verlet in the order of LAMMPS fix nve (docs/dynamics.md). Starts at the body's reference
/// positions. Refuses dt above the Gershgorin stable limit 2/ω_bound unless --force-unstable.
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include "command.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/dynamics/dynamics.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string body, velocities, dump, thermo;
  std::int64_t steps = -1, every = 0, thermo_every = 1, seed = 12345;
  std::optional<double> temperature;
  double dt = 0.0;
  bool force_unstable = false;
  std::string kernels = "auto";
};

int run(const Options& o) {
  using namespace pdcg;
  if (o.steps < 0)
    throw InputError("bad number of steps").key("--steps").value(std::to_string(o.steps)).expected("an integer >= 0");
  if (!(o.dt > 0.0) || !std::isfinite(o.dt))
    throw InputError("bad time step").key("--dt").value(fmt::format("{}", o.dt)).expected("a positive number");
  if (o.temperature && !o.velocities.empty())
    throw InputError("give one of --temperature and --velocities").key("--temperature/--velocities");
  if (!o.dump.empty() && o.every < 1)
    throw InputError("--dump needs --every K (K >= 1)").key("--every").value(std::to_string(o.every)).expected("K >= 1");
  if (o.dump.empty() && o.every != 0) throw InputError("--every needs --dump FILE").key("--every");
  if (o.thermo_every < 1)
    throw InputError("bad thermo interval").key("--thermo-every").value(std::to_string(o.thermo_every)).expected(">= 1");
  if (o.kernels != "auto" && o.kernels != "general")
    throw InputError("bad force kernel choice").key("--kernels").value(o.kernels).expected("auto or general");
  // before any computation
  if (!o.dump.empty()) io::require_writable_output(o.dump, "--dump");
  if (!o.thermo.empty()) io::require_writable_output(o.thermo, "--thermo");
  if (o.temperature && (!(*o.temperature >= 0.0) || !std::isfinite(*o.temperature)))
    throw InputError("bad temperature").key("--temperature").value(fmt::format("{}", *o.temperature)).expected("T >= 0");

  const body::Body b = body::read_body(o.body);
  dynamics::check_masses(b, o.body);
  std::vector<double> v;
  if (o.temperature) {
    v = dynamics::thermal_velocities(b, *o.temperature, static_cast<std::uint64_t>(o.seed));
  } else if (!o.velocities.empty()) {
    v = dynamics::velocities_from_atoms(b, atomistic::read_atoms(o.velocities, 0), o.velocities);
  }
  const auto limit = dynamics::stable_time_step(b);
  dynamics::require_stable_time_step(o.dt, limit, o.force_unstable);
  if (o.dt > limit.dt_stable)
    std::fprintf(stderr, "warning: dt = %g is %.3g× the stable limit %g (--force-unstable)\n", o.dt,
                 o.dt / limit.dt_stable, limit.dt_stable);
  std::fprintf(stderr, "md: %zu points, %s body, dt = %g (stable limit %.6g, ω_bound %.6g)\n", b.size(),
               std::string(body::to_string(b.kind)).c_str(), o.dt, limit.dt_stable, limit.omega_bound);

  dynamics::VelocityVerlet vv(b, b.x, std::move(v), o.dt,
                              o.kernels == "general" ? dynamics::Kernels::general : dynamics::Kernels::automatic);
  std::optional<dynamics::DumpWriter> dump;
  std::optional<io::AtomicTextFile> thermo;
  auto write_thermo = [&] {
    if (!thermo) return;
    const auto t = vv.thermo();
    thermo->stream() << fmt::format("{},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n", t.step, t.time, t.kinetic, t.potential,
                                    t.total, t.temperature);
  };
  if (!o.dump.empty()) {
    dump.emplace(o.dump);
    dump->write(b, 0, vv.positions(), vv.velocities());
  }
  if (!o.thermo.empty()) {
    thermo.emplace(o.thermo);
    thermo->stream() << "step,time,kinetic,potential,total,temperature\n";
    write_thermo();
  }
  const auto t0 = vv.thermo();
  const auto start = std::chrono::steady_clock::now();
  for (std::int64_t s = 1; s <= o.steps; ++s) {
    const bool report = thermo && s % o.thermo_every == 0;
    vv.step(report);  // energies only on thermo steps, as LAMMPS
    if (report) write_thermo();
    if (dump && s % o.every == 0) dump->write(b, s, vv.positions(), vv.velocities());
    if (!std::isfinite(vv.positions()[0]))
      throw NumericalError(fmt::format("positions are not finite at step {}: the time step {} is too large (stable limit {:.6g})",
                                       s, o.dt, limit.dt_stable));
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (dump) dump->commit();
  if (thermo) thermo->commit();
  const auto t1 = vv.thermo();
  std::fprintf(stderr,
               "md: %lld steps in %.3f s, %.4g atom-steps/s; energy %.12g -> %.12g (relative change %.3g)\n",
               static_cast<long long>(o.steps), wall,
               wall > 0 ? static_cast<double>(b.size()) * static_cast<double>(o.steps) / wall : 0.0, t0.total, t1.total,
               t0.total != 0 ? (t1.total - t0.total) / std::abs(t0.total) : 0.0);
  return 0;
}

pdcg::cli::Registration reg(150, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand("md", "Explicit dynamics of a body (velocity Verlet, fixed families)");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("--steps", o->steps, "Number of steps")->required();
  sub->add_option("--dt", o->dt, "Time step (time units of the body's unit style)")->required();
  sub->add_option("--temperature", o->temperature, "Initial Gaussian velocities at temperature T");
  sub->add_option("--seed", o->seed, "Random seed for --temperature (default 12345)");
  sub->add_option("--velocities", o->velocities, "Initial velocities: dump with vx vy vz and the body's ids (frame 0)");
  sub->add_option("--dump", o->dump, "LAMMPS text dump of the trajectory (id type x y z ix iy iz vx vy vz)");
  sub->add_option("--every", o->every, "Dump every K steps");
  sub->add_option("--thermo", o->thermo, "CSV step,time,kinetic,potential,total,temperature");
  sub->add_option("--thermo-every", o->thermo_every, "Thermo every K steps (default 1)");
  sub->add_flag("--force-unstable", o->force_unstable, "Run even when dt exceeds the stable limit");
  sub->add_option("--kernels", o->kernels,
                  "Force evaluation: auto (the dedicated pair, EAM or many-body kernel where one exists) or "
                  "general (the body's general evaluator; for checks and benchmarks)");
  sub->footer(
      "Initial velocities are zero unless --temperature or --velocities is given.\n"
      "Example:\n  pdcg md body.h5 --steps 1000 --dt 0.005 --temperature 0.1 --dump run.dump --every 10 "
      "--thermo thermo.csv");
  return [o] { return run(*o); };
});

}  // namespace
