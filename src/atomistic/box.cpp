#include "pdcg/atomistic/box.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <limits>

namespace pdcg::atomistic {

Eigen::Matrix3d Box::h() const {
  const Eigen::Vector3d l = lengths();
  Eigen::Matrix3d m;
  m << l.x(), xy, xz,  //
      0.0, l.y(), yz,  //
      0.0, 0.0, l.z();
  return m;
}

Eigen::Matrix3d Box::h_inverse() const {
  // Upper-triangular inverse in closed form (as LAMMPS Domain::set_global_box).
  const Eigen::Vector3d l = lengths();
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  m(0, 0) = 1.0 / l.x();
  m(1, 1) = 1.0 / l.y();
  m(2, 2) = 1.0 / l.z();
  m(0, 1) = -xy / (l.x() * l.y());
  m(1, 2) = -yz / (l.y() * l.z());
  m(0, 2) = (xy * yz - l.y() * xz) / (l.x() * l.y() * l.z());
  return m;
}

double Box::volume() const {
  const Eigen::Vector3d l = lengths();
  return l.x() * l.y() * l.z();
}

Eigen::Vector3d Box::to_fractional(const Eigen::Vector3d& x) const { return h_inverse() * (x - lo); }

Eigen::Vector3d Box::to_cartesian(const Eigen::Vector3d& s) const { return lo + h() * s; }

Eigen::Vector3d Box::minimum_image(const Eigen::Vector3d& d) const {
  Eigen::Vector3d s = h_inverse() * d;
  for (int k = 0; k < 3; ++k)
    if (periodic[static_cast<std::size_t>(k)]) s[k] -= std::floor(s[k] + 0.5);
  return h() * s;
}

Eigen::Vector3d Box::minimum_image_exact(const Eigen::Vector3d& d) const {
  const Eigen::Vector3d r = minimum_image(d);
  const Eigen::Matrix3d H = h();
  Eigen::Vector3d best = r;
  double best2 = r.squaredNorm();
  const int nx = periodic[0] ? 1 : 0, ny = periodic[1] ? 1 : 0, nz = periodic[2] ? 1 : 0;
  for (int i = -nx; i <= nx; ++i)
    for (int j = -ny; j <= ny; ++j)
      for (int k = -nz; k <= nz; ++k) {
        const Eigen::Vector3d c = r + H * Eigen::Vector3d(i, j, k);
        const double c2 = c.squaredNorm();
        if (c2 < best2) {
          best2 = c2;
          best = c;
        }
      }
  return best;
}

Eigen::Vector3d Box::wrap(const Eigen::Vector3d& x, Eigen::Vector3i& image) const {
  Eigen::Vector3d s = to_fractional(x);
  for (int k = 0; k < 3; ++k) {
    if (!periodic[static_cast<std::size_t>(k)]) continue;
    const double shift = std::floor(s[k]);
    s[k] -= shift;
    if (s[k] >= 1.0) {  // round-off guard: keep s in [0,1)
      s[k] -= 1.0;
      image[k] += 1;
    }
    image[k] += static_cast<int>(shift);
  }
  return to_cartesian(s);
}

Eigen::Vector3d Box::unwrap(const Eigen::Vector3d& x, const Eigen::Vector3i& image) const {
  return x + h() * image.cast<double>();
}

Eigen::Vector3d Box::heights() const {
  // Height along k = 1 / |row k of H⁻¹| (distance between the faces s_k = 0 and 1).
  const Eigen::Matrix3d hi = h_inverse();
  return {1.0 / hi.row(0).norm(), 1.0 / hi.row(1).norm(), 1.0 / hi.row(2).norm()};
}

}  // namespace pdcg::atomistic
