// Model files: a body written and read back evaluates to the same energies and forces; bad files
// are refused with the file and item named.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>

#include "pdcg/body/model_file.hpp"
#include "pdcg/body/statistics.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/io/hdf5.hpp"
#include "pdcg_test.hpp"
#include "toy_potentials.hpp"

using namespace pdcg;
using namespace pdcg::body;

TEST(ModelFile, RoundTripEvaluatesIdentically) {
  auto pot = std::make_shared<test::Glue>(3.0, 1.0, 1.5, 1.6);
  atomistic::Atoms a = test::cubic_lattice(4, 3, 3, 1.0, 0.05, true);
  a.box.xy = 0.3;
  atomistic::PotentialSpec spec;
  spec.lines = {"pair_style test", "pair_coeff * * file.txt"};
  spec.type_mass = {NAN, 1.0, 2.0};
  Body b = make_delta_body(a, pot, spec, {.dimension = 3, .cutoff = 0.0, .source = "lattice"});
  b.potential_files.push_back({"file.txt", "line one\nline two\n"});
  Statistics st = isotropic_gaussian(b, 0.03);
  st.method = Statistics::Method::sampling;
  st.samples = 7;
  Eigen::Matrix3d C0;  // a full symmetric covariance for atom 0 (off-diagonal terms too)
  C0 << 9e-4, 2e-4, -1e-4, 2e-4, 8e-4, 3e-4, -1e-4, 3e-4, 7e-4;
  st.set_covariance(0, C0);
  make_statistical(b, st);
  const auto dir = std::filesystem::temp_directory_path() / "pdcg_test_model_file";
  std::filesystem::create_directories(dir);
  const auto path = dir / "b.h5";
  write_body(b, path);
  const Body c = read_body(
      path, [&](const atomistic::PotentialSpec& s, const std::vector<EmbeddedFile>& files) {
        EXPECT_EQ(s.lines, spec.lines);
        EXPECT_EQ(files.size(), 1u);
        EXPECT_EQ(files[0].contents, "line one\nline two\n");
        return std::shared_ptr<const atomistic::Potential>(pot);
      });
  EXPECT_EQ(c.kind, BodyKind::statistical);
  EXPECT_EQ(c.id, b.id);
  EXPECT_EQ(c.families.neighbor, b.families.neighbor);
  EXPECT_EQ(c.families.shift, b.families.shift);
  EXPECT_EQ(c.families.reverse, b.families.reverse);
  EXPECT_EQ(c.statistics->covariance, b.statistics->covariance);
  EXPECT_EQ(c.statistics->covariance_of(0), C0);
  {  // the file still holds ξ (derived from x, H, n) for older readers: x_j − x_k + H n
    io::H5Reader r(path);
    const auto xi = r.read_double("families/xi");
    ASSERT_EQ(xi.size(), 3 * b.families.bonds());
    const Eigen::Matrix3d H = b.box.h();
    for (std::size_t k = 0; k < b.size(); ++k)
      for (auto e = static_cast<std::size_t>(b.families.offset[k]);
           e < static_cast<std::size_t>(b.families.offset[k + 1]); ++e) {
        const auto j = static_cast<std::size_t>(b.families.neighbor[e]);
        const Eigen::Vector3d n(b.families.shift[3 * e], b.families.shift[3 * e + 1],
                                b.families.shift[3 * e + 2]);
        for (int d = 0; d < 3; ++d) {
          const auto dd = static_cast<std::size_t>(d);
          // round-off of x_j − x_k + (H n)_d with |x|, |H n| ≲ 5: 1e-13 absolute
          ASSERT_NEAR(xi[3 * e + dd], b.x[3 * j + dd] - b.x[3 * k + dd] + (H * n)[d], 1e-13);
        }
      }
  }
  Evaluator e1(b), e2(c);
  const Eigen::Matrix3d F = Eigen::Vector3d(1.1, 0.9, 1.05).asDiagonal();
  const double U1 = e1.homogeneous(F).energy, U2 = e2.homogeneous(F).energy;
  EXPECT_EQ(U1, U2);  // same data, same seed, same arithmetic
  EXPECT_EQ(c.provenance, b.provenance);
  // not a body file
  {
    io::FileInfo info;
    info.format = "pdcg-results";
    io::H5Writer w(dir / "r.h5", info);
    w.write("x", std::vector<double>{1.0});
    w.commit();
  }
  EXPECT_THROW((void)read_body(dir / "r.h5"), InputError);
  EXPECT_THROW((void)read_body(dir / "missing.h5"), InputError);
  std::filesystem::remove_all(dir);
}

// read_body from an open reader (the fuzz harness reads bodies held in memory): the bytes of
// the corpus's lj/cut body (written by pdcg atoms2pd) read as an image give the body read from
// the file, and errors name the image's name.
TEST(ModelFile, ReadFromAnImageIsTheBodyOfTheFile) {
  const std::filesystem::path path =
      std::string(PDCG_SOURCE_DIR) + "/tests/fuzz/corpus/model_file/lj_body.h5";
  std::ifstream in(path, std::ios::binary);
  const io::H5Image bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  const PotentialFactory none = [](const atomistic::PotentialSpec&,
                                   const std::vector<EmbeddedFile>&) {
    return std::shared_ptr<const atomistic::Potential>();
  };
  const Body a = read_body(path, none);
  const Body b = read_body(io::H5Reader(io::InMemory{"lj body image"}, bytes), none);
  ASSERT_GT(a.size(), 0u);
  EXPECT_EQ(b.id, a.id);
  EXPECT_EQ(b.x, a.x);
  EXPECT_EQ(b.mass, a.mass);
  EXPECT_EQ(b.families.offset, a.families.offset);
  EXPECT_EQ(b.families.neighbor, a.families.neighbor);
  EXPECT_EQ(b.potential_spec.lines, a.potential_spec.lines);
  EXPECT_EQ(b.epsilon, a.epsilon);
  // an image of another kind of file: refused naming the image
  io::H5Image results;
  {
    io::H5Writer w(io::InMemory{"results"}, {"pdcg-results", 1, UnitStyle::lj, "", ""});
    w.write("x", std::vector<double>{1.0});
    w.commit();
    results = w.image();
  }
  try {
    (void)read_body(io::H5Reader(io::InMemory{"results image"}, results), none);
    ADD_FAILURE() << "a results file was read as a body";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("results image"), std::string::npos) << e.what();
  }
}
