// Full disk, file size limit, damaged files and killed writers: the atomic writers report the
// final file, the OS error and the fix; an earlier file under the final name and the directory
// stay intact; readers refuse truncated or corrupt HDF5 instead of returning its bytes.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/io/atomic_output.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg/io/png.hpp"

namespace fs = std::filesystem;
using namespace pdcg;

namespace {

fs::path scratch_dir(const std::string& name) {
  fs::path d =
      fs::temp_directory_path() / ("pdcg_test_atomic_" + std::to_string(::getpid())) / name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.push_back(e.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// RLIMIT_FSIZE = bytes for the scope, SIGXFSZ ignored (as pdcg's main() does): writes beyond
/// the limit fail with EFBIG, which is what a full disk (ENOSPC) looks like to the writer.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &old_);
    old_handler_ = signal(SIGXFSZ, SIG_IGN);
    rlimit l = old_;
    l.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &l);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &old_);
    signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit old_{};
  sighandler_t old_handler_{};
};

void expect_clear_write_error(const std::string& what, const fs::path& final_path) {
  EXPECT_NE(what.find(final_path.string()), std::string::npos) << what;  // which file
  EXPECT_NE(what.find("File too large"), std::string::npos) << what;     // the OS error
  EXPECT_NE(what.find("ulimit -f"), std::string::npos) << what;          // how to fix it
  EXPECT_NE(what.find("-o"), std::string::npos) << what;                 // or write elsewhere
}

}  // namespace

TEST(AtomicOutput, TextFileBeyondTheFileSizeLimitIsAClearErrorAndKeepsTheOldFile) {
  const auto dir = scratch_dir("text");
  const auto final_path = dir / "reactions.csv";
  {
    io::AtomicTextFile f(final_path);
    f.stream() << "step,t\n0,0\n";
    f.commit();
  }
  std::string what;
  {
    FileSizeLimit limit(4096);
    io::AtomicTextFile f(final_path);
    for (int i = 0; i < 20000; ++i) f.stream() << i << ",0.123456789\n";  // ~260 kB
    try {
      f.commit();
    } catch (const Error& e) {
      what = e.what();
    }
  }
  ASSERT_FALSE(what.empty()) << "commit() of a file beyond the limit did not throw";
  expect_clear_write_error(what, final_path);
  EXPECT_EQ(slurp(final_path), "step,t\n0,0\n");  // the earlier version intact
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"reactions.csv"});  // temporary removed
}

TEST(AtomicOutput, Hdf5BeyondTheFileSizeLimitIsAClearErrorAndLeavesNoFile) {
  const auto dir = scratch_dir("h5");
  const auto final_path = dir / "results_0003.h5";
  std::string what;
  {
    FileSizeLimit limit(64 * 1024);
    try {
      io::H5Writer w(final_path, {"pdcg-test", 1, UnitStyle::none, "", ""});
      const std::vector<double> x(100000, 1.5);  // 800 kB
      w.write("fields/x", x);
      w.commit();
    } catch (const Error& e) {
      what = e.what();
    }
  }
  ASSERT_FALSE(what.empty()) << "writing 800 kB under a 64 kB limit did not throw";
  expect_clear_write_error(what, final_path);
  EXPECT_TRUE(names_in(dir).empty());  // no final file, no temporary
}

TEST(AtomicOutput, PngBeyondTheFileSizeLimitIsAClearError) {
  const auto dir = scratch_dir("png");
  const auto final_path = dir / "S.png";
  std::vector<std::uint8_t> rgb(256 * 256 * 3);
  std::mt19937 gen(7);  // noise: does not compress below the limit
  for (auto& c : rgb) c = static_cast<std::uint8_t>(gen());
  std::string what;
  {
    FileSizeLimit limit(8192);
    try {
      io::write_png(final_path, 256, 256, rgb);
    } catch (const Error& e) {
      what = e.what();
    }
  }
  ASSERT_FALSE(what.empty());
  expect_clear_write_error(what, final_path);
  EXPECT_TRUE(names_in(dir).empty());
}

