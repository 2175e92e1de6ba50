// Cauchy–Born material of delta, homogenised and rescaled bodies (docs/elastic.md):
//  - C11, C12, C44 of FCC LJ and FCC Cu (EAM Cu_u3) against LAMMPS: second differences of
//    LAMMPS's total energy of the same perfect crystal under ±Green–Lagrange strain
//    (C_IJKL = ∂²W/∂E_IJ∂E_KL, the definition pdcg reports), via embedded LAMMPS;
//  - the homogenised and rescaled bodies give the same constants (docs/theory.md §3–4);
//  - P against central differences of W, A = ∂P/∂F against central differences of P;
//  - the rescaled potential's analytic tangent against the FD default.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "../atomistic/potential_test_util.hpp"
#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/cauchy_born.hpp"
#include "pdcg/body/cauchy_born_material.hpp"
#include "pdcg/body/statistics.hpp"
#include "pdcg/coarsen/homogenise.hpp"
#include "pdcg/coarsen/kernels.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;
using namespace pdcg::body;
using atomistic::Atoms;

namespace {

Atoms perfect_fcc(int n, double a) { return test::cubic_lattice(n, n, n, a, 4, 0.0, false, 0); }

struct Model {
  atomistic::PotentialSpec spec;
  std::shared_ptr<const atomistic::Potential> pot;
  Atoms atoms;
  Body body;
};

Model model(const std::string& cmds, int cells, double a) {
  Model m;
  m.spec = atomistic::read_potential_commands_from_string(cmds, "cb-test", 1);
  m.pot = atomistic::make_potential(m.spec);
  m.atoms = perfect_fcc(cells, a);
  m.body =
      make_delta_body(m.atoms, m.pot, m.spec, {.dimension = 3, .cutoff = 0.0, .source = "fcc"});
  return m;
}

/// Upper-triangular F with FᵀF = I + 2E (so F·H stays a LAMMPS box for diagonal H).
Eigen::Matrix3d f_of_strain(const Eigen::Matrix3d& E) {
  const Eigen::Matrix3d C = Eigen::Matrix3d::Identity() + 2.0 * E;
  const Eigen::Matrix3d L = C.llt().matrixL();
  return L.transpose();
}

/// LAMMPS energy density of the crystal deformed by F (upper triangular).
double lammps_W(const atomistic::LammpsEngine& engine, const Atoms& ref, const Eigen::Matrix3d& F) {
  Atoms at = ref;
  const Eigen::Matrix3d H = F * ref.box.h();
  at.box.lo = {0, 0, 0};
  at.box.hi = {H(0, 0), H(1, 1), H(2, 2)};
  at.box.xy = H(0, 1);
  at.box.xz = H(0, 2);
  at.box.yz = H(1, 2);
  for (std::size_t i = 0; i < at.size(); ++i) {
    const Eigen::Vector3d y = F * Eigen::Vector3d(ref.x[3 * i], ref.x[3 * i + 1], ref.x[3 * i + 2]);
    for (int c = 0; c < 3; ++c) at.x[3 * i + static_cast<std::size_t>(c)] = y[c];
  }
  return engine.evaluate(at).total_energy / std::abs(ref.box.h().determinant());
}

/// C11, C12, C44 = ∂²W/∂E∂E by second differences of LAMMPS energies (step h in E).
Eigen::Vector3d lammps_constants(const Model& m, double h) {
  const atomistic::LammpsEngine engine(m.spec);
  auto W = [&](double e11, double e22, double e23) {
    Eigen::Matrix3d E = Eigen::Matrix3d::Zero();
    E(0, 0) = e11;
    E(1, 1) = e22;
    E(1, 2) = E(2, 1) = e23;
    return lammps_W(engine, m.atoms, f_of_strain(E));
  };
  const double W0 = W(0, 0, 0);
  const double c11 = (W(h, 0, 0) - 2 * W0 + W(-h, 0, 0)) / (h * h);
  const double c12 = (W(h, h, 0) - W(h, -h, 0) - W(-h, h, 0) + W(-h, -h, 0)) / (4 * h * h);
  // E23 = E32 = s: d²W/ds² = 4 C_2323
  const double c44 = (W(0, 0, h) - 2 * W0 + W(0, 0, -h)) / (4 * h * h);
  return {c11, c12, c44};
}

Eigen::Vector3d cb_constants(const Body& b, Matrix6d* full = nullptr) {
  const CauchyBorn cb(b);
  const Matrix6d C = voigt_elastic_constants(Eigen::Matrix3d::Identity(),
                                             cb.evaluate(Eigen::Matrix3d::Identity()));
  if (full) *full = C;
  return {C(0, 0), C(0, 1), C(3, 3)};
}

void check_against_lammps(const std::string& cmds, int cells, double a, double h) {
  const Model m = model(cmds, cells, a);
  Matrix6d C;
  const Eigen::Vector3d pd = cb_constants(m.body, &C);
  const Eigen::Vector3d ref = lammps_constants(m, h);
  std::printf("  [%s] C11 %.8g (LAMMPS %.8g), C12 %.8g (%.8g), C44 %.8g (%.8g)\n",
              m.pot->style().c_str(), pd[0], ref[0], pd[1], ref[1], pd[2], ref[2]);
  for (int i = 0; i < 3; ++i)
    EXPECT_LT(std::abs(pd[i] - ref[i]) / std::abs(ref[i]), 5e-3)
        << i;  // acceptance vs LAMMPS: 0.5%
  // cubic symmetry of the CB constants (exact for the perfect crystal: round-off)
  EXPECT_NEAR(C(1, 1), C(0, 0), 1e-9 * C(0, 0));
  EXPECT_NEAR(C(4, 4), C(3, 3), 1e-9 * C(0, 0));
  EXPECT_NEAR(C(0, 3), 0.0, 1e-9 * C(0, 0));

  // homogenised (grid incommensurate with the lattice) and rescaled bodies: same constants
  coarsen::GridOptions g;
  g.spacing = 0.83 * a;
  g.shift = {0.31, -0.17, 0.44};
  const Body hom =
      coarsen::homogenise_on_grid(m.body, coarsen::make_kernel("cubic-bspline", 1.3 * a), g);
  const Body res = coarsen::rescale(m.body, 2.5);
  const Body both = coarsen::rescale(hom, 3.0);
  for (const Body* b : {&hom, &res, &both}) {
    const Eigen::Vector3d c = cb_constants(*b);
    // sums of the same terms in another order (and scaled by ε^d / ε^d): round-off
    EXPECT_LT((c - pd).cwiseAbs().maxCoeff() / pd.cwiseAbs().maxCoeff(), 1e-10)
        << to_string(b->kind);
  }
}

}  // namespace

