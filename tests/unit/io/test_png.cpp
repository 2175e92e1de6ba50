#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <cstdlib>
#include <string>
#include <vector>

#include "pdcg/io/png.hpp"

// The signature and the IHDR size fields; the file is decoded by matplotlib (an independent
// decoder) in the test below (python3-matplotlib, a declared dependency).
TEST(Png, WritesSignatureAndHeader) {
  const auto path = std::filesystem::temp_directory_path() / "pdcg_test.png";
  std::vector<double> field(6 * 4);
  for (std::size_t i = 0; i < field.size(); ++i) field[i] = static_cast<double>(i);
  pdcg::io::write_png_field(path, 6, 4, field, false);
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 33u);
  const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  for (int i = 0; i < 8; ++i) EXPECT_EQ(bytes[static_cast<std::size_t>(i)], sig[i]);
  EXPECT_EQ(bytes[19], 6);  // width (big-endian u32 at offset 16)
  EXPECT_EQ(bytes[23], 4);  // height
  std::filesystem::remove(path);
}

TEST(Png, DecodedByMatplotlib) {
  const auto path = std::filesystem::temp_directory_path() / "pdcg_test_decode.png";
  std::vector<double> field(5 * 3, 0.0);
  field[0] = 1.0;  // top-left pixel at the top of the colour map (viridis yellow 253,231,37)
  pdcg::io::write_png_field(path, 5, 3, field, false);
  // python3-matplotlib is a declared dependency (workflows/lib/setup.sh): its absence is a failure.
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/python3"));
  const std::string cmd =
      "/usr/bin/python3 -c \"import matplotlib.image as m; a = m.imread('" + path.string() +
      "'); import sys; sys.exit(0 if a.shape == (3, 5, 3) and round(a[0,0,0]*255) == 253 and "
      "round(a[0,0,1]*255) == 231 and round(a[1,1,0]*255) == 68 else 1)\"";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  std::filesystem::remove(path);
}
