/// `pdcg dispersion`: measured dispersion of a trajectory (and, with a body file, the model's).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "command.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"
#include "pdcg/core/progress.hpp"
#include "pdcg/dispersion/trajectory.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/io/png.hpp"

namespace {

struct Options {
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

/// Reference curves: a CSV with a `kappa` column and one or more `omega…` columns.
struct Curves {
  std::vector<double> kappa;
  std::vector<std::vector<double>> omega;  // per branch
};

Curves read_curves(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw pdcg::InputError("cannot open comparison file").key("--compare").value(path).expected("a CSV file");
  std::string line;
  long lineno = 1;
  if (!std::getline(in, line)) throw pdcg::InputError("empty comparison file").source(path);
  std::vector<std::string> header;
  std::stringstream hs(line);
  for (std::string h; std::getline(hs, h, ',');) header.push_back(std::string(pdcg::trim(h)));
  int kcol = -1;
  std::vector<int> wcols;
  for (std::size_t c = 0; c < header.size(); ++c) {
    if (header[c] == "kappa") kcol = static_cast<int>(c);
    if (header[c].rfind("omega", 0) == 0 && header[c].find("ref") == std::string::npos) wcols.push_back(static_cast<int>(c));
  }
  if (kcol < 0 || wcols.empty())
    throw pdcg::InputError("comparison file lacks the columns it needs")
        .source(path)
        .line(1)
        .value(line)
        .expected("a header with `kappa` and at least one `omega…` column")
        .fix("use a CSV written by `pdcg dispersion`");
  Curves c;
  c.omega.resize(wcols.size());
  while (std::getline(in, line)) {
    ++lineno;
    if (pdcg::trim(line).empty()) continue;
    std::vector<std::string> f;
    std::stringstream ls(line);
    for (std::string v; std::getline(ls, v, ',');) f.push_back(v);
    if (f.size() < header.size())
      throw pdcg::InputError("fewer columns than the header").source(path).line(lineno).value(line);
    c.kappa.push_back(pdcg::parse_double(pdcg::trim(f[static_cast<std::size_t>(kcol)]), {path, lineno, "kappa"}));
    for (std::size_t b = 0; b < wcols.size(); ++b)
      c.omega[b].push_back(pdcg::parse_double(pdcg::trim(f[static_cast<std::size_t>(wcols[b])]), {path, lineno, header[static_cast<std::size_t>(wcols[b])]}));
  }
  return c;
}

/// Linear interpolation of branch b at κ; NaN outside the reference's range.
double interpolate(const Curves& c, std::size_t b, double k) {
  for (std::size_t i = 0; i + 1 < c.kappa.size(); ++i) {
    const double k0 = c.kappa[i], k1 = c.kappa[i + 1];
    if ((k >= k0 && k <= k1) || (k <= k0 && k >= k1)) {
      const double s = k1 == k0 ? 0.0 : (k - k0) / (k1 - k0);
      return c.omega[b][i] + s * (c.omega[b][i + 1] - c.omega[b][i]);
    }
  }
  if (!c.kappa.empty() && std::abs(k - c.kappa.back()) <= 1e-12 * std::abs(k)) return c.omega[b].back();
  return std::numeric_limits<double>::quiet_NaN();
}

int run_trajectory(const Options& o) {
  pdcg::atomistic::DumpReader reader(o.trajectory);
  const auto range = pdcg::parse_frame_range(o.frames, reader.nframes(), "--frames");
  const auto idx = range.indices();
  if (idx.size() < 2)
    throw pdcg::InputError("too few frames for a frequency spectrum")
        .key("--frames")
        .value(o.frames)
        .expected("at least 4 frames");
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
  for (std::size_t k = 1; k < idx.size(); ++k) {
    const auto step = reader.info(idx[k]).timestep - reader.info(idx[k - 1]).timestep;
    if (step != i1.timestep - i0.timestep)
      throw pdcg::InputError("frames are not evenly spaced in time")
          .source(o.trajectory)
          .key(fmt::format("frame {}", idx[k]))
          .value(fmt::format("timestep gap {}", step))
          .expected(fmt::format("the gap of the first two selected frames, {}", i1.timestep - i0.timestep))
          .fix("select an evenly spaced range with --frames A:B:S");
  }
  std::vector<pdcg::atomistic::Atoms> frames;
  frames.reserve(idx.size());
  pdcg::Progress progress("frames", idx.size());
  for (auto i : idx) {
    frames.push_back(reader.frame(i));
    progress.update(frames.size());
  }
  progress.finish();

  pdcg::dispersion::TrajectoryOptions topt;
  topt.axis = axis_index(o.axis, "--axis");
  topt.component = axis_index(o.component.empty() ? o.axis : o.component, "--component");
  topt.frame_interval = interval;
  topt.window = o.window == "none" ? pdcg::dispersion::Window::none : pdcg::dispersion::Window::hann;
  topt.min_resolution = o.resolution;
  topt.source = o.trajectory;
  const auto spectrum = pdcg::dispersion::measure(frames, topt);
  const auto ridge = pdcg::dispersion::ridge(spectrum);

  Curves ref;
  if (!o.compare.empty()) ref = read_curves(o.compare);
  double worst = 0.0, worst_k = 0.0;
  pdcg::io::AtomicTextFile csv(o.output);
  csv.stream() << "kappa,omega,power,resolution" << (o.compare.empty() ? "" : ",omega_ref,error,error_in_bins")
               << "\n";
  for (const auto& p : ridge) {
    csv.stream() << fmt::format("{:.17g},{:.17g},{:.17g},{:.17g}", p.kappa, p.omega, p.power, p.resolution);
    if (!o.compare.empty()) {
      // the reference branch nearest to the measured frequency
      double best = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t b = 0; b < ref.omega.size(); ++b) {
        const double w = interpolate(ref, b, p.kappa);
        if (std::isfinite(w) && (!std::isfinite(best) || std::abs(w - p.omega) < std::abs(best - p.omega))) best = w;
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
  std::printf("measured dispersion: %zu wavenumbers, %zu frames, Δω = %.6g -> %s\n", ridge.size(), idx.size(),
              spectrum.resolution, o.output.c_str());
  if (!o.compare.empty())
    std::printf("worst error against %s: %.6g at κ = %.6g (%.3g frequency bins)\n", o.compare.c_str(), worst, worst_k,
                worst / spectrum.resolution);
  if (!o.spectrum.empty()) {
    // image: κ to the right, ω upwards, up to 1.5× the highest ridge frequency; each κ a
    // column `sx` pixels wide so that short lattices still give a readable picture.
    double wmax = 0.0;
    for (const auto& p : ridge) wmax = std::max(wmax, p.omega);
    const int h = std::max(2, std::min(static_cast<int>(spectrum.nw),
                                       static_cast<int>(std::ceil(1.5 * wmax / spectrum.resolution)) + 1));
    const int sx = std::max(1, 480 / static_cast<int>(spectrum.nk));
    const int sy = std::max(1, 320 / h);
    const int w = static_cast<int>(spectrum.nk) * sx, hp = h * sy;
    std::vector<double> img(static_cast<std::size_t>(w) * hp);
    for (int x = 0; x < w; ++x)
      for (int y = 0; y < hp; ++y)
        img[static_cast<std::size_t>(hp - 1 - y) * w + x] =
            spectrum.power[static_cast<std::size_t>(x / sx) * spectrum.nw + static_cast<std::size_t>(y / sy)];
    pdcg::io::write_png_field(o.spectrum, w, hp, img, true);
    std::printf("power spectrum S(κ, ω) (log scale, κ → right, ω ↑) -> %s\n", o.spectrum.c_str());
  }
  return 0;
}

pdcg::cli::Registration reg(400, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand("dispersion", "Dispersion ω(κ) measured from a trajectory, compared with a reference");
  auto o = std::make_shared<Options>();
  sub->add_option("--trajectory", o->trajectory, "LAMMPS dump (text or .gz) of a periodic lattice")->required();
  sub->add_option("--axis", o->axis, "Wave direction: x, y or z (a lattice direction)");
  sub->add_option("--component", o->component, "Displacement component (default: the axis, longitudinal)");
  sub->add_option("--frames", o->frames, "Frames A:B[:S] (inclusive, 0-based, negative from the end)");
  sub->add_option("--dt", o->dt, "MD time step, when the dump has no ITEM: TIME");
  sub->add_option("--resolution", o->resolution, "Refuse trajectories whose frequency resolution is coarser");
  sub->add_option("--window", o->window, "Time window: hann (default) or none")->check(CLI::IsMember({"hann", "none"}));
  sub->add_option("-o,--output", o->output, "CSV: kappa,omega,power,resolution[,omega_ref,error,error_in_bins]")
      ->required();
  sub->add_option("--spectrum", o->spectrum, "PNG image of the power spectrum S(κ, ω)");
  sub->add_option("--compare", o->compare, "CSV with kappa and omega… columns (model or closed form) to compare with");
  sub->footer(
      "Example:\n"
      "  pdcg dispersion --trajectory chain.dump --axis x --dt 0.01 -o measured.csv --spectrum S.png\n"
      "Atoms are grouped into lattice planes normal to the axis; the plane displacements are\n"
      "transformed in space and time (FFTW); the ridge is the frequency of peak power per κ.");
  return [o] { return run_trajectory(*o); };
});

}  // namespace