TEST(CauchyBorn, FccLennardJonesMatchesLammps) {
  if (!atomistic::lammps_available()) GTEST_SKIP() << "embedded LAMMPS not enabled";
  // h = 1e-4: truncation O(h²) ≈ 1e-8 and round-off ≈ 1e-13·|U|/h² ≈ 1e-7 relative
  check_against_lammps("units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", 3,
                       1.5599, 1e-4);
}

TEST(CauchyBorn, FccCopperEamMatchesLammps) {
  if (!atomistic::lammps_available()) GTEST_SKIP() << "embedded LAMMPS not enabled";
  check_against_lammps("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n", 3, 3.615, 1e-4);
}

TEST(CauchyBorn, StressAndTangentAgreeWithFiniteDifferences) {
  for (const char* cmds : {"units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n",
                           "units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n"}) {
    const bool lj = std::string(cmds).find("lj/cut") != std::string::npos;
    const Model m = model(cmds, 3, lj ? 1.5599 : 3.615);
    for (const Body& b : {m.body, coarsen::rescale(m.body, 1.7)}) {
      const CauchyBorn cb(b);
      Eigen::Matrix3d F;
      F << 1.03, 0.02, -0.01, 0.015, 0.98, 0.025, -0.02, 0.01, 1.01;
      const CauchyBornState s = cb.evaluate(F);
      const double step =
          1e-6;  // central differences: O(step²) ≈ 1e-12 truncation, round-off ≈ 1e-10
      Eigen::Matrix3d Pfd;
      Matrix9d Afd;
      for (int r = 0; r < 9; ++r) {
        Eigen::Matrix3d Fp = F, Fm = F;
        Fp(r / 3, r % 3) += step;
        Fm(r / 3, r % 3) -= step;
        const CauchyBornState sp = cb.evaluate(Fp, false), sm = cb.evaluate(Fm, false);
        Pfd(r / 3, r % 3) = (sp.W - sm.W) / (2 * step);
        const Eigen::Matrix3d dP = (sp.P - sm.P) / (2 * step);
        for (int q = 0; q < 9; ++q) Afd(q, r) = dP(q / 3, q % 3);
      }
      const double perr = (s.P - Pfd).cwiseAbs().maxCoeff() / s.P.cwiseAbs().maxCoeff();
      const double aerr = (s.A - Afd).cwiseAbs().maxCoeff() / s.A.cwiseAbs().maxCoeff();
      std::printf("  [%s, %s] P vs FD(W) %.2e, A vs FD(P) %.2e, major symmetry %.2e\n",
                  m.pot->style().c_str(), std::string(to_string(b.kind)).c_str(), perr, aerr,
                  (s.A - s.A.transpose()).cwiseAbs().maxCoeff() / s.A.cwiseAbs().maxCoeff());
      EXPECT_LT(perr, 1e-6);  // acceptance (FD accuracy ≈ 1e-9)
      EXPECT_LT(aerr, 1e-6);  // acceptance
      EXPECT_LT((s.A - s.A.transpose()).cwiseAbs().maxCoeff(),
                1e-10 * s.A.cwiseAbs().maxCoeff());  // round-off
    }
  }
}

