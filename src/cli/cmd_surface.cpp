/// `pdcg surface BODY.h5 (--plane HKL | --normal "nx ny nz") [--thickness T] [--no-relax]
///   [--min-style cg|fire] [--ftol F] [--max-iterations N] [--skin S] [--json]`:
/// surface energy γ of a crystal plane from the atoms of a periodic delta body, unrelaxed and
/// relaxed by molecular statics, the Griffith G_c = 2γ, and the Cauchy–Born ideal strength
/// along the plane normal (docs/fracture.md).
#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

#include "body_cli_util.hpp"
#include "command.hpp"
#include "pdcg/body/cauchy_born.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/body/statics.hpp"
#include "pdcg/body/surface.hpp"
#include "pdcg/core/units.hpp"

namespace {

struct Options {
  std::string body, plane, normal, min_style = "cg";
  double thickness = 0.0, ftol = 1e-10, skin = -1.0, max_step = 0.0;
  std::int64_t max_iterations = 100000;
  int search = 8;
  bool json = false, no_relax = false, no_strength = false;
};

/// Miller indices "111", "1-10", "-1 1 0", "2,1,0".
Eigen::Vector3d parse_plane(const std::string& text) {
  using namespace pdcg;
  std::vector<int> v;
  auto bad = [&] {
    return InputError("bad Miller indices")
        .source("--plane")
        .value(text)
        .expected(
            "three integers h k l: \"111\", \"1-10\" (one digit each, '-' for a bar) or "
            "\"1 -1 0\" (any integers)")
        .fix("for a general direction give --normal \"nx ny nz\"");
  };
  const bool separated = text.find_first_of(" ,\t") != std::string::npos;
  if (separated) {
    const auto nums = cli::body_util::numbers(text, 3, "--plane");
    for (double x : nums) {
      if (x != std::round(x)) throw bad();
      v.push_back(static_cast<int>(x));
    }
  } else {
    int sign = 1;
    for (char c : text) {
      if (c == '-') {
        if (sign < 0) throw bad();
        sign = -1;
      } else if (std::isdigit(static_cast<unsigned char>(c))) {
        v.push_back(sign * (c - '0'));
        sign = 1;
      } else {
        throw bad();
      }
    }
    if (sign < 0) throw bad();
  }
  if (v.size() != 3 || (v[0] == 0 && v[1] == 0 && v[2] == 0)) throw bad();
  return {static_cast<double>(v[0]), static_cast<double>(v[1]), static_cast<double>(v[2])};
}

std::string statics_json(const pdcg::body::StaticsResult& s) {
  return fmt::format(
      "{{\"energy\": {:.17g}, \"energy_start\": {:.17g}, \"force_norm\": {:.17g}, \"force_max\": "
      "{:.17g}, \"iterations\": {}, \"evaluations\": {}, \"family_rebuilds\": {}, "
      "\"family_radius\": {:.17g}, \"converged\": {}, \"stop\": \"{}\"}}",
      s.energy, s.energy0, s.force_norm, s.force_max, s.iterations, s.evaluations, s.rebuilds,
      s.family_radius, s.converged, s.stop);
}

std::string num_or_null(double v) {
  return std::isfinite(v) ? fmt::format("{:.17g}", v) : std::string("null");
}

int run(const Options& o) {
  using namespace pdcg;
  if (o.plane.empty() == o.normal.empty())
    throw InputError("give one of --plane and --normal")
        .key("--plane/--normal")
        .expected(
            "--plane 111 (Miller indices, cubic crystal with the cube axes along x y z) "
            "or --normal \"nx ny nz\" (Cartesian)");
  Eigen::Vector3d nrm;
  if (!o.plane.empty()) {
    nrm = parse_plane(o.plane);
  } else {
    const auto v = cli::body_util::numbers(o.normal, 3, "--normal");
    nrm = Eigen::Vector3d(v[0], v[1], v[2]);
    if (!(nrm.norm() > 0.0) || !nrm.allFinite())
      throw InputError("bad plane normal")
          .source("--normal")
          .value(o.normal)
          .expected("a nonzero vector");
  }
  if (!(o.thickness >= 0.0) || !std::isfinite(o.thickness))
    throw InputError("bad slab thickness")
        .source("--thickness")
        .value(fmt::format("{}", o.thickness))
        .expected("a length >= 0 (0: 4 × the potential cutoff)");
  if (!(o.ftol > 0.0) || !std::isfinite(o.ftol))
    throw InputError("bad force tolerance")
        .source("--ftol")
        .value(fmt::format("{}", o.ftol))
        .expected("a number > 0");
  if (o.max_iterations < 1)
    throw InputError("bad iteration limit")
        .source("--max-iterations")
        .value(std::to_string(o.max_iterations))
        .expected(">= 1");
  body::StaticsOptions so;
  so.style = body::parse_min_style(o.min_style, "--min-style");
  so.force_tolerance = o.ftol;
  so.max_iterations = o.max_iterations;
  so.skin = o.skin;
  so.max_step = o.max_step;
  if (o.skin != -1.0 && !(o.skin > 0.0))
    throw InputError("bad family margin")
        .source("--skin")
        .value(fmt::format("{}", o.skin))
        .expected("a length > 0");
  if (!(o.max_step >= 0.0))
    throw InputError("bad step limit")
        .source("--max-step")
        .value(fmt::format("{}", o.max_step))
        .expected("a length >= 0");

  const body::Body b = body::read_body(o.body);
  body::SlabOptions sl;
  sl.normal = nrm;
  sl.min_thickness = o.thickness;
  sl.search = o.search;
  const body::Slab slab = body::make_slab(b, sl);
  const body::SurfaceEnergy se =
      body::surface_energy(slab, o.no_relax ? std::nullopt : std::optional(so));

  // Ideal strength of the Cauchy–Born material: peak of P_nn under uniaxial strain along n.
  double lam_c = 0.0, p_c = std::numeric_limits<double>::quiet_NaN();
  body::LatticeNote note;
  bool relaxed_ion = false;
  if (!o.no_strength) {
    const body::CauchyBorn cb(b);
    note = body::cauchy_born_lattice_note(cb.lattice(), body::IonRelaxation::automatic);
    relaxed_ion = cb.relaxed_values();
    lam_c = body::uniaxial_peak_stretch(cb, slab.normal);
    if (lam_c > 0.0) {
      const Eigen::Matrix3d F =
          Eigen::Matrix3d::Identity() + (lam_c - 1.0) * slab.normal * slab.normal.transpose();
      p_c = slab.normal.dot(cb.evaluate(F, false).P * slab.normal);
    }
  }

  const UnitNames names = unit_names(b.units);
  const std::string area_unit = fmt::format("{}/{}^2", names.energy, names.length);
  const std::string u = std::string(to_string(b.units));
  const double jm2 = body::energy_per_area_to_j_per_m2(b.units);
  const double gpa = energy_density_to_gpa(b.units);
  const Eigen::Matrix3i& M = slab.M;
  if (o.json) {
    std::string out = fmt::format(
        "{{\"body\": \"{}\", \"units\": \"{}\", \"unit\": \"{}\", \"to_J_per_m2\": {}, "
        "\"normal\": [{:.17g}, {:.17g}, {:.17g}], \"plane\": \"{}\", "
        "\"cell\": {{\"M\": [[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]], \"atoms\": {}, "
        "\"area\": {:.17g}, \"height\": {:.17g}, \"period\": {:.17g}, \"layers\": {}, "
        "\"cut_gap\": {:.17g}}}, "
        "\"unrelaxed\": {{\"e_bulk\": {:.17g}, \"e_slab\": {:.17g}, \"gamma\": {:.17g}, "
        "\"G_c\": {:.17g}, \"gamma_J_per_m2\": {}, \"G_c_J_per_m2\": {}}}",
        o.body, u, area_unit, num_or_null(jm2), slab.normal[0], slab.normal[1], slab.normal[2],
        o.plane.empty() ? o.normal : o.plane, M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2),
        M(2, 0), M(2, 1), M(2, 2), slab.slab.size(), slab.area, slab.height, slab.period,
        slab.layers, slab.cut_gap, se.e_bulk, se.e_slab, se.gamma, 2 * se.gamma,
        num_or_null(se.gamma * jm2), num_or_null(2 * se.gamma * jm2));
    if (se.gamma_relaxed)
      out.append(fmt::format(
          ", \"relaxed\": {{\"min_style\": \"{}\", \"ftol\": {:.17g}, \"e_bulk\": {:.17g}, "
          "\"e_slab\": {:.17g}, \"gamma\": {:.17g}, \"G_c\": {:.17g}, \"gamma_J_per_m2\": {}, "
          "\"G_c_J_per_m2\": {}, \"bulk_statics\": {}, \"slab_statics\": {}}}",
          o.min_style, o.ftol, *se.e_bulk_relaxed, *se.e_slab_relaxed, *se.gamma_relaxed,
          2 * *se.gamma_relaxed, num_or_null(*se.gamma_relaxed * jm2),
          num_or_null(2 * *se.gamma_relaxed * jm2), statics_json(*se.bulk_statics),
          statics_json(*se.slab_statics)));
    else
      out.append(", \"relaxed\": null");
    if (!o.no_strength)
      out.append(fmt::format(
          ", \"ideal_strength\": {{\"path\": \"uniaxial strain along the normal, Cauchy-Born\", "
          "\"stretch\": {}, \"stress\": {}, \"stress_unit\": \"{}\", \"stress_GPa\": {}, "
          "\"relaxed_ion\": {}}}",
          lam_c > 0.0 ? fmt::format("{:.17g}", lam_c) : "null", num_or_null(p_c),
          names.energy_density, num_or_null(p_c * gpa), relaxed_ion));
    out.append("}\n");
    std::fputs(out.c_str(), stdout);
    return 0;
  }
  auto in_j = [&](double v) {
    return std::isfinite(jm2) ? fmt::format(" ({:.8g} J/m^2)", v * jm2) : std::string();
  };
  std::printf("%s: plane %s, normal (%.6g, %.6g, %.6g), units %s\n", o.body.c_str(),
              (o.plane.empty() ? o.normal : o.plane).c_str(), slab.normal[0], slab.normal[1],
              slab.normal[2], u.c_str());
  std::printf(
      "slab cell: %zu atoms, M = [%d %d %d; %d %d %d; %d %d %d], area %.10g, height %.10g "
      "(%d layers, period %.10g), cut in a gap of %.6g\n",
      slab.slab.size(), M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2), M(2, 0), M(2, 1),
      M(2, 2), slab.area, slab.height, slab.layers, slab.period, slab.cut_gap);
  std::printf("energies and gamma in %s and %s%s\n", names.energy.data(), area_unit.c_str(),
              std::isfinite(jm2) ? "" : " (reduced units: no J/m^2 value)");
  std::printf(
      "unrelaxed: E_bulk = %.15g, E_slab = %.15g, gamma = %.12g%s, G_c = 2 gamma = %.12g%s\n",
      se.e_bulk, se.e_slab, se.gamma, in_j(se.gamma).c_str(), 2 * se.gamma,
      in_j(2 * se.gamma).c_str());
  if (se.gamma_relaxed) {
    std::printf(
        "relaxed (%s, |f| <= %g): E_bulk = %.15g, E_slab = %.15g, gamma = %.12g%s, G_c = %.12g%s\n",
        o.min_style.c_str(), o.ftol, *se.e_bulk_relaxed, *se.e_slab_relaxed, *se.gamma_relaxed,
        in_j(*se.gamma_relaxed).c_str(), 2 * *se.gamma_relaxed,
        in_j(2 * *se.gamma_relaxed).c_str());
    std::printf(
        "statics: bulk %lld iterations (|f| = %.3g), slab %lld iterations (|f| = %.3g), %d family "
        "rebuilds\n",
        static_cast<long long>(se.bulk_statics->iterations), se.bulk_statics->force_norm,
        static_cast<long long>(se.slab_statics->iterations), se.slab_statics->force_norm,
        se.bulk_statics->rebuilds + se.slab_statics->rebuilds);
  }
  if (!o.no_strength) {
    if (!note.text.empty())
      std::printf("%s: %s\n", note.warning ? "warning" : "note", note.text.c_str());
    if (lam_c > 0.0)
      std::printf(
          "ideal strength (Cauchy-Born, %s, uniaxial strain along the normal): stretch %.6f, "
          "P_nn = %.8g %s%s\n",
          relaxed_ion ? "relaxed ion" : "clamped ion", lam_c, p_c, names.energy_density.data(),
          std::isfinite(gpa) ? fmt::format(" ({:.6g} GPa)", p_c * gpa).c_str() : "");
    else
      std::printf("ideal strength: no peak of P_nn up to stretch 1.6\n");
  }
  return 0;
}

