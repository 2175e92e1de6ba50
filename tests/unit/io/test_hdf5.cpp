#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <span>
#include <stdexcept>

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
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
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

namespace {
io::H5Image bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
/// The file of RoundTripWithProvenance, written by `w`.
void fill(io::H5Writer& w) {
  w.write("points/x", std::vector<double>{1.0, 2.0, 3.0, 4.0, 5.0, 6.0}, {2, 3});
  w.write("points/id", std::vector<std::int64_t>{7, 8});
  w.write("potential/pair_style", "lj/cut 2.5");
  w.write_strings("potential/lines", {"pair_style lj/cut 2.5", "pair_coeff * * 1 1"});
  w.attribute("points", "count", std::int64_t{2});
  w.attribute("/", "epsilon", 2.5);
}
void expect_content(const io::H5Reader& r) {
  EXPECT_EQ(r.info().format, "pdcg-test");
  EXPECT_EQ(r.info().schema_version, 3);
  EXPECT_EQ(r.info().units, UnitStyle::metal);
  EXPECT_EQ(r.info().command_line, "pdcg test --x");
  EXPECT_EQ(r.dims("points/x"), (std::vector<std::size_t>{2, 3}));
  EXPECT_EQ(r.read_double("points/x"), (std::vector<double>{1.0, 2.0, 3.0, 4.0, 5.0, 6.0}));
  EXPECT_EQ(r.read_int("points/id"), (std::vector<std::int64_t>{7, 8}));
  EXPECT_EQ(r.read_string("potential/pair_style"), "lj/cut 2.5");
  EXPECT_EQ(r.read_strings("potential/lines"),
            (std::vector<std::string>{"pair_style lj/cut 2.5", "pair_coeff * * 1 1"}));
  EXPECT_EQ(r.attribute_int("points", "count"), 2);
  EXPECT_EQ(r.attribute_double("/", "epsilon"), 2.5);
  EXPECT_NO_THROW(r.verify());
}
}  // namespace

// In memory (the fuzz harness's files): an in-memory writer creates nothing on disk, and its
// image is a complete HDF5 file — HDF5 opens it from disk (the ordinary reader) with the same
// content; the image reader reads a file written to disk (its bytes) the same way.
TEST(Hdf5, InMemoryFilesAreCompleteHdf5Files) {
  const io::FileInfo info{"pdcg-test", 3, UnitStyle::metal, "", "pdcg test --x"};
  const auto dir = scratch("in_memory.h5").parent_path();
  const std::size_t before = files_in(dir);
  io::H5Image image;
  {
    io::H5Writer w(io::InMemory{"memory file"}, info);
    fill(w);
    EXPECT_THROW((void)w.image(), std::logic_error);  // before commit()
    w.commit();
    image = w.image();
  }
  EXPECT_EQ(files_in(dir), before) << "the in-memory writer created a file";
  expect_content(io::H5Reader(io::InMemory{"memory file"}, image));
  // the image on disk, read by HDF5's ordinary file driver
  const auto copy = scratch("image_copy.h5");
  std::ofstream(copy, std::ios::binary)
      .write(reinterpret_cast<const char*>(image.data()),
             static_cast<std::streamsize>(image.size()));
  expect_content(io::H5Reader(copy));
  // a file written to disk, read as an image
  const auto disk = scratch("disk.h5");
  {
    io::H5Writer w(disk, info);
    fill(w);
    w.commit();
    EXPECT_THROW((void)w.image(), std::logic_error);  // a writer to a file has no image
  }
  const io::H5Reader from_bytes(io::InMemory{"disk bytes"}, bytes_of(disk));
  expect_content(from_bytes);
  EXPECT_EQ(from_bytes.path(), "disk bytes");
  // two images open at once are two files (the core driver's names are unique)
  const io::H5Reader a(io::InMemory{"a"}, image), b(io::InMemory{"a"}, bytes_of(disk));
  EXPECT_EQ(a.read_int("points/id"), b.read_int("points/id"));
}

// Damaged images are refused like damaged files: InputError naming the caller's name.
TEST(Hdf5, InMemoryDamagedImagesAreRefusedWithTheirName) {
  io::H5Image image;
  {
    io::H5Writer w(io::InMemory{"x"}, {"pdcg-test", 1, UnitStyle::lj, "", ""});
    w.write("x", std::vector<double>(100, 1.5));
    w.commit();
    image = w.image();
  }
  auto refused = [](std::span<const unsigned char> bytes, const std::string& what) {
    try {
      io::H5Reader r(io::InMemory{"fuzz input 7"}, bytes);
      r.verify();
      ADD_FAILURE() << "accepted: " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("fuzz input 7"), std::string::npos) << e.what();
    }
  };
  refused({}, "no bytes");
  const std::string text = "hello, not HDF5\n";
  refused({reinterpret_cast<const unsigned char*>(text.data()), text.size()}, "text");
  refused(std::span(image).first(image.size() / 2), "the first half");
  // a flipped value in the raw data of x (the last bytes of the file hold them): its checksum
  io::H5Image flipped = image;
  const unsigned char one_and_a_half[8] = {0, 0, 0, 0, 0, 0, 0xf8, 0x3f};  // 1.5, little-endian
  const auto at = std::search(flipped.begin(), flipped.end(), std::begin(one_and_a_half),
                              std::end(one_and_a_half));
  ASSERT_NE(at, flipped.end());
  at[7] = 0x40;  // 1.5 → 2.0 + …: a different double
  refused(flipped, "a value changed");
}