TEST(CauchyBorn, RescaledPotentialTangentIsAnalytic) {
  const Model m = model("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n", 3, 3.615);
  const Body r = coarsen::rescale(m.body, 2.0);
  const auto& fam = r.families;
  const std::int64_t n = fam.offset[1] - fam.offset[0];
  std::vector<int> nt(static_cast<std::size_t>(n), 1);
  std::vector<double> Y(static_cast<std::size_t>(3 * n));
  atomistic::family_bond_vectors(fam, r.x, 0, Y.data());
  for (std::size_t i = 0; i < Y.size(); ++i) Y[i] *= 1.0 + 0.01 * std::sin(static_cast<double>(i));
  atomistic::FamilyState f;
  f.type = 1;
  f.size = n;
  f.neighbor_type = nt.data();
  f.bond = Y.data();
  const auto nn = static_cast<std::size_t>(9 * n * n);
  std::vector<double> Ka(nn), Kf(nn), work(atomistic::Potential::tangent_workspace(n));
  r.potential->force_state_tangent(f, Ka.data(), work.data());
  r.potential->atomistic::Potential::force_state_tangent(f, Kf.data(), work.data());
  EXPECT_TRUE(test::all_close(Ka, Kf, {0, 1e-6}));  // FD default ≈ 1e-9 on smooth pieces
  double scale = 0, diff = 0;
  for (std::size_t i = 0; i < nn; ++i) {
    scale = std::max(scale, std::abs(Kf[i]));
    diff = std::max(diff, std::abs(Ka[i] - Kf[i]));
  }
  EXPECT_LT(diff / scale, 1e-7);  // as in test_potential_tangent
}

