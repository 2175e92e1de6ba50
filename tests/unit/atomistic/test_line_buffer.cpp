// The line buffer of the text readers (src/atomistic/text_source.hpp, LineReader) starts at
// 64 KiB and doubles at each refill up to its chunk size (8 MiB for dumps), and further for a
// line longer than the buffer. These tests read dumps whose frames cross every growth step,
// forward and by random access (seeks back into bytes read with a smaller buffer), plain and
// gzip, and a dump whose lines are longer than the first buffer; every value is compared with
// the value written (decimal text with an exact binary value: no tolerance).
#include <gtest/gtest.h>
#include <zlib.h>

#include <fstream>
#include <string>

#include "pdcg/atomistic/dump_reader.hpp"
#include "scratch_dir.hpp"

using namespace pdcg;

namespace {

constexpr int kFrames = 12, kAtoms = 4000;  // ~150 KB per frame, ~1.9 MB in all

/// x = id/4 + frame, y = −id/8, z = frame/2: short decimals with exact binary values.
std::string many_frames() {
  std::string s;
  for (int f = 0; f < kFrames; ++f) {
    s += "ITEM: TIMESTEP\n" + std::to_string(100 * f) + "\nITEM: NUMBER OF ATOMS\n" +
         std::to_string(kAtoms) + "\nITEM: BOX BOUNDS pp pp pp\n0 2000\n-600 0\n0 10\n" +
         "ITEM: ATOMS id type x y z\n";
    for (int id = kAtoms; id >= 1; --id)  // reverse order: the reader sorts by id
      s += std::to_string(id) + " " + std::to_string(1 + id % 2) + " " +
           std::to_string(id / 4.0 + f) + " " + std::to_string(-id / 8.0) + " " +
           std::to_string(f / 2.0) + "\n";
  }
  return s;
}

void check_frame(const atomistic::DumpReader& dump, int f) {
  const auto a = dump.frame(static_cast<std::size_t>(f));
  ASSERT_EQ(a.id.size(), static_cast<std::size_t>(kAtoms)) << "frame " << f;
  EXPECT_EQ(dump.info(static_cast<std::size_t>(f)).timestep, 100 * f);
  for (int k = 0; k < kAtoms; ++k) {
    const int id = k + 1;
    ASSERT_EQ(a.id[k], id);
    ASSERT_EQ(a.type[k], 1 + id % 2);
    ASSERT_EQ(a.x[3 * k + 0], id / 4.0 + f) << "frame " << f << " id " << id;
    ASSERT_EQ(a.x[3 * k + 1], -id / 8.0);
    ASSERT_EQ(a.x[3 * k + 2], f / 2.0);
  }
}

void check_all_orders(const std::string& path) {
  atomistic::DumpReader dump(path);
  ASSERT_EQ(dump.nframes(), static_cast<std::size_t>(kFrames));
  for (int f = kFrames - 1; f >= 0; --f) check_frame(dump, f);  // seeks backwards
  for (int f = 0; f < kFrames; f += 5) check_frame(dump, f);
  atomistic::DumpReader fresh(path);  // lazy index: frame 5 first, then 2
  check_frame(fresh, 5);
  check_frame(fresh, 2);
  check_frame(fresh, kFrames - 1);
}

}  // namespace

TEST(DumpLineBuffer, FramesAcrossBufferGrowthReadBackExactly) {
  test::ScratchDir dir("line_buffer");
  const std::string path = dir / "many.dump";
  std::ofstream(path) << many_frames();
  check_all_orders(path);
}

TEST(DumpLineBuffer, GzipFramesAcrossBufferGrowthReadBackExactly) {
  test::ScratchDir dir("line_buffer_gz");
  const std::string path = dir / "many.dump.gz";
  const std::string text = many_frames();
  gzFile gz = gzopen(path.c_str(), "wb1");
  ASSERT_NE(gz, nullptr);
  ASSERT_EQ(gzwrite(gz, text.data(), static_cast<unsigned>(text.size())),
            static_cast<int>(text.size()));
  ASSERT_EQ(gzclose(gz), Z_OK);
  check_all_orders(path);
}

// A header line of ~150 KB and atom lines of ~100 KB: longer than the first 64 KiB buffer.
TEST(DumpLineBuffer, LinesLongerThanTheFirstBufferAreReadWhole) {
  test::ScratchDir dir("line_buffer_long");
  const std::string path = dir / "wide.dump";
  constexpr int kExtra = 20000;
  std::string s =
      "ITEM: TIMESTEP\n7\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS pp pp pp\n0 9\n0 9\n0 9\n"
      "ITEM: ATOMS id type x y z";
  for (int c = 0; c < kExtra; ++c) s += " c_q" + std::to_string(c);
  s += "\n";
  for (int id = 1; id <= 3; ++id) {
    s += std::to_string(id) + " 1 " + std::to_string(id + 0.5) + " 2.25 -3.125";
    for (int c = 0; c < kExtra; ++c) s += " 0.5";
    s += "\n";
  }
  std::ofstream(path) << s;
  atomistic::DumpReader dump(path);
  ASSERT_EQ(dump.nframes(), 1u);
  EXPECT_EQ(dump.columns().size(), static_cast<std::size_t>(5 + kExtra));
  const auto a = dump.frame(0);
  ASSERT_EQ(a.id.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(a.x[3 * k + 0], k + 1.5);
    EXPECT_EQ(a.x[3 * k + 1], 2.25);
    EXPECT_EQ(a.x[3 * k + 2], -3.125);
  }
}
