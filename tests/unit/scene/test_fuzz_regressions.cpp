// Inputs found by the libFuzzer harnesses of tests/fuzz (docs/testing.md "Sanitizers and
// fuzzing"), kept as unit tests.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "pdcg/core/error.hpp"
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
