// Potential styles against LAMMPS, data-driven (docs/testing.md "Potential styles against
// LAMMPS"; the files: tests/potentials/README.md). Each case file holds LAMMPS's `run 0`
// reference, written by tests/potentials/generate.py with Debian's LAMMPS; pdcg computes the
// case through its public readers and the body evaluator, as `pdcg forces` / `pdcg energy` do.
//
// ctest runs one case per test (PotentialYaml.<file>: the environment variable
// PDCG_POTENTIAL_CASE names the file); without it the test runs every native case file.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>

#include "potential_case.hpp"
#include "scratch_dir.hpp"

namespace {

namespace pc = pdcg::test::potential_case;

TEST(PotentialYaml, MatchesLammps) {
  std::vector<std::string> files;
  if (const char* one = std::getenv("PDCG_POTENTIAL_CASE"); one && *one)
    files.emplace_back(one);
  else
    files = pc::case_files(PDCG_POTENTIAL_CASES_DIR);
  ASSERT_FALSE(files.empty()) << "no case files in " << PDCG_POTENTIAL_CASES_DIR;
  int ran = 0;
  for (const std::string& path : files) {
    SCOPED_TRACE(path);
    const pc::Case c = pc::load_case(path);
    if (!pc::native(c)) {
      // ctest registers native cases only; a whole-directory run passes over the others
      if (std::getenv("PDCG_POTENTIAL_CASE"))
        ADD_FAILURE() << c.name << ": engine " << c.engine
                      << " cases are run by the CLI harness (ctest potential.*), not here";
      continue;
    }
    pdcg::test::ScratchDir dir("potential_yaml");
    const pc::Computed got = pc::compute_with_pdcg(c, dir.path());
    const pc::Comparison cmp = pc::compare(c, got);
    for (const auto& w : cmp.worst)
      std::printf("%s (%s): %-15s max relative difference %.2e%s%s (epsilon %g)\n", c.name.c_str(),
                  c.style.c_str(), w.quantity.c_str(), w.relative, w.where.empty() ? "" : " at ",
                  w.where.c_str(), c.epsilon);
    for (const auto& f : cmp.failures) ADD_FAILURE() << f;
    ++ran;
  }
  EXPECT_GT(ran, 0);
}

}  // namespace
