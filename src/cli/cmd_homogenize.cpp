/// `pdcg homogenize BODY.h5 --kernel NAME --width W [--spacing H | --points FILE] -o hom.h5`
/// Homogenises a body (docs/theory.md §3) on a regular grid or on given points.
#include <fmt/format.h>

#include <Eigen/Dense>
#include <cstdio>
#include <fstream>

#include "command.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/coarsen/homogenise.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace {

struct Options {
  std::string body, kernel, points, output, axes, shift;
  double width = 0.0, spacing = 0.0;
};

std::vector<double> numbers(const std::string& text, std::size_t count, std::string_view option) {
  const auto tok = pdcg::split_blanks(text);
  if (tok.size() != count)
    throw pdcg::InputError("wrong number of values")
        .source(option)
        .value(text)
        .expected(fmt::format("{} numbers separated by blanks", count));
  std::vector<double> v;
  for (auto t : tok) v.push_back(pdcg::parse_double(t, {option, 0, option}));
  return v;
}

/// Points file: one point per line, "x y z" (blanks or commas), '#' comments.
std::vector<double> read_points(const std::string& path) {
  std::ifstream in(path);
  if (!in)
    throw pdcg::InputError("cannot open points file")
        .source(path)
        .fix("check the path given to --points");
  std::vector<double> pts;
  std::string line;
  long n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (auto h = line.find('#'); h != std::string::npos) line.resize(h);
    for (auto& c : line)
      if (c == ',') c = ' ';
    const auto tok = pdcg::split_blanks(line);
    if (tok.empty()) continue;
    if (tok.size() != 3)
      throw pdcg::InputError("a point needs 3 coordinates")
          .source(path)
          .line(n)
          .value(pdcg::trim(line))
          .expected("x y z");
    for (int k = 0; k < 3; ++k)
      pts.push_back(pdcg::parse_double(tok[static_cast<std::size_t>(k)], {path, n, "xyz"}));
  }
  if (pts.empty())
    throw pdcg::InputError("points file holds no points").source(path).expected("lines 'x y z'");
  return pts;
}

int run(const Options& o) {
  pdcg::io::require_writable_output(o.output, "--output");  // before any computation
  using namespace pdcg;
  if ((o.spacing > 0.0) == !o.points.empty())
    throw InputError("give exactly one of --spacing and --points")
        .key("--spacing/--points")
        .fix("--spacing H for a regular grid, --points FILE for given points");
  const body::Body b = body::read_body(o.body);
  const coarsen::Kernel k = coarsen::make_kernel(o.kernel, o.width);
  coarsen::HomogeniseReport rep;
  body::Body h;
  if (!o.points.empty()) {
    h = coarsen::homogenise_on_points(b, k, read_points(o.points), &rep);
  } else {
    coarsen::GridOptions g;
    g.spacing = o.spacing;
    if (!o.axes.empty()) {
      const auto a = numbers(o.axes, 9, "--axes");
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          g.rotation(c, r) = a[static_cast<std::size_t>(3 * r + c)];  // rows given = axes
      if (!(g.rotation.transpose() * g.rotation).isApprox(Eigen::Matrix3d::Identity(), 1e-8) ||
          g.rotation.determinant() < 0)
        throw InputError("grid axes are not orthonormal and right-handed")
            .source("--axes")
            .value(o.axes)
            .expected("three orthonormal vectors a b c (9 numbers), a × b = c");
    }
    if (!o.shift.empty()) {
      const auto s = numbers(o.shift, 3, "--shift");
      g.shift = {s[0], s[1], s[2]};
    }
    h = coarsen::homogenise_on_grid(b, k, g, &rep);
  }
  h.provenance.back() += " (" + pdcg::command_line() + ")";
  body::write_body(h, o.output);
  double m = 0;
  for (double v : h.homogenisation->mass) m += v;
  std::printf("%s: %zu points from %zu atoms, kernel %s width %g, total mass %.17g\n",
              o.output.c_str(), h.homogenisation->size(), h.size(), o.kernel.c_str(), o.width, m);
  return 0;
}

pdcg::cli::Registration reg(120, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand("homogenize",
                                 "Homogenise a PD body with a kernel on a grid or given points");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("--kernel", o->kernel, "top-hat | gaussian | cubic-bspline | wendland-c2")
      ->required();
  sub->add_option("--width", o->width, "Kernel width: support radius (σ for gaussian)")->required();
  sub->add_option("--spacing", o->spacing, "Regular grid of this spacing");
  sub->add_option("--axes", o->axes,
                  "Grid axes, 9 numbers \"a1 a2 a3 b1 b2 b3 c1 c2 c3\" (orthonormal)");
  sub->add_option("--shift", o->shift, "Grid offset in units of the spacing, \"sx sy sz\"");
  sub->add_option("--points", o->points, "Text file of points, one 'x y z' per line");
  sub->add_option("-o,--output", o->output, "Output model file")->required();
  sub->footer(
      "Example:\n  pdcg homogenize body.h5 --kernel wendland-c2 --width 6 --spacing 2 -o hom.h5");
  return [o] { return run(*o); };
});

}  // namespace
