// The body commands end to end: LAMMPS (the lmp binary, run here) writes a dump with its own
// forces and per-atom energies; pdcg atoms2pd / forces / energy must reproduce them. Bad input
// gives exit code 2 and a message naming the values.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "pdcg_test.hpp"

namespace fs = std::filesystem;

namespace {

struct Run {
  int code;
  std::string out;
};

Run run(const std::string& cmd) {
  std::array<char, 4096> buf{};
  std::string out;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return {-1, ""};
  while (fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

Run cli(const std::string& args) { return run(std::string(PDCG_EXE) + " " + args); }

bool have_lmp() { return run("command -v lmp").code == 0; }

/// Columns of every frame of a dump written with `id type x y z fx fy fz c_pe`.
struct Frame {
  std::map<long, std::array<double, 4>> f;  // id -> fx fy fz pe
};
std::vector<Frame> read_dump(const fs::path& p) {
  std::ifstream in(p);
  std::vector<Frame> frames;
  std::string line;
  long n = 0;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: NUMBER OF ATOMS", 0) == 0) {
      std::getline(in, line);
      n = std::stol(line);
    }
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      Frame fr;
      for (long i = 0; i < n; ++i) {
        std::getline(in, line);
        std::istringstream s(line);
        long id, type;
        double x, y, z, fx, fy, fz, pe;
        s >> id >> type >> x >> y >> z >> fx >> fy >> fz >> pe;
        fr.f[id] = {fx, fy, fz, pe};
      }
      frames.push_back(fr);
    }
  }
  return frames;
}

std::map<long, std::array<double, 3>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("# pdcg forces: units ", 0), 0u) << line;  // units line first
  std::getline(in, line);
  EXPECT_EQ(line, "id,fx,fy,fz,pe");
  std::map<long, std::array<double, 3>> m;
  while (std::getline(in, line)) {
    for (auto& c : line)
      if (c == ',') c = ' ';
    std::istringstream s(line);
    long id;
    double a, b, c;
    s >> id >> a >> b >> c;
    m[id] = {a, b, c};
  }
  return m;
}

double compare_forces(const std::map<long, std::array<double, 3>>& pd, const Frame& ref) {
  std::vector<double> a, e;
  for (const auto& [id, f] : ref.f) {
    auto it = pd.find(id);
    EXPECT_NE(it, pd.end()) << "id " << id;
    if (it == pd.end()) return 1;
    for (int k = 0; k < 3; ++k) {
      a.push_back(it->second[k]);
      e.push_back(f[k]);
    }
  }
  const double err = pdcg::test::max_norm_relative_error(a, e);
  std::printf("  forces vs LAMMPS dump: max-norm relative error %.2e over %zu atoms\n", err,
              ref.f.size());
  return err;
}

class BodyCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_lmp()) GTEST_SKIP() << "lmp not found";
    dir = fs::temp_directory_path() / ("pdcg_body_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    write("pot.lj", "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n");
    // frame 0: perturbed triclinic fcc; frame 1 (run 1 without integrator: nothing moves but the
    // dump at step 1): displaced further; frame 2: orthogonal box
    // strained homogeneously (change_box … remap) — LAMMPS's own forces and pe/atom dumped.
    write("in.lj", R"(units lj
atom_style atomic
lattice fcc 0.8442
region box prism 0 4 0 4 0 4 0.5 -0.3 0.2
create_box 1 box
create_atoms 1 box
mass 1 1.0
displace_atoms all random 0.03 0.03 0.03 1234
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
compute pe all pe/atom
dump d all custom 1 dump.tri id type x y z fx fy fz c_pe
dump_modify d format float %.17g
run 0
write_data data.tri
displace_atoms all random 0.02 0.02 0.02 99
run 1
)");
    write("in.orth", R"(units lj
atom_style atomic
lattice fcc 0.8442
region box block 0 4 0 4 0 4
create_box 1 box
create_atoms 1 box
mass 1 1.0
displace_atoms all random 0.03 0.03 0.03 555
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
compute pe all pe/atom
dump d all custom 1 dump.orth id type x y z fx fy fz c_pe
dump_modify d format float %.17g
run 0
change_box all x scale 1.02 y scale 0.99 z scale 1.01 remap
run 1
)");
    ASSERT_EQ(run("cd " + dir.string() + " && lmp -in in.lj -log none -screen none").code, 0);
    ASSERT_EQ(run("cd " + dir.string() + " && lmp -in in.orth -log none -screen none").code, 0);
  }
  void TearDown() override {
    if (!dir.empty()) fs::remove_all(dir);
  }
  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
  }
  std::string p(const std::string& name) const { return (dir / name).string(); }
  fs::path dir;
};

}  // namespace

