#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/box.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::atomistic;

namespace {
Box triclinic_box() {
  Box b;
  b.lo = {-1.0, 0.5, 2.0};
  b.hi = {9.0, 8.5, 14.0};
  b.xy = 2.5;
  b.xz = -1.5;
  b.yz = 3.0;
  return b;
}
}  // namespace

TEST(Box, FractionalRoundTripAndInverse) {
  const Box b = triclinic_box();
  EXPECT_TRUE((b.h() * b.h_inverse() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-15);
  const Eigen::Vector3d x(3.0, 4.0, 5.0);
  EXPECT_LT((b.to_cartesian(b.to_fractional(x)) - x).norm(), 1e-13);
  EXPECT_DOUBLE_EQ(b.volume(), 10.0 * 8.0 * 12.0);  // det H = lx ly lz
}

TEST(Box, MinimumImageIsShortestAmongImages) {
  const Box b = triclinic_box();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d d(u(rng), u(rng), u(rng));
    const Eigen::Vector3d m = b.minimum_image_exact(d);
    // m differs from d by a lattice vector
    const Eigen::Vector3d n = b.h_inverse() * (d - m);
    EXPECT_LT((n - n.array().round().matrix()).norm(), 1e-9);
    // no image within ±2 cells is shorter (brute force)
    for (int i = -3; i <= 3; ++i)
      for (int j = -3; j <= 3; ++j)
        for (int k = -3; k <= 3; ++k)
          EXPECT_LE(m.norm(), (m + b.h() * Eigen::Vector3d(i, j, k)).norm() + 1e-12);
  }
}

TEST(Box, WrapUnwrapRestoresPositionAndCountsImages) {
  Box b = triclinic_box();
  b.periodic = {true, true, false};
  const Eigen::Vector3d x(25.0, -13.0, 40.0);
  Eigen::Vector3i img(0, 0, 0);
  const Eigen::Vector3d w = b.wrap(x, img);
  const Eigen::Vector3d s = b.to_fractional(w);
  EXPECT_GE(s.x(), 0.0);
  EXPECT_LT(s.x(), 1.0);
  EXPECT_GE(s.y(), 0.0);
  EXPECT_LT(s.y(), 1.0);
  EXPECT_EQ(img.z(), 0);  // non-periodic: untouched
  EXPECT_LT((b.unwrap(w, img) - x).norm(), 1e-12);
}

TEST(Atoms, SortByIdPermutesEveryArrayAndRejectsDuplicates) {
  Atoms a;
  a.id = {3, 1, 2};
  a.type = {30, 10, 20};
  a.x = {3, 3, 3, 1, 1, 1, 2, 2, 2};
  a.extra["c_pe"] = {-3.0, -1.0, -2.0};
  sort_by_id(a, "test");
  EXPECT_EQ(a.id, (std::vector<std::int64_t>{1, 2, 3}));
  EXPECT_EQ(a.type, (std::vector<int>{10, 20, 30}));
  EXPECT_EQ(a.x[3], 2.0);
  EXPECT_EQ(a.extra["c_pe"][2], -3.0);
  Atoms d;
  d.id = {1, 5, 5};
  d.x.assign(9, 0.0);
  EXPECT_THROW(sort_by_id(d, "frame.dump"), pdcg::InputError);
}
