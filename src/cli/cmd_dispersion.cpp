/// `pdcg dispersion`: measured dispersion of a trajectory (and, with a body file, the model's).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

#include "command.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/body/lattice.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/config.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"
#include "pdcg/core/progress.hpp"
#include "pdcg/core/units.hpp"
#include "pdcg/dispersion/body_dispersion.hpp"
#include "pdcg/dispersion/crystal.hpp"
#include "pdcg/dispersion/curves.hpp"
#include "pdcg/dispersion/plan.hpp"
#include "pdcg/dispersion/trajectory.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/io/png.hpp"

namespace {

struct Options {
  std::string body, direction, path, lattice, plot;
  double a = 0.0, kmax = 0.0;
  int nk = 50;
  long point = -1;
  bool cell = false, grid = false;
  std::string trajectory, axis = "x", component, frames = "0:-1", output, spectrum, compare;
  double dt = 0.0, resolution = 0.0;
  std::string window = "hann";
};

int axis_index(const std::string& s, const char* option) {
  if (s == "x") return 0;
  if (s == "y") return 1;
  if (s == "z") return 2;
  throw pdcg::InputError("unknown axis").key(option).value(s).expected("x, y or z");
}

using pdcg::dispersion::Curves;
using pdcg::dispersion::interpolate;
using pdcg::dispersion::read_curves;

int run_trajectory(const Options& o) {
  pdcg::atomistic::DumpReader reader(o.trajectory);
  const auto range = pdcg::parse_frame_range(o.frames, reader.nframes(), "--frames");
  const auto idx = range.indices();
  if (idx.size() < 4)
    throw pdcg::InputError("too few frames for a frequency spectrum")
        .source(o.trajectory)
        .key("--frames")
        .value(fmt::format("{} selects {} of {} frames", o.frames, idx.size(), reader.nframes()))
        .expected("at least 4 frames (Δω = 2π/(T·Δt) with T frames)")
        .fix("select more frames, or dump more often / run longer");
  // Frame interval: ITEM: TIME when the dump has it, else timestep difference × --dt.
  const auto& i0 = reader.info(idx[0]);
  const auto& i1 = reader.info(idx[1]);
  double interval = 0.0;
  if (std::isfinite(i0.time) && std::isfinite(i1.time) && i1.time > i0.time) {
    interval = i1.time - i0.time;
  } else {
    if (!(o.dt > 0))
      throw pdcg::InputError("the time between frames is unknown")
          .source(o.trajectory)
          .key("--dt")
          .expected("the MD time step (the dump has no ITEM: TIME)")
          .fix("pass --dt with the LAMMPS `timestep` value, or dump with `dump_modify time yes`");
    interval = static_cast<double>(i1.timestep - i0.timestep) * o.dt;
  }
  if (o.resolution > 0) {  // before reading the frames: the frame count and interval decide Δω
    const double dw = 2.0 * std::numbers::pi / (static_cast<double>(idx.size()) * interval);
    if (dw > o.resolution)
      throw pdcg::InputError("trajectory too short for the requested frequency resolution")
          .source(o.trajectory)
          .key("--resolution")
          .value(
              fmt::format("{} frames × Δt_frame {:.6g} give Δω = {:.4g}", idx.size(), interval, dw))
          .expected(fmt::format("Δω ≤ {:.4g}, i.e. at least {} frames", o.resolution,
                                static_cast<std::size_t>(
                                    std::ceil(2.0 * std::numbers::pi / (o.resolution * interval)))))
          .fix("run longer or dump more often (or ask for a coarser --resolution)");
  }
  for (std::size_t k = 1; k < idx.size(); ++k) {
    const auto step = reader.info(idx[k]).timestep - reader.info(idx[k - 1]).timestep;
    if (step != i1.timestep - i0.timestep)
      throw pdcg::InputError("frames are not evenly spaced in time")
          .source(o.trajectory)
          .key(fmt::format("frame {}", idx[k]))
          .value(fmt::format("timestep gap {}", step))
          .expected(fmt::format("the gap of the first two selected frames, {}",
                                i1.timestep - i0.timestep))
          .fix("select an evenly spaced range with --frames A:B:S");
  }
  // A trajectory along one axis needs the positions along that axis and the measured component
  // (a 1D chain dumped as `id xu vx` is enough along x); ids match atoms between frames.
  pdcg::atomistic::FrameNeeds needs;
  needs.position = {false, false, false};
  needs.position[static_cast<std::size_t>(axis_index(o.axis, "--axis"))] = true;
  needs.position[static_cast<std::size_t>(
      axis_index(o.component.empty() ? o.axis : o.component, "--component"))] = true;
  needs.id = true;
  needs.operation = "pdcg dispersion --trajectory";
  for (auto i : idx) reader.require(i, needs);  // before reading any frame
  std::vector<pdcg::atomistic::Atoms> frames;
  frames.reserve(idx.size());
  pdcg::Progress progress("frames", idx.size());
  for (auto i : idx) {
    frames.push_back(reader.frame(i, needs));
    progress.update(frames.size());
  }
  progress.finish();

  pdcg::dispersion::TrajectoryOptions topt;
  topt.axis = axis_index(o.axis, "--axis");
  topt.component = axis_index(o.component.empty() ? o.axis : o.component, "--component");
  topt.frame_interval = interval;
  topt.window =
      o.window == "none" ? pdcg::dispersion::Window::none : pdcg::dispersion::Window::hann;
  topt.min_resolution = o.resolution;
  topt.source = o.trajectory;
  const auto spectrum = pdcg::dispersion::measure(frames, topt);
  const auto ridge = pdcg::dispersion::ridge(spectrum);

  Curves ref;
  if (!o.compare.empty()) ref = read_curves(o.compare);
  double worst = 0.0, worst_k = 0.0;
  pdcg::io::AtomicTextFile csv(o.output);
  // units line (docs/formats.md): a dump carries no unit style; κ is in the inverse length of
  // its coordinates, ω in radians per time unit of the frame interval (ITEM: TIME or --dt)
  csv.stream() << "# pdcg dispersion --trajectory: kappa [1/length of the dump], omega, "
                  "resolution [rad per time unit of ITEM: TIME or --dt], power [arbitrary]\n";
  csv.stream() << "kappa,omega,power,resolution"
               << (o.compare.empty() ? "" : ",omega_ref,error,error_in_bins") << "\n";
  for (const auto& p : ridge) {
    csv.stream() << fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}", p.kappa, p.omega, p.power,
                                p.resolution);
    if (!o.compare.empty()) {
      // the reference branch nearest to the measured frequency
      double best = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t b = 0; b < ref.omega.size(); ++b) {
        const double w = interpolate(ref, b, p.kappa);
        if (std::isfinite(w) &&
            (!std::isfinite(best) || std::abs(w - p.omega) < std::abs(best - p.omega)))
          best = w;
      }
      const double err = p.omega - best;
      csv.stream() << fmt::format(",{:.17g},{:.17g},{:.6g}", best, err, err / p.resolution);
      if (std::isfinite(err) && std::abs(err) > std::abs(worst)) {
        worst = err;
        worst_k = p.kappa;
      }
    }
    csv.stream() << "\n";
  }
  csv.commit();
  std::printf("measured dispersion: %zu wavenumbers, %zu frames, Δω = %.6g -> %s\n", ridge.size(),
              idx.size(), spectrum.resolution, o.output.c_str());
  if (!o.compare.empty())
    std::printf("worst error against %s: %.6g at κ = %.6g (%.3g frequency bins)\n",
                o.compare.c_str(), worst, worst_k, worst / spectrum.resolution);
  if (!o.spectrum.empty()) {
    // image: κ to the right, ω upwards, up to 1.5× the highest ridge frequency; each κ a
    // column `sx` pixels wide so that short lattices still give a readable picture.
    double wmax = 0.0;
    for (const auto& p : ridge) wmax = std::max(wmax, p.omega);
    const int h =
        std::max(2, std::min(static_cast<int>(spectrum.nw),
                             static_cast<int>(std::ceil(1.5 * wmax / spectrum.resolution)) + 1));
    const int sx = std::max(1, 480 / static_cast<int>(spectrum.nk));
    const int sy = std::max(1, 320 / h);
    const int w = static_cast<int>(spectrum.nk) * sx, hp = h * sy;
    std::vector<double> img(static_cast<std::size_t>(w) * hp);
    for (int x = 0; x < w; ++x)
      for (int y = 0; y < hp; ++y)
        img[static_cast<std::size_t>(hp - 1 - y) * w + x] =
            spectrum.power[static_cast<std::size_t>(x / sx) * spectrum.nw +
                           static_cast<std::size_t>(y / sy)];
    pdcg::io::write_png_field(o.spectrum, w, hp, img, true);
    std::printf("power spectrum S(κ, ω) (log scale, κ → right, ω ↑) -> %s\n", o.spectrum.c_str());
  }
  return 0;
}

