// Inputs as users bring them, end to end through `pdcg atoms2pd` + `pdcg forces` against the
// `lmp` binary reading the same files: data files and decks written here from scratch (no
// LAMMPS-written geometry), Debian's potential files. Each input class is either equal to
// LAMMPS (forces and energy to 1e-9 relative) or refused with exit code 2 and a message that
// names the fix:
//   periodicity — free clusters and slabs from data files (which say nothing about
//     boundaries), the `boundary` command in a commands file or a full deck, --boundary, the
//     dump header;
//   units — EAM files (UNITS: metal) without `units`, with `units real` (converted as LAMMPS
//     does) and with a unit style LAMMPS refuses;
//   topology — a bond style with a configuration that carries no bonds;
//   special_bonds — periodic molecular boxes smaller than twice the cutoff (orthogonal and
//     triclinic), where images of special partners within the cutoff are ordinary pairs.
// PDCG_TEST_EXE (environment) runs these against another pdcg executable, e.g. one built from
// an older commit.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "pdcg_test.hpp"

namespace fs = std::filesystem;

namespace {

struct Outcome {
  int code;
  std::string out;
};

Outcome run(const std::string& cmd) {
  std::array<char, 4096> buf{};
  std::string out;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (!p) return {-1, ""};
  while (fgets(buf.data(), buf.size(), p)) out += buf.data();
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

std::string exe() {
  const char* e = std::getenv("PDCG_TEST_EXE");
  return e && *e ? e : PDCG_EXE;
}

Outcome cli(const std::string& args) { return run(exe() + " " + args); }

bool have_lmp() { return run("command -v lmp").code == 0; }

struct Atom {
  int type;
  double x, y, z;
  long mol = 1;
};
struct Bond {
  int type;
  long a, b;
};

struct Config {
  std::array<double, 3> lo{0, 0, 0}, hi{1, 1, 1};
  double xy = 0;
  std::vector<Atom> atoms;
  std::vector<Bond> bonds;
  int ntypes = 1, nbondtypes = 0;
  std::vector<double> masses{1.0};
};

/// A LAMMPS data file written the way a user writes one by hand: counts, box, Masses, Atoms
/// with the style comment (atomic, molecular or full), Bonds if any.
void write_data(const fs::path& path, const Config& c, const std::string& style,
                bool with_bonds = true) {
  std::ofstream f(path);
  f.precision(17);
  f << "written from scratch\n\n" << c.atoms.size() << " atoms\n";
  if (with_bonds && !c.bonds.empty()) f << c.bonds.size() << " bonds\n";
  f << c.ntypes << " atom types\n";
  if (with_bonds && !c.bonds.empty()) f << c.nbondtypes << " bond types\n";
  f << "\n"
    << c.lo[0] << " " << c.hi[0] << " xlo xhi\n"
    << c.lo[1] << " " << c.hi[1] << " ylo yhi\n"
    << c.lo[2] << " " << c.hi[2] << " zlo zhi\n";
  if (c.xy != 0) f << c.xy << " 0 0 xy xz yz\n";
  f << "\nMasses\n\n";
  for (std::size_t t = 0; t < c.masses.size(); ++t) f << t + 1 << " " << c.masses[t] << "\n";
  f << "\nAtoms # " << style << "\n\n";
  for (std::size_t i = 0; i < c.atoms.size(); ++i) {
    const Atom& a = c.atoms[i];
    f << i + 1 << " ";
    if (style != "atomic") f << a.mol << " ";
    f << a.type << " ";
    if (style == "full") f << "0.0 ";
    f << a.x << " " << a.y << " " << a.z << "\n";
  }
  if (with_bonds && !c.bonds.empty()) {
    f << "\nBonds\n\n";
    for (std::size_t i = 0; i < c.bonds.size(); ++i)
      f << i + 1 << " " << c.bonds[i].type << " " << c.bonds[i].a << " " << c.bonds[i].b << "\n";
  }
}

/// fcc sites (i + b) a for 0 ≤ site ≤ n a along each direction with `closed` (the faces at n a
/// included: a free cube), else < n a (a periodic cell); small deterministic displacements.
std::vector<Atom> fcc_block(std::array<int, 3> n, double a, std::array<bool, 3> closed,
                            double noise, unsigned seed, int ntypes = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-noise, noise);
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::vector<Atom> out;
  int count = 0;
  for (int i = 0; i <= n[0]; ++i)
    for (int j = 0; j <= n[1]; ++j)
      for (int k = 0; k <= n[2]; ++k)
        for (const auto& b : basis) {
          const double s[3] = {i + b[0], j + b[1], k + b[2]};
          bool keep = true;
          for (int d = 0; d < 3; ++d)
            keep = keep && (closed[static_cast<std::size_t>(d)]
                                ? s[d] <= n[static_cast<std::size_t>(d)] + 1e-12
                                : s[d] < n[static_cast<std::size_t>(d)] - 1e-12);
          if (!keep) continue;
          out.push_back(
              {1 + (count++ % ntypes), s[0] * a + u(rng), s[1] * a + u(rng), s[2] * a + u(rng)});
        }
  return out;
}

/// Per atom id: fx fy fz pe of a dump written with `id type x y z fx fy fz c_pe`.
std::map<long, std::array<double, 4>> read_dump(const fs::path& p) {
  std::ifstream in(p);
  std::map<long, std::array<double, 4>> m;
  std::string line;
  long n = 0;
  while (std::getline(in, line)) {
    if (line.rfind("ITEM: NUMBER OF ATOMS", 0) == 0) {
      std::getline(in, line);
      n = std::stol(line);
    }
    if (line.rfind("ITEM: ATOMS", 0) == 0) {
      m.clear();
      for (long i = 0; i < n && std::getline(in, line); ++i) {
        std::istringstream s(line);
        long id, type;
        double x, y, z, fx, fy, fz, pe;
        s >> id >> type >> x >> y >> z >> fx >> fy >> fz >> pe;
        m[id] = {fx, fy, fz, pe};
      }
    }
  }
  return m;
}

std::map<long, std::array<double, 3>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::string line;
  while (std::getline(in, line) && line.rfind('#', 0) == 0) {
  }  // `#` units line, then the header
  std::map<long, std::array<double, 3>> m;
  while (std::getline(in, line)) {
    for (auto& ch : line)
      if (ch == ',') ch = ' ';
    std::istringstream s(line);
    long id;
    double a, b, c;
    s >> id >> a >> b >> c;
    m[id] = {a, b, c};
  }
  return m;
}

class TrustInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_lmp()) GTEST_SKIP() << "lmp not found";
    dir = fs::temp_directory_path() / ("pdcg_trust_inputs_" + std::to_string(::getpid()));
    fs::create_directories(dir);
  }
  void TearDown() override {
    if (!dir.empty()) fs::remove_all(dir);
  }
  void write(const std::string& name, const std::string& text) const {
    std::ofstream(dir / name) << text;
  }
  std::string p(const std::string& name) const { return (dir / name).string(); }

  /// Runs `deck` (a LAMMPS input written here) with lmp in the scratch directory; the deck
  /// must dump `id type x y z fx fy fz c_pe` into `dump`.
  std::map<long, std::array<double, 4>> lammps(const std::string& name, const std::string& deck,
                                               const std::string& dump) const {
    write(name, deck);
    const Outcome r = run("cd " + dir.string() + " && lmp -in " + name +
                          " -log lmp.log -screen none || tail -3 lmp.log");
    EXPECT_EQ(r.out.find("ERROR"), std::string::npos) << "lmp failed on " << name << ":\n" << r.out;
    return read_dump(dir / dump);
  }

  /// `pdcg atoms2pd ARGS -o NAME.h5`, then `pdcg forces`: the forces and energy against the
  /// LAMMPS reference (max-norm relative force error and relative energy error below 1e-9).
  void expect_equal(const std::string& atoms2pd_args,
                    const std::map<long, std::array<double, 4>>& ref, const std::string& label) {
    ASSERT_FALSE(ref.empty()) << label;
    Outcome r = cli("atoms2pd " + atoms2pd_args + " -o " + p("body.h5"));
    ASSERT_EQ(r.code, 0) << label << ":\n" << r.out;
    r = cli("forces " + p("body.h5") + " -o " + p("f.csv"));
    ASSERT_EQ(r.code, 0) << label << ":\n" << r.out;
    const auto pos = r.out.find("energy ");
    ASSERT_NE(pos, std::string::npos) << r.out;
    const double energy = std::strtod(r.out.c_str() + pos + 7, nullptr);
    const auto f = read_csv(dir / "f.csv");
    ASSERT_EQ(f.size(), ref.size()) << label;
    std::vector<double> a, e;
    double u = 0;
    for (const auto& [id, v] : ref) {
      const auto it = f.find(id);
      ASSERT_NE(it, f.end()) << label << ": id " << id;
      for (int k = 0; k < 3; ++k) {
        a.push_back(it->second[static_cast<std::size_t>(k)]);
        e.push_back(v[static_cast<std::size_t>(k)]);
      }
      u += v[3];
    }
    const double ferr = pdcg::test::max_norm_relative_error(a, e);
    std::printf("  [%s] %zu atoms: force error %.2e, energy %.15g vs LAMMPS %.15g (rel %.1e)\n",
                label.c_str(), ref.size(), ferr, energy, u, std::abs(energy - u) / std::abs(u));
    // same double-precision formulas, other summation order; dumps printed with 17 digits
    EXPECT_LT(ferr, 1e-9) << label;
    EXPECT_TRUE(pdcg::test::close(energy, u, {0, 1e-9})) << label;
  }

  void expect_refused(const std::string& atoms2pd_args, std::vector<std::string> phrases,
                      const std::string& label) {
    const Outcome r = cli("atoms2pd " + atoms2pd_args + " -o " + p("refused.h5"));
    EXPECT_EQ(r.code, 2) << label << ":\n" << r.out;
    for (const auto& s : phrases)
      EXPECT_NE(r.out.find(s), std::string::npos) << label << ": " << r.out;
    EXPECT_FALSE(fs::exists(dir / "refused.h5")) << label;
  }

  fs::path dir;
};

