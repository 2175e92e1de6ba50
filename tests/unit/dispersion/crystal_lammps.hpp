// Shared by test_crystal_dispersion.cpp and slow/test_crystal_dispersion_slow.cpp: perfect
// crystals with a basis, pdcg's primitive-cell dispersion and the LAMMPS reference.
//
// Reference (computed here, from LAMMPS forces only): the force constants of a periodic
// supercell, Φ_sc(jα, sβ) = −∂F_jα/∂u_sβ for each basis representative s, by central
// differences with Richardson extrapolation, Φ = [4 Φ_c(h/2) − Φ_c(h)]/3 (error O(h⁴));
// D_ref(κ)_{cα,sβ} = Σ_{j∈c} Φ_sc(jα, r_c β)… see dynamical_matrix below. At κ commensurate
// with the supercell (e^{iκ·L_i} = 1 for the box vectors) this Fourier sum is exact for any
// supercell size — displacing atom s in the supercell displaces all its images, and the sum of
// the crystal's force constants over those images is what the phase e^{iκ·R} needs there — so
// the only error of the reference is the finite difference.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/body/lattice.hpp"
#include "pdcg/core/units.hpp"
#include "pdcg/dispersion/crystal.hpp"

namespace pdcg::test_crystal {

using namespace pdcg;
using namespace pdcg::atomistic;

/// A crystal given by an orthorhombic conventional cell (edges L), fractional basis positions
/// with types, replicated n times along each axis; `periodic_z` false for a 2D sheet (z free).
struct CrystalSpec {
  std::string name;
  std::string commands;  // LAMMPS potential commands (units, mass, pair_style, pair_coeff)
  Eigen::Vector3d cell;
  std::vector<Eigen::Vector3d> basis;  // fractional
  std::vector<int> types;
  std::array<int, 3> n{1, 1, 1};
  std::vector<double> type_mass;  // index 0 unused
  int dimension = 3;
  std::vector<std::string> labels;  // high-symmetry points to compare at
};

inline Atoms build(const CrystalSpec& c) {
  Atoms at;
  at.box.lo = {0, 0, 0};
  at.box.hi = {c.n[0] * c.cell[0], c.n[1] * c.cell[1], c.n[2] * c.cell[2]};
  if (c.dimension == 2) {
    at.box.lo[2] = -10.0;
    at.box.hi[2] = 10.0;
    at.box.periodic = {true, true, false};
  }
  at.type_mass = c.type_mass;
  for (int i = 0; i < c.n[0]; ++i)
    for (int j = 0; j < c.n[1]; ++j)
      for (int k = 0; k < c.n[2]; ++k)
        for (std::size_t b = 0; b < c.basis.size(); ++b) {
          at.id.push_back(static_cast<std::int64_t>(at.id.size() + 1));
          at.type.push_back(c.types[b]);
          const Eigen::Vector3d f = c.basis[b];
          at.x.insert(at.x.end(), {(i + f[0]) * c.cell[0], (j + f[1]) * c.cell[1],
                                   c.dimension == 2 ? 0.0 : (k + f[2]) * c.cell[2]});
        }
  return at;
}

/// LAMMPS reference: Φ columns of every basis representative, from LAMMPS forces.
struct LammpsReference {
  Atoms atoms;
  std::vector<std::size_t> rep;      // representative atom per class
  std::vector<int> class_of;         // per atom
  std::vector<double> mass;          // per class, × mvv2e
  std::vector<Eigen::MatrixXd> phi;  // per class s: 3N × 3, Φ_sc(jα, r_s β)

