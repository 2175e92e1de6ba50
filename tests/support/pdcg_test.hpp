/// \file
/// Test helpers: numeric comparison with both an absolute and a relative
/// tolerance (MFEM style), reporting the worst entry.
///
/// An entry i passes when |a_i - e_i| <= abs_tol + rel_tol * |e_i|.
/// On failure the message names the worst entry (largest ratio of error to
/// allowed error), both values and both tolerances.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace pdcg::test {

/// The running test's own scratch directory, TMP/<prefix>/<Suite>.<Test> (created): tests that
/// ctest runs in parallel (-j) never write the same file.
inline std::filesystem::path scratch_dir(const std::string& prefix) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / prefix;
  if (const auto* info = ::testing::UnitTest::GetInstance()->current_test_info())
    dir /= std::string(info->test_suite_name()) + "." + info->name();
  std::filesystem::create_directories(dir);
  return dir;
}

struct Tolerance {
  double abs = 0.0;
  double rel = 0.0;
};

template <class A, class E>
::testing::AssertionResult all_close(const A& actual, const E& expected, Tolerance tol) {
  const std::size_t n = static_cast<std::size_t>(std::size(actual));
  if (n != static_cast<std::size_t>(std::size(expected)))
    return ::testing::AssertionFailure()
           << "size mismatch: actual " << n << ", expected " << std::size(expected);
  double worst_ratio = -1.0;
  std::size_t worst = 0;
  std::size_t failures = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = static_cast<double>(actual[i]);
    const double e = static_cast<double>(expected[i]);
    const double allowed = tol.abs + tol.rel * std::abs(e);
    const double err = std::abs(a - e);
    const double ratio = std::isfinite(a) ? (allowed > 0 ? err / allowed : (err > 0 ? INFINITY : 0))
                                          : INFINITY;
    if (!(ratio <= 1.0)) ++failures;
    if (!(ratio <= worst_ratio)) {
      worst_ratio = ratio;
      worst = i;
    }
  }
  if (failures == 0) return ::testing::AssertionSuccess();
  std::ostringstream m;
  m.precision(17);
  m << failures << " of " << n << " entries out of tolerance (abs " << tol.abs << ", rel "
    << tol.rel << "); worst entry [" << worst << "]: actual " << actual[worst] << ", expected "
    << expected[worst] << ", |diff| " << std::abs(static_cast<double>(actual[worst]) - static_cast<double>(expected[worst]));
  return ::testing::AssertionFailure() << m.str();
}

inline ::testing::AssertionResult close(double actual, double expected, Tolerance tol) {
  const double a[1] = {actual};
  const double e[1] = {expected};
  return all_close(a, e, tol);
}

/// Largest |a_i - e_i| over max_i |e_i|: the "max-norm relative" error used
/// for force comparisons (relative to the largest force).
template <class A, class E>
double max_norm_relative_error(const A& actual, const E& expected) {
  double num = 0.0, den = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(std::size(actual)); ++i) {
    num = std::max(num, std::abs(static_cast<double>(actual[i]) - static_cast<double>(expected[i])));
    den = std::max(den, std::abs(static_cast<double>(expected[i])));
  }
  return den > 0 ? num / den : num;
}

}  // namespace pdcg::test