const char* kDumpLines =
    "compute pe all pe/atom\n"
    "dump d all custom 1 DUMP id type x y z fx fy fz c_pe\n"
    "dump_modify d format float %.17g\n"
    "run 0\n";

std::string deck_tail(const std::string& dump) {
  std::string s = kDumpLines;
  s.replace(s.find("DUMP"), 4, dump);
  return s;
}

}  // namespace

// A free fcc cube (faces at 0 and n a both present) and a sphere in boxes that just hold them:
// with LAMMPS's default p p p the images of opposite faces land on the atoms.
TEST_F(TrustInputs, FreeClustersFromDataFilesEqualLammps) {
  const double a = std::cbrt(4.0 / 0.8442);  // `lattice fcc 0.8442`
  Config cube;
  cube.atoms = fcc_block({3, 3, 3}, a, {true, true, true}, 0.02 * a, 11);
  cube.hi = {3 * a + 0.03 * a, 3 * a + 0.03 * a, 3 * a + 0.03 * a};
  cube.lo = {-0.03 * a, -0.03 * a, -0.03 * a};
  write_data(dir / "cube.data", cube, "atomic");
  // sphere of two types (mixing) around a lattice site, box = its bounding box
  Config sphere;
  sphere.ntypes = 2;
  sphere.masses = {1.0, 2.0};
  {
    const auto block = fcc_block({6, 6, 6}, a, {true, true, true}, 0.0, 1, 2);
    const double c = 3 * a, R = 2.6 * a;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-0.015 * a, 0.015 * a);
    double ext = 0;
    for (const Atom& at : block) {
      const double d = std::hypot(at.x - c, at.y - c, at.z - c);
      if (d > R) continue;
      sphere.atoms.push_back({at.type, at.x - c + u(rng), at.y - c + u(rng), at.z - c + u(rng)});
      ext = std::max({ext, std::abs(sphere.atoms.back().x), std::abs(sphere.atoms.back().y),
                      std::abs(sphere.atoms.back().z)});
    }
    sphere.lo = {-ext, -ext, -ext};
    sphere.hi = {ext, ext, ext};
  }
  write_data(dir / "sphere.data", sphere, "atomic");
  const std::string lj1 = "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n";
  const std::string lj2 =
      "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\npair_coeff 2 2 0.8 0.9 2.2\n"
      "pair_modify mix arithmetic\n";
  for (const auto& [name, lj] : {std::pair{std::string("cube"), lj1}, {"sphere", lj2}}) {
    const std::string data = name + ".data";
    write("pot_" + name, "units lj\n" + lj);
    write("pot_s_" + name, "units lj\nboundary s s s\n" + lj);
    // LAMMPS itself: shrink-wrapped boundaries, the data file read by read_data
    const std::string deck = "units lj\natom_style atomic\nboundary s s s\nread_data " + data +
                             "\n" + lj + deck_tail("dump." + name);
    const auto ref = lammps("in." + name, deck, "dump." + name);
    // nothing states the periodicity: refused, with the fix
    expect_refused("--input " + p(data) + " --potential " + p("pot_" + name),
                   {"periodic images overlap", "boundary s s s", "--boundary"}, name);
    // the boundary command of the commands file
    expect_equal("--input " + p(data) + " --potential " + p("pot_s_" + name), ref,
                 name + ", boundary s s s");
    // the option (f: non-periodic as s)
    expect_equal(
        "--input " + p(data) + " --potential " + p("pot_" + name) + " --boundary \"f f f\"", ref,
        name + ", --boundary f f f");
    // the whole LAMMPS deck as the commands file
    expect_equal("--input " + p(data) + " --potential " + p("in." + name), ref,
                 name + ", full deck");
    // LAMMPS's own dump of the cluster: its header (ss ss ss) says non-periodic
    write("pot_m_" + name, "units lj\nmass * 1.0\n" + lj);
    expect_equal("--input " + p("dump." + name) + " --potential " + p("pot_m_" + name), ref,
                 name + ", dump header");
  }
  // --boundary wins over a different boundary command, and says so
  const Outcome r = cli("atoms2pd --input " + p("cube.data") + " --potential " + p("pot_s_cube") +
                        " --boundary \"p p p\" -o " + p("pp.h5"));
  EXPECT_EQ(r.code, 0) << r.out;  // stated periodic: the overlap warns
  EXPECT_NE(r.out.find("--boundary \"p p p\" wins over `boundary s s s`"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("periodic images overlap"), std::string::npos) << r.out;
  // LAMMPS's boundary rules: p on one side only is refused, as LAMMPS does
  expect_refused(
      "--input " + p("cube.data") + " --potential " + p("pot_cube") + " --boundary \"pf f f\"",
      {"both sides of a periodic boundary must be p"}, "pf");
}

