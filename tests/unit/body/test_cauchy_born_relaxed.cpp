// Cauchy–Born with inner relaxation of crystals with a basis (docs/theory.md §11,
// docs/elastic.md §2.2):
//  - the relaxed state is LAMMPS's equilibrium: LAMMPS's energy of the atoms at F·X + s*
//    equals pdcg's relaxed W and LAMMPS's force on every atom vanishes (diamond Si, sw and
//    tersoff; hcp LJ), while at s = 0 (clamped) the forces do not;
//  - P = ∂W/∂F (central differences of the relaxed W) and A = ∂P/∂F (central differences of
//    the relaxed P, Schur complement) at a general F;
//  - Bravais lattices (FCC LJ, FCC Cu eam): relaxation is a no-op, bitwise; B2 (every atom a
//    centre of inversion): shifts and corrections vanish to round-off;
//  - homogenised and rescaled bodies keep the relaxed constants (W_ε = W);
//  - bad input: a vacancy under mode relaxed is an InputError naming the lattice and the fix;
//    the per-point sums refuse a body-level relaxing material (the per-point one relaxes with
//    the bulk's shifts: test_per_point_relaxed.cpp).
// Relaxed constants against LAMMPS's minimised stress differences: tests/cli/elastic_relaxed.sh.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/cauchy_born.hpp"
#include "pdcg/body/cauchy_born_material.hpp"
#include "pdcg/coarsen/homogenise.hpp"
#include "pdcg/coarsen/kernels.hpp"
#include "pdcg/coarsen/rescale.hpp"
#include "pdcg/core/error.hpp"

using namespace pdcg;
using namespace pdcg::body;
using atomistic::Atoms;

namespace {

/// n×n×n cubic cells of edge a with the fractional basis `basis` (type per site).
Atoms cubic_crystal(int n, double a, const std::vector<Eigen::Vector3d>& basis,
                    const std::vector<int>& types) {
  Atoms at;
  at.box.hi = {n * a, n * a, n * a};
  std::int64_t id = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (std::size_t s = 0; s < basis.size(); ++s) {
          at.id.push_back(++id);
          at.type.push_back(types[s]);
          at.x.push_back((i + basis[s][0]) * a);
          at.x.push_back((j + basis[s][1]) * a);
          at.x.push_back((k + basis[s][2]) * a);
        }
  return at;
}

Atoms diamond(int n, double a) {
  std::vector<Eigen::Vector3d> b;
  for (const Eigen::Vector3d& f : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.5, 0.5, 0),
                                   Eigen::Vector3d(0.5, 0, 0.5), Eigen::Vector3d(0, 0.5, 0.5)}) {
    b.push_back(f);
    b.push_back(f + Eigen::Vector3d(0.25, 0.25, 0.25));
  }
  return cubic_crystal(n, a, b, std::vector<int>(8, 1));
}

/// hcp with ideal c/a: orthogonal cell a × √3a × c, 4 atoms.
Atoms hcp(int nx, int ny, int nz, double a) {
  const double b = std::sqrt(3.0) * a, c = std::sqrt(8.0 / 3.0) * a;
  Atoms at;
  at.box.hi = {nx * a, ny * b, nz * c};
  const double f[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 5.0 / 6.0, 0.5}, {0, 1.0 / 3.0, 0.5}};
  std::int64_t id = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (const auto& s : f) {
          at.id.push_back(++id);
          at.type.push_back(1);
          at.x.push_back((i + s[0]) * a);
          at.x.push_back((j + s[1]) * b);
          at.x.push_back((k + s[2]) * c);
        }
  return at;
}

struct Model {
  atomistic::PotentialSpec spec;
  std::shared_ptr<const atomistic::Potential> pot;
  Atoms atoms;
  Body body;
};

Model model(const std::string& cmds, Atoms atoms, int ntypes = 1) {
  Model m;
  m.spec = atomistic::read_potential_commands_from_string(cmds, "relax-test", ntypes);
  m.pot = atomistic::make_potential(m.spec);
  m.atoms = std::move(atoms);
  m.body = make_delta_body(m.atoms, m.pot, m.spec, {.dimension = 3, .cutoff = 0.0, .source = "t"});
  return m;
}

