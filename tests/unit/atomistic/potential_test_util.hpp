// Shared helpers for the potential tests: perturbed lattices and the comparison with
// embedded LAMMPS (the independent reference).
#pragma once

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potentials.hpp"

namespace pdcg::test {

using atomistic::Atoms;
using atomistic::Box;

/// FCC lattice (4 atoms per cell, lattice constant a) of nx·ny·nz cells, positions perturbed
/// by uniform noise of amplitude `noise`·a, types drawn at random from 1..ntypes.
inline Atoms fcc(int nx, int ny, int nz, double a, double noise, int ntypes, unsigned seed) {
  Atoms at;
  at.box.lo = {0, 0, 0};
  at.box.hi = {nx * a, ny * a, nz * a};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> ut(1, ntypes);
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::int64_t id = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (const auto& b : basis) {
          at.id.push_back(++id);
          at.type.push_back(ut(rng));
          at.x.push_back((i + b[0]) * a + noise * a * u(rng));
          at.x.push_back((j + b[1]) * a + noise * a * u(rng));
          at.x.push_back((k + b[2]) * a + noise * a * u(rng));
        }
  return at;
}

/// The 8 sites of the diamond-cubic cell in units of the cube edge: the 4 FCC sites, then the
/// same shifted by (¼, ¼, ¼).
inline constexpr double kDiamondBasis[8][3] = {
    {0, 0, 0},          {0.5, 0.5, 0},      {0.5, 0, 0.5},      {0, 0.5, 0.5},
    {0.25, 0.25, 0.25}, {0.75, 0.75, 0.25}, {0.75, 0.25, 0.75}, {0.25, 0.75, 0.75}};

/// nx·ny·nz cubic cells of edge a holding the first `nbasis` sites of kDiamondBasis (4: FCC,
/// 8: diamond), ids 1, 2, … cell by cell; type 1, or with `two_types` type 2 on the shifted
/// sites (zincblende); every coordinate displaced by a uniform random amount in
/// [−noise, noise] (length units, not a fraction of a).
inline Atoms cubic_lattice(int nx, int ny, int nz, double a, int nbasis, double noise,
                           bool two_types, unsigned seed) {
  Atoms at;
  at.box.hi = {nx * a, ny * a, nz * a};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::int64_t id = 0;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (int b = 0; b < nbasis; ++b) {
          at.id.push_back(++id);
          at.type.push_back(two_types && b >= 4 ? 2 : 1);
          // braced list: evaluated left to right, so the draws go x, y, z
          at.x.insert(at.x.end(), {(i + kDiamondBasis[b][0]) * a + noise * u(rng),
                                   (j + kDiamondBasis[b][1]) * a + noise * u(rng),
                                   (k + kDiamondBasis[b][2]) * a + noise * u(rng)});
        }
  return at;
}

/// Diamond (types 1 1) or zincblende (types 1 2) lattice of nx·ny·nz cubic cells of 8 atoms,
/// every coordinate displaced by a uniform random amount in [−noise, noise] Å.
inline Atoms diamond(int nx, int ny, int nz, double a, double noise, bool two_types,
                     unsigned seed) {
  return cubic_lattice(nx, ny, nz, a, 8, noise, two_types, seed);
}

/// The same of n³ cells.
inline Atoms diamond(int n, double a, double noise, bool two_types, unsigned seed) {
  return cubic_lattice(n, n, n, a, 8, noise, two_types, seed);
}

/// Free surfaces normal to z: the box stays, z is not periodic (a slab of the crystal).
inline Atoms slab(Atoms at) {
  at.box.periodic = {true, true, false};
  return at;
}

/// Shears a configuration into a triclinic box (x += xy·y/ly + xz·z/lz, y += yz·z/lz).
inline void make_triclinic(Atoms& at, double xy, double xz, double yz) {
  const Eigen::Vector3d L = at.box.lengths();
  for (std::size_t i = 0; i < at.size(); ++i) {
    const double y = at.x[3 * i + 1] - at.box.lo[1], z = at.x[3 * i + 2] - at.box.lo[2];
    at.x[3 * i] += xy * y / L[1] + xz * z / L[2];
    at.x[3 * i + 1] += yz * z / L[2];
  }
  at.box.xy = xy;
  at.box.xz = xz;
  at.box.yz = yz;
}

/// Keeps the atoms within `radius` of the box centre, non-periodic: a free cluster.
inline Atoms cluster(const Atoms& at, double radius) {
  Atoms c;
  c.box = at.box;
  c.box.periodic = {false, false, false};
  const Eigen::Vector3d centre = 0.5 * (at.box.lo + at.box.hi);
  std::int64_t id = 0;
  for (std::size_t i = 0; i < at.size(); ++i) {
    const Eigen::Vector3d x(at.x[3 * i], at.x[3 * i + 1], at.x[3 * i + 2]);
    if ((x - centre).norm() > radius) continue;
    c.id.push_back(++id);
    c.type.push_back(at.type[i]);
    c.x.insert(c.x.end(), {x[0], x[1], x[2]});
  }
  return c;
}

struct PdResult {
  std::vector<double> psi, force;
  double total = 0;
};

/// ψ_k and f_k through families (cutoff × `family_margin`, so bonds beyond the potential's
/// cutoff exist and must carry nothing), force states and PD forces.
inline PdResult pd_evaluate(const atomistic::Potential& pot, const Atoms& at,
                            double family_margin = 1.15,
                            const std::vector<atomistic::Bond>* bonds = nullptr,
                            std::array<double, 3> special = {1, 1, 1}) {
  atomistic::FamilyOptions opt;
  opt.cutoff = pot.cutoff() * family_margin;
  opt.molecular_bonds = bonds;
  opt.special_lj = special;
  const auto fam = atomistic::build_families(at, opt);
  std::vector<double> Y(3 * fam.bonds()), t(3 * fam.bonds());
  PdResult r;
  r.psi.resize(at.size());
  r.force.resize(3 * at.size());
  atomistic::deformed_bonds(fam, at.x, fam.h, Y);
  r.total = atomistic::force_states(pot, fam, at.type, Y, r.psi, t);
  atomistic::pd_forces(fam, t, r.force);
  return r;
}

}  // namespace pdcg::test
