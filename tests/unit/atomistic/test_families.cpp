// Families against a brute-force sum over periodic images (the definition), including boxes
// smaller than twice the cutoff where one atom meets several images of another.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <string>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "pdcg/atomistic/families.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::atomistic;

namespace {

/// ψ_k = ½ Σ_j ½ c (r − r0)² — a harmonic pair potential written here as the test's model.
class Springs final : public Potential {
 public:
  Springs(double c, double r0, double rc) : c_(c), r0_(r0), rc_(rc) {}
  std::string style() const override { return "test springs"; }
  double cutoff() const override { return rc_; }
  int ntypes() const override { return 1; }
  bool pairwise() const override { return true; }
  double force_state(const FamilyState& f, double* t) const override {
    double psi = 0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double r = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
      psi += 0.25 * c_ * (r - r0_) * (r - r0_);
      const double s = 0.5 * c_ * (r - r0_) / r;  // ½ φ'(r)/r
      for (int k = 0; k < 3; ++k) t[3 * b + k] = s * y[k];
    }
    return psi;
  }

 private:
  double c_, r0_, rc_;
};

Atoms random_atoms(std::size_t n, const Box& box, unsigned seed) {
  Atoms a;
  a.box = box;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    a.id.push_back(static_cast<std::int64_t>(i + 1));
    a.type.push_back(1);
    const Eigen::Vector3d x = box.to_cartesian(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    a.x.insert(a.x.end(), {x[0], x[1], x[2]});
  }
  return a;
}

/// Brute force: U and forces by summing over all images within ±4 cells.
void brute_force(const Atoms& a, double c, double r0, double rc, double& U,
                 std::vector<double>& f) {
  const Eigen::Matrix3d H = a.box.h();
  const std::size_t n = a.size();
  U = 0;
  f.assign(3 * n, 0.0);
  const int m = 4;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      for (int p = -m; p <= m; ++p)
        for (int q = -m; q <= m; ++q)
          for (int s = -m; s <= m; ++s) {
            if (!a.box.periodic[0] && p) continue;
            if (!a.box.periodic[1] && q) continue;
            if (!a.box.periodic[2] && s) continue;
            if (i == j && p == 0 && q == 0 && s == 0) continue;
            const Eigen::Vector3d d =
                Eigen::Vector3d(a.x[3 * j] - a.x[3 * i], a.x[3 * j + 1] - a.x[3 * i + 1],
                                a.x[3 * j + 2] - a.x[3 * i + 2]) +
                H * Eigen::Vector3d(p, q, s);
            const double r = d.norm();
            if (r >= rc) continue;
            U += 0.25 * c * (r - r0) * (r - r0);  // each pair counted twice
            for (int k = 0; k < 3; ++k) f[3 * i + k] += c * (r - r0) * d[k] / r;
          }
}

void check(const Atoms& atoms, double rc) {
  const Springs pot(2.0, 0.9, rc);
  const Families fam = build_families(atoms, {rc});
  ASSERT_EQ(fam.points(), atoms.size());
  // ξ_b = x_j − x_k + H n_b (written out here with the box's own matrix), shorter than the
  // cutoff; reverse of reverse is identity, the reverse bond is −ξ and goes back to k.
  const Eigen::Matrix3d H = atoms.box.h();
  std::vector<double> xi(3 * fam.bonds());
  for (std::size_t k = 0; k < fam.points(); ++k)
    for (auto b = static_cast<std::size_t>(fam.offset[k]);
         b < static_cast<std::size_t>(fam.offset[k + 1]); ++b) {
      const auto j = static_cast<std::size_t>(fam.neighbor[b]);
      const Eigen::Vector3d n(fam.shift[3 * b], fam.shift[3 * b + 1], fam.shift[3 * b + 2]);
      const Eigen::Vector3d want =
          Eigen::Vector3d(atoms.x[3 * j] - atoms.x[3 * k], atoms.x[3 * j + 1] - atoms.x[3 * k + 1],
                          atoms.x[3 * j + 2] - atoms.x[3 * k + 2]) +
          H * n;
      const Eigen::Vector3d got = bond_vector(fam, atoms.x, k, b);
      // round-off of a sum of |x| ≲ 10 and |H n| ≲ 10: 1e-12 absolute
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(got[c], want[c], 1e-12);
      ASSERT_LT(got.norm(), rc);
      for (int c = 0; c < 3; ++c) xi[3 * b + static_cast<std::size_t>(c)] = got[c];
      const auto r = static_cast<std::size_t>(fam.reverse[b]);
      ASSERT_EQ(static_cast<std::size_t>(fam.reverse[r]), b);
      ASSERT_EQ(static_cast<std::size_t>(fam.neighbor[r]), k);
    }
  for (std::size_t k = 0; k < fam.points(); ++k)
    for (auto b = static_cast<std::size_t>(fam.offset[k]);
         b < static_cast<std::size_t>(fam.offset[k + 1]); ++b) {
      const auto r = static_cast<std::size_t>(fam.reverse[b]);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(xi[3 * b + c], -xi[3 * r + c], 1e-12);
    }
  EXPECT_EQ(bond_vectors(fam, atoms.x), xi);  // all at once: the same numbers
  std::vector<double> Y(3 * fam.bonds()), t(3 * fam.bonds()), psi(atoms.size()),
      f(3 * atoms.size());
  deformed_bonds(fam, atoms.x, fam.h, Y);
  EXPECT_EQ(Y, xi);  // identity deformation: Y = ξ bit for bit (same arithmetic)
  const double U = force_states(pot, fam, atoms.type, Y, psi, t);
  pd_forces(fam, t, f);
  double Uref;
  std::vector<double> fref;
  brute_force(atoms, 2.0, 0.9, rc, Uref, fref);
  // Same double-precision sums in a different order: round-off only.
  EXPECT_TRUE(pdcg::test::close(U, Uref, {1e-12, 1e-12}));
  EXPECT_LT(pdcg::test::max_norm_relative_error(f, fref), 1e-12);
}

}  // namespace