std::string potential_path(const char* name) {
  const auto p = atomistic::find_potential_file(name);
  return p ? *p : std::string("/usr/share/lammps/potentials/") + name;
}
std::string sw_cmds() {
  return "units metal\nmass 1 28.0855\npair_style sw\npair_coeff * * " + potential_path("Si.sw") +
         " Si\n";
}
std::string tersoff_cmds() {
  return "units metal\nmass 1 28.0855\npair_style tersoff\npair_coeff * * " +
         potential_path("Si.tersoff") + " Si\n";
}
const char* lj_cmds = "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n";

Eigen::Matrix3d general_F() {
  Eigen::Matrix3d F;
  F << 1.004, 0.006, -0.003, 0.002, 0.997, 0.005, -0.004, 0.001, 1.003;
  return F;
}

/// LAMMPS energy and max |force| of the crystal with atom k at F·X_k + s_{site(k)} in the
/// box F·H.
std::pair<double, double> lammps_at(const Model& m, const LatticeInfo& lat,
                                    const Eigen::Matrix3d& F, const std::vector<double>& s) {
  const atomistic::LammpsEngine engine(m.spec);
  Atoms at = m.atoms;
  const Eigen::Matrix3d H = F * m.atoms.box.h();
  // LAMMPS needs an upper-triangular box: rotate with the QR factor (energy is objective)
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(H);
  Eigen::Matrix3d Q = qr.householderQ();
  Eigen::Matrix3d R = Q.transpose() * H;
  for (int d = 0; d < 3; ++d)
    if (R(d, d) < 0) {
      R.row(d) *= -1;
      Q.col(d) *= -1;
    }
  at.box.lo = {0, 0, 0};
  at.box.hi = {R(0, 0), R(1, 1), R(2, 2)};
  at.box.xy = R(0, 1);
  at.box.xz = R(0, 2);
  at.box.yz = R(1, 2);
  for (std::size_t i = 0; i < at.size(); ++i) {
    const auto q = static_cast<std::size_t>(lat.class_of[i]);
    const Eigen::Vector3d y =
        Q.transpose() *
        (F * Eigen::Vector3d(m.atoms.x[3 * i], m.atoms.x[3 * i + 1], m.atoms.x[3 * i + 2]) +
         Eigen::Vector3d(s[3 * q], s[3 * q + 1], s[3 * q + 2]));
    for (int c = 0; c < 3; ++c) at.x[3 * i + static_cast<std::size_t>(c)] = y[c];
  }
  const auto r = engine.evaluate(at);
  double fmax = 0;
  for (double f : r.force) fmax = std::max(fmax, std::abs(f));
  return {r.total_energy, fmax};
}

void check_relaxed_state_is_lammps_equilibrium(const Model& m, const char* name) {
  const CauchyBorn cb(m.body, IonRelaxation::relaxed);
  ASSERT_TRUE(cb.relaxing()) << name;
  const Eigen::Matrix3d F = general_F();
  const CauchyBornState st = cb.evaluate(F, false);
  const CauchyBorn clamped(m.body, IonRelaxation::clamped);
  const double Wc = clamped.energy(F);
  const double V = m.body.reference_volume();
  const auto [E, fmax] = lammps_at(m, cb.lattice(), F, st.shift);
  const auto [Ec, fmaxc] = lammps_at(m, cb.lattice(), F, std::vector<double>(st.shift.size(), 0));
  std::printf(
      "  [%s] relaxed W %.12g (LAMMPS %.12g), clamped %.12g; max|f| relaxed %.2e, "
      "clamped %.2e; shift of site 1 (%.3g %.3g %.3g), %d Newton steps\n",
      name, st.W, E / V, Wc, fmax, fmaxc, st.shift[3], st.shift[4], st.shift[5], st.iterations);
  // same energy as LAMMPS's of the same positions: round-off of the sums (≈1e-14 relative)
  EXPECT_NEAR(st.W, E / V, 1e-10 * std::abs(E / V)) << name;
  EXPECT_NEAR(Wc, Ec / V, 1e-10 * std::abs(Ec / V)) << name;
  // the minimum: LAMMPS's forces vanish (converged to 1e-12 d_nn in the shifts: forces
  // ≈ K·1e-12 Å, far below 1e-7 eV/Å), where the clamped positions carry forces
  EXPECT_LT(fmax, 1e-7 * std::max(1.0, fmaxc)) << name;
  EXPECT_GT(fmaxc, 1e-4) << name;  // the strain does force the sublattices apart
  EXPECT_LT(st.W, Wc) << name;
}