/// Path to a helper script, relative to the executable: <prefix>/share/pdcg for an installed
/// bin/pdcg, <build>/share/pdcg for the build tree's pdcg (copied there by CMake). Never the
/// source tree: an installed or moved pdcg must not depend on where it was built from.
std::string helper_script(const std::string& name) {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw pdcg::Error("cannot locate the pdcg executable (/proc/self/exe): " + ec.message());
  const auto dir = exe.parent_path();
  const std::filesystem::path candidates[] = {dir.parent_path() / "share" / "pdcg" / name,
                                              dir / "share" / "pdcg" / name};
  for (const auto& p : candidates)
    if (std::filesystem::exists(p)) return p.string();
  throw pdcg::Error(fmt::format("helper script {} not found (looked in {} and {}); reinstall pdcg",
                                name, candidates[0].parent_path().string(),
                                candidates[1].parent_path().string()));
}

void plot_csv(const std::string& csv, const std::string& png, const std::string& title) {
  const std::string script = helper_script("plot_dispersion.py");
  const std::string cmd =
      fmt::format("/usr/bin/python3 '{}' '{}' '{}' '{}'", script, csv, png, title);
  if (std::system(cmd.c_str()) != 0)
    throw pdcg::Error("plotting failed (needs /usr/bin/python3 with matplotlib): " + cmd);
}

