/// \file
/// Families (neighbour sets fixed in the reference configuration) in CSR form, built by a
/// cell list over periodic images of an orthogonal or triclinic box, and the loops that turn
/// a Potential into PD force states, internal forces and energies.
///
/// Bond b of atom k points to atom j = neighbor[b] through the periodic image shift
/// n_b = shift[3b..3b+3) (integers, in units of the box edge vectors), relative to the
/// positions as given (wrapped or unwrapped): the reference bond is
///   ξ_b = x_j − x_k + H n_b,
/// and in a deformed configuration y with box matrix H_y the bond is Y_b = y_j − y_k + H_y n_b.
/// ξ_b is not stored (it is derivable from the positions, and would take 24 B per bond of the
/// 8 B the topology needs): bond_vector / family_bond_vectors / bond_vectors compute it.
/// reverse[b] is the bond (j → k) with shift −n_b, so f_k = Σ_{b∈k} (t_b − t_reverse[b]).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/potential.hpp"

namespace pdcg::atomistic {

struct Families {
  std::vector<std::int64_t> offset;  ///< N+1; bonds of k are [offset[k], offset[k+1])
  std::vector<std::int32_t> neighbor;
  /// 3 per bond: image shift n_b, |n_b,i| ≤ 127 (build_families throws InputError beyond:
  /// a periodic box edge shorter than 1/127 of the cutoff, or positions unwrapped by more
  /// than 127 box lengths)
  std::vector<std::int8_t> shift;
  /// index of the bond j → k; int32: at most 2³¹ − 1 bonds in all (InputError beyond,
  /// ≈ 4·10⁷ atoms at 54 bonds per atom)
  std::vector<std::int32_t> reverse;
  std::vector<double> pair_factor;  ///< per bond, special_bonds factor; empty = all 1
  std::vector<int> bond_type;       ///< per bond, molecular bond type (0 = none); empty = none
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();  ///< reference box matrix (periodic shifts)