TEST(Families, OrthogonalPeriodicMatchesBruteForce) {
  Box b;
  b.lo = {0, 0, 0};
  b.hi = {5, 6, 7};
  check(random_atoms(60, b, 1), 2.2);
}

TEST(Families, TriclinicBoxSmallerThanCutoffMatchesBruteForce) {
  Box b;
  b.lo = {-1, 0, 1};
  b.hi = {2.0, 2.5, 3.2};
  b.xy = 0.8;
  b.xz = -0.6;
  b.yz = 0.5;
  // cutoff larger than every box height: several images of the same atom in one family
  check(random_atoms(12, b, 2), 3.1);
}

TEST(Families, ImageShiftsBeyondOneByteAreAnInputError) {
  // Shifts are stored as int8: a periodic edge of 1/200 of the cutoff needs 200 images.
  Box b;
  b.hi = {0.01, 5, 5};
  b.periodic = {true, false, false};
  const Atoms a = random_atoms(1, b, 4);
  EXPECT_THROW(build_families(a, {2.0}), pdcg::InputError);
  // 1/126 of the cutoff still fits: 126 images on each side, the last ones at shift ±126.
  const Families f = build_families(a, {1.26 + 1e-9});
  EXPECT_EQ(f.bonds(), 252u);
  int widest = 0;
  for (auto s : f.shift) widest = std::max(widest, std::abs(static_cast<int>(s)));
  EXPECT_EQ(widest, 126);
}

TEST(Families, FreeClusterHasNoImages) {
  Box b;
  b.hi = {6, 6, 6};
  b.periodic = {false, false, false};
  Atoms a = random_atoms(50, b, 3);
  check(a, 2.0);
  const Families fam = build_families(a, {2.0});
  for (auto s : fam.shift) EXPECT_EQ(s, 0);
}

TEST(Families, MixedPeriodicity) {
  Box b;
  b.hi = {4, 4, 9};
  b.xy = 1.0;
  b.periodic = {true, true, false};
  check(random_atoms(40, b, 4), 2.5);
}

TEST(Families, MolecularBondsJoinFamiliesWithSpecialFactors) {
  Box b;
  b.hi = {10, 10, 10};
  Atoms a;
  a.box = b;
  // a chain 1-2-3-4-5 along x, spacing 1.0, plus atom 5 far away bonded to 1 across the boundary
  for (int i = 0; i < 5; ++i) {
    a.id.push_back(i + 1);
    a.type.push_back(1);
    a.x.insert(a.x.end(), {1.0 + i, 5.0, 5.0});
  }
  std::vector<Bond> bonds{{1, 1, 2}, {1, 2, 3}, {2, 3, 4}, {1, 4, 5}};
  FamilyOptions opt{1.5, &bonds, {0.0, 0.5, 0.75}};
  opt.cutoff = 3.5;
  const Families fam = build_families(a, opt);
  ASSERT_FALSE(fam.bond_type.empty());
  // family of atom 1 (index 0): partners 2 (1-2), 3 (1-3), 4 (1-4): factors 0, .5, .75
  for (auto bnd = fam.offset[0]; bnd < fam.offset[1]; ++bnd) {
    const auto j = fam.neighbor[static_cast<std::size_t>(bnd)];
    const double expect = j == 1 ? 0.0 : j == 2 ? 0.5 : j == 3 ? 0.75 : 1.0;
    EXPECT_EQ(fam.pair_factor[static_cast<std::size_t>(bnd)], expect) << "partner index " << j;
    EXPECT_EQ(fam.bond_type[static_cast<std::size_t>(bnd)], j == 1 ? 1 : 0);
  }
  std::vector<Bond> bad{{1, 1, 99}};
  EXPECT_THROW(build_families(a, {1.5, &bad}), pdcg::InputError);
}

