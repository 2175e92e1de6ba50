/// `pdcg energy BODY.h5 --F "F11 F12 F13 F21 F22 F23 F31 F32 F33" [--json]`: total energy and
/// energy per reference volume under the homogeneous deformation y = F x (H_y = F H); with
/// --stress also the first Piola–Kirchhoff stress P = ∂W/∂F (Evaluator::stress: for statistical
/// bodies the expected value, at F = I minus the virial part of LAMMPS's pressure tensor).
/// --quasi-harmonic T: also the quasi-harmonic free energy density W_T(F), with --stress its
/// stress P_T = ∂W_T/∂F (body::QuasiHarmonicCauchyBorn; docs/temperature.md §3.1).
#include <fmt/format.h>

#include <cstdio>
#include <optional>
#include <string>

#include "body_cli_util.hpp"
#include "command.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/body/quasi_harmonic.hpp"
#include "pdcg/core/units.hpp"

namespace {

struct Options {
  std::string body, F;
  bool json = false, stress = false;
  std::optional<double> quasi_harmonic;
};

int run(const Options& o) {
  using namespace pdcg;
  const Eigen::Matrix3d F = cli::body_util::deformation_gradient(o.F, "--F");
  const body::Body b = body::read_body(o.body);
  body::Evaluator ev(b);
  const body::Evaluation e = ev.homogeneous(F);
  const double vol = b.reference_volume();
  Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
  if (o.stress) P = ev.stress(F);
  const UnitNames un = unit_names(b.units);
  const std::string unit = std::string(to_string(b.units));
  // the volume's unit: length^d of the body's dimension (area for 2D, length for 1D)
  const std::string len = std::string(un.length);
  const std::string vol_unit = b.dimension == 1 ? len : fmt::format("{}^{}", len, b.dimension);
  const std::string dens_unit = fmt::format("{}/{}", un.energy, vol_unit);
  std::string qh_json, qh_text;
  if (o.quasi_harmonic) {
    const body::QuasiHarmonic q = body::quasi_harmonic(b, F, *o.quasi_harmonic);
    qh_json = fmt::format(
        ", \"free_energy_density\": {:.17g}, \"sum_ln_omega\": {:.17g}, \"temperature\": {:.17g}",
        q.free_energy_density, q.sum_ln_omega, *o.quasi_harmonic);
    qh_text = fmt::format("free_energy_density {:.17g} {}\nsum_ln_omega {:.17g}\n",
                          q.free_energy_density, dens_unit, q.sum_ln_omega);
    if (o.stress) {  // P_T = ∂W_T/∂F of the quasi-harmonic material (13 Hessians)
      const Eigen::Matrix3d PT =
          body::QuasiHarmonicCauchyBorn(b, *o.quasi_harmonic).evaluate(F, false).P;
      std::string v;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) v += fmt::format("{}{:.17g}", r + c ? ", " : "", PT(r, c));
      qh_json += fmt::format(", \"free_energy_stress\": [{}]", v);
      std::erase(v, ',');
      qh_text += fmt::format("free_energy_stress {} {}\n", v, dens_unit);
    }
  }
  std::string stress_json, stress_text;
  if (o.stress) {
    std::string v;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) v += fmt::format("{}{:.17g}", r + c ? ", " : "", P(r, c));
    stress_json = fmt::format(", \"stress\": [{}], \"stress_unit\": \"{}\"", v, dens_unit);
    std::string w = v;
    std::erase(w, ',');
    stress_text = fmt::format("stress {} {}\n", w, dens_unit);
  }
  if (o.json)
    std::printf(
        "{\"energy\": %.17g, \"energy_density\": %.17g, \"volume\": %.17g, \"units\": \"%s\", "
        "\"energy_unit\": \"%s\", \"energy_density_unit\": \"%s\", \"volume_unit\": \"%s\"%s%s}\n",
        e.energy, e.energy / vol, vol, unit.c_str(), std::string(un.energy).c_str(),
        dens_unit.c_str(), vol_unit.c_str(), stress_json.c_str(), qh_json.c_str());
  else
    std::printf("energy %.17g %s\nenergy_density %.17g %s\nvolume %.17g %s\nunits %s\n%s%s",
                e.energy, std::string(un.energy).c_str(), e.energy / vol, dens_unit.c_str(), vol,
                vol_unit.c_str(), unit.c_str(), stress_text.c_str(), qh_text.c_str());
  return 0;
}

pdcg::cli::Registration reg(115, [](CLI::App& app) -> pdcg::cli::Runner {
  auto* sub =
      app.add_subcommand("energy", "Energy and energy density under a homogeneous deformation F");
  auto o = std::make_shared<Options>();
  sub->add_option("body", o->body, "Model file (pdcg-body)")->required();
  sub->add_option("--F", o->F, "Deformation gradient, 9 numbers row-major")->required();
  sub->add_flag("--json", o->json, "JSON output: energy, energy_density, volume and their units");
  sub->add_flag("--stress", o->stress,
                "Also the first Piola–Kirchhoff stress P = dW/dF (9 numbers row-major, energy per "
                "reference volume; statistical bodies: expected value)");
  sub->add_option(
      "--quasi-harmonic", o->quasi_harmonic,
      "Also the classical quasi-harmonic free energy density W_T(F) at this "
      "temperature (periodic 3D delta bodies of up to 3000 atoms, or homogenised or rescaled "
      "models of one: the atoms' free energy; hbar = 1: defined up "
      "to an F-independent constant; docs/temperature.md); with --stress also its stress "
      "P_T = dW_T/dF (free_energy_stress)");
  sub->footer("Example:\n  pdcg energy body.h5 --F \"1.01 0 0 0 1 0 0 0 1\" --json");
  return [o] { return run(*o); };
});

}  // namespace