// A slab periodic in x and y, free along z, in a box whose z extent just holds it.
TEST_F(TrustInputs, SlabPeriodicInPlaneFreeAlongZ) {
  const double a = std::cbrt(4.0 / 0.8442);
  Config slab;
  slab.atoms = fcc_block({3, 3, 3}, a, {false, false, true}, 0.02 * a, 21);
  slab.hi = {3 * a, 3 * a, 3 * a + 0.05 * a};
  slab.lo = {0, 0, -0.05 * a};
  write_data(dir / "slab.data", slab, "atomic");
  const std::string lj = "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n";
  write("pot", "units lj\n" + lj);
  write("pot_ppm", "units lj\nboundary p p m\n" + lj);
  const auto ref = lammps("in.slab",
                          "units lj\natom_style atomic\nboundary p p s\nread_data slab.data\n" +
                              lj + deck_tail("dump.slab"),
                          "dump.slab");
  expect_refused("--input " + p("slab.data") + " --potential " + p("pot"),
                 {"periodic images overlap", "shifted by (0, 0, "}, "slab, p p p assumed");
  expect_equal("--input " + p("slab.data") + " --potential " + p("pot") + " --boundary \"p p f\"",
               ref, "slab, --boundary p p f");
  expect_equal("--input " + p("slab.data") + " --potential " + p("pot_ppm"), ref,
               "slab, boundary p p m");
}