TEST_F(BodyCli, ForcesEqualLammpsAtReferenceAndDeformedFrames) {
  auto r = cli("atoms2pd --input " + p("dump.tri") + " --frame 0 --potential " + p("pot.lj") +
               " --density delta --family-cutoff 2.8 -o " + p("body.h5"));
  ASSERT_EQ(r.code, 0) << r.out;
  const auto ref = read_dump(dir / "dump.tri");
  ASSERT_EQ(ref.size(), 2u);
  r = cli("forces " + p("body.h5") + " -o " + p("f0.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  // same formulas in double precision; required: 1e-9 relative
  EXPECT_LT(compare_forces(read_csv(dir / "f0.csv"), ref[0]), 1e-9);
  // deformed: frame 1 (wrapped positions, atoms may have crossed the boundary)
  r = cli("forces " + p("body.h5") + " --deformed " + p("dump.tri") + " --frame 1 -o " +
          p("f1.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_LT(compare_forces(read_csv(dir / "f1.csv"), ref[1]), 1e-9);
  // the same configuration from a data file (wrapped positions + image flags, Masses section)
  r = cli("atoms2pd --input " + p("data.tri") + " --potential " + p("pot.lj") + " -o " +
          p("bd.h5"));
  ASSERT_EQ(r.code, 0) << r.out;
  r = cli("forces " + p("bd.h5") + " -o " + p("fd.csv"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_LT(compare_forces(read_csv(dir / "fd.csv"), ref[0]), 1e-9);
}

TEST_F(BodyCli, EnergyUnderHomogeneousDeformationEqualsLammps) {
  auto r = cli("atoms2pd --input " + p("dump.orth") + " --potential " + p("pot.lj") +
               " --density delta --family-cutoff 2.8 -o " + p("orth.h5"));
  ASSERT_EQ(r.code, 0) << r.out;
  const auto ref = read_dump(dir / "dump.orth");
  ASSERT_EQ(ref.size(), 2u);
  double U0 = 0, U1 = 0;
  for (const auto& [id, f] : ref[0].f) U0 += f[3];
  for (const auto& [id, f] : ref[1].f) U1 += f[3];
  r = cli("energy " + p("orth.h5") + " --F \"1 0 0 0 1 0 0 0 1\" --json");
  ASSERT_EQ(r.code, 0) << r.out;
  double e = 0, w = 0, v = 0;
  ASSERT_EQ(std::sscanf(r.out.c_str(),
                        "{\"energy\": %lf, \"energy_density\": %lf, \"volume\": %lf}", &e, &w, &v),
            3)
      << r.out;
  EXPECT_TRUE(pdcg::test::close(e, U0, {0, 1e-9}));  // round-off; pe/atom printed with 17 digits
  EXPECT_TRUE(pdcg::test::close(w * v, e, {0, 1e-15}));
  const double L = 4 * std::cbrt(4 / 0.8442);  // box edge of `lattice fcc 0.8442`, 4 cells
  EXPECT_TRUE(pdcg::test::close(v, L * L * L, {0, 1e-12}));
  r = cli("energy " + p("orth.h5") + " --F \"1.02 0 0 0 0.99 0 0 0 1.01\" --json");
  ASSERT_EQ(r.code, 0) << r.out;
  ASSERT_EQ(std::sscanf(r.out.c_str(), "{\"energy\": %lf", &e), 1);
  EXPECT_TRUE(pdcg::test::close(e, U1, {0, 1e-9}));
}

TEST_F(BodyCli, HomogenizeRescaleStatisticalAndBadInput) {
  ASSERT_EQ(
      cli("atoms2pd --input " + p("dump.tri") + " --potential " + p("pot.lj") + " -o " + p("b.h5"))
          .code,
      0);
  // homogenise and rescale keep the energy density under a homogeneous F
  auto r = cli("homogenize " + p("b.h5") + " --kernel wendland-c2 --width 3 --spacing 1.3 -o " +
               p("h.h5"));
  ASSERT_EQ(r.code, 0) << r.out;
  r = cli("rescale " + p("h.h5") + " --factor 3.5 -o " + p("r.h5"));
  ASSERT_EQ(r.code, 0) << r.out;
  r = cli("info " + p("r.h5"));
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("rescaled body, dimension 3, 256 points"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("horizon 8.75, epsilon 3.5"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("kernel wendland-c2"), std::string::npos) << r.out;
  const std::string F = " --F \"1.1 0.05 0 0 0.95 0.02 0 0 1.03\" --json";
  double w0 = 0, w1 = 0, e;
  r = cli("energy " + p("b.h5") + F);
  ASSERT_EQ(std::sscanf(r.out.c_str(), "{\"energy\": %lf, \"energy_density\": %lf", &e, &w0), 2)
      << r.out;
  r = cli("energy " + p("r.h5") + F);
  ASSERT_EQ(std::sscanf(r.out.c_str(), "{\"energy\": %lf, \"energy_density\": %lf", &e, &w1), 2)
      << r.out;
  EXPECT_TRUE(pdcg::test::close(w1, w0, {0, 1e-12}));  // W_ε(F) = W(F), round-off
  // statistical body from two frames, empirical: energy = mean of the two frames' energies
  r = cli("atoms2pd --input " + p("dump.tri") + " --frames 0:1 --potential " + p("pot.lj") +
          " --density statistical --statistics empirical --family-cutoff 2.8 -o " + p("s.h5"));
  ASSERT_EQ(r.code, 0) << r.out;
  const auto ref = read_dump(dir / "dump.tri");
  double Uavg = 0;
  for (const auto& fr : ref)
    for (const auto& [id, f] : fr.f) Uavg += 0.5 * f[3];
  r = cli("energy " + p("s.h5") + " --F \"1 0 0 0 1 0 0 0 1\" --json");
  ASSERT_EQ(std::sscanf(r.out.c_str(), "{\"energy\": %lf", &e), 1) << r.out;
  EXPECT_TRUE(pdcg::test::close(e, Uavg, {0, 1e-9}));

  // --- bad input: exit 2 and the values named
  r = cli("atoms2pd --input " + p("dump.tri") + " --frame 5 --potential " + p("pot.lj") + " -o " +
          p("x.h5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("frame range out of bounds"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("2 frames"), std::string::npos) << r.out;
  write("nomass.lj", "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n");
  r = cli("atoms2pd --input " + p("dump.tri") + " --potential " + p("nomass.lj") + " -o " +
          p("x.h5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("mass of type 1"), std::string::npos) << r.out;
  write("two.lj", "units lj\nmass * 1.0\npair_style lj/cut 2.5\npair_coeff * * 1.0 1.0\n");
  write("metal.lj",
        "units metal\nmass 1 1.0\npair_style eam/alloy\npair_coeff * * AlCu.eam.alloy Al Cu\n");
  r = cli("atoms2pd --input " + p("dump.tri") + " --potential " + p("metal.lj") + " -o " +
          p("x.h5"));
  EXPECT_EQ(r.code, 2) << r.out;  // 2 elements mapped, the dump has 1 type
  EXPECT_NE(r.out.find("AlCu.eam.alloy"), std::string::npos) << r.out;
  write(
      "metal.dump",
      "ITEM: UNITS\nmetal\nITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n"
      "0 5\n0 5\n0 5\nITEM: ATOMS id type x y z\n1 1 0 0 0\n2 1 1 1 1\n");
  r = cli("atoms2pd --input " + p("metal.dump") + " --potential " + p("pot.lj") + " -o " +
          p("x.h5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("different units"), std::string::npos) << r.out;
  r = cli("rescale " + p("b.h5") + " --factor 0 -o " + p("x.h5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("rescaling factor must be positive"), std::string::npos) << r.out;
  r = cli("rescale " + p("b.h5") + " --factor -2 -o " + p("x.h5"));
  EXPECT_EQ(r.code, 2);
  r = cli("homogenize " + p("b.h5") + " --kernel top-hat --width 0.5 --spacing 0.4 -o " +
          p("x.h5"));
  EXPECT_EQ(r.code, 0) << r.out;  // a warning, not an error
  EXPECT_NE(r.out.find("smaller than the lattice spacing"), std::string::npos) << r.out;
  r = cli("energy " + p("b.h5") + " --F \"-1 0 0 0 1 0 0 0 1\"");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("det F = -1"), std::string::npos) << r.out;
  write("few.dump",
        "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp pp\n0 5\n0 5\n0 5\n"
        "ITEM: ATOMS id type x y z\n1 1 0 0 0\n7 1 1 1 1\n");
  r = cli("forces " + p("b.h5") + " --deformed " + p("few.dump") + " -o " + p("x.csv"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("does not hold the body's atoms"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("first differing id 7"), std::string::npos) << r.out;
  r = cli("homogenize " + p("b.h5") + " --kernel nope --width 1 --spacing 1 -o " + p("x.h5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("wendland-c2"), std::string::npos) << r.out;
}