TEST(CauchyBorn, NeoHookeanFitAndCriticalStretch) {
  const Model m =
      model("units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", 3, 1.5599);
  const CauchyBorn cb(m.body);
  Matrix6d C;
  cb_constants(m.body, &C);
  const Moduli mod = moduli(C, 3);
  // hydrostatic set: Ī₁ = 3, so the fit sees K only; K(1 ± 3e)… = the cubic bulk modulus
  // (C11 + 2C12)/3 up to O(strain) = 1e-3 relative terms
  std::vector<Eigen::Matrix3d> hydro;
  for (double l : {0.999, 0.9995, 1.0005, 1.001}) hydro.push_back(l * Eigen::Matrix3d::Identity());
  const auto fk = fit_neo_hookean(cb, hydro);
  EXPECT_NEAR(fk.bulk, mod.bulk_voigt, 5e-3 * mod.bulk_voigt);
  // a cubic crystal is not isotropic: the full fit has a visible error (reported, not zero)
  const auto full = fit_neo_hookean(cb, fit_deformations(3, 1.2, 4));
  std::printf(
      "  3D FCC LJ neo-Hookean (λ ≤ 1.2): μ %.5g K %.5g rel.err %.3g (C: K %.5g, G_V %.5g, G_R "
      "%.5g)\n",
      full.mu, full.bulk, full.relative_error, mod.bulk_voigt, mod.shear_voigt, mod.shear_reuss);
  EXPECT_GT(full.relative_error, 0.0);

  const double infl = pair_inflection_stretch(*m.pot, 1, 1);
  // LJ closed form: r_infl/r_min = (26/7)^(1/6) / 2^(1/6); bisection to 1e-12
  EXPECT_NEAR(infl, std::pow(13.0 / 7.0, 1.0 / 6.0), 1e-9);
  const double lc = uniaxial_peak_stretch(cb, Eigen::Vector3d(1, 0, 0));
  std::printf("  LJ bond inflection stretch %.6f, CB uniaxial [100] peak stretch %.6f\n", infl, lc);
  EXPECT_GT(lc, 1.0);
  EXPECT_THROW(
      pair_inflection_stretch(
          *model("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n", 2, 3.615).pot, 1, 1),
      InputError);
}

TEST(CauchyBorn, TriangularSheetPlaneStrainIsNeoHookeanAtSmallStrain) {
  // 2D triangular lattice with a pair potential: in-plane isotropic with the Cauchy relation
  // C12 = C66, i.e. exactly the small-strain plane-strain neo-Hookean law with μ = C66,
  // K = C12 + 2μ/3 (C11 = K + 4μ/3 = 3μ). The fit at small strain must find them.
  Atoms at;
  const double a = 1.11, h = a * std::sqrt(3.0) / 2;
  const int nx = 6, ny = 6;
  at.box.hi = {nx * a, ny * h, 10.0};
  at.box.periodic = {true, true, false};
  std::int64_t id = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      at.id.push_back(++id);
      at.type.push_back(1);
      at.x.insert(at.x.end(), {(i + 0.5 * (j % 2)) * a, j * h, 5.0});
    }
  const auto spec = atomistic::read_potential_commands_from_string(
      "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", "tri", 1);
  const std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  const Body b = make_delta_body(at, pot, spec, {.dimension = 2, .cutoff = 0.0, .source = "tri"});
  const CauchyBorn cb(b);
  const Matrix6d C = voigt_elastic_constants(Eigen::Matrix3d::Identity(),
                                             cb.evaluate(Eigen::Matrix3d::Identity()));
  EXPECT_NEAR(C(0, 0), C(1, 1), 1e-9 * C(0, 0));      // isotropy (round-off)
  EXPECT_NEAR(C(0, 0), 3 * C(0, 1), 1e-9 * C(0, 0));  // Cauchy relation + isotropy (round-off)
  EXPECT_NEAR(C(5, 5), C(0, 1), 1e-9 * C(0, 0));
  const auto fit = fit_neo_hookean(cb, fit_deformations(2, 1.0002, 2));
  const double mu = C(5, 5), K = C(0, 1) + 2 * mu / 3;
  std::printf(
      "  triangular LJ: C11 %.6g C12 %.6g C66 %.6g; fit μ %.6g (%.6g) K %.6g (%.6g), rel.err "
      "%.2e\n",
      C(0, 0), C(0, 1), C(5, 5), fit.mu, mu, fit.bulk, K, fit.relative_error);
  EXPECT_NEAR(fit.mu, mu, 2e-3 * mu);  // O(strain) = 2e-4 higher-order terms, with margin
  EXPECT_NEAR(fit.bulk, K, 2e-3 * K);
  EXPECT_LT(fit.relative_error, 1e-2);
  const auto big = fit_neo_hookean(cb, fit_deformations(2, 1.1, 5));
  std::printf("  triangular LJ, λ ≤ 1.1: μ %.6g K %.6g rel.err %.3g\n", big.mu, big.bulk,
              big.relative_error);
}