  LammpsReference(const Atoms& a, const LammpsEngine& engine, std::vector<std::size_t> reps,
                  std::vector<int> classes, double mvv2e, double h)
      : atoms(a), rep(std::move(reps)), class_of(std::move(classes)) {
    const std::size_t n = a.size();
    auto central = [&](std::size_t s, int beta, double step) {
      Atoms p = a, q = a;
      p.x[3 * s + static_cast<std::size_t>(beta)] += step;
      q.x[3 * s + static_cast<std::size_t>(beta)] -= step;
      const auto fp = engine.evaluate(p).force, fq = engine.evaluate(q).force;
      Eigen::VectorXd col(static_cast<Eigen::Index>(3 * n));
      for (std::size_t i = 0; i < 3 * n; ++i)
        col[static_cast<Eigen::Index>(i)] = -(fp[i] - fq[i]) / (2 * step);
      return col;
    };
    for (auto s : rep) {
      Eigen::MatrixXd m(static_cast<Eigen::Index>(3 * n), 3);
      for (int beta = 0; beta < 3; ++beta)
        m.col(beta) = (4.0 * central(s, beta, h / 2) - central(s, beta, h)) / 3.0;  // Richardson
      phi.push_back(m);
      mass.push_back(a.mass_of(s) * mvv2e);
    }
  }