  std::size_t points() const { return offset.empty() ? 0 : offset.size() - 1; }
  std::size_t bonds() const { return neighbor.size(); }
};

/// Y_b = y_j − y_k + H_y n_b of bond b of atom k (H_y: box matrix of y). With the reference
/// positions and families.h this is ξ_b; the arithmetic (left to right, y_j − y_k first) is
/// that of deformed_bonds, so the reference evaluation sees exactly these bonds.
inline Eigen::Vector3d bond_vector(const Families& f, std::span<const double> y,
                                   const Eigen::Matrix3d& h_y, std::size_t k, std::size_t b) {
  const auto j = static_cast<std::size_t>(f.neighbor[b]);
  const double s0 = f.shift[3 * b], s1 = f.shift[3 * b + 1], s2 = f.shift[3 * b + 2];
  Eigen::Vector3d v;
  for (int c = 0; c < 3; ++c) {
    const auto cc = static_cast<std::size_t>(c);
    v[c] = y[3 * j + cc] - y[3 * k + cc] + h_y(c, 0) * s0 + h_y(c, 1) * s1 + h_y(c, 2) * s2;
  }
  return v;
}

/// Reference bond ξ_b = x_j − x_k + H n_b (x: the 3N reference positions, H = f.h).
inline Eigen::Vector3d bond_vector(const Families& f, std::span<const double> x, std::size_t k,
                                   std::size_t b) {
  return bond_vector(f, x, f.h, k, b);
}

/// ξ of every bond of atom k, in family order, into out (3 per bond; caller's scratch of at
/// least 3·family size). Allocates nothing.
inline void family_bond_vectors(const Families& f, std::span<const double> x, std::size_t k,
                                double* out) {
  const auto b0 = static_cast<std::size_t>(f.offset[k]),
             b1 = static_cast<std::size_t>(f.offset[k + 1]);
  for (std::size_t b = b0; b < b1; ++b) {
    const Eigen::Vector3d v = bond_vector(f, x, f.h, k, b);
    out[3 * (b - b0)] = v[0];
    out[3 * (b - b0) + 1] = v[1];
    out[3 * (b - b0) + 2] = v[2];
  }
}

/// Atom k's family as a potential sees it: the centre's type type_k, the partners' types and
/// the bonds from the caller (one type and 3 values a bond, in family order), and the
/// families' pair factors and bond types of k.
inline FamilyState family_state(const Families& f, std::size_t k, int type_k,
                                const int* neighbor_type, const double* bond) {
  const auto b0 = static_cast<std::size_t>(f.offset[k]);
  FamilyState s;
  s.type = type_k;
  s.size = f.offset[k + 1] - f.offset[k];
  s.neighbor_type = neighbor_type;
  s.bond = bond;
  s.pair_factor = f.pair_factor.empty() ? nullptr : f.pair_factor.data() + b0;
  s.bond_type = f.bond_type.empty() ? nullptr : f.bond_type.data() + b0;
  return s;
}

/// Atom k's family at positions y (box matrix h_y) as a potential sees it: the bonds Y_b of
/// bond_vector and the partners' types, gathered into this scratch (reused from call to call),
/// and the families' pair factors and bond types. The state points into the scratch: valid
/// until the next call.
struct FamilyGather {
  std::vector<double> bond;
  std::vector<int> neighbor_type;
  FamilyState operator()(const Families& f, std::span<const int> type, std::span<const double> y,
                         const Eigen::Matrix3d& h_y, std::size_t k) {
    const auto b0 = static_cast<std::size_t>(f.offset[k]),
               b1 = static_cast<std::size_t>(f.offset[k + 1]);
    const std::size_t m = b1 - b0;
    bond.resize(3 * m);
    neighbor_type.resize(m);
    for (std::size_t b = b0; b < b1; ++b) {
      const Eigen::Vector3d v = bond_vector(f, y, h_y, k, b);
      for (int a = 0; a < 3; ++a) bond[3 * (b - b0) + static_cast<std::size_t>(a)] = v[a];
      neighbor_type[b - b0] = type[static_cast<std::size_t>(f.neighbor[b])];
    }
    return family_state(f, k, type[k], neighbor_type.data(), bond.data());
  }
};

/// ξ of every bond (3 per bond) in a new array: for code outside hot loops that wants them all
/// at once (the Families do not keep them).
std::vector<double> bond_vectors(const Families& f, std::span<const double> x);

struct FamilyOptions {
  double cutoff = 0.0;                                 ///< bonds with |ξ| < cutoff
  const std::vector<Bond>* molecular_bonds = nullptr;  ///< added regardless of length
  /// Pair factor for 1-2, 1-3, 1-4 partners (by atom, found through the molecular bonds). As in
  /// LAMMPS's neighbour lists it applies to an image of a partner only when every Cartesian
  /// component of the separation along a periodic direction is within half the box length
  /// (Domain::minimum_image_check); farther images within the cutoff are ordinary pairs
  /// (factor 1). Boxes shorter than twice the cutoff have such images.
  std::array<double, 3> special_lj{1.0, 1.0, 1.0};
};

/// Builds the families of every atom with a cell list (O(N)); periodic directions of
/// atoms.box contribute as many image shells as the cutoff needs (boxes smaller than the
/// cutoff work, down to an edge of 1/127 of the cutoff). Families are sorted by (neighbour,
/// shift). Throws InputError for a non-positive cutoff, a molecular bond naming an unknown
/// atom id, an image shift beyond ±127 box lengths or more than 2³¹ − 1 bonds.
Families build_families(const Atoms& atoms, const FamilyOptions& options);

/// Y_b = y_j − y_k + H_y n_b for every bond (y: 3N deformed positions in the same convention
/// as the reference positions; h_deformed: deformed box matrix, F·H for a homogeneous F).
void deformed_bonds(const Families& families, std::span<const double> y,
                    const Eigen::Matrix3d& h_deformed, std::span<double> bond_out);

/// ψ_k for every atom and t_b for every bond (OpenMP over atoms). Returns Σ_k ψ_k.
double force_states(const Potential& potential, const Families& families, std::span<const int> type,
                    std::span<const double> bonds, std::span<double> psi_out,
                    std::span<double> t_out);

/// f_k = Σ_{b∈k} (t_b − t_reverse[b]) (OpenMP over atoms, gather: no races).
void pd_forces(const Families& families, std::span<const double> t, std::span<double> f_out);

}  // namespace pdcg::atomistic
