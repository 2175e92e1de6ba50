// Inputs found by the libFuzzer harnesses of tests/fuzz (docs/testing.md "Sanitizers and
// fuzzing"), kept as unit tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "pdcg/core/error.hpp"
#include "pdcg/io/hdf5.hpp"

using namespace pdcg;

// fuzz_h5_result, first input (a pdcg body file): read_string on a dataset of three strings
// (a file whose `scene` or `series` is an array) let H5Dread write three pointers into one
// char* on the stack (ASan: stack-buffer-overflow). Now a pdcg::Error naming the dataset.
TEST(FuzzRegression, ReadStringOfStringArrayIsRefused) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("pdcg_test_io_fuzz_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "strings.h5";
  {
    io::H5Writer w(path, {"pdcg-test", 1, UnitStyle::none, "", ""});
    w.write_strings("lines", {"pair_style zero 1.0", "pair_coeff * *", "mass * 1.0"});
    w.write("one", "scene text");
    w.commit();
  }
  io::H5Reader r(path);
  EXPECT_EQ(r.read_string("one"), "scene text");
  try {
    (void)r.read_string("lines");
    ADD_FAILURE() << "a dataset of 3 strings read as one string";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("expected one string, found 3 elements"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("lines"), std::string::npos) << e.what();
  }
  EXPECT_EQ(r.read_strings("lines").size(), 3u);
  std::filesystem::remove_all(dir);
}
