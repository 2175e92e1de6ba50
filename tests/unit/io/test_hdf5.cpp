#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pdcg/core/error.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/io/hdf5.hpp"

namespace fs = std::filesystem;
using namespace pdcg;

namespace {
fs::path scratch(const std::string& name) {
  fs::path d = fs::temp_directory_path() / ("pdcg_test_io_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d / name;
}
std::size_t files_in(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}
}  // namespace

TEST(Hdf5, RoundTripWithProvenance) {
  const auto path = scratch("round.h5");
  {
    io::H5Writer w(path, {"pdcg-test", 3, UnitStyle::metal, "", "pdcg test --x"});
    const std::vector<double> x{1.0, 2.0, 3.0, 4.0, 5.0, 6.0};
    const std::vector<std::int64_t> ids{7, 8};
    w.write("points/x", x, {2, 3});
    w.write("points/id", ids);
    w.write("potential/pair_style", "lj/cut 2.5");
    w.write_strings("potential/lines", {"pair_style lj/cut 2.5", "pair_coeff * * 1 1"});
    w.attribute("points", "count", std::int64_t{2});
    w.attribute("/", "epsilon", 2.5);
    w.commit();
  }
  io::H5Reader r(path);
  EXPECT_EQ(r.info().format, "pdcg-test");
  EXPECT_EQ(r.info().schema_version, 3);
  EXPECT_EQ(r.info().units, UnitStyle::metal);
  EXPECT_EQ(r.info().command_line, "pdcg test --x");
  EXPECT_FALSE(r.info().pdcg_version.empty());
  EXPECT_EQ(r.dims("points/x"), (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(r.read_double("points/x")[4], 5.0);
  EXPECT_EQ(r.read_int("points/id")[1], 8);
  EXPECT_EQ(r.read_string("potential/pair_style"), "lj/cut 2.5");
  EXPECT_EQ(r.read_strings("potential/lines")[1], "pair_coeff * * 1 1");
  EXPECT_EQ(r.attribute_int("points", "count"), 2);
  EXPECT_EQ(r.attribute_double("/", "epsilon"), 2.5);
  EXPECT_TRUE(r.exists("points/x"));
  EXPECT_FALSE(r.exists("points/nothing"));
  EXPECT_FALSE(r.exists("nothing/deeper"));
  EXPECT_THROW(r.read_double("nothing"), InputError);
  EXPECT_THROW(r.require_format("pdcg-body", 1), InputError);
  EXPECT_NO_THROW(r.require_format("pdcg-test", 3));
  EXPECT_THROW(r.require_format("pdcg-test", 2), InputError);  // newer schema than reader knows
}

// Acceptance: a write interrupted by an exception leaves no file
// under the final name, and the previous file under that name intact.
TEST(Hdf5, InterruptedWriteLeavesNoFileAndKeepsThePreviousOne) {
  const auto path = scratch("atomic.h5");
  fs::remove(path);
  const auto dir = path.parent_path();
  const std::size_t before = files_in(dir);

  auto interrupted_write = [&](double value) {
    io::H5Writer w(path, {"pdcg-test", 1, UnitStyle::lj, "", ""});
    const std::vector<double> x(1000, value);
    w.write("x", x);
    throw std::runtime_error("simulated crash in the middle of a write");
  };

  EXPECT_THROW(interrupted_write(1.0), std::runtime_error);
  EXPECT_FALSE(fs::exists(path)) << "a half-written file appeared under the final name";
  EXPECT_EQ(files_in(dir), before) << "the temporary file was left behind";

  {  // a complete file
    io::H5Writer w(path, {"pdcg-test", 1, UnitStyle::lj, "", ""});
    const std::vector<double> x(10, 42.0);
    w.write("x", x);
    w.commit();
  }
  EXPECT_THROW(interrupted_write(-1.0), std::runtime_error);
  io::H5Reader r(path);
  const auto x = r.read_double("x");
  ASSERT_EQ(x.size(), 10u);
  EXPECT_EQ(x[0], 42.0) << "the previous file was damaged by the interrupted write";
  EXPECT_EQ(files_in(dir), before + 1);
}

TEST(Hdf5, ClearErrorsOnBadFiles) {
  const auto text = scratch("not.h5");
  std::ofstream(text) << "hello\n";
  try {
    io::H5Reader r(text);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not an HDF5 file"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(text.string()), std::string::npos);
  }
  EXPECT_THROW(io::H5Reader(scratch("missing.h5")), InputError);
}

TEST(AtomicTextFile, CommitAndAbort) {
  const auto path = scratch("out.csv");
  fs::remove(path);
  {
    io::AtomicTextFile f(path);
    f.stream() << "id,fx\n";
  }  // not committed
  EXPECT_FALSE(fs::exists(path));
  {
    io::AtomicTextFile f(path);
    f.stream() << "id,fx\n1,0.5\n";
    f.commit();
  }
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "id,fx");
}
