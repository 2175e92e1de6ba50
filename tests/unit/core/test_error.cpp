#include <gtest/gtest.h>

#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"
#include "pdcg/core/units.hpp"
#include "pdcg_test.hpp"

using namespace pdcg;

TEST(InputError, MessageNamesEveryPart) {
  InputError e = InputError("not a number")
                     .source("run.dump")
                     .line(12)
                     .key("x")
                     .value("abc")
                     .expected("a floating-point number")
                     .fix("check the columns");
  EXPECT_STREQ(e.what(),
               "run.dump:12: x: not a number: got 'abc', expected a floating-point number. "
               "Fix: check the columns");
}

TEST(InputError, OmitsEmptyParts) {
  InputError e("unknown unit style");
  EXPECT_STREQ(e.what(), "unknown unit style.");
}

TEST(Parse, DoublesAndIntegers) {
  const TextLocation at{"f.txt", 3, "col"};
  EXPECT_EQ(parse_double("1.5e-3", at), 1.5e-3);
  EXPECT_EQ(parse_double("+2", at), 2.0);
  EXPECT_EQ(parse_double("-0.25", at), -0.25);
  EXPECT_EQ(parse_int("-42", at), -42);
}

TEST(Parse, RejectsGarbageNaNAndInfWithLocation) {
  const TextLocation at{"f.txt", 7, "vx"};
  for (const char* bad : {"abc", "1.0x", "", "nan", "inf", "-inf"}) {
    try {
      parse_double(bad, at);
      FAIL() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("f.txt:7"), std::string::npos) << m;
      EXPECT_NE(m.find("vx"), std::string::npos) << m;
      EXPECT_NE(m.find(std::string("'") + bad + "'"), std::string::npos) << m;
    }
  }
  EXPECT_THROW(parse_int("1.5", at), InputError);
}

TEST(Parse, SplitBlanks) {
  auto t = split_blanks("  a\tbb  c \r");
  ASSERT_EQ(t.size(), 3u);
  EXPECT_EQ(t[0], "a");
  EXPECT_EQ(t[1], "bb");
  EXPECT_EQ(t[2], "c");
  EXPECT_TRUE(split_blanks("   ").empty());
  EXPECT_EQ(trim("  x y \n"), "x y");
}

TEST(Units, ParseAndReject) {
  EXPECT_EQ(parse_unit_style("metal"), UnitStyle::metal);
  EXPECT_EQ(to_string(UnitStyle::lj), "lj");
  EXPECT_THROW(parse_unit_style("cgs", "scene.yaml"), InputError);
  // LAMMPS metal: mvv2e = 1.0364269e-4 (eV per amu*(A/ps)^2), boltz = 8.617343e-5 eV/K
  EXPECT_TRUE(test::close(unit_constants(UnitStyle::metal).mvv2e, 1.0364269e-4, {0, 1e-15}));
}

TEST(TestHelper, AllCloseReportsWorstEntry) {
  const std::vector<double> a{1.0, 2.0, 3.1}, e{1.0, 2.0, 3.0};
  auto r = test::all_close(a, e, {1e-12, 1e-3});
  EXPECT_FALSE(r);
  EXPECT_NE(std::string(r.message()).find("[2]"), std::string::npos) << r.message();
  EXPECT_TRUE(test::all_close(a, e, {0.11, 0.0}));
  EXPECT_DOUBLE_EQ(test::max_norm_relative_error(a, e), 0.1 / 3.0);
}

TEST(Parse, FrameRanges) {
  EXPECT_EQ(parse_frame_range("3", 10, "--frame").indices(), (std::vector<std::size_t>{3}));
  EXPECT_EQ(parse_frame_range("2:8:3", 10, "--frames").indices(), (std::vector<std::size_t>{2, 5, 8}));
  EXPECT_EQ(parse_frame_range("0:-1", 4, "--frames").indices(), (std::vector<std::size_t>{0, 1, 2, 3}));
  for (const char* bad : {"10", "0:10", "5:2", "1:3:0", "a:b", "1:2:3:4", "-11"}) {
    try {
      parse_frame_range(bad, 10, "--frames");
      FAIL() << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("frames 0 to 9"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos) << e.what();
    }
  }
}
