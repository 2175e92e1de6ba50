/// `pdcg elastic BODY.h5 [--F "F11 … F33"] [--json] [--fit MAX_STRETCH] [--critical]
/// [--clamped-ion] [--quasi-harmonic T]`: Cauchy–Born elastic constants of a model file
/// (docs/elastic.md): relaxed-ion by default (the basis of a crystal with a basis relaxed at F,
/// §2.2), the Voigt matrix C_IJ = ∂²W/∂E_I∂E_J (Green–Lagrange strain, second Piola–Kirchhoff
/// stress) at the pre-strain F, Voigt/Reuss bulk and shear moduli, optionally a neo-Hookean fit and
/// critical stretches.
/// `--quasi-harmonic T`: the same of the quasi-harmonic free energy W_T(F) at temperature T
/// (docs/temperature.md §3; body::QuasiHarmonicCauchyBorn), the isothermal constants.
#include <fmt/format.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "body_cli_util.hpp"
#include "command.hpp"
#include "pdcg/body/cauchy_born.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/body/quasi_harmonic.hpp"
#include "pdcg/core/units.hpp"

namespace {

struct Options {
  std::string body, F = "1 0 0 0 1 0 0 0 1";
  bool json = false, critical = false, clamped = false;
  double fit = 0.0;
  int fit_steps = 4;
  std::optional<double> quasi_harmonic;       ///< temperature of the free energy W_T
  std::optional<double> quasi_harmonic_step;  ///< central-difference step in E of its vibrational
                                              ///< part (default kQuasiHarmonicStepDefault)
};

std::string matrix_json(const Eigen::MatrixXd& m) {
  std::string s = "[";
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    s.append(r ? ", [" : "[");
    for (Eigen::Index c = 0; c < m.cols(); ++c)
      s.append(fmt::format("{}{:.17g}", c ? ", " : "", m(r, c)));
    s.append("]");
  }
  return s.append("]");
}