Eigen::Vector3d parse_vector(const std::string& text, const char* option) {
  std::vector<double> v;
  std::stringstream ss(text);
  for (std::string t; std::getline(ss, t, ',');)
    v.push_back(pdcg::parse_double(pdcg::trim(t), {"", 0, option}));
  if (v.size() != 3 || Eigen::Vector3d(v[0], v[1], v[2]).norm() == 0.0)
    throw pdcg::InputError("a direction needs three components, not all zero")
        .key(option)
        .value(text)
        .expected("e.g. 1,0,0");
  return {v[0], v[1], v[2]};
}

/// First line of a model-dispersion CSV (docs/formats.md): the body's unit style and the unit
/// of every column. ω is an angular frequency, ω² = eigenvalue of the dynamical matrix
/// (mvv2e applied), in radians per time unit of the style.
std::string units_line(const pdcg::body::Body& body) {
  const auto un = pdcg::unit_names(body.units);
  return fmt::format(
      "# pdcg dispersion: units {}; kappa, kx, ky, kz [{}], omega* [{}] (angular frequency{})\n",
      pdcg::to_string(body.units), un.wavenumber, un.frequency,
      body.units == pdcg::UnitStyle::lj ? "; reduced units" : "");
}

/// --plot: /usr/bin/python3 must have matplotlib — checked before any computation (the PNG's
/// directory is checked, and created when missing, by require_writable_output in the runner).
void check_plot_target(const std::string& png) {
  if (png.empty()) return;
  if (std::system("/usr/bin/python3 -c 'import matplotlib' > /dev/null 2>&1") != 0)
    throw pdcg::InputError("--plot needs /usr/bin/python3 with matplotlib")
        .key("--plot")
        .value(png)
        .expected("python3 -c 'import matplotlib' to work")
        .fix("apt-get install python3-matplotlib, or drop --plot and plot the CSV yourself");
}

