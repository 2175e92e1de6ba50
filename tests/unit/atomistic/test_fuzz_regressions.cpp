// Inputs found by the libFuzzer harnesses of tests/fuzz (docs/testing.md "Sanitizers and
// fuzzing"), kept as unit tests. The defects they found are undefined behaviour that a
// normal build may not show: these tests fail on the old code in the sanitizer build
// (tests/sanitize.sh); in every build they check that the input is read correctly.
#include <gtest/gtest.h>
#include <zlib.h>

#include <string>

#include "pdcg/atomistic/dump_reader.hpp"
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
