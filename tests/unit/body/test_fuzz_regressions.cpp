// Inputs found by the libFuzzer harnesses of tests/fuzz (docs/testing.md "Sanitizers and
// fuzzing"), kept as unit tests.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/body/model_file.hpp"
#include "pdcg/core/error.hpp"

using namespace pdcg;

// fuzz_h5_struct: a valid HDF5 body whose box/lo holds 2 values instead of 3. read_body read
// lo[0..2] unchecked (UBSan: reference binding to null pointer for an empty dataset; a heap
// read past the end for a short one; in a normal build a silent garbage box). Now refused
// with an InputError naming the dataset.
TEST(FuzzRegression, BodyWithShortBoxDatasetIsRefused) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("pdcg_fuzz_body_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "short_lo.h5";
  std::filesystem::copy_file(
      std::string(PDCG_SOURCE_DIR) + "/tests/fuzz/corpus/model_file/lj_body.h5", path,
      std::filesystem::copy_options::overwrite_existing);
  {
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "box/lo", H5P_DEFAULT), 0);
    const hsize_t n = 2;
    const double v[2] = {0.0, 0.0};
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t d =
        H5Dcreate2(f, "box/lo", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(d, 0);
    ASSERT_GE(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v), 0);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  try {
    (void)body::read_body(path);
    ADD_FAILURE() << "a 2-value box/lo was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("box/lo"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

namespace {
void write_vlen_strings(hid_t file, const char* path, const std::vector<const char*>& v) {
  const hsize_t n = v.size();
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  const hid_t space = H5Screate_simple(1, &n, nullptr);
  const hid_t d = H5Dcreate2(file, path, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(d, 0);
  ASSERT_GE(H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0);
  H5Dclose(d);
  H5Sclose(space);
  H5Tclose(type);
}
}  // namespace

// fuzz_h5_struct: a body with two potential file names but one file content. read_body
// indexed the contents with at(): std::out_of_range escaped the reader (not a pdcg::Error).
// Now refused with an InputError naming potential/file_contents.
TEST(FuzzRegression, BodyWithFewerPotentialFileContentsThanNamesIsRefused) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("pdcg_fuzz_files_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "files.h5";
  std::filesystem::copy_file(
      std::string(PDCG_SOURCE_DIR) + "/tests/fuzz/corpus/model_file/lj_body.h5", path,
      std::filesystem::copy_options::overwrite_existing);
  {
    const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    H5Ldelete(f, "potential/file_names", H5P_DEFAULT);  // absent in an lj body
    H5Ldelete(f, "potential/file_contents", H5P_DEFAULT);
    write_vlen_strings(f, "potential/file_names", {"a.eam", "b.eam"});
    write_vlen_strings(f, "potential/file_contents", {"only one"});
    H5Fclose(f);
  }
  try {
    (void)body::read_body(path);
    ADD_FAILURE() << "two file names with one content were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("potential/file_contents"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

// fuzz_h5_struct (in memory, 7 208th execution): an eam body whose /potential@ntypes is
// 2^31 − 1. read_body passed it to the rebuilt potential's command reader, which sized its
// per-type mass table with ntypes + 1 (UBSan: signed integer overflow; without the overflow a
// 16 GiB table). Now the stored count is checked against atoms2pd's bound (1..kMaxAtomTypes),
// an InputError naming the attribute, before any potential is built; so are 0, negatives and a
// count beyond int.
TEST(FuzzRegression, BodyWithAtomTypeCountOutOfRangeIsRefused) {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("pdcg_fuzz_ntypes_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "ntypes.h5";
  for (const std::int64_t ntypes :
       {std::int64_t{2147483647}, std::int64_t{1} << 40, std::int64_t{0}, std::int64_t{-1},
        std::int64_t{atomistic::kMaxAtomTypes} + 1}) {
    std::filesystem::copy_file(
        std::string(PDCG_SOURCE_DIR) + "/tests/fuzz/corpus/model_file/cu_body.h5", path,
        std::filesystem::copy_options::overwrite_existing);
    {
      const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      ASSERT_GE(f, 0);
      // through the open group (HDF5 1.10.8 does not write an attribute opened by name)
      const hid_t g = H5Oopen(f, "/potential", H5P_DEFAULT);
      const hid_t a = H5Aopen(g, "ntypes", H5P_DEFAULT);
      ASSERT_GE(a, 0);
      ASSERT_GE(H5Awrite(a, H5T_NATIVE_INT64, &ntypes), 0);
      H5Aclose(a);
      H5Oclose(g);
      H5Fclose(f);
    }
    try {
      (void)body::read_body(path, body::potential_from_commands);
      ADD_FAILURE() << "ntypes " << ntypes << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("/potential@ntypes"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(std::to_string(ntypes)), std::string::npos) << e.what();
    }
  }
  // the file as written (ntypes 1) reads
  std::filesystem::copy_file(
      std::string(PDCG_SOURCE_DIR) + "/tests/fuzz/corpus/model_file/cu_body.h5", path,
      std::filesystem::copy_options::overwrite_existing);
  EXPECT_GT(body::read_body(path, body::potential_from_commands).size(), 0u);
  std::filesystem::remove_all(dir);
}
