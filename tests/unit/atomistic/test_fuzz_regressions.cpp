// Inputs found by the libFuzzer harnesses of tests/fuzz (docs/testing.md "Sanitizers and
// fuzzing"), kept as unit tests. The defects they found are undefined behaviour that a
// normal build may not show: these tests fail on the old code in the sanitizer build
// (tests/sanitize.sh); in every build they check that the input is read correctly.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <string>

#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/atomistic/eam_spline.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"
#include "scratch_dir.hpp"

using namespace pdcg;

namespace {

void write_gzip(const std::string& path, const std::string& text) {
  gzFile gz = gzopen(path.c_str(), "wb");
  ASSERT_NE(gz, nullptr);
  ASSERT_EQ(gzwrite(gz, text.data(), static_cast<unsigned>(text.size())),
            static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(gz), Z_OK);
}

}  // namespace

// fuzz_dump_gzip, first input (any gzip dump): the first random-access point of a gzip
// stream copied its window tail from an empty std::vector, memcpy(dst, nullptr, 0), which
// UBSan reports ("null pointer passed as argument 2").
TEST(FuzzRegression, GzipDumpFirstAccessPointWithEmptyTail) {
  test::ScratchDir dir("fuzz_gzip");
  const std::string path = dir / "two.dump.gz";
  write_gzip(path,
             "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n"
             "0 4\n0 5\n0 6\nITEM: ATOMS id type x y z\n2 1 1.5 2.5 3.5\n1 1 0.25 0.5 0.75\n");
  atomistic::DumpReader dump(path);
  ASSERT_TRUE(dump.compressed());
  ASSERT_EQ(dump.nframes(), 1u);
  const auto a = dump.frame(0);
  ASSERT_EQ(a.id.size(), 2u);
  // the values as written (sorted by id); exact: decimal text → double, no arithmetic
  EXPECT_EQ(a.id[0], 1);
  EXPECT_EQ(a.x[0], 0.25);
  EXPECT_EQ(a.x[5], 3.5);
}

// fuzz_eam: an EAM file whose densities are large and negative gave ρ̄ = −1.48e13, and the
// embedding lookup converted ρ̄/dρ + 1 to int (undefined outside the int range; UBSan:
// "outside the range of representable values of type 'int'"). LAMMPS's PairEAM clamps the
// row to [1, nrho−1]: row 1 here, whose cubic in p = ρ̄/dρ + 1 − 1 is evaluated as written.
TEST(FuzzRegression, EamEmbeddingOfHugeNegativeDensityUsesRowOne) {
  // rows 0..2, 7 coefficients each; row 1: F′ = 1 (c2), F = 2p + 3 (c5, c6); rows 0 and 2
  // are poison so that a wrong row shows
  const double table[21] = {9, 9, 9, 9, 9, 9, 9,  //
                            0, 0, 1, 0, 0, 2, 3,  //
                            7, 7, 7, 7, 7, 7, 7};
  const double rho = -1.48e13;
  const auto e = atomistic::eam::embedding(table, rho, 1.0, 3, 10.0);
  const double p = rho;  // ρ̄·1 + 1 − 1: exact, |ρ̄| < 2^53
  EXPECT_EQ(e.value, 2.0 * p + 3.0);
  EXPECT_EQ(e.first, 1.0);
  EXPECT_EQ(e.second, 0.0);
}

// fuzz_eam: a funcfl file whose cutoff (4.7e8) lies far past its r table (nr·dr = 4.8): a bond
// inside that cutoff gave r/dr + 1 > 2^31, converted to int for the density row (UB; UBSan:
// "outside the range of representable values of type 'int'"; in a normal build the row index
// became INT_MIN). LAMMPS's row choice min((int) p, nr − 1) is kept without the conversion: the
// last row at p = 1. With constant tables the density and F are constant (F′ = 0), and the
// pair term is φ = z2r/r with z2r constant, so the force state scales as 1/r² exactly: the
// bond at 5e9 (UB before) is compared with the bond at 2e9 (p < 2^31, defined before too).
TEST(FuzzRegression, EamBondFarPastTheRadialTableUsesTheLastRow) {
  test::ScratchDir dir("fuzz_eam_row");
  const std::string path = dir / "const.eam";
  {
    std::ofstream f(path);
    f << "constant tables\n29 63.55 3.615 FCC\n5 0.1 5 1.0 1e10\n";
    for (int k = 0; k < 5; ++k) f << "0 ";  // F(rho) = 0
    f << "\n";
    for (int k = 0; k < 5; ++k) f << "1 ";  // Z(r) = 1
    f << "\n";
    for (int k = 0; k < 5; ++k) f << "0.5 ";  // rho(r) = 0.5
    f << "\n";
  }
  const auto spec = atomistic::read_potential_commands_from_string(
      "units metal\npair_style eam\npair_coeff * * " + path + "\n", "fuzz.in", 1);
  const auto pot = atomistic::make_potential(spec);
  auto force_at = [&](double r) {
    const double bond[3] = {r, 0.0, 0.0};
    const int type[1] = {1};
    atomistic::FamilyState fs;
    fs.type = 1;
    fs.size = 1;
    fs.neighbor_type = type;
    fs.bond = bond;
    std::vector<double> t(3, 0.0);
    (void)pot->force_state(fs, t.data());
    return t;
  };
  const auto far = force_at(5e9), near = force_at(2e9);
  ASSERT_TRUE(std::isfinite(far[0]));
  ASSERT_NE(near[0], 0.0);
  // 1/r² scaling: (5e9/2e9)² = 6.25; tolerance: two divisions by r² in double precision
  EXPECT_NEAR(near[0] / far[0], 6.25, 1e-12);
  EXPECT_EQ(far[1], 0.0);
  EXPECT_EQ(far[2], 0.0);
}

// fuzz_eam: a setfl header declaring Nr = 10⁹ (one mutated digit) made read_setfl size its
// tables first — malloc of 16 GB, libFuzzer out-of-memory. The counts are now checked against
// the file's size (two bytes per value at least) before anything is allocated.
TEST(FuzzRegression, EamHeaderCountsBeyondTheFileAreRefusedBeforeAllocation) {
  test::ScratchDir dir("fuzz_eam_oom");
  const std::string path = dir / "big.eam.alloy";
  {
    std::ofstream f(path);
    f << "c1\nc2\nc3\n1 Cu\n5 0.1 1000000000 0.001 4.5\n29 63.55 3.615 fcc\n0 0 0 0 0\n";
  }
  try {
    (void)atomistic::make_potential(atomistic::read_potential_commands_from_string(
        "units metal\npair_style eam/alloy\npair_coeff * * " + path + " Cu\n", "fuzz.in", 1));
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("too short for its header"), std::string::npos) << what;
    EXPECT_NE(what.find("table values declared"), std::string::npos) << what;
  }
}
