// The harness of the potential-style tests can fail: copies of a real case file with one
// reference entry moved (a force component, a per-atom energy, the energy, a virial component)
// are reported as failures naming the file, the atom or component, and the quantity; a move of
// a hundredth of epsilon is not. Malformed case files are refused with the file and the key.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "potential_case.hpp"
#include "scratch_dir.hpp"

namespace {

namespace pc = pdcg::test::potential_case;

// the smallest native case (64 atoms, many-body: every code path of compare is exercised)
const std::string kCase = std::string(PDCG_POTENTIAL_CASES_DIR) + "/sw.yaml";

/// Writes `root` to `dir/name` (doubles at 17 digits) and returns the path.
std::string write_copy(const YAML::Node& root, const pdcg::test::ScratchDir& dir,
                       const std::string& name) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << root;
  const std::string path = dir / name;
  std::ofstream(path) << out.c_str() << "\n";
  return path;
}

/// The case file with one reference entry moved by `factor` × epsilon × the largest |entry| of
/// that quantity; `key` is forces, per_atom_energy, energy or virial; `row`/`col` pick the
/// entry (row of the id-sorted table; col 1..3 for forces, 1 for per_atom_energy, the
/// component 0..5 for the virial).
std::string perturbed_copy(const pdcg::test::ScratchDir& dir, const std::string& name,
                           const std::string& key, std::size_t row, std::size_t col,
                           double factor) {
  YAML::Node root = YAML::LoadFile(kCase);
  const double eps = root["epsilon"].as<double>();
  YAML::Node ref = root["reference"];
  double scale = 0.0;
  if (key == "energy") {
    scale = std::abs(ref["energy"].as<double>());
    ref["energy"] = ref["energy"].as<double>() + factor * eps * scale;
  } else if (key == "virial") {
    for (const auto& v : ref["virial"]) scale = std::max(scale, std::abs(v.as<double>()));
    ref["virial"][col] = ref["virial"][col].as<double>() + factor * eps * scale;
  } else {
    for (const auto& r : ref[key])
      for (std::size_t d = 1; d < r.size(); ++d)
        scale = std::max(scale, std::abs(r[d].as<double>()));
    ref[key][row][col] = ref[key][row][col].as<double>() + factor * eps * scale;
  }
  return write_copy(root, dir, name);
}

class PotentialYamlHarness : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    original_ = new pc::Case(pc::load_case(kCase));
    pdcg::test::ScratchDir dir("potential_yaml_harness");
    computed_ = new pc::Computed(pc::compute_with_pdcg(*original_, dir.path()));
  }
  static void TearDownTestSuite() {
    delete original_;
    delete computed_;
  }
  static pc::Case* original_;
  static pc::Computed* computed_;
};
pc::Case* PotentialYamlHarness::original_ = nullptr;
pc::Computed* PotentialYamlHarness::computed_ = nullptr;

TEST_F(PotentialYamlHarness, TheUnchangedCasePasses) {
  const pc::Comparison cmp = pc::compare(*original_, *computed_);
  EXPECT_TRUE(cmp.ok()) << (cmp.failures.empty() ? "" : cmp.failures.front());
  ASSERT_EQ(cmp.worst.size(), 4u);
}

struct Perturbation {
  std::string key;
  std::size_t row, col;
  std::string quantity;  // as the message names it
  std::string where;     // atom or component
};

TEST_F(PotentialYamlHarness, AMovedReferenceEntryFailsNamingFileAtomAndQuantity) {
  pdcg::test::ScratchDir dir("potential_yaml_harness");
  const std::int64_t id = original_->reference.ids[16];  // row 16 of the id-sorted tables
  const std::vector<Perturbation> cases = {
      {"forces", 16, 2, "force", "atom " + std::to_string(id) + " fy"},
      {"per_atom_energy", 16, 1, "per-atom energy", "atom " + std::to_string(id)},
      {"energy", 0, 0, "energy", ""},
      {"virial", 0, 4, "virial", "xz"},
  };
  for (const Perturbation& p : cases) {
    SCOPED_TRACE(p.key);
    // 10 × epsilon: must fail, on this one entry only
    const std::string bad = perturbed_copy(dir, "perturbed_sw.yaml", p.key, p.row, p.col, 10.0);
    const pc::Comparison cmp = pc::compare(pc::load_case(bad), *computed_);
    ASSERT_EQ(cmp.failures.size(), 1u);
    const std::string& msg = cmp.failures.front();
    EXPECT_NE(msg.find("perturbed_sw.yaml: " + p.quantity), std::string::npos) << msg;
    if (!p.where.empty()) {
      EXPECT_NE(msg.find("at " + p.where + ":"), std::string::npos) << msg;
    }
    EXPECT_NE(msg.find("(1 of "), std::string::npos) << msg;
    // 0.01 × epsilon: within the tolerance
    const std::string fine = perturbed_copy(dir, "nudged_sw.yaml", p.key, p.row, p.col, 0.01);
    const pc::Comparison ok = pc::compare(pc::load_case(fine), *computed_);
    EXPECT_TRUE(ok.ok()) << (ok.failures.empty() ? "" : ok.failures.front());
  }
}

TEST_F(PotentialYamlHarness, NaNFromPdcgFails) {
  pc::Computed got = *computed_;
  got.forces[3 * 5 + 1] = std::nan("");
  const pc::Comparison cmp = pc::compare(*original_, got);
  ASSERT_EQ(cmp.failures.size(), 1u);
  EXPECT_NE(cmp.failures.front().find("sw.yaml: force at atom " +
                                      std::to_string(original_->reference.ids[5]) + " fy:"),
            std::string::npos)
      << cmp.failures.front();
}

TEST_F(PotentialYamlHarness, MissingAtomIsReported) {
  pc::Computed got = *computed_;
  got.ids.back() += 1000;
  const pc::Comparison cmp = pc::compare(*original_, got);
  ASSERT_EQ(cmp.failures.size(), 1u);
  EXPECT_NE(cmp.failures.front().find("sw.yaml: the atoms differ from the reference"),
            std::string::npos)
      << cmp.failures.front();
}

TEST(PotentialYamlHarnessFiles, MalformedCaseFilesNameFileAndKey) {
  pdcg::test::ScratchDir dir("potential_yaml_harness");
  auto expect_error = [&](YAML::Node root, const std::string& key) {
    const std::string path = write_copy(root, dir, "broken.yaml");
    try {
      pc::load_case(path);
      ADD_FAILURE() << "no error for " << key;
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("broken.yaml: key `" + key + "`"), std::string::npos) << msg;
    }
  };
  {
    YAML::Node root = YAML::LoadFile(kCase);
    root.remove("epsilon");
    expect_error(root, "epsilon");
  }
  {
    YAML::Node root = YAML::LoadFile(kCase);
    root["epsilon"] = "tight";
    expect_error(root, "epsilon");
  }
  {
    YAML::Node root = YAML::LoadFile(kCase);
    root["reference"]["virial"].push_back(1.0);
    expect_error(root, "reference.virial");
  }
  {
    YAML::Node root = YAML::LoadFile(kCase);
    root["reference"]["forces"][3] = YAML::Load("[4, 1.0, 2.0]");
    expect_error(root, "reference.forces");
  }
}

// Every case file of the directory is well formed (the ctest list comes from the same glob).
TEST(PotentialYamlHarnessFiles, EveryCaseFileLoads) {
  const auto files = pc::case_files(PDCG_POTENTIAL_CASES_DIR);
  EXPECT_GE(files.size(), 10u);
  for (const auto& f : files) EXPECT_NO_THROW(pc::load_case(f)) << f;
}

}  // namespace