TEST(AtomicOutput, Hdf5ReaderRefusesAFlippedByte) {
  const auto dir = scratch_dir("flip");
  const auto path = dir / "state.h5";
  std::vector<double> u(1000);
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = 1e-3 * static_cast<double>(i);
  {
    io::H5Writer w(path, {"pdcg-test", 1, UnitStyle::none, "", ""});
    w.write("state/u", u);
    w.write("series", "step,t\n0,0\n");
    w.commit();
  }
  {
    io::H5Reader r(path);
    EXPECT_EQ(r.read_double("state/u"), u);  // intact: reads and verifies
    EXPECT_NO_THROW(r.verify());
  }
  // one byte of value 500 changed in place, as a disk error or a bad copy would
  haddr_t offset = HADDR_UNDEF;
  {
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const hid_t d = H5Dopen2(f, "state/u", H5P_DEFAULT);
    offset = H5Dget_offset(d);
    H5Dclose(d);
    H5Fclose(f);
  }
  ASSERT_NE(offset, HADDR_UNDEF);
  {
    std::fstream io(path, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(static_cast<std::streamoff>(offset + 500 * sizeof(double) + 3));
    io.put('\x5a');
  }
  io::H5Reader r(path);
  try {
    (void)r.read_double("state/u");
    FAIL() << "a corrupt dataset was read without an error";
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("state/u"), std::string::npos) << w;
    EXPECT_NE(w.find("checksum"), std::string::npos) << w;
    EXPECT_NE(w.find(path.string()), std::string::npos) << w;
  }
  EXPECT_THROW(r.verify(), InputError);
  EXPECT_EQ(r.read_string("series"), "step,t\n0,0\n");  // the other dataset is fine
}

TEST(AtomicOutput, Hdf5ReaderRefusesATruncatedFile) {
  const auto dir = scratch_dir("trunc");
  const auto path = dir / "checkpoint_00000004.h5";
  {
    io::H5Writer w(path, {"pdcg-test", 1, UnitStyle::none, "", ""});
    w.write("state/u", std::vector<double>(5000, 2.0));
    w.commit();
  }
  fs::resize_file(path, fs::file_size(path) / 2);
  try {
    io::H5Reader r(path);
    (void)r.read_double("state/u");
    FAIL() << "a truncated file was read without an error";
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("truncated"), std::string::npos) << w;
    EXPECT_NE(w.find(path.string()), std::string::npos) << w;
  }
}

TEST(AtomicOutput, StaleTemporariesOfDeadProcessesAreRemoved) {
  const auto dir = scratch_dir("stale");
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_GT(child, 0);
  waitpid(child, nullptr, 0);  // its pid now names no process
  const std::string dead = ".results_0010.h5.tmp." + std::to_string(child) + ".3";
  const std::string mine = ".results_0011.h5.tmp." + std::to_string(getpid()) + ".4";
  for (const auto& n : {dead, mine, std::string("results_0009.h5"), std::string(".hidden.tmp.x")})
    std::ofstream(dir / n) << "x";
  EXPECT_EQ(io::remove_stale_temporaries(dir), 1);
  std::vector<std::string> kept{mine, ".hidden.tmp.x", "results_0009.h5"};  // alive, not ours
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(names_in(dir), kept);
}

TEST(AtomicOutput, UnwritableOutputIsRefusedBeforeAnyWork) {
  const auto dir = scratch_dir("unwritable");
  std::ofstream(dir / "plain") << "a file, not a directory";
  try {
    io::require_writable_output(dir / "plain" / "out.h5", "--output");
    FAIL() << "an output below a regular file was accepted";
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("--output"), std::string::npos) << w;
    EXPECT_NE(w.find("plain"), std::string::npos) << w;
  }
  EXPECT_THROW(io::require_writable_output(dir, "--output"), InputError);     // a directory
  io::require_writable_output(dir / "new" / "deeper" / "x.csv", "--output");  // created
  EXPECT_TRUE(fs::is_directory(dir / "new" / "deeper"));
  EXPECT_TRUE(names_in(dir / "new" / "deeper").empty());  // the probe is gone
}
