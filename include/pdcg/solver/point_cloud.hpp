/// \file
/// Boundary face vectors s_k and a spacing for a body given as a point cloud (the points of a
/// pdcg model file, `geometry: {shape: model, file: …}`), docs/solver.md §2.1.
///
/// The weak form (model.hpp) needs, per point, the area-weighted outward normal s_k of the body
/// surface it owns. A grid knows its cells; a cloud does not. Two rules:
///
///  - **lattice** (every point is x₀ + A n, n integer, to 1e-6 of the spacing: homogenisation
///    grids, rescaled models, perfect crystals): each point owns the Wigner–Seitz cell of the
///    lattice (the Voronoi cell of a lattice point: a square/cube on a rectangular grid, a
///    hexagon on a triangular lattice, a rhombic dodecahedron on FCC). Its faces f are the
///    bisector planes of the lattice vectors v_f with face area a_f, normal v̂_f. Then
///        s_k = Σ_{f : x_k + v_f is not a point, or the bond crosses a crack} a_f v̂_f,
///    exactly the missing-neighbour faces of the grid path (cell-centre grids give the same
///    s_k). Point volumes V_k = |det A| when the model stores none.
///  - **voronoi** (any other cloud): the Voronoi cell of x_k among the cloud, clipped by the
///    ball of radius R = 1.0·h around x_k (h the mean nearest-neighbour distance). The bisector
///    face between k and j, clipped by that ball, is the same set seen from k or from j (on the
///    bisector |p − x_k| = |p − x_j|), so it is computed once per pair. The free surface of the
///    clipped cell is what the ball cuts off, and since a closed surface has ∮ n dS = 0,
///        s_k = − Σ_{j : bisector face with k, bond not crossing a crack} a_kj v̂_kj,
///    v̂_kj = (x_j − x_k)/|x_j − x_k|. Consequences: Σ_k s_k = 0 exactly (each face enters twice
///    with opposite signs); s_k = 0 to round-off for a point whose Voronoi cell lies inside its
///    ball (the interior: cell radius < R), so a homogeneous state meets the interior
///    equations exactly. In 3D the clipping disc of a face is a regular 64-gon (area 0.9984 of
///    the disc), the same polygon for both ends of the face.
#pragma once

#include <optional>
#include <vector>

#include "pdcg/solver/discretization.hpp"

namespace pdcg::solver {

enum class SurfaceRule { lattice, voronoi };

struct CloudGeometry {
  std::vector<Vec3> surface;   ///< s_k
  std::vector<double> volume;  ///< the given volumes, or |det A| (lattice) / fallback
  SurfaceRule rule = SurfaceRule::voronoi;
  Eigen::Matrix3d basis = Eigen::Matrix3d::Identity();  ///< lattice vectors (columns)
  double spacing = 0.0;            ///< the hint, or the mean nearest-neighbour distance
  double nearest_neighbour = 0.0;  ///< mean nearest-neighbour distance
  double voronoi_radius = 0.0;     ///< R (voronoi rule)
  std::size_t surface_points = 0;  ///< points with s_k ≠ 0
};

/// Mean over the points of the distance to the nearest other point.
double mean_nearest_neighbour_distance(int dimension, const std::vector<Vec3>& x);

/// The lattice basis (columns; in 2D the third is e_z) if every point is x₀ + A n with integer
/// n to rel_tol·|a| (basis from the shortest independent neighbour vectors of a central point,
/// or `hint` when given and valid). nullopt otherwise.
std::optional<Eigen::Matrix3d> detect_lattice(int dimension, const std::vector<Vec3>& x,
                                              const std::optional<Eigen::Matrix3d>& hint = {},
                                              double rel_tol = 1e-6);

/// Wigner–Seitz faces of a lattice: lattice vectors v_f (integer combinations of the basis) and
/// face vectors a_f v̂_f.
struct LatticeFace {
  std::array<int, 3> n{};
  Vec3 v = Vec3::Zero();
  Vec3 area = Vec3::Zero();
};
std::vector<LatticeFace> wigner_seitz_faces(int dimension, const Eigen::Matrix3d& basis);

/// s_k by the lattice rule (x must be lattice points of `basis`).
std::vector<Vec3> lattice_surface(int dimension, const std::vector<Vec3>& x,
                                  const Eigen::Matrix3d& basis, const std::vector<Crack>& cracks);
/// s_k by the ball-clipped Voronoi rule with radius R.
std::vector<Vec3> voronoi_surface(int dimension, const std::vector<Vec3>& x, double radius,
                                  const std::vector<Crack>& cracks);

/// Analyses a cloud: lattice rule if detect_lattice succeeds, else voronoi (R = radius_factor·h).
/// `volume` empty: lattice cell volume |det A|, or `fallback_volume` for a general cloud.
/// `spacing_hint` > 0 is the spacing (e.g. a homogenisation grid's); else the mean
/// nearest-neighbour distance.
CloudGeometry analyse_cloud(int dimension, const std::vector<Vec3>& x, std::vector<double> volume,
                            double fallback_volume, const std::vector<Crack>& cracks,
                            double spacing_hint = 0.0,
                            const std::optional<Eigen::Matrix3d>& basis_hint = {},
                            double radius_factor = 1.0);

}  // namespace pdcg::solver