/// max relative differences of P vs FD of W, and A vs FD of P (central, step h).
std::pair<double, double> fd_errors(const CauchyBorn& cb, const Eigen::Matrix3d& F, double h) {
  const CauchyBornState st = cb.evaluate(F, true);
  Eigen::Matrix3d Pfd;
  Matrix9d Afd;
  for (int r = 0; r < 9; ++r) {
    Eigen::Matrix3d Fp = F, Fm = F;
    Fp(r / 3, r % 3) += h;
    Fm(r / 3, r % 3) -= h;
    const CauchyBornState sp = cb.evaluate(Fp, false), sm = cb.evaluate(Fm, false);
    Pfd(r / 3, r % 3) = (sp.W - sm.W) / (2 * h);
    const Eigen::Matrix3d dP = (sp.P - sm.P) / (2 * h);
    for (int q = 0; q < 9; ++q) Afd(q, r) = dP(q / 3, q % 3);
  }
  return {(Pfd - st.P).cwiseAbs().maxCoeff() / st.P.cwiseAbs().maxCoeff(),
          (Afd - st.A).cwiseAbs().maxCoeff() / st.A.cwiseAbs().maxCoeff()};
}

}  // namespace

TEST(CauchyBornRelaxed, RelaxedStateIsLammpsEquilibrium) {
  check_relaxed_state_is_lammps_equilibrium(model(sw_cmds(), diamond(3, 5.431)), "Si sw");
  check_relaxed_state_is_lammps_equilibrium(model(tersoff_cmds(), diamond(3, 5.432)), "Si tersoff");
  check_relaxed_state_is_lammps_equilibrium(model(lj_cmds, hcp(5, 3, 3, 1.09)), "hcp LJ");
}

TEST(CauchyBornRelaxed, StressAndTangentAreDerivativesOfTheRelaxedEnergy) {
  for (const auto& [m, name] : {std::pair{model(sw_cmds(), diamond(3, 5.431)), "Si sw"},
                                std::pair{model(tersoff_cmds(), diamond(3, 5.432)), "Si tersoff"},
                                std::pair{model(lj_cmds, hcp(5, 3, 3, 1.09)), "hcp LJ"}}) {
    const CauchyBorn cb(m.body);
    ASSERT_TRUE(cb.relaxing());
    // h = 1e-5: truncation ~h²·W'''/W'' ≈ 1e-10, round-off ~1e-16·W/h² … 1e-16/h ≈ 1e-11
    const auto [ep, ea] = fd_errors(cb, general_F(), 1e-5);
    std::printf("  [%s] relaxed P vs FD of W %.2e, A vs FD of P %.2e\n", name, ep, ea);
    EXPECT_LT(ep, 1e-6) << name;  // acceptance of the task: 1e-6 relative
    EXPECT_LT(ea, 1e-6) << name;
    // and the Schur correction matters: the clamped tangent differs by far more than that
    const CauchyBorn cl(m.body, IonRelaxation::clamped);
    const Matrix9d dA = cl.evaluate(general_F()).A - cb.evaluate(general_F()).A;
    EXPECT_GT(dA.cwiseAbs().maxCoeff() / cl.evaluate(general_F()).A.cwiseAbs().maxCoeff(), 1e-3)
        << name;
    // major symmetry of the relaxed tangent (Schur complement of a symmetric matrix)
    const Matrix9d A = cb.evaluate(general_F()).A;
    EXPECT_LT((A - A.transpose()).cwiseAbs().maxCoeff() / A.cwiseAbs().maxCoeff(), 1e-12) << name;
  }
}

TEST(CauchyBornRelaxed, BravaisLatticesAreUnchangedBitwise) {
  const std::vector<Eigen::Vector3d> fcc = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  const std::string cu = "units metal\nmass 1 63.546\npair_style eam\npair_coeff 1 1 " +
                         potential_path("Cu_u3.eam") + "\n";
  for (const auto& [m, name] :
       {std::pair{model(lj_cmds, cubic_crystal(3, 1.5599, fcc, {1, 1, 1, 1})), "fcc LJ"},
        std::pair{model(cu, cubic_crystal(3, 3.615, fcc, {1, 1, 1, 1})), "fcc Cu eam"}}) {
    const CauchyBorn rel(m.body, IonRelaxation::relaxed), cl(m.body, IonRelaxation::clamped);
    EXPECT_TRUE(rel.lattice().bravais()) << name;
    EXPECT_FALSE(rel.relaxing()) << name;
    EXPECT_TRUE(rel.relaxed_values()) << name;
    EXPECT_FALSE(cl.relaxed_values()) << name;
    const CauchyBornState a = rel.evaluate(general_F()), b = cl.evaluate(general_F());
    EXPECT_EQ(a.W, b.W) << name;
    EXPECT_TRUE(a.P == b.P) << name;
    EXPECT_TRUE(a.A == b.A) << name;
    EXPECT_TRUE(a.shift.empty()) << name;
  }
}