int run(const Options& o) {
  using namespace pdcg;
  using namespace pdcg::body;
  const Eigen::Matrix3d F = cli::body_util::deformation_gradient(o.F, "--F");
  if (o.fit != 0.0 && !(o.fit > 1.0))
    throw InputError("--fit needs the largest stretch of the fit set")
        .source("--fit")
        .value(fmt::format("{}", o.fit))
        .expected("a stretch > 1, e.g. 1.1");
  const body::Body b = body::read_body(o.body);
  if (b.dimension == 2 &&
      (F(0, 2) != 0.0 || F(1, 2) != 0.0 || F(2, 0) != 0.0 || F(2, 1) != 0.0 || F(2, 2) != 1.0))
    throw InputError("2D body: F must be a plane-strain deformation")
        .source("--F")
        .value(o.F)
        .expected(
            "F13 = F23 = F31 = F32 = 0 and F33 = 1 (bodies of dimension 2 lie in the xy plane)");
  if (o.quasi_harmonic && (o.fit != 0.0 || o.critical))
    throw InputError("--fit and --critical are not available for the quasi-harmonic free energy")
        .source(o.fit != 0.0 ? "--fit" : "--critical")
        .fix("drop --quasi-harmonic for the static lattice's fit and critical stretches");
  if (o.quasi_harmonic && o.clamped)
    throw InputError("--clamped-ion is implied by --quasi-harmonic")
        .source("--clamped-ion")
        .fix("drop --clamped-ion: the quasi-harmonic material holds every atom at F x");
  // quasi-harmonic: the atoms are held at F x (bodies whose basis would relax are refused)
  const body::IonRelaxation ion =
      o.clamped || o.quasi_harmonic ? body::IonRelaxation::clamped : body::IonRelaxation::relaxed;
  std::optional<body::QuasiHarmonicCauchyBorn> qh;
  if (o.quasi_harmonic_step && !o.quasi_harmonic)
    throw InputError("--quasi-harmonic-step without --quasi-harmonic")
        .source("--quasi-harmonic-step")
        .fix("add --quasi-harmonic T, or drop --quasi-harmonic-step");
  const double step = o.quasi_harmonic_step.value_or(body::kQuasiHarmonicStepDefault);
  if (!(step >= body::kQuasiHarmonicStepMin && step <= body::kQuasiHarmonicStepMax))
    throw InputError(
        "the central-difference strain step of the quasi-harmonic tangent is out of "
        "range")
        .source("--quasi-harmonic-step")
        .value(fmt::format("{}", step))
        .expected(fmt::format("{:g} ≤ h ≤ {:g} (default {:g})", body::kQuasiHarmonicStepMin,
                              body::kQuasiHarmonicStepMax, body::kQuasiHarmonicStepDefault))
        .fix("1e-4 for analytic potentials, ≈ 1e-2 for tabulated EAM (docs/temperature.md §3.1)");
  if (o.quasi_harmonic) qh.emplace(b, *o.quasi_harmonic, step);
  std::optional<body::CauchyBorn> static_cb;  // relaxed: InputError unless a perfect crystal
  if (!qh) static_cb.emplace(b, ion);
  const body::CauchyBorn& cb = qh ? qh->cauchy_born() : *static_cb;
  const body::CauchyBornState st = qh ? qh->evaluate(F) : cb.evaluate(F);
  const body::Matrix6d C = body::voigt_elastic_constants(F, st);
  const body::Moduli mod = body::moduli(C, b.dimension);
  const Eigen::Matrix3d S = F.inverse() * st.P;
  std::optional<body::NeoHookeanFit> fit;
  if (o.fit > 1.0)
    fit = body::fit_neo_hookean(cb, body::fit_deformations(b.dimension, o.fit, o.fit_steps));
  double infl = 0.0, peak = 0.0;
  if (o.critical) {
    if (b.base_potential && b.base_potential->pairwise() && b.base_potential->ntypes() >= 1)
      infl = body::pair_inflection_stretch(*b.base_potential, 1, 1);
    peak = body::uniaxial_peak_stretch(cb, Eigen::Vector3d(1, 0, 0));
  }
  const std::string u = std::string(to_string(b.units));
  const UnitNames names = unit_names(b.units);
  const std::string unit = std::string(names.energy_density);
  // energy/volume -> GPa through LAMMPS's nktv2p and the pressure unit (metal: bar = 1e-4 GPa,
  // real: atm = 1.01325e-4 GPa); NaN for reduced (lj) and none units
  const double gpa = energy_density_to_gpa(b.units);
  const bool has_gpa = std::isfinite(gpa);
  const LatticeInfo& lat = cb.lattice();
  const LatticeNote note = cauchy_born_lattice_note(lat, ion);
  const char* ion_name = cb.relaxed_values() ? "relaxed" : "clamped";
  if (o.json) {
    std::string out = fmt::format(
        "{{\"body\": \"{}\", \"kind\": \"{}\", \"dimension\": {}, \"units\": \"{}\", "
        "\"unit\": \"{}\", \"F\": {}, "
        "\"energy_density\": {:.17g}, \"P\": {}, \"S\": {}, \"C_voigt\": {}, \"voigt_order\": "
        "[\"11\", \"22\", \"33\", \"23\", \"13\", \"12\"], \"bulk_voigt\": {:.17g}, "
        "\"shear_voigt\": "
        "{:.17g}, \"bulk_reuss\": {:.17g}, \"shear_reuss\": {:.17g}",
        o.body, to_string(b.kind), b.dimension, u, unit, matrix_json(F), st.W, matrix_json(st.P),
        matrix_json(S), matrix_json(C), mod.bulk_voigt, mod.shear_voigt, mod.bulk_reuss,
        mod.shear_reuss);
    if (has_gpa)
      out.append(fmt::format(
          ", \"to_GPa\": {:.17g}, \"GPa\": {{\"S\": {}, \"C_voigt\": {}, \"bulk_voigt\": {:.17g}, "
          "\"shear_voigt\": {:.17g}, \"bulk_reuss\": {:.17g}, \"shear_reuss\": {:.17g}}}",
          gpa, matrix_json(S * gpa), matrix_json(C * gpa), mod.bulk_voigt * gpa,
          mod.shear_voigt * gpa, mod.bulk_reuss * gpa, mod.shear_reuss * gpa));
    else
      out.append(", \"to_GPa\": null, \"GPa\": null");
    out.append(
        fmt::format(", \"lattice\": {{\"perfect\": {}, \"basis\": {}, \"centrosymmetric\": {}, "
                    "\"clamped_ion\": {}, \"summary\": \"{}\"}}, \"ion_relaxation\": \"{}\", "
                    "\"relaxation_iterations\": {}",
                    lat.perfect, lat.basis, lat.centrosymmetric, !note.text.empty(), lat.summary,
                    ion_name, st.iterations));
    if (o.quasi_harmonic)
      out.append(
          fmt::format(", \"free_energy\": \"quasi-harmonic\", \"temperature\": {:.17g}, "
                      "\"quasi_harmonic_step\": {:.17g}",
                      *o.quasi_harmonic, qh->strain_step()));
    if (!st.shift.empty()) {
      Eigen::MatrixXd sh(lat.basis, 3);
      for (int q = 0; q < lat.basis; ++q)
        for (int i = 0; i < 3; ++i) sh(q, i) = st.shift[static_cast<std::size_t>(3 * q + i)];
      out.append(fmt::format(", \"sublattice_shift\": {}", matrix_json(sh)));
    }
    if (fit)
      out.append(fmt::format(
          ", \"neo_hookean\": {{\"mu\": {:.17g}, \"bulk\": {:.17g}, \"rms_error\": {:.17g}, "
          "\"relative_error\": {:.17g}, \"samples\": {}, \"max_stretch\": {:.17g}}}",
          fit->mu, fit->bulk, fit->rms_error, fit->relative_error, fit->samples, o.fit));
    if (o.critical)
      out.append(fmt::format(
          ", \"bond_inflection_stretch\": {:.17g}, \"uniaxial_peak_stretch_x\": {:.17g}", infl,
          peak));
    out.append("}\n");
    std::fputs(out.c_str(), stdout);
    return 0;
  }
  // with GPa: a second column block in GPa; lj: say the values are reduced
  auto in_gpa = [&](double v) { return has_gpa ? fmt::format(" ({:.6g} GPa)", v * gpa) : ""; };
  std::printf("%s: %s body, dimension %d, units %s\n", o.body.c_str(),
              std::string(to_string(b.kind)).c_str(), b.dimension, u.c_str());
  std::printf("lattice: %s\n", lat.summary.c_str());
  if (o.quasi_harmonic)
    std::printf(
        "free energy: quasi-harmonic at T = %g (W_T = W + k_B T Σ ln(ω/k_B T) / V₀ of the cell's "
        "%zu vibrations; its vibrational part by central differences in E, step %g)\n",
        *o.quasi_harmonic, 3 * b.size() - 3, qh->strain_step());
  if (qh && lat.bravais())
    std::printf("ion relaxation: none needed (Bravais lattice; every atom at F x)\n");
  else if (cb.relaxing())
    std::printf(
        "ion relaxation: relaxed (sublattice shifts minimise W at F: %d Newton steps; "
        "--clamped-ion for the clamped values)\n",
        st.iterations);
  else if (cb.relaxed_values())
    std::printf("ion relaxation: relaxed (Bravais lattice: nothing to relax)\n");
  else
    std::printf("ion relaxation: clamped (every atom follows F)\n");
  if (!note.text.empty())
    std::printf("%s: %s\n", note.warning ? "warning" : "note", note.text.c_str());
  if (has_gpa)
    std::printf(
        "stresses and constants in %s (1 %s = %.8g GPa: LAMMPS nktv2p %.8g %s per %s × %.6g "
        "GPa/%s)\n",
        unit.c_str(), unit.c_str(), gpa, unit_constants(b.units).nktv2p,
        std::string(names.pressure).c_str(), unit.c_str(), unit_constants(b.units).pressure_to_gpa,
        std::string(names.pressure).c_str());
  else
    std::printf("stresses and constants in %s: %s units have no GPa value\n", unit.c_str(),
                u.c_str());
  std::printf("%s = %.10g %s (energy/volume)\n", qh ? "W_T(F)" : "W(F)", st.W, unit.c_str());
  std::printf("second Piola–Kirchhoff stress S = F⁻¹P [%s]:\n", unit.c_str());
  for (int r = 0; r < 3; ++r) std::printf("  %14.7g %14.7g %14.7g\n", S(r, 0), S(r, 1), S(r, 2));
  std::printf("C_IJ = ∂²%s/∂E_I∂E_J, %s-ion (Voigt 11 22 33 23 13 12) [%s]:\n", qh ? "W_T" : "W",
              ion_name, unit.c_str());
  for (int r = 0; r < 6; ++r) {
    std::printf(" ");
    for (int c = 0; c < 6; ++c) std::printf(" %13.6g", C(r, c));
    std::printf("\n");
  }
  if (has_gpa) {
    std::printf("C_IJ [GPa], %s-ion:\n", ion_name);
    for (int r = 0; r < 6; ++r) {
      std::printf(" ");
      for (int c = 0; c < 6; ++c) std::printf(" %13.6g", C(r, c) * gpa);
      std::printf("\n");
    }
  }
  std::printf(
      "%sbulk modulus [%s]: Voigt %.6g%s, Reuss %.6g%s; shear modulus: Voigt %.6g%s, "
      "Reuss %.6g%s\n",
      b.dimension == 2 ? "2D (in-plane) " : "", unit.c_str(), mod.bulk_voigt,
      in_gpa(mod.bulk_voigt).c_str(), mod.bulk_reuss, in_gpa(mod.bulk_reuss).c_str(),
      mod.shear_voigt, in_gpa(mod.shear_voigt).c_str(), mod.shear_reuss,
      in_gpa(mod.shear_reuss).c_str());
  if (fit)
    std::printf(
        "neo-Hookean fit (%d deformations, stretch ≤ %g): μ = %.6g%s, K = %.6g%s [%s], RMS error "
        "%.3g (%.2f%% of RMS W)\n",
        fit->samples, o.fit, fit->mu, in_gpa(fit->mu).c_str(), fit->bulk, in_gpa(fit->bulk).c_str(),
        unit.c_str(), fit->rms_error, 100 * fit->relative_error);
  if (o.critical) {
    if (infl > 0) std::printf("bond inflection stretch (types 1-1) r_infl/r0 = %.6f\n", infl);
    if (peak > 0)
      std::printf("uniaxial-strain peak stretch along x λ_c = %.6f\n", peak);
    else
      std::printf("uniaxial-strain peak stretch along x: no peak up to λ = 1.6\n");
  }
  return 0;
}