/// One-point dispersion (--direction, --path, --grid without --cell) linearises one atom with
/// its family as the whole cell: right for a Bravais lattice only. A crystal with a basis gets
/// 3 of its 3n branches (no optical branches; acoustic ones of atoms moving without their basis
/// partners): a warning, or — when --path would guess the lattice from the neighbour shell (hcp
/// looks like fcc) — a refusal. Runs before the model is linearised (seconds for big families).
int run_grid(const Options& o) {
  if (!o.plot.empty() || !o.compare.empty())
    throw pdcg::InputError("--grid writes the whole κ-grid; it has no curve to plot or compare")
        .key(o.plot.empty() ? "--compare" : "--plot")
        .expected("--grid without --plot and --compare")
        .fix("use --direction or --path for curves");
  const pdcg::body::Body body = pdcg::body::read_body(o.body);
  pdcg::dispersion::check_one_point_lattice(body, o.cell, "--grid", !o.lattice.empty() && o.a > 0,
                                            o.body);
  const pdcg::dispersion::BodyDispersion model(
      body,
      o.point >= 0 ? std::optional<std::size_t>(static_cast<std::size_t>(o.point)) : std::nullopt,
      o.cell);
  const auto g = model.grid();
  pdcg::io::AtomicTextFile csv(o.output);
  csv.stream() << units_line(body) << "kappa,omega_1,omega_2,omega_3,kx,ky,kz\n";
  double wmin = 0.0;
  for (std::size_t i = 0; i < g.kappa.size(); ++i) {
    const auto& k = g.kappa[i];
    const auto& w = g.omega[i];
    wmin = std::min(wmin, w.minCoeff());
    csv.stream() << fmt::format("{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g},{:.17g}\n",
                                k.norm(), w[0], w[1], w[2], k[0], k[1], k[2]);
  }
  csv.commit();
  std::printf("model dispersion of %s on the κ-grid %d×%d×%d of the periodic box (one FFT) -> %s\n",
              model.description().c_str(), g.size[0], g.size[1], g.size[2], o.output.c_str());
  if (wmin < 0)
    std::printf(
        "warning: unstable modes (ω² < 0, written as −√|ω²|): the reference configuration is not a "
        "minimum\n");
  return 0;
}