// EAM files carry `UNITS: metal` in their first line. LAMMPS refuses them in any unit style
// but metal and real, and converts them to real (energies × 23.060549).
TEST_F(TrustInputs, EamUnitsAsLammps) {
  struct Case {
    std::string name, style, coeff, structure;
    double a;
    int ntypes;
    std::vector<double> masses;
  };
  const std::vector<Case> cases = {
      {"cu", "eam", "pair_coeff 1 1 Cu_u3.eam", "fcc", 3.615, 1, {63.546}},
      {"cuni", "eam/alloy", "pair_coeff * * CuNi.eam.alloy Cu Ni", "fcc", 3.56, 2, {63.546, 58.69}},
      {"fe", "eam/fs", "pair_coeff * * Fe_mm.eam.fs Fe", "bcc", 2.855, 1, {55.845}},
  };
  for (const Case& c : cases) {
    Config cfg;
    cfg.ntypes = c.ntypes;
    cfg.masses = c.masses;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-0.05, 0.05);
    const int n = 3;
    const std::vector<std::array<double, 3>> basis =
        c.structure == "fcc"
            ? std::vector<std::array<double, 3>>{{0, 0, 0}, {.5, .5, 0}, {.5, 0, .5}, {0, .5, .5}}
            : std::vector<std::array<double, 3>>{{0, 0, 0}, {.5, .5, .5}};
    int count = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          for (const auto& b : basis)
            cfg.atoms.push_back({1 + (count++ % 3 == 0 ? c.ntypes - 1 : 0),
                                 (i + b[0]) * c.a + u(rng), (j + b[1]) * c.a + u(rng),
                                 (k + b[2]) * c.a + u(rng)});
    cfg.hi = {n * c.a, n * c.a, n * c.a};
    write_data(dir / (c.name + ".data"), cfg, "atomic");
    const std::string pot = "pair_style " + c.style + "\n" + c.coeff + "\n";
    // no units command: LAMMPS's default lj, which the file refuses
    write("nounits_" + c.name, pot);
    expect_refused("--input " + p(c.name + ".data") + " --potential " + p("nounits_" + c.name),
                   {"requires metal units but lj units are in use", "add `units metal`"},
                   c.name + ", no units");
    write("si_" + c.name, "units si\n" + pot);
    expect_refused("--input " + p(c.name + ".data") + " --potential " + p("si_" + c.name),
                   {"requires metal units but si units are in use"}, c.name + ", units si");
    for (const std::string units : {"metal", "real"}) {
      write(units + "_" + c.name, "units " + units + "\n" + pot);
      const auto ref = lammps("in." + units + c.name,
                              "units " + units + "\natom_style atomic\nread_data " + c.name +
                                  ".data\n" + pot + deck_tail("dump." + units + c.name),
                              "dump." + units + c.name);
      expect_equal("--input " + p(c.name + ".data") + " --potential " + p(units + "_" + c.name),
                   ref, c.name + ", units " + units);
    }
  }
}

namespace {

/// Chains of 4 beads (bond length 1.5, random directions) in a periodic box of edge L, no two
/// non-bonded beads closer than 2.8 (minimum image); bond types alternate 1, 2, 1.
Config chains(double L, int nchains, unsigned seed, double xy = 0) {
  Config c;
  c.hi = {L, L, L};
  c.xy = xy;
  c.masses = {14.0};
  c.nbondtypes = 2;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, L);
  std::normal_distribution<double> g(0, 1);
  auto min_dist = [&](const std::array<double, 3>& q) {
    double m = 1e9;
    for (const Atom& a : c.atoms) {
      double d[3] = {q[0] - a.x, q[1] - a.y, q[2] - a.z};
      // triclinic minimum image: z, y (with the tilt), then x
      d[1] -= L * std::round(d[1] / L);
      d[0] -= xy * std::round((q[1] - a.y) / L);
      d[0] -= L * std::round(d[0] / L);
      d[2] -= L * std::round(d[2] / L);
      m = std::min(m, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
    }
    return m;
  };
  for (int ch = 0; ch < nchains; ++ch) {
    for (int attempt = 0; attempt < 100000; ++attempt) {
      std::vector<std::array<double, 3>> beads{{u(rng), u(rng), u(rng)}};
      bool ok = min_dist(beads[0]) > 2.8;
      for (int b = 1; b < 4 && ok; ++b) {
        std::array<double, 3> q;
        do {
          double v[3] = {g(rng), g(rng), g(rng)};
          const double nv = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
          for (int k = 0; k < 3; ++k)
            q[static_cast<std::size_t>(k)] =
                beads.back()[static_cast<std::size_t>(k)] + 1.5 * v[k] / nv;
        } while (b >= 2 &&
                 std::hypot(q[0] - beads[beads.size() - 2][0], q[1] - beads[beads.size() - 2][1],
                            q[2] - beads[beads.size() - 2][2]) < 2.2);
        ok = min_dist(q) > 2.8;
        beads.push_back(q);
      }
      if (!ok) continue;
      const long first = static_cast<long>(c.atoms.size()) + 1;
      for (const auto& q : beads) c.atoms.push_back({1, q[0], q[1], q[2], ch + 1});
      for (long b = 0; b < 3; ++b)
        c.bonds.push_back({1 + static_cast<int>(b % 2), first + b, first + b + 1});
      break;
    }
  }
  return c;
}

const char* kMolecular =
    "pair_style lj/cut 8.0\npair_coeff 1 1 0.1 3.0\nbond_style harmonic\n"
    "bond_coeff 1 300.0 1.5\nbond_coeff 2 250.0 1.45\nspecial_bonds lj 0.0 0.0 0.5\n";

}  // namespace