TEST(CauchyBornRelaxed, CentrosymmetricBasisRelaxesToZeroShift) {
  // B2 with two LJ types (every atom a centre of inversion): s* = 0 by symmetry, so the relaxed
  // values equal the clamped ones (round-off of the Newton check and the Schur term)
  const std::vector<Eigen::Vector3d> b2 = {{0, 0, 0}, {0.5, 0.5, 0.5}};
  const Model m = model(
      "units metal\nmass * 1.0\npair_style lj/cut 4.0\npair_coeff 1 1 0.1 2.5\n"
      "pair_coeff 2 2 0.15 2.4\npair_coeff 1 2 0.2 2.45\n",
      cubic_crystal(3, 3.0, b2, {1, 2}), 2);
  const CauchyBorn rel(m.body), cl(m.body, IonRelaxation::clamped);
  ASSERT_TRUE(rel.relaxing());
  EXPECT_TRUE(rel.lattice().centrosymmetric);
  const CauchyBornState a = rel.evaluate(general_F()), b = cl.evaluate(general_F());
  const double scale = b.A.cwiseAbs().maxCoeff();
  std::printf("  B2: |s| %.2e, |ΔW|/|W| %.2e, |ΔP| %.2e, |ΔA|/max|A| %.2e\n",
              Eigen::Map<const Eigen::VectorXd>(a.shift.data(), 6).cwiseAbs().maxCoeff(),
              std::abs(a.W - b.W) / std::abs(b.W), (a.P - b.P).cwiseAbs().maxCoeff(),
              (a.A - b.A).cwiseAbs().maxCoeff() / scale);
  EXPECT_LT(std::abs(a.W - b.W), 1e-12 * std::abs(b.W));  // task acceptance: 1e-12
  EXPECT_LT((a.P - b.P).cwiseAbs().maxCoeff(), 1e-12 * scale);
  EXPECT_LT((a.A - b.A).cwiseAbs().maxCoeff(), 1e-12 * scale);
}

TEST(CauchyBornRelaxed, HomogenisedAndRescaledBodiesKeepTheRelaxedConstants) {
  const Model m = model(sw_cmds(), diamond(2, 5.431));
  const double a = 5.431;
  auto C = [](const Body& b) {
    const CauchyBorn cb(b);
    EXPECT_TRUE(cb.relaxing()) << to_string(b.kind);
    return voigt_elastic_constants(Eigen::Matrix3d::Identity(),
                                   cb.evaluate(Eigen::Matrix3d::Identity()));
  };
  const Matrix6d c0 = C(m.body);
  const Matrix6d cc = voigt_elastic_constants(
      Eigen::Matrix3d::Identity(),
      CauchyBorn(m.body, IonRelaxation::clamped).evaluate(Eigen::Matrix3d::Identity()));
  EXPECT_LT(c0(3, 3), 0.6 * cc(3, 3));  // relaxation halves C44 of sw Si (56.4 vs 109.7 GPa)
  coarsen::GridOptions g;
  g.spacing = 0.83 * a;
  g.shift = {0.31, -0.17, 0.44};
  const Body hom =
      coarsen::homogenise_on_grid(m.body, coarsen::make_kernel("cubic-bspline", 1.3 * a), g);
  const Body res = coarsen::rescale(m.body, 2.5);
  const Body both = coarsen::rescale(hom, 3.0);
  for (const Body* b : {&hom, &res, &both}) {
    const Matrix6d c = C(*b);
    // the same sums in another order (scaled by ε^d/ε^d; shifts scale by ε): round-off and the
    // 1e-12 d_nn Newton tolerance
    EXPECT_LT((c - c0).cwiseAbs().maxCoeff() / c0.cwiseAbs().maxCoeff(), 1e-10)
        << to_string(b->kind);
  }
}