int run_model(const Options& o) {
  if (o.grid) {
    if (!o.direction.empty() || !o.path.empty())
      throw pdcg::InputError("give one of --direction, --path and --grid")
          .key(o.direction.empty() ? "--path and --grid" : "--direction and --grid")
          .expected("--direction 1,0,0, --path G-X-L or --grid");
    return run_grid(o);
  }
  if (o.direction.empty() == o.path.empty())
    throw pdcg::InputError("give exactly one of --direction, --path and --grid")
        .key(o.direction.empty() ? "--direction/--path/--grid" : "--direction and --path")
        .expected("--direction 1,0,0, --path G-X-L or --grid");
  if (o.nk < 1)
    throw pdcg::InputError("--nk must be at least 1").key("--nk").value(std::to_string(o.nk));
  check_plot_target(o.plot);
  const pdcg::body::Body body = pdcg::body::read_body(o.body);
  pdcg::dispersion::DispersionRequest request;
  request.path = o.path;
  if (o.path.empty()) {
    request.direction = parse_vector(o.direction, "--direction").normalized();
    request.direction_text = o.direction;
  }
  request.nk = o.nk;
  request.kmax = o.kmax;
  request.lattice = o.lattice;
  request.a = o.a;
  if (o.point >= 0) request.point = static_cast<std::size_t>(o.point);
  request.cell = o.cell;
  request.source = o.body;
  // the selection (crystal with a basis, one point, --cell) and its checks: dispersion/plan.hpp
  const auto plan = pdcg::dispersion::plan_dispersion(body, request);
  const auto& ks = plan.kappa;
  auto omega = [&](const Eigen::Vector3d& k) -> Eigen::VectorXd { return plan.omega(k); };
  const std::string description = plan.description();
  Curves ref;
  if (!o.compare.empty()) ref = read_curves(o.compare);
  pdcg::io::AtomicTextFile csv(o.output);
  const auto first = omega(ks[0].second);
  const auto nb = static_cast<std::size_t>(first.size());
  csv.stream() << units_line(body);
  if (!plan.labels.empty()) {
    // second comment line: the path's labelled corners at their kappa (path length)
    csv.stream() << "# path labels:";
    for (const auto& [s, label] : plan.corners())
      csv.stream() << fmt::format(" {}@{:.17g}", label, s);
    csv.stream() << "\n";
  }
  csv.stream() << "kappa";
  for (std::size_t b = 0; b < nb; ++b) csv.stream() << ",omega_" << b + 1;
  csv.stream() << ",kx,ky,kz";
  for (std::size_t j = 0; j < ref.omega.size(); ++j)
    csv.stream() << ",omega_ref_" << j + 1 << ",error_" << j + 1;
  csv.stream() << "\n";
  double worst = 0.0, worst_k = 0.0, wmin = 0.0;
  for (const auto& [s, k] : ks) {
    const Eigen::VectorXd w = omega(k);
    wmin = std::min(wmin, w.minCoeff());
    csv.stream() << fmt::format("{:.17g}", s);
    for (Eigen::Index b = 0; b < w.size(); ++b) csv.stream() << fmt::format(",{:.17g}", w[b]);
    csv.stream() << fmt::format(",{:.17g},{:.17g},{:.17g}", k[0], k[1], k[2]);
    for (std::size_t j = 0; j < ref.omega.size(); ++j) {
      const double r = interpolate(ref, j, s);
      double best = std::numeric_limits<double>::quiet_NaN();
      for (Eigen::Index b = 0; b < w.size(); ++b)
        if (!std::isfinite(best) || std::abs(w[b] - r) < std::abs(best - r)) best = w[b];
      const double err = best - r;
      csv.stream() << fmt::format(",{:.17g},{:.17g}", r, err);
      if (std::isfinite(err) && std::abs(err) > std::abs(worst)) {
        worst = err;
        worst_k = s;
      }
    }
    csv.stream() << "\n";
  }
  csv.commit();
  std::printf("model dispersion of %s: %zu κ points, %zu branches -> %s\n", description.c_str(),
              ks.size(), nb, o.output.c_str());
  if (wmin < 0)
    std::printf(
        "warning: unstable modes (ω² < 0, written as −√|ω²|): the reference configuration is not a "
        "minimum\n");
  if (!o.compare.empty())
    std::printf("worst error against %s: %.6g at κ = %.6g\n", o.compare.c_str(), worst, worst_k);
  if (!o.plot.empty()) {
    plot_csv(o.output, o.plot, description);
    std::printf("plot -> %s\n", o.plot.c_str());
  }
  return 0;
}

