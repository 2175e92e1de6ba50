/// \file
/// Measures of a grid cell cut by a circular (2D) or spherical (3D) hole: the cut-cell
/// volumes of the points next to a hole (docs/solver.md §2, "Cut-cell volumes";
/// docs/theory.md §6).
#pragma once

#include <Eigen/Core>

namespace pdcg::solver {

/// Exact area of the rectangle [lo, hi] (x, y components) ∩ the disk |p − c| < R.
/// Piecewise-exact integral of the clipped chord length over x (breakpoints where the chord
/// meets y = lo.y, y = hi.y or ends): round-off accurate.
double disk_rectangle_area(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                           const Eigen::Vector3d& c, double R);

/// Volume of the box [lo, hi] ∩ the ball |p − c| < R: ∫ disk_rectangle_area(r(z)) dz with
/// r(z) = √(R² − (z − c_z)²), by 20-node Gauss–Legendre quadrature on each interval between
/// the heights where the section's topology changes (r(z) equal to the distance from the
/// axis to an edge line or a corner of the rectangle, and the ball's equator), after the
/// substitution z = z₀ + (z₁ − z₀)(1 − cos θ)/2 that clusters the nodes at the interval ends
/// (the section area has (z − z_b)^{1/2} and ^{3/2} terms there). Relative error ≲ 1e-11
/// (tested against spherical caps, the ball and the sum over a tiling).
double ball_box_volume(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                       const Eigen::Vector3d& c, double R);

/// |[lo, hi] ∩ hole|: the disk (dimension 2, z ignored) or the ball (dimension 3).
double cell_hole_measure(int dimension, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                         const Eigen::Vector3d& c, double R);

}  // namespace pdcg::solver
