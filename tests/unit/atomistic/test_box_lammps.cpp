// Box::wrap (LAMMPS Domain::remap) and Box::minimum_image against LAMMPS itself
// in a periodic triclinic box: LAMMPS's remapped positions and image flags after
// a run, and the pair distances LAMMPS uses for forces (compute pair/local dist
// with property/local patom1 patom2; this LAMMPS version has no dx/dy/dz there).
#if PDCG_WITH_LAMMPS

#include <gtest/gtest.h>

#include "lammps_driver.hpp"
#include "pdcg/atomistic/box.hpp"
#include "pdcg_test.hpp"

using pdcg::atomistic::Box;
using pdcg::test::Lammps;

namespace {

Box to_box(const Lammps::BoxData& b) {
  Box box;
  box.lo = b.lo;
  box.hi = b.hi;
  box.xy = b.xy;
  box.xz = b.xz;
  box.yz = b.yz;
  for (int k = 0; k < 3; ++k) box.periodic[static_cast<std::size_t>(k)] = b.periodic[k] != 0;
  return box;
}

class BoxVsLammps : public ::testing::Test {
 protected:
  void SetUp() override {
    lmp_.run(R"(
units lj
atom_style atomic
atom_modify map array
boundary p p p
lattice fcc 0.8442
region box prism 0 4 0 4 0 5 1.3 -0.9 0.7 units lattice
create_box 1 box
create_atoms 1 box
mass 1 1.0
velocity all create 6.0 31337 loop geom
pair_style lj/cut 2.5
pair_coeff * * 1.0 1.0
timestep 0.01
fix 1 all nve
compute pa all property/local patom1 patom2
compute pl all pair/local dist
run 40
run 0
)");  // the final `run 0` remaps every atom into the box (Domain::pbc) and updates images
  }
  Lammps lmp_;
};

TEST_F(BoxVsLammps, WrapReproducesRemapAndImageFlags) {
  const Box box = to_box(lmp_.box());
  const auto x = lmp_.gather_double("x", 3);
  const auto img = lmp_.gather_int("image", 3);
  const auto u = lmp_.unwrapped_positions();
  int crossed = 0;
  std::vector<double> wrapped(x.size());
  std::vector<int> image(img.size());
  for (std::size_t i = 0; i < lmp_.natoms(); ++i) {
    Eigen::Vector3i m = Eigen::Vector3i::Zero();
    const Eigen::Vector3d w = box.wrap(Eigen::Vector3d(u[3 * i], u[3 * i + 1], u[3 * i + 2]), m);
    for (int k = 0; k < 3; ++k) {
      wrapped[3 * i + static_cast<std::size_t>(k)] = w[k];
      image[3 * i + static_cast<std::size_t>(k)] = m[k];
      crossed += img[3 * i + static_cast<std::size_t>(k)] != 0;
    }
  }
  EXPECT_GT(crossed, 10);  // the test exercises image flags
  EXPECT_EQ(image, img);
  // x → s → x round trips cost a few ulps of L.
  EXPECT_TRUE(pdcg::test::all_close(wrapped, x, {1e-12 * (box.hi - box.lo).maxCoeff(), 0.0}));
}

TEST_F(BoxVsLammps, MinimumImageMatchesPairSeparations) {
  const Box box = to_box(lmp_.box());
  void* h = lmp_.handle();
  const int rows =
      *static_cast<int*>(lammps_extract_compute(h, "pl", LMP_STYLE_LOCAL, LMP_SIZE_ROWS));
  const auto** pairs =
      static_cast<const double**>(lammps_extract_compute(h, "pa", LMP_STYLE_LOCAL, LMP_TYPE_ARRAY));
  // One value (dist): a local vector, not an array.
  const auto* dist =
      static_cast<const double*>(lammps_extract_compute(h, "pl", LMP_STYLE_LOCAL, LMP_TYPE_VECTOR));
  ASSERT_NE(pairs, nullptr);
  ASSERT_NE(dist, nullptr);
  ASSERT_GT(rows, 1000);  // 320 atoms × ~37 neighbours / 2 within 2.5σ
  ASSERT_EQ(*static_cast<int*>(lammps_extract_compute(h, "pa", LMP_STYLE_LOCAL, LMP_SIZE_ROWS)),
            rows);
  // Unwrapped positions: their differences are many box vectors away from the
  // minimum image for atoms that crossed boundaries, which is what we test.
  const auto u = lmp_.unwrapped_positions();
  std::vector<double> got, want;
  for (int r = 0; r < rows; ++r) {
    const auto i = static_cast<std::size_t>(pairs[r][0]) - 1;  // ids are 1..N
    const auto j = static_cast<std::size_t>(pairs[r][1]) - 1;
    const Eigen::Vector3d d(u[3 * i] - u[3 * j], u[3 * i + 1] - u[3 * j + 1],
                            u[3 * i + 2] - u[3 * j + 2]);
    got.push_back(box.minimum_image(d).norm());
    want.push_back(dist[r]);
  }
  // Separations from unwrapped positions carry round-off of |u| ~ a few L: 1e-12·L.
  // A wrong image would be off by at least the smallest box height (~6σ).
  EXPECT_TRUE(pdcg::test::all_close(got, want, {1e-12 * (box.hi - box.lo).maxCoeff(), 0.0}));
}

}  // namespace

#endif  // PDCG_WITH_LAMMPS