  /// D_{cα,sβ}(κ) = Σ_{l∈s} Φ(r_c α, l β) e^{iκ·(x_l − x_{r_c})}/√(m_c m_s); Φ symmetric, so
  /// Φ(r_c α, l β) = Φ_sc(l β, r_c α), column α of class c's displacement.
  Eigen::MatrixXcd dynamical_matrix(const Eigen::Vector3d& kappa) const {
    const auto nb = static_cast<Eigen::Index>(rep.size());
    Eigen::MatrixXcd D = Eigen::MatrixXcd::Zero(3 * nb, 3 * nb);
    for (Eigen::Index c = 0; c < nb; ++c) {
      const std::size_t rc = rep[static_cast<std::size_t>(c)];
      const Eigen::Vector3d xc(atoms.x[3 * rc], atoms.x[3 * rc + 1], atoms.x[3 * rc + 2]);
      for (std::size_t l = 0; l < atoms.size(); ++l) {
        const Eigen::Index s = class_of[l];
        const Eigen::Vector3d xl(atoms.x[3 * l], atoms.x[3 * l + 1], atoms.x[3 * l + 2]);
        const std::complex<double> ph = std::polar(1.0, kappa.dot(xl - xc));
        for (int al = 0; al < 3; ++al)
          for (int be = 0; be < 3; ++be)
            D(3 * c + al, 3 * s + be) +=
                phi[static_cast<std::size_t>(c)](static_cast<Eigen::Index>(3 * l) + be, al) * ph /
                std::sqrt(mass[static_cast<std::size_t>(c)] * mass[static_cast<std::size_t>(s)]);
      }
    }
    return D;
  }
  Eigen::VectorXd omega(const Eigen::Vector3d& kappa) const {
    const Eigen::MatrixXcd D = dynamical_matrix(kappa);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXcd> es(0.5 * (D + D.adjoint()),
                                                       Eigen::EigenvaluesOnly);
    Eigen::VectorXd w = es.eigenvalues();
    for (auto& v : w) v = v >= 0 ? std::sqrt(v) : -std::sqrt(-v);
    return w;
  }
};

struct Comparison {
  /// max |ω_pdcg − ω_LAMMPS| over branches and points, except the 3 acoustic modes at Γ
  double worst = 0.0;
  /// max |ω_LAMMPS| of the 3 acoustic modes at Γ (0 in exact arithmetic; pdcg gives exactly 0):
  /// √ of the reference's finite-difference round-off, ≈ √(ε_mach F/h / m)
  double gamma_acoustic = 0.0;
  double wmax = 0.0;  // max ω_LAMMPS
  int branches = 0, points = 0;
  std::string lattice;
};

/// Builds the body and the reference, compares ω at the named points (each checked to be
/// commensurate with the supercell), prints the numbers, returns them.
inline Comparison compare_with_lammps(const CrystalSpec& c, int expect_basis,
                                      const std::string& expect_lattice, double h = 1e-2) {
  const int ntypes = *std::max_element(c.types.begin(), c.types.end());
  const PotentialSpec spec = read_potential_commands_from_string(c.commands, c.name, ntypes);
  const std::shared_ptr<const Potential> potential = make_potential(spec);
  const Atoms atoms = build(c);
  body::DeltaBodyOptions opt;
  opt.dimension = c.dimension;
  const body::Body b = body::make_delta_body(atoms, potential, spec, opt);
  const auto info = body::detect_lattice(b);
  EXPECT_TRUE(info.perfect) << info.summary;
  EXPECT_EQ(info.basis, expect_basis) << info.summary;
  const auto cl = dispersion::classify_lattice(info, c.dimension);
  EXPECT_EQ(cl.lattice, expect_lattice) << cl.summary;
  const dispersion::CrystalDispersion model(b, info);
  const double mvv2e = unit_constants(b.units).mvv2e;
  const LammpsEngine engine(spec);
  std::vector<std::size_t> reps = model.representatives();
  std::vector<std::size_t> reps_atoms;  // body atoms are sorted by id = atoms order here
  for (auto r : reps) reps_atoms.push_back(static_cast<std::size_t>(b.id[r] - 1));
  std::vector<int> cls(atoms.size());
  for (std::size_t k = 0; k < b.size(); ++k)
    cls[static_cast<std::size_t>(b.id[k] - 1)] = info.class_of[k];
  const LammpsReference ref(atoms, engine, reps_atoms, cls, mvv2e, h);
  const Eigen::Matrix3d H = atoms.box.h();
  Comparison out;
  out.lattice = cl.lattice;
  for (const auto& label : c.labels) {
    Eigen::Vector3d k = Eigen::Vector3d::Constant(std::nan(""));
    for (const auto& p : cl.points)
      if (p.label == label) k = p.kappa;
    EXPECT_TRUE(std::isfinite(k[0])) << label;
    if (!std::isfinite(k[0])) continue;
    for (int i = 0; i < c.dimension; ++i)  // commensurate: the reference is exact there
      EXPECT_NEAR(std::remainder(k.dot(H.col(i)), 2 * std::numbers::pi), 0.0, 1e-9)
          << label << " axis " << i;
    const Eigen::VectorXd w = model.omega(k), r = ref.omega(k);
    EXPECT_EQ(w.size(), 3 * expect_basis);
    out.branches = static_cast<int>(w.size());
    ++out.points;
    out.wmax = std::max(out.wmax, r.maxCoeff());
    if (k.norm() == 0.0) {
      EXPECT_EQ(w.head(3), Eigen::Vector3d::Zero());  // pdcg: exactly 0 (round-off zeroed)
      out.gamma_acoustic = r.head(3).cwiseAbs().maxCoeff();
      out.worst = std::max(out.worst, (w - r).tail(w.size() - 3).cwiseAbs().maxCoeff());
    } else {
      out.worst = std::max(out.worst, (w - r).cwiseAbs().maxCoeff());
    }
    std::printf("  %s %s: pdcg", c.name.c_str(), label.c_str());
    for (auto v : w) std::printf(" %.8g", v);
    std::printf("\n  %s %s: LAMMPS", c.name.c_str(), label.c_str());
    for (auto v : r) std::printf(" %.8g", v);
    std::printf("\n");
  }
  std::printf(
      "  %s (%s, %d branches): max |Δω| = %.3g = %.3g of ω_max %.6g over %d points (Γ acoustic: "
      "LAMMPS FD %.3g = %.3g of ω_max, pdcg 0)\n",
      c.name.c_str(), cl.summary.c_str(), out.branches, out.worst, out.worst / out.wmax, out.wmax,
      out.points, out.gamma_acoustic, out.gamma_acoustic / out.wmax);
  return out;
}

}  // namespace pdcg::test_crystal