pdcg::cli::Registration reg(145, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub = app.add_subcommand(
      "surface", "Surface energy γ and Griffith G_c = 2γ of a crystal plane from the atoms");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body) of a periodic bulk crystal")->required();
  sub->add_option("--plane", o->plane,
                  "Miller indices (cubic crystal, cube axes along x y z): 100, 110, 111, 1-10, "
                  "\"2 1 0\"");
  sub->add_option("--normal", o->normal, "Plane normal, Cartesian \"nx ny nz\" (any crystal)");
  sub->add_option("--thickness", o->thickness,
                  "Least slab height along the normal (length; default 4 × the cutoff)");
  sub->add_flag("--no-relax", o->no_relax, "Unrelaxed γ only (no molecular statics)");
  sub->add_option("--min-style", o->min_style, "Minimiser: cg (default) or fire");
  sub->add_option("--ftol", o->ftol,
                  "Force tolerance: 2-norm of the 3N forces (LAMMPS ftol; default 1e-10)");
  sub->add_option("--max-iterations", o->max_iterations, "Iteration limit (default 100000)");
  sub->add_option("--skin", o->skin,
                  "Family margin (length; default 0.1 × cutoff): families rebuilt when an atom "
                  "moves more than skin/2");
  sub->add_option("--max-step", o->max_step,
                  "Largest atom displacement per step (length; default 0.1 × shortest bond)");
  sub->add_option("--search", o->search, "Range |m_i| of box translations searched (default 8)");
  sub->add_flag("--no-strength", o->no_strength, "Skip the Cauchy–Born ideal strength");
  sub->add_flag("--json", o->json, "JSON output");
  sub->footer(
      "γ = (E_slab − E_bulk)/(2A): the slab is the bulk cell with its direction along the normal "
      "made non-periodic (two surfaces).\n"
      "Examples:\n  pdcg surface cu.h5 --plane 111 --json\n  pdcg surface lj.h5 --plane 100 "
      "--no-relax");
  return [o] { return run(*o); };
});

}  // namespace