TEST(Families, UnwrappedPositionsSeveralBoxesApartMatchWrapped) {
  // Data files and dumps with image flags give unwrapped positions x + H·image; after a melt
  // neighbours can carry image flags that differ by 2 or more. The families (energy, forces,
  // bond count) must be those of the wrapped configuration, checked by brute force.
  Box b;
  b.lo = {0, 0, 0};
  b.hi = {5, 6, 7};
  b.xy = 0.7;
  b.yz = -0.4;
  const Atoms wrapped = random_atoms(60, b, 5);
  Atoms unwrapped = wrapped;
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> img(-3, 3);
  const Eigen::Matrix3d H = b.h();
  int far = 0;
  for (std::size_t i = 0; i < unwrapped.size(); ++i) {
    const Eigen::Vector3d n(img(rng), img(rng), img(rng));
    far += n.cwiseAbs().maxCoeff() >= 2;
    const Eigen::Vector3d d = H * n;
    for (int k = 0; k < 3; ++k) unwrapped.x[3 * i + static_cast<std::size_t>(k)] += d[k];
  }
  ASSERT_GT(far, 20);  // many atoms two or three boxes away from their neighbours
  const double rc = 2.2;
  const Springs pot(2.0, 0.9, rc);
  const Families fw = build_families(wrapped, {rc}), fu = build_families(unwrapped, {rc});
  EXPECT_EQ(fu.bonds(), fw.bonds());
  std::vector<double> Y(3 * fu.bonds()), t(3 * fu.bonds()), psi(unwrapped.size()),
      f(3 * unwrapped.size());
  deformed_bonds(fu, unwrapped.x, fu.h, Y);
  const double U = force_states(pot, fu, unwrapped.type, Y, psi, t);
  pd_forces(fu, t, f);
  double Uref;
  std::vector<double> fref;
  brute_force(wrapped, 2.0, 0.9, rc, Uref, fref);
  // bond vectors x_j − x_i + H n of positions ~20 box units: round-off ~1e-14 relative
  EXPECT_TRUE(pdcg::test::close(U, Uref, {1e-11, 1e-11}));
  EXPECT_LT(pdcg::test::max_norm_relative_error(f, fref), 1e-11);
}

namespace {
/// A potential that refuses any atom of type 2 (as a real one refuses a collapsed pair): the
/// refusal is thrown inside the OpenMP loop over atoms of force_states.
class RefusesTypeTwo final : public Potential {
 public:
  std::string style() const override { return "test refusal"; }
  double cutoff() const override { return 2.0; }
  int ntypes() const override { return 2; }
  double force_state(const FamilyState& f, double* t) const override {
    if (f.type == 2) throw pdcg::NumericalError("atom of type 2 refused by the test potential");
    for (std::int64_t b = 0; b < 3 * f.size; ++b) t[b] = 0.0;
    return 1.0;
  }
};
}  // namespace

TEST(Families, AnExceptionInTheParallelLoopReachesTheCaller) {
  // An exception may not leave an OpenMP region (the runtime would call std::terminate and
  // end the process): force_states carries the first one out, unchanged, on any thread count.
  Box b;
  b.hi = {6, 6, 6};
  b.periodic = {true, true, true};
  Atoms a = random_atoms(200, b, 5);
  a.type[150] = 2;
  const Families fam = build_families(a, {2.0});
  std::vector<double> Y(3 * fam.bonds()), t(3 * fam.bonds()), psi(a.size());
  deformed_bonds(fam, a.x, fam.h, Y);
  const RefusesTypeTwo pot;
#ifdef _OPENMP
  const int saved = omp_get_max_threads();
#endif
  for (int threads : {1, 2, 4}) {
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    try {
      force_states(pot, fam, a.type, Y, psi, t);
      ADD_FAILURE() << "no exception with " << threads << " threads";
    } catch (const pdcg::NumericalError& e) {
      EXPECT_NE(std::string(e.what()).find("type 2 refused"), std::string::npos) << e.what();
    }
  }
#ifdef _OPENMP
  omp_set_num_threads(saved);
#endif
  // and the next call (all atoms of type 1) runs normally
  a.type[150] = 1;
  EXPECT_DOUBLE_EQ(force_states(pot, fam, a.type, Y, psi, t), 200.0);
}
