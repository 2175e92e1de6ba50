// Crystals with a basis against LAMMPS (crystal_lammps.hpp), the EAM systems: their force
// constants reach twice the cutoff, so the supercells are larger and each LAMMPS evaluation
// slower (label slow). hcp Mg (eam/fs) at its zero-stress a, c; L1₂ Ni₃Al and B2 NiAl
// (eam/alloy, Ni–Al of NiAlH_jea); FCC Cu (one basis atom: the same numbers as the one-point
// dispersion, LatticeDispersion.FccCopperEam…).
#include <gtest/gtest.h>

#include "../crystal_lammps.hpp"

using pdcg::test_crystal::compare_with_lammps;
using pdcg::test_crystal::CrystalSpec;

namespace {
// ω_max · 1e-6: the acceptance. The reference: central differences with Richardson
// extrapolation at h = 1e-4, 5e-5 Å — below the knot spacing of the tabulated EAM functions
// (Mg_mm 7.5e-4 Å, NiAlH_jea 5.7e-3 Å, Cu_u3 1e-2 Å): a step across knots sees the spline's
// jumps in the third derivative (h = 1e-2: 1e-3 of ω_max for Mg, 5e-6 for Cu; h = 1e-4: all
// points off Γ agree to 8 digits).
constexpr double kAcceptance = 1e-6;
// Γ's acoustic modes: the reference gives √(round-off of ω²) ≈ 6e-5 rad/ps at h = 1e-4 (force
// round-off ~1e-15 eV/Å over h), ~1e-6 of ω_max: asserted below 2e-6 (pdcg gives exactly 0)
constexpr double kGammaFloor = 2e-6;
const double H = 1e-4;
}  // namespace

#if PDCG_WITH_LAMMPS
// Mg, Mendelev eam/fs, a = 3.184214012456 Å, c = 5.184423275441 Å: zero stress from LAMMPS
// `fix box/relax aniso 0.0 couple xy` (|p| < 1e-10 bar). Orthorhombic cell a × √3a × c with 4
// atoms; 6 × 4 × 4 cells: M, K, A, L, H commensurate; 38 Å > 2·(2 r_c = 15 Å).
TEST(CrystalDispersionSlow, HcpMagnesiumEamFsMatchesLammps) {
  CrystalSpec c;
  c.name = "Mg eam/fs";
  c.commands = "units metal\nmass 1 24.305\npair_style eam/fs\npair_coeff * * Mg_mm.eam.fs Mg\n";
  const double a = 3.184214012456, cz = 5.184423275441;
  c.cell = {a, std::sqrt(3.0) * a, cz};
  c.basis = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 1.0 / 6, 0.5}, {0, 2.0 / 3, 0.5}};
  c.types.assign(4, 1);
  c.n = {6, 4, 4};
  c.type_mass = {0.0, 24.305};
  c.labels = {"G", "M", "K", "A", "L", "H"};
  const auto r = compare_with_lammps(c, 2, "hcp", H);
  EXPECT_EQ(r.branches, 6);
  EXPECT_LT(r.worst, kAcceptance * r.wmax);
  EXPECT_LT(r.gamma_acoustic, kGammaFloor * r.wmax);
}

// L1₂ Ni₃Al, a = 3.567653228471 Å (zero pressure, LAMMPS box/relax iso); sc lattice, 4 basis
// atoms (Al at the corner, Ni on the faces): 12 branches.
TEST(CrystalDispersionSlow, L12Ni3AlEamAlloyMatchesLammps) {
  CrystalSpec c;
  c.name = "Ni3Al eam/alloy";
  c.commands =
      "units metal\nmass 1 58.71\nmass 2 26.98\npair_style eam/alloy\npair_coeff * * "
      "NiAlH_jea.eam.alloy Ni Al\n";
  const double a = 3.567653228471;
  c.cell = {a, a, a};
  c.basis = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  c.types = {2, 1, 1, 1};
  c.n = {4, 4, 4};
  c.type_mass = {0.0, 58.71, 26.98};
  c.labels = {"G", "X", "M", "R"};
  const auto r = compare_with_lammps(c, 4, "sc", H);
  EXPECT_EQ(r.branches, 12);
  EXPECT_LT(r.worst, kAcceptance * r.wmax);
  EXPECT_LT(r.gamma_acoustic, kGammaFloor * r.wmax);
}

// B2 NiAl, a = 2.88 Å (near equilibrium; the comparison is of the same configuration, stress
// or not): sc lattice, 2 basis atoms, 6 branches.
TEST(CrystalDispersionSlow, B2NiAlEamAlloyMatchesLammps) {
  CrystalSpec c;
  c.name = "B2 NiAl eam/alloy";
  c.commands =
      "units metal\nmass 1 58.71\nmass 2 26.98\npair_style eam/alloy\npair_coeff * * "
      "NiAlH_jea.eam.alloy Ni Al\n";
  const double a = 2.88;
  c.cell = {a, a, a};
  c.basis = {{0, 0, 0}, {0.5, 0.5, 0.5}};
  c.types = {1, 2};
  c.n = {4, 4, 4};
  c.type_mass = {0.0, 58.71, 26.98};
  c.labels = {"G", "X", "M", "R"};
  const auto r = compare_with_lammps(c, 2, "sc", H);
  EXPECT_EQ(r.branches, 6);
  EXPECT_LT(r.worst, kAcceptance * r.wmax);
  EXPECT_LT(r.gamma_acoustic, kGammaFloor * r.wmax);
}

// FCC Cu (Cu_u3.eam, a = 3.615 Å): one basis atom, 3 branches.
TEST(CrystalDispersionSlow, FccCopperEamMatchesLammps) {
  CrystalSpec c;
  c.name = "Cu eam";
  c.commands = "units metal\npair_style eam\npair_coeff 1 1 Cu_u3.eam\n";
  c.cell = {3.615, 3.615, 3.615};
  c.basis = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  c.types.assign(4, 1);
  c.n = {4, 4, 4};
  c.type_mass = {0.0, 63.55};
  c.labels = {"G", "X", "W", "K", "L", "U"};
  const auto r = compare_with_lammps(c, 1, "fcc", H);
  EXPECT_EQ(r.branches, 3);
  EXPECT_LT(r.worst, kAcceptance * r.wmax);
  EXPECT_LT(r.gamma_acoustic, kGammaFloor * r.wmax);
}
#endif