// A bond style needs the bonds, which only a data file with a Bonds section carries.
TEST_F(TrustInputs, BondStyleNeedsBondsInTheConfiguration) {
  const Config c = chains(16.0, 8, 4);
  write_data(dir / "mol.data", c, "full");
  write_data(dir / "nobonds.data", c, "full", /*with_bonds=*/false);
  const std::string pot = std::string("units real\natom_style full\n") + kMolecular;
  write("pot", pot);
  const auto ref = lammps("in.mol",
                          "units real\natom_style full\nread_data mol.data\n" +
                              std::string(kMolecular) + deck_tail("dump.mol"),
                          "dump.mol");
  // LAMMPS's dump of the system: no bonds in it
  write("pot_m", pot + "mass 1 14.0\n");
  expect_refused("--input " + p("dump.mol") + " --potential " + p("pot_m"),
                 {"carries no bonds", "write_data", "Bonds section"}, "dump + bond_style");
  expect_refused("--input " + p("nobonds.data") + " --potential " + p("pot"),
                 {"carries no bonds", "bond_style"}, "data file without Bonds + bond_style");
  // the data file with its Bonds (two bond types)
  expect_equal("--input " + p("mol.data") + " --potential " + p("pot"), ref, "chains, 16 A box");
  // a trailing wildcard reaches every bond type of the configuration, as in LAMMPS
  std::string wild = pot;
  wild.replace(wild.find("bond_coeff 2 "), 13, "bond_coeff 2* ");
  write("pot_w", wild);
  expect_equal("--input " + p("mol.data") + " --potential " + p("pot_w"), ref,
               "chains, bond_coeff 2*");
  // a bond type without coefficients: LAMMPS refuses ("All bond coeffs are not set")
  write("pot_one",
        "units real\natom_style full\npair_style lj/cut 8.0\npair_coeff 1 1 0.1 3.0\n"
        "bond_style harmonic\nbond_coeff 1 300.0 1.5\n");
  expect_refused("--input " + p("mol.data") + " --potential " + p("pot_one"),
                 {"bond type 2", "bond_coeff 2"}, "bond type 2 without bond_coeff");
}

// Boxes smaller than twice the cutoff (8 Å): a special partner (1-2, 1-3, 1-4 by atom id) is
// weighted only at the image within half the box; its other images within the cutoff are
// ordinary pairs (LAMMPS: Domain::minimum_image_check in every neighbour-list build).
TEST_F(TrustInputs, SpecialBondsInBoxesSmallerThanTwiceTheCutoff) {
  struct Case {
    std::string name, style;
    double L, xy;
  };
  for (const Case& k : {Case{"orthogonal 11 A, full", "full", 11.0, 0.0},
                        Case{"triclinic 10 A xy 3, molecular", "molecular", 10.0, 3.0}}) {
    const Config c = chains(k.L, 6, 7, k.xy);
    write_data(dir / "small.data", c, k.style);
    const std::string pot = "units real\natom_style " + k.style + "\n" + kMolecular;
    write("pot", pot);
    const auto ref =
        lammps("in.small",
               "units real\natom_style " + k.style + "\nboundary p p p\nread_data small.data\n" +
                   kMolecular + deck_tail("dump.small"),
               "dump.small");
    expect_equal("--input " + p("small.data") + " --potential " + p("pot"), ref, k.name);
  }
}
