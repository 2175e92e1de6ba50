/// libFuzzer harness: scene YAML files (load_scene: every section, numbers and expressions
/// in t and x, y, z), then the resolved YAML written back and every expression evaluated.
/// The discretisation is not built (a fuzzed spacing could ask for any number of points).
#include "pdcg/scene/scene.hpp"

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = pdcg::fuzz::scratch_path("scene", ".yaml");
  pdcg::fuzz::write_file(path, data, size);
  return pdcg::fuzz::guarded([&] {
    const auto s = pdcg::scene::load_scene(path);
    (void)pdcg::scene::resolved_yaml(s);
    for (const auto& bc : s.boundary)
      for (const auto& f : bc.value)
        if (f)
          for (double t : {0.0, 0.5, 1.0}) (void)f(t);
    const double x[3] = {0.25, 0.5, 0.75};
    for (const auto& f : s.initial_velocity)
      if (f) (void)f(x);
  });
}