TEST(CauchyBorn, SolverMaterialAdapterAndEnvironmentClasses) {
  const Model m = model("units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n", 3, 3.615);
  const auto body = std::make_shared<const Body>(m.body);
  const CauchyBornMaterial mat(body, "cu");
  EXPECT_EQ(mat.cauchy_born().environments(), 1u);  // perfect FCC: one environment
  EXPECT_EQ(mat.dimension(), 3);
  Eigen::Matrix3d F;
  F << 1.02, 0.01, 0.0, -0.01, 0.99, 0.02, 0.0, 0.01, 1.01;
  double psi;
  solver::Mat3 P;
  solver::Tangent A;
  ASSERT_TRUE(mat.evaluate(F, &psi, &P, &A));
  // every atom evaluated (a perturbed copy has N environments): same W, P, A to round-off
  Atoms pert = m.atoms;
  pert.x[0] += 1e-3;
  const Body bp =
      make_delta_body(pert, m.pot, m.spec, {.dimension = 3, .cutoff = 0.0, .source = "p"});
  const CauchyBorn cbp(bp);
  EXPECT_GT(cbp.environments(), 1u);
  const CauchyBornState s = CauchyBorn(m.body).evaluate(F);
  EXPECT_NEAR(psi, s.W, 1e-14 * std::abs(s.W));
  EXPECT_FALSE(mat.evaluate(-F, &psi, &P, &A));  // det F < 0: inadmissible
  const auto copy = mat.clone();
  double psi2;
  ASSERT_TRUE(copy->evaluate(F, &psi2, nullptr, nullptr));
  EXPECT_EQ(psi2, psi);
}

// The refusal for statistical bodies names the option that makes a body statistical
// (`pdcg atoms2pd --density statistical`; `--statistics` only chooses the form of the density).
TEST(CauchyBorn, StatisticalRefusalNamesTheRealOption) {
  Model m =
      model("units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", 2, 1.5599);
  Statistics s;
  s.covariance.assign(6 * m.body.size(), 0.0);
  for (std::size_t k = 0; k < m.body.size(); ++k)
    s.set_covariance(k, 1e-4 * Eigen::Matrix3d::Identity());
  make_statistical(m.body, std::move(s));
  try {
    const CauchyBorn cb(m.body);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("without `--density statistical`"), std::string::npos) << what;
    EXPECT_EQ(what.find("--statistics`"), std::string::npos) << what;
  }
}

// Clamped-ion note: none for a perfect Bravais lattice; a warning for a crystal with a basis
// whose sites are not inversion centres; an info note for a crystal that is not perfect.
TEST(CauchyBorn, LatticeNote) {
  const Model m =
      model("units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", 3, 1.5599);
  const CauchyBorn cb(m.body);
  EXPECT_TRUE(cb.lattice().bravais());
  EXPECT_TRUE(cauchy_born_lattice_note(cb.lattice()).text.empty());
  LatticeInfo basis;
  basis.perfect = true;
  basis.basis = 2;
  basis.summary = "perfect crystal with a basis of 2 atoms per primitive cell";
  const auto w = cauchy_born_lattice_note(basis);
  EXPECT_TRUE(w.warning);
  EXPECT_NE(w.text.find("clamped-ion"), std::string::npos);
  basis.centrosymmetric = true;  // B2, NaCl, L1₂: clamped-ion CB is exact
  EXPECT_TRUE(cauchy_born_lattice_note(basis).text.empty());
  Atoms pert = m.atoms;
  pert.x[0] += 1e-3;
  const Body bp =
      make_delta_body(pert, m.pot, m.spec, {.dimension = 3, .cutoff = 0.0, .source = "p"});
  const CauchyBorn cbp(bp);
  EXPECT_FALSE(cbp.lattice().perfect);
  const auto n = cauchy_born_lattice_note(cbp.lattice());
  EXPECT_FALSE(n.warning);
  EXPECT_NE(n.text.find("not a perfect crystal"), std::string::npos) << n.text;
}