TEST(CauchyBornRelaxed, ImperfectCrystalIsRefusedUnderRelaxedMode) {
  Atoms at = diamond(3, 5.431);
  // remove atom 5: a vacancy
  at.id.erase(at.id.begin() + 5);
  at.type.erase(at.type.begin() + 5);
  at.x.erase(at.x.begin() + 15, at.x.begin() + 18);
  const Model m = model(sw_cmds(), at);
  try {
    const CauchyBorn cb(m.body, IonRelaxation::relaxed);
    FAIL() << "no error for a vacancy";
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("not a perfect crystal"), std::string::npos) << w;
    EXPECT_NE(w.find("--clamped-ion"), std::string::npos) << w;
    EXPECT_NE(w.find("perfect periodic cell"), std::string::npos) << w;
  }
  // automatic: clamped-ion (with a warning), no error
  const CauchyBorn au(m.body);
  EXPECT_FALSE(au.relaxing());
  EXPECT_FALSE(au.relaxed_values());
  EXPECT_TRUE(cauchy_born_lattice_note(au.lattice(), IonRelaxation::automatic).warning);
}

TEST(CauchyBornRelaxed, PerPointSumsAreClampedOnly) {
  const Model m = model(sw_cmds(), diamond(2, 5.431));
  const CauchyBorn cb(m.body);
  EXPECT_THROW((void)cb.point_sum(0, Eigen::Matrix3d::Identity()), InputError);
  // the per-point solver material relaxes with the bulk's shifts (test_per_point_relaxed.cpp);
  // clamped-ion on request
  const PerPointCauchyBornMaterial pp(std::make_shared<const Body>(m.body),
                                      std::vector<double>(m.body.size(), 1.0));
  EXPECT_TRUE(pp.cauchy_born().point_relaxing());
  EXPECT_NO_THROW((void)pp.cauchy_born().point_sum(0, Eigen::Matrix3d::Identity()));
  const PerPointCauchyBornMaterial pc(std::make_shared<const Body>(m.body),
                                      std::vector<double>(m.body.size(), 1.0), "",
                                      IonRelaxation::clamped);
  EXPECT_FALSE(pc.cauchy_born().relaxing());
  EXPECT_FALSE(pc.cauchy_born().point_relaxing());
  const CauchyBornMaterial bl(std::make_shared<const Body>(m.body));
  EXPECT_TRUE(bl.cauchy_born().relaxing());
}

