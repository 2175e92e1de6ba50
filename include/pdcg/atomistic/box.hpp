/// \file
/// The simulation box exactly as LAMMPS defines it
/// (https://docs.lammps.org/Howto_triclinic.html).
///
/// Edge vectors (columns of the matrix H):
///   a = (lx, 0, 0),  b = (xy, ly, 0),  c = (xz, yz, lz),
///   lx = xhi − xlo, ly = yhi − ylo, lz = zhi − zlo.
/// A point is x = lo + H s with fractional (LAMMPS "lamda") coordinates s ∈ [0,1)³
/// inside the box. For a triclinic dump LAMMPS writes the bounding box
/// (xlo_bound …); readers convert to (lo, hi, tilt) with the rules of the page above.
#pragma once

#include <Eigen/Core>

#include <array>

namespace pdcg::atomistic {

struct Box {
  Eigen::Vector3d lo{0.0, 0.0, 0.0};
  Eigen::Vector3d hi{1.0, 1.0, 1.0};
  double xy = 0.0, xz = 0.0, yz = 0.0;          ///< tilt factors
  std::array<bool, 3> periodic{true, true, true};

  bool triclinic() const { return xy != 0.0 || xz != 0.0 || yz != 0.0; }
  Eigen::Vector3d lengths() const { return hi - lo; }
  /// H = [a b c] (columns are the edge vectors).
  Eigen::Matrix3d h() const;
  Eigen::Matrix3d h_inverse() const;
  double volume() const;

  /// s = H⁻¹ (x − lo)
  Eigen::Vector3d to_fractional(const Eigen::Vector3d& x) const;
  /// x = lo + H s
  Eigen::Vector3d to_cartesian(const Eigen::Vector3d& s) const;

  /// Shortest image of a separation vector d = x_j − x_i along the periodic
  /// directions (fractional components reduced to [−½, ½)). Exact for any
  /// separation shorter than half the smallest box height; for strongly
  /// tilted boxes with longer separations, see Box::minimum_image_exact.
  Eigen::Vector3d minimum_image(const Eigen::Vector3d& d) const;
  /// Searches the 27 neighbouring images after reduction: the true shortest
  /// image for any tilt (LAMMPS's own minimum_image is the reduced form).
  Eigen::Vector3d minimum_image_exact(const Eigen::Vector3d& d) const;

  /// Maps x into the box along periodic directions, updating image flags
  /// (LAMMPS Domain::remap). Non-periodic directions are left alone.
  Eigen::Vector3d wrap(const Eigen::Vector3d& x, Eigen::Vector3i& image) const;
  /// x + H·image (LAMMPS Domain::unmap).
  Eigen::Vector3d unwrap(const Eigen::Vector3d& x, const Eigen::Vector3i& image) const;

  /// Perpendicular distances between opposite faces (LAMMPS prd/h_inv based
  /// heights): the largest cutoff a single periodic image shell can handle is
  /// half of the smallest of these.
  Eigen::Vector3d heights() const;
};

}  // namespace pdcg::atomistic