pdcg::cli::Registration reg(400, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand(
      "dispersion",
      "Dispersion ω(κ) of a body (model) or of a trajectory (measured), compared with a reference");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "pdcg body file (model dispersion)");
  sub->add_option("--direction", o->direction, "Model: wave direction, e.g. 1,0,0");
  sub->add_option("--path", o->path,
                  "Model: high-symmetry path, e.g. G-X-W-K-G-L ('|' for a jump), or auto; a "
                  "crystal with a basis gets all 3n branches of its primitive cell");
  sub->add_option("--nk", o->nk, "Model: κ points per direction or path segment (default 50)");
  sub->add_option("--kmax", o->kmax, "Model, --direction: largest |κ| (default: zone edge)");
  sub->add_option("--lattice", o->lattice,
                  "Model: fcc, bcc, sc, hex or chain (default: from the neighbour shell)");
  sub->add_option("--a", o->a,
                  "Model: lattice constant for --path (default: from the neighbour shell)");
  sub->add_option("--point", o->point,
                  "Model: atom / homogenised point index (default: nearest the box centre)");
  sub->add_flag(
      "--grid", o->grid,
      "Model: every κ commensurate with the periodic box at once (FFTW); CSV kappa = |κ|");
  sub->add_flag("--cell", o->cell,
                "Model: all atoms of the periodic body as a basis (3N folded branches)");
  sub->add_option("--plot", o->plot, "Model: PNG plot of the curves (matplotlib)");
  sub->add_option("--trajectory", o->trajectory,
                  "Measured: LAMMPS dump (text or .gz) of a periodic lattice");
  sub->add_option("--axis", o->axis, "Measured: wave direction x, y or z (a lattice direction)");
  sub->add_option("--component", o->component,
                  "Measured: displacement component (default: the axis)");
  sub->add_option("--frames", o->frames,
                  "Measured: frames A:B[:S] (inclusive, 0-based, negative from the end)");
  sub->add_option("--dt", o->dt, "Measured: MD time step, when the dump has no ITEM: TIME");
  sub->add_option("--resolution", o->resolution,
                  "Measured: refuse trajectories whose Δω is coarser");
  sub->add_option("--window", o->window, "Measured: time window hann (default) or none")
      ->check(CLI::IsMember({"hann", "none"}));
  sub->add_option("-o,--output", o->output,
                  "CSV: model kappa,omega_1..omega_n,kx,ky,kz (--path: a '# path labels:' line); "
                  "measured kappa,omega,power,resolution; "
                  "--compare adds reference and error columns")
      ->required();
  sub->add_option("--spectrum", o->spectrum, "Measured: PNG image of the power spectrum S(κ, ω)");
  sub->add_option("--compare", o->compare, "CSV with kappa and omega… columns to compare with");
  sub->footer(
      "Examples:\n"
      "  pdcg dispersion body.h5 --path G-X-K-G-L --nk 40 -o disp.csv --plot disp.png\n"
      "  pdcg dispersion si.h5 --path auto -o si.csv      (diamond: 6 branches)\n"
      "  pdcg dispersion chain.h5 --direction 1,0,0 -o model.csv\n"
      "  pdcg dispersion body.h5 --grid -o grid.csv\n"
      "  pdcg dispersion --trajectory chain.dump --axis x --dt 0.01 -o measured.csv --compare "
      "model.csv\n"
      "Model: eigenvalues of the dynamical matrix of the linearised body at one point (or cell);\n"
      "--path on a crystal with a basis: its primitive cell (3n branches).\n"
      "Measured: lattice planes normal to the axis, space–time FFT (FFTW), ridge of peak power per "
      "κ.");
  return [o] {
    if (o->body.empty() == o->trajectory.empty())
      throw pdcg::InputError("give either a body file (model) or --trajectory (measured), not both")
          .key("pdcg dispersion")
          .expected("pdcg dispersion BODY.h5 … or pdcg dispersion --trajectory DUMP …");
    // before any computation
    pdcg::io::require_writable_output(o->output, "--output");
    if (!o->spectrum.empty()) pdcg::io::require_writable_output(o->spectrum, "--spectrum");
    if (!o->plot.empty()) pdcg::io::require_writable_output(o->plot, "--plot");
    return o->body.empty() ? run_trajectory(*o) : run_model(*o);
  };
});

}  // namespace
