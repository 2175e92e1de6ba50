// Acceptance: dispersion of FCC delta bodies (Lennard-Jones and EAM Cu) along Γ–X and
// Γ–L equals the lattice dynamics computed here from LAMMPS forces by finite differences, and
// the long-wave sound speeds match √(A/ρ) from LAMMPS energies under homogeneous deformation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <numbers>

#include "../atomistic/potential_test_util.hpp"
#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/dispersion/model.hpp"
#include "pdcg_test.hpp"

#if PDCG_WITH_LAMMPS
using namespace pdcg;
using namespace pdcg::atomistic;
using namespace pdcg::dispersion;

namespace {

Atoms perfect_fcc(int n, double a, double mass) {
  Atoms at = test::cubic_lattice(n, n, n, a, 4, 0.0, false, 0);
  at.type_mass = {0.0, mass};
  return at;
}

/// Lattice dynamics from LAMMPS: Φ(j,0)_{αβ} = −∂F_jα/∂u_0β by central differences (step h),
/// D(κ)_{αβ} = (1/M) Σ_j Φ(j,0)_{βα} e^{iκ·(R_j − R_0)} (minimum-image R). Φ(j,0) is non-zero
/// up to the cutoff for pair potentials and up to twice the cutoff for EAM (through common
/// neighbours), so the supercell must exceed twice that range to avoid image aliasing.
struct LammpsLatticeDynamics {
  Atoms atoms;
  std::vector<Eigen::Matrix3d> phi;  // per atom j: Φ(j,0)
  double mass;
  LammpsLatticeDynamics(const Atoms& a, const LammpsEngine& engine, double h, double m)
      : atoms(a), mass(m) {
    const std::size_t n = a.size();
    phi.assign(n, Eigen::Matrix3d::Zero());
    for (int beta = 0; beta < 3; ++beta) {
      Atoms p = a, q = a;
      p.x[static_cast<std::size_t>(beta)] += h;
      q.x[static_cast<std::size_t>(beta)] -= h;
      const auto fp = engine.evaluate(p).force, fq = engine.evaluate(q).force;
      for (std::size_t j = 0; j < n; ++j)
        for (int alpha = 0; alpha < 3; ++alpha)
          phi[j](alpha, beta) = -(fp[3 * j + static_cast<std::size_t>(alpha)] -
                                  fq[3 * j + static_cast<std::size_t>(alpha)]) /
                                (2 * h);
    }
  }
  Eigen::Vector3d omega(const Eigen::Vector3d& kappa) const {
    Eigen::Matrix3cd D = Eigen::Matrix3cd::Zero();
    for (std::size_t j = 0; j < atoms.size(); ++j) {
      const Eigen::Vector3d r = atoms.box.minimum_image(
          Eigen::Vector3d(atoms.x[3 * j] - atoms.x[0], atoms.x[3 * j + 1] - atoms.x[1],
                          atoms.x[3 * j + 2] - atoms.x[2]));
      D += phi[j].transpose().cast<std::complex<double>>() * std::polar(1.0, kappa.dot(r)) / mass;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3cd> es(0.5 * (D + D.adjoint()),
                                                       Eigen::EigenvaluesOnly);
    Eigen::Vector3d w;
    for (int i = 0; i < 3; ++i) w[i] = std::sqrt(std::max(0.0, es.eigenvalues()[i]));
    return w;
  }
};

/// A_{iJiJ} = (1/V) ∂²E/∂F_iJ² at F = I, from LAMMPS energies under F = I + η e_i⊗e_J.
double lammps_wave_modulus(const Atoms& a, const LammpsEngine& engine, int i, int J, double eta) {
  auto energy = [&](double e) {
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(i, J) += e;
    Atoms d = a;
    for (std::size_t k = 0; k < a.size(); ++k) {
      const Eigen::Vector3d y = F * Eigen::Vector3d(a.x[3 * k], a.x[3 * k + 1], a.x[3 * k + 2]);
      for (int c = 0; c < 3; ++c) d.x[3 * k + static_cast<std::size_t>(c)] = y[c];
    }
    const Eigen::Matrix3d H = F * a.box.h();  // upper triangular for these F (i ≤ J)
    d.box.hi = d.box.lo + Eigen::Vector3d(H(0, 0), H(1, 1), H(2, 2));
    d.box.xy = H(0, 1);
    d.box.xz = H(0, 2);
    d.box.yz = H(1, 2);
    return engine.evaluate(d).total_energy;
  };
  return (energy(eta) + energy(-eta) - 2 * energy(0.0)) / (eta * eta * a.box.volume());
}

void check_lattice(const std::string& commands, int cells, double a, double mass, double h_fd,
                   double mvv2e) {
  const PotentialSpec spec = read_potential_commands_from_string(commands, "test potential", 1);
  const auto potential = make_potential(spec);
  const LammpsEngine engine(spec);
  const Atoms atoms = perfect_fcc(cells, a, mass);
  ASSERT_GT(cells * a, 2 * potential->cutoff() * (potential->pairwise() ? 1 : 2));
  const Families fam = build_families(atoms, {potential->cutoff()});
  const std::int32_t atom0[] = {0};
  const LinearisedFamilies lin(*potential, fam, atoms.x, atoms.type, atom0);
  const std::vector<double> masses(atoms.size(), mass);
  const std::pair<std::int32_t, double> site[] = {{0, 1.0}};
  // the reference in the unit style's time units: ω² = D/(M·mvv2e)
  const LammpsLatticeDynamics ref(atoms, engine, h_fd, mass * mvv2e);

  // Γ–X and Γ–L, 10 points each
  std::vector<double> model, lammps;
  for (const auto& [s, k] : path("fcc", a, "G-X", 10)) {
    const auto w = point_omega(lin, site, masses, k, mvv2e);
    const auto r = ref.omega(k);
    model.insert(model.end(), {w[0], w[1], w[2]});
    lammps.insert(lammps.end(), {r[0], r[1], r[2]});
  }
  for (const auto& [s, k] : path("fcc", a, "G-L", 10)) {
    const auto w = point_omega(lin, site, masses, k, mvv2e);
    const auto r = ref.omega(k);
    model.insert(model.end(), {w[0], w[1], w[2]});
    lammps.insert(lammps.end(), {r[0], r[1], r[2]});
  }
  const double wmax = *std::max_element(lammps.begin(), lammps.end());
  // Central differences of LAMMPS forces (step h_fd): error O(h²) ≈ 1e-6 relative; ω = 0 at Γ
  // needs the absolute part.
  EXPECT_TRUE(test::all_close(model, lammps, {1e-5 * wmax, 1e-5}));

  // Long waves along [100]: ρ v_L² = A_1111, ρ v_T² = A_2121 (F-based moduli: the long-wave
  // limit of the dynamical matrix, valid also under the lattice's residual stress).
  const double rho = mvv2e * mass * static_cast<double>(atoms.size()) / atoms.box.volume();
  const double vL = std::sqrt(lammps_wave_modulus(atoms, engine, 0, 0, 1e-4) / rho);
  const double vT =
      std::sqrt(lammps_wave_modulus(atoms, engine, 0, 1, 1e-4) / rho);  // A_1212 = A_2121 (cubic)
  const double k = 0.01 * 2 * std::numbers::pi / a;  // κa = 0.063: dispersion correction < 0.1%
  const auto w = point_omega(lin, site, masses, {k, 0, 0}, mvv2e);
  EXPECT_NEAR(w[2] / k, vL, 0.01 * vL);  // acceptance: sound speeds within 1%
  EXPECT_NEAR(w[0] / k, vT, 0.01 * vT);
  EXPECT_NEAR(w[1] / k, vT, 0.01 * vT);
  std::printf(
      "  ω_max %.6g, model max rel. dev. %.3g; v_L %.6g (LAMMPS %.6g), v_T %.6g (LAMMPS %.6g)\n",
      wmax, test::max_norm_relative_error(model, lammps), w[2] / k, vL, w[0] / k, vT);
}

}  // namespace

TEST(LatticeDispersion, FccLennardJonesMatchesLammpsLatticeDynamics) {
  check_lattice("units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0 2.5\n", 4,
                1.5874010519681994, 1.0, 1e-4, 1.0);
}

TEST(LatticeDispersion, FccCopperEamMatchesLammpsLatticeDynamics) {
  check_lattice("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n", 6, 3.615, 63.55, 1e-4,
                1.0364269e-4);  // 6a > 4 r_c = 19.8
}
#endif

#if PDCG_WITH_LAMMPS
// A finite-difference fallback for potentials evaluated through LAMMPS. A style pdcg
// has no native force states for (lj/smooth/linear) is evaluated by embedded LAMMPS (force
// states by central differences of pe/atom); its tangent is the central-difference default of
// Potential. The chain's dispersion has the closed form (Born & Huang ch. V)
//   longitudinal ω² = (2/M) Σ_n φ''(nh)(1 − cos nκh),  transverse ω² = (2/M) Σ_n φ'(nh)/(nh) (1 −
//   cos nκh),
// with φ = φ_LJ(r) − φ_LJ(r_c) − (r − r_c) φ_LJ'(r_c) (so φ'' = φ_LJ'', φ' = φ_LJ' − φ_LJ'(r_c)).
TEST(LatticeDispersion, EmbeddedLammpsStyleByFiniteDifferencesMatchesClosedForm) {
  const double h = 1.1, rc = 2.5;
  const int n = 16;
  const PotentialSpec spec = read_potential_commands_from_string(
      "units lj\nmass 1 1.0\npair_style lj/smooth/linear 2.5\npair_coeff 1 1 1.0 1.0\n",
      "test potential", 1);
  const auto potential = make_potential(spec);
  Atoms a;
  a.box.lo = {0, -10, -10};
  a.box.hi = {n * h, 10, 10};
  a.box.periodic = {true, false, false};
  a.type_mass = {0.0, 1.0};
  for (int i = 0; i < n; ++i) {
    a.id.push_back(i + 1);
    a.type.push_back(1);
    a.x.insert(a.x.end(), {i * h, 0.0, 0.0});
  }
  const Families fam = build_families(a, {potential->cutoff()});
  const std::int32_t atom0[] = {0};
  const LinearisedFamilies lin(*potential, fam, a.x, a.type, atom0);
  const std::vector<double> masses(a.size(), 1.0);
  const std::pair<std::int32_t, double> site[] = {{0, 1.0}};
  auto d1 = [](double r) { return 4 * (-12 * std::pow(r, -13) + 6 * std::pow(r, -7)); };
  auto d2 = [](double r) { return 4 * (156 * std::pow(r, -14) - 42 * std::pow(r, -8)); };
  double worst = 0, wmax = 0;
  for (double k : {0.3, 1.0, 2.0, std::numbers::pi / h}) {
    double wl2 = 0, wt2 = 0;
    for (int m = 1; m * h < rc; ++m) {
      wl2 += 2 * d2(m * h) * (1 - std::cos(m * k * h));
      wt2 += 2 * (d1(m * h) - d1(rc)) / (m * h) * (1 - std::cos(m * k * h));
    }
    const auto w = point_omega(lin, site, masses, {k, 0, 0});
    const double wt = wt2 >= 0 ? std::sqrt(wt2) : -std::sqrt(-wt2), wl = std::sqrt(wl2);
    worst = std::max({worst, std::abs(w[2] - wl), std::abs(w[0] - wt), std::abs(w[1] - wt)});
    wmax = std::max(wmax, wl);
  }
  // the acceptance tolerance for central differences (1e-5 relative); FD tangent (step 6e-6 |ξ|) of
  // FD force states (≈ 1e-10 relative) bounds the error by ≈ 2e-5, measured 2e-8
  EXPECT_LT(worst, 1e-5 * wmax);
  std::printf("  embedded lj/smooth/linear chain: worst |ω − closed form| = %.3g of ω_max %.6g\n",
              worst / wmax, wmax);
}
#endif