// The solver's body-level material (`model: cauchy-born` in a scene) is the relaxed one, in 3D
// (diamond Si) and in 2D (a graphene sheet, BNC.tersoff C, body of dimension 2: in-plane
// shifts, plane strain): its P and A are the relaxed CauchyBorn's, its A matches central
// differences of its own P, and it differs from the clamped material.
TEST(CauchyBornRelaxed, SolverMaterialIsRelaxedIn2DAnd3D) {
  // honeycomb, bond d: rectangular cell 3d × √3d with 4 atoms
  const double d = 1.44, sq3 = std::sqrt(3.0);
  Atoms sheet;
  const int nx = 4, ny = 6;
  sheet.box.hi = {nx * 3 * d, ny * sq3 * d, 10.0};
  const double f[4][2] = {{0, 0}, {1.0 / 3.0, 0}, {0.5, 0.5}, {5.0 / 6.0, 0.5}};
  std::int64_t id = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (const auto& s : f) {
        sheet.id.push_back(++id);
        sheet.type.push_back(1);
        sheet.x.push_back((i + s[0]) * 3 * d);
        sheet.x.push_back((j + s[1]) * sq3 * d);
        sheet.x.push_back(0.0);
      }
  Model g;
  g.spec = atomistic::read_potential_commands_from_string(
      "units metal\nmass 1 12.011\npair_style tersoff\npair_coeff * * " +
          potential_path("BNC.tersoff") + " C\n",
      "relax-test", 1);
  g.pot = atomistic::make_potential(g.spec);
  g.atoms = sheet;
  g.body = make_delta_body(g.atoms, g.pot, g.spec, {.dimension = 2, .cutoff = 0.0, .source = "g"});
  const Model si = model(sw_cmds(), diamond(2, 5.431));
  const Model& gc = g;
  for (const auto& [m, name] : {std::pair{&si, "3D diamond Si"}, std::pair{&gc, "2D graphene"}}) {
    const CauchyBornMaterial mat(std::make_shared<const Body>(m->body));
    ASSERT_TRUE(mat.cauchy_born().relaxing()) << name;
    const CauchyBorn rel(m->body), cl(m->body, IonRelaxation::clamped);
    solver::Mat3 F = general_F();
    if (m->body.dimension == 2) {
      F.row(2) = Eigen::RowVector3d(0, 0, 1);
      F.col(2) = Eigen::Vector3d(0, 0, 1);
    }
    double psi = 0;
    solver::Mat3 P;
    solver::Tangent A;
    ASSERT_TRUE(mat.evaluate(F, &psi, &P, &A)) << name;
    const CauchyBornState r = rel.evaluate(F), c = cl.evaluate(F);
    const int nd = m->body.dimension;
    if (nd == 2) {  // the relaxed sheet keeps its atoms in the plane
      for (std::size_t q = 0; q < r.shift.size(); q += 3) EXPECT_EQ(r.shift[q + 2], 0.0) << name;
    }
    EXPECT_NEAR(psi, r.W, 1e-14 * std::abs(r.W)) << name;  // same numbers (warm start: round-off)
    double dP = 0, dPc = 0, pmax = 0, eA = 0, amax = 0;
    for (int i = 0; i < nd; ++i)
      for (int J = 0; J < nd; ++J) {
        dP = std::max(dP, std::abs(P(i, J) - r.P(i, J)));
        dPc = std::max(dPc, std::abs(P(i, J) - c.P(i, J)));
        pmax = std::max(pmax, std::abs(r.P(i, J)));
      }
    // A of the material vs central FD of the material's P (in-plane block), h = 1e-6
    const double h = 1e-6;
    for (int k = 0; k < nd; ++k)
      for (int L = 0; L < nd; ++L) {
        solver::Mat3 Fp = F, Fm = F, Pp, Pm;
        Fp(k, L) += h;
        Fm(k, L) -= h;
        ASSERT_TRUE(mat.evaluate(Fp, nullptr, &Pp, nullptr));
        ASSERT_TRUE(mat.evaluate(Fm, nullptr, &Pm, nullptr));
        for (int i = 0; i < nd; ++i)
          for (int J = 0; J < nd; ++J) {
            const double fd = (Pp(i, J) - Pm(i, J)) / (2 * h);
            eA = std::max(eA, std::abs(fd - A(3 * i + J, 3 * k + L)));
            amax = std::max(amax, std::abs(A(3 * i + J, 3 * k + L)));
          }
      }
    std::printf(
        "  [%s] material P vs relaxed CB %.1e, vs clamped %.1e (of max|P| %.3g); A vs FD of "
        "P %.1e relative\n",
        name, dP, dPc, pmax, eA / amax);
    EXPECT_LT(dP, 1e-12 * pmax) << name;  // the relaxed CauchyBorn's P (warm start: round-off)
    EXPECT_GT(dPc, 1e-3 * pmax) << name;  // and not the clamped one
    EXPECT_LT(eA / amax, 1e-6) << name;   // acceptance for tangents
  }
}

// A deformation where the relaxation cannot be carried out (atoms on top of each other: the LJ
// energy overflows) is a NumericalError naming F and the fix; the solver material reports the
// state inadmissible (false) instead of a NaN stress.
TEST(CauchyBornRelaxed, FailedRelaxationIsDiagnosed) {
  const Model m = model(lj_cmds, hcp(5, 3, 3, 1.09));
  const CauchyBorn cb(m.body);
  ASSERT_TRUE(cb.relaxing());
  Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
  F(0, 0) = 1e-40;  // det F > 0, but atoms along x collapse: r⁻¹² overflows
  try {
    (void)cb.evaluate(F);
    FAIL() << "no error";
  } catch (const NumericalError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("inner relaxation"), std::string::npos) << w;
    EXPECT_NE(w.find("non-finite"), std::string::npos) << w;
    EXPECT_NE(w.find("--clamped-ion"), std::string::npos) << w;
  }
  const CauchyBornMaterial mat(std::make_shared<const Body>(m.body));
  solver::Mat3 P;
  EXPECT_FALSE(mat.evaluate(F, nullptr, &P, nullptr));
}
