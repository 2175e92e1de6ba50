// Inputs found by the libFuzzer harnesses of tests/fuzz (docs/testing.md "Sanitizers and
// fuzzing"), kept as unit tests. The defects they found are undefined behaviour that a
// normal build may not show: these tests fail on the old code in the sanitizer build
// (tests/sanitize.sh); in every build they check that the input is read correctly.
#include <gtest/gtest.h>
#include <zlib.h>

#include <string>

#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/atomistic/eam_spline.hpp"
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
