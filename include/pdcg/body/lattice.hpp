/// \file
/// Is a body's atomic layer a perfect Bravais lattice, or a crystal with a basis? (docs/elastic.md
/// §2.1). Operations that assume one atom per primitive cell — the Cauchy–Born material without
/// inner relaxation, one-atom-per-cell dispersion — check their input with `detect_lattice`.
///
/// Method: atoms are sorted into environment classes: two atoms are in one class when they have
/// the same type and the same set of (ξ, partner type, bond type, pair factor) over their
/// families, ξ compared component-wise to `tolerance`·d_nn (d_nn the shortest bond). In a perfect
/// crystal the atoms of a class are images of each other under lattice translations, so
///   - a perfect crystal has equally populated classes (every atom of the primitive basis
///     repeated N/n times), periodic along the body's first `dimension` box directions;
///   - the number of classes n is the number of basis atoms of the primitive cell (1 = Bravais);
///   - the primitive vectors are the shortest independent translations between atoms of one
///     class (checked: their cell measure is V₀·n/N).
/// A vacancy, a free surface or a perturbation makes classes of unequal size (or more than
/// `max_classes`): not perfect. Limit: a box with no translation symmetry inside it (every atom
/// its own class, all of size 1) is reported as a perfect crystal whose basis is the whole box;
/// a perturbed crystal of more than `max_classes` atoms is reported as not perfect.
/// Cost: O(N · bonds · classes) with early exits; at most `max_classes` classes are built.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "pdcg/body/body.hpp"

namespace pdcg::body {

struct LatticeOptions {
  /// ξ components match when they differ by at most tolerance·d_nn (positions written with
  /// 7+ significant digits stay within it; thermal noise does not).
  double tolerance = 1e-6;
  /// Stop classifying after this many environment classes (then: not a perfect crystal).
  int max_classes = 64;
};

struct LatticeInfo {
  /// Every atom is one of `basis` equally populated environments and the body is periodic
  /// along its first `dimension` box directions.
  bool perfect = false;
  /// perfect and basis == 1: one atom per primitive cell.
  bool bravais() const { return perfect && basis == 1; }
  /// Atoms per primitive cell (the number of classes) when perfect; 0 otherwise.
  int basis = 0;
  /// Environment classes found (max_classes + 1 when the search stopped).
  int classes = 0;
  /// Every class is invariant under ξ → −ξ: every atom is a centre of inversion, so a
  /// homogeneous strain puts no force on any sublattice (clamped-ion Cauchy–Born is exact).
  bool centrosymmetric = false;
  /// `dimension` primitive translation vectors (shortest first) of a perfect crystal, when
  /// found and consistent with V₀·basis/N; empty otherwise.
  std::vector<Eigen::Vector3d> primitive;
  /// Per atom: its class (0 … classes−1); −1 for atoms not classified (search stopped).
  std::vector<int> class_of;
  double nearest = 0.0;  ///< shortest bond length d_nn
  /// One line for messages: "perfect Bravais lattice", "perfect crystal with a basis of 2
  /// atoms per primitive cell", "not a perfect crystal (…)".
  std::string summary;
};

/// Classifies the atomic layer of `body` (any kind; the families as built). Never throws for a
/// body with families; a body without atoms or bonds is reported as not perfect.
LatticeInfo detect_lattice(const Body& body, const LatticeOptions& options = {});

/// Fixed families under a deformation (docs/bodies.md): a body's families are its reference
/// neighbours within the family cutoff; in a deformed frame pairs outside them may come within
/// the potential's cutoff and are then missed. `check_families` builds the deformed frame's
/// neighbour pairs within the potential cutoff r_c and reports those that are not bonds of
/// the body.
struct FamilyCheck {
  std::size_t missing = 0;      ///< pairs (k, j, image) within r_c in the frame, not in families
  double needed_cutoff = 0.0;   ///< largest reference separation of such a pair (0 if none)
  double max_stretch = 0.0;     ///< largest | |Y_b| − |ξ_b| | over the family bonds
  double cutoff = 0.0;          ///< r_c used (the body's potential cutoff)
  double family_cutoff = 0.0;   ///< the body's family radius (horizon)
  std::int64_t example_k = -1;  ///< ids of one missing pair (the one with the largest |ξ|)
  std::int64_t example_j = -1;
};
/// y: 3N deformed positions aligned with the body's images (cli deformed_positions); deformed:
/// the frame's box (its periodic flags are the body's). O(N) with a cell list.
FamilyCheck check_families(const Body& body, const std::vector<double>& y,
                           const atomistic::Box& deformed);

}  // namespace pdcg::body
