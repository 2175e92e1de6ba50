/// libFuzzer harness: scene expressions (include/pdcg/scene/expression.hpp). First byte
/// even: an expression in t; odd: in x, y, z. Each parsed expression is evaluated at a few
/// points, including 0 and negative values (log, sqrt, division).
#include "pdcg/scene/expression.hpp"

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const bool xyz = data[0] & 1;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  return pdcg::fuzz::guarded([&] {
    if (xyz) {
      const auto f = pdcg::scene::parse_expression(text, "fuzz", {"x", "y", "z"});
      const double p[2][3] = {{0.0, 0.0, 0.0}, {-1.5, 2.0, 1e300}};
      for (const auto& v : p) (void)f(v);
    } else {
      const auto f = pdcg::scene::parse_expression(text, "fuzz");
      for (double t : {0.0, 1.0, -2.5, 1e308}) (void)f(t);
    }
  });
}