pdcg::cli::Registration reg(140, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("elastic", "Cauchy–Born elastic constants of a model at a pre-strain F");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("--F", o->F,
                  "Pre-strain deformation gradient, 9 numbers row-major (default identity)");
  sub->add_flag("--json", o->json, "JSON output");
  sub->add_option("--fit", o->fit,
                  "Neo-Hookean fit over uniaxial/biaxial/shear deformations up to this stretch");
  sub->add_option("--fit-steps", o->fit_steps,
                  "Stretch values per deformation mode in the fit (default 4)");
  sub->add_flag("--clamped-ion", o->clamped,
                "Clamped-ion constants: every atom follows F (default: relaxed-ion, the basis of "
                "a crystal with a basis relaxed; needs a perfect crystal)");
  sub->add_option("--quasi-harmonic", o->quasi_harmonic,
                  "Isothermal constants of the classical quasi-harmonic free energy W_T(F) at "
                  "this temperature (kelvin; k_B T/ε in units lj): periodic 3D delta body of a "
                  "crystal cell or a homogenised or rescaled model of one (the atoms' free "
                  "energy), ≤ 3000 atoms (docs/temperature.md)");
  sub->add_option("--quasi-harmonic-step", o->quasi_harmonic_step,
                  "Central-difference step in the Green–Lagrange strain of the vibrational part "
                  "(1e-6 to 1e-2, default 1e-4; tabulated EAM needs ≈ 1e-2: a step spanning the "
                  "tables' knots, docs/temperature.md §3.1)");
  sub->add_flag(
      "--critical", o->critical,
      "Critical stretches: bond inflection (pair potentials) and uniaxial peak stress along x");
  sub->footer(
      "C is ∂²W/∂E∂E (Green–Lagrange strain E; at a stress-free F = I the usual elastic "
      "constants), relaxed-ion by default (W minimised over sublattice shifts).\n"
      "Example:\n  pdcg elastic cu.h5 --json\n  pdcg elastic lj.h5 --F \"1.01 0 0 0 1 0 0 0 1\" "
      "--fit 1.1 --critical");
  return [o] { return run(*o); };
});

}  // namespace
