// Inputs found by the libFuzzer harnesses of tests/fuzz (docs/testing.md "Sanitizers and
// fuzzing"), kept as unit tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "pdcg/core/error.hpp"
#include "pdcg/scene/expression.hpp"
#include "pdcg/scene/scene.hpp"

using namespace pdcg;

// fuzz_scene: a mapping key that is not a plain scalar (a tagged empty key `!rom:` from a
// mutated `from:`, or a sequence as key) escaped load_scene as YAML::BadConversion ("bad
// conversion", no key, no line). Now an InputError naming the section and the line.
TEST(FuzzRegression, SceneKeyThatIsNotAPlainName) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("pdcg_scene_fuzz_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "bad.yaml";
  for (const char* crack : {"{!rom: [0.0, 0.5], to: [0.3, 0.5]}", "{[a, b]: 1, to: [0.3, 0.5]}"}) {
    std::ofstream(path) << "dimension: 2\n"
                           "geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0],\n"
                           "           spacing: 0.1, cracks: ["
                        << crack << "]}\n";
    try {
      (void)scene::load_scene(path);
      ADD_FAILURE() << crack << ": accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("a key must be a plain name"), std::string::npos) << what;
      EXPECT_NE(what.find("geometry.cracks[]"), std::string::npos) << what;
      EXPECT_EQ(e.line_number(), 3) << what;
    }
  }
  std::filesystem::remove_all(dir);
}

// fuzz_scene: a required key missing from a list item (`holes: [{center: [0.2, 0.5]}]`)
// escaped load_scene as YAML::InvalidNode ("invalid node; first invalid key: \"radius\""): the
// number/text/vector accessors asked the absent node its type, which throws. Now an InputError
// "missing key" naming the key, for each kind of accessor.
TEST(FuzzRegression, RequiredKeyMissingFromAListItem) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("pdcg_scene_fuzz_key_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / "bad.yaml";
  struct Case {
    const char* geometry_tail;
    const char* key;
  };
  for (const Case& c : {Case{"holes: [{center: [0.2, 0.5]}]", "geometry.holes[].radius"},
                        Case{"holes: [{radius: 0.1}]", "geometry.holes[].center"},
                        Case{"cracks: [{from: [0.0, 0.5]}]", "geometry.cracks[].to"}}) {
    std::ofstream(path) << "dimension: 2\n"
                           "geometry: {shape: rectangle, origin: [0.0, 0.0], size: [1.0, 1.0],\n"
                           "           spacing: 0.1, "
                        << c.geometry_tail << "}\n";
    try {
      (void)scene::load_scene(path);
      ADD_FAILURE() << c.geometry_tail << ": accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("missing key"), std::string::npos) << what;
      EXPECT_NE(what.find(c.key), std::string::npos) << what;
    }
  }
  std::filesystem::remove_all(dir);
}

// fuzz_expression: 300 '(' overflowed the stack of the recursive-descent parser (ASan
// stack-overflow in Parser::unary); a long chain "1+1+…" would overflow it when evaluated
// (one nested closure per operation). Both are InputErrors now; ordinary nesting still works.
TEST(FuzzRegression, ExpressionNestingAndLengthAreBounded) {
  const auto refused = [](const std::string& text, const char* why) {
    try {
      (void)scene::parse_expression(text, "loading.value");
      ADD_FAILURE() << text.substr(0, 40) << "…: accepted";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(why), std::string::npos) << what;
      EXPECT_NE(what.find("loading.value"), std::string::npos) << what;
    }
  };
  refused(std::string(300, '(') + "1" + std::string(300, ')'), "nested more than 64 levels");
  refused(std::string(5000, '-') + "1", "nested more than 64 levels");
  std::string chain = "1";
  for (int k = 0; k < 5000; ++k) chain += "+1";
  refused(chain, "more than 1000 operations");
  // 60 levels and 999 operations are fine, with the value of the closed form
  EXPECT_EQ(scene::parse_expression(std::string(60, '(') + "t" + std::string(60, ')'),
                                    "loading.value")(2.5),
            2.5);
  std::string sum = "t";
  for (int k = 0; k < 999; ++k) sum += "+t";
  EXPECT_EQ(scene::parse_expression(sum, "loading.value")(0.5), 500.0);
}
