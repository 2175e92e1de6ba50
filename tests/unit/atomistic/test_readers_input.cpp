// Readers on hand-written files: header handling (orthogonal box, boundary
// flags, extra columns, ITEM: UNITS/TIME), and one test per kind of bad input,
// each checking that the message names the file and the line.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <tuple>

#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/core/error.hpp"
#include "scratch_dir.hpp"

using namespace pdcg::atomistic;

namespace {

class Files : public ::testing::Test {
 protected:
  pdcg::test::ScratchDir dir{"readers_input"};
  std::string write(const std::string& name, const std::string& text) {
    const std::string p = dir / name;
    std::ofstream(p) << text;
    return p;
  }
  /// Runs f, expects an InputError whose message contains `what`, names `path`, and gives `line`.
  template <class F>
  void expect_error(F&& f, const std::string& path, long line, const std::string& what) {
    try {
      f();
      ADD_FAILURE() << "no InputError; expected: " << what;
    } catch (const pdcg::InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(what), std::string::npos) << m;
      const std::string where = line > 0 ? path + ":" + std::to_string(line) + ": " : path + ": ";
      EXPECT_NE(m.find(where), std::string::npos)
          << "expected " << path << ":" << line << " in: " << m;
    }
  }
};

const char* kOrthoDump =
    "ITEM: UNITS\n"
    "metal\n"
    "ITEM: TIME\n"
    "0.25\n"
    "ITEM: TIMESTEP\n"
    "100\n"
    "ITEM: NUMBER OF ATOMS\n"
    "3\n"
    "ITEM: BOX BOUNDS pp pp ff\n"
    "0 10\n"
    "-5 5\n"
    "0 20\n"
    "ITEM: ATOMS type id x y z element c_pe v_s[2]\n"
    "2 3 1.5 2.5 3.5 Cu -3.25 7\n"
    "1 1 0.5 -4 19 Ni -1e-3 8\n"
    "1 2 9.5 4.5 0 Ni +2.5 9\n";

/// The frame of kOrthoDump without its UNITS/TIME items (starts at ITEM: TIMESTEP).
std::string frame2() {
  const std::string t = kOrthoDump;
  return t.substr(t.find("ITEM: TIMESTEP"));
}
/// Erases the line that starts with `prefix`.
void erase_line(std::string& t, const std::string& prefix, bool last = false) {
  const auto b = last ? t.rfind(prefix) : t.find(prefix);
  t.erase(b, t.find('\n', b) + 1 - b);
}

TEST_F(Files, OrthogonalDumpWithExtrasAndFlags) {
  const auto p = write("o.dump", kOrthoDump);
  DumpReader r(p);
  ASSERT_EQ(r.nframes(), 1u);
  EXPECT_EQ(r.units(), "metal");
  EXPECT_EQ(r.info(0).time, 0.25);
  EXPECT_EQ(r.info(0).line, 1);
  EXPECT_EQ(r.info(0).atoms_line, 14);
  const Atoms a = r.frame(0);
  EXPECT_EQ(a.timestep, 100);
  EXPECT_EQ(a.box.lo, Eigen::Vector3d(0, -5, 0));
  EXPECT_EQ(a.box.hi, Eigen::Vector3d(10, 5, 20));
  EXPECT_FALSE(a.box.triclinic());
  EXPECT_TRUE(a.box.periodic[0] && a.box.periodic[1]);
  EXPECT_FALSE(a.box.periodic[2]);
  EXPECT_EQ(a.id, (std::vector<std::int64_t>{1, 2, 3}));  // sorted by id
  EXPECT_EQ(a.type, (std::vector<int>{1, 1, 2}));
  EXPECT_EQ(a.x, (std::vector<double>{0.5, -4, 19, 9.5, 4.5, 0, 1.5, 2.5, 3.5}));
  EXPECT_TRUE(a.image.empty() && a.v.empty() && a.f.empty());
  ASSERT_EQ(a.extra.count("c_pe"), 1u);
  EXPECT_EQ(a.extra.at("c_pe"), (std::vector<double>{-1e-3, 2.5, -3.25}));
  EXPECT_EQ(a.extra.at("v_s[2]"), (std::vector<double>{8, 9, 7}));
  EXPECT_EQ(a.extra.count("element"), 0u);  // names are skipped
}

TEST_F(Files, GzipIsDetectedByContent) {
  const std::string p = dir / "o.dump.z";  // no .gz suffix on purpose
  gzFile gz = gzopen(p.c_str(), "wb");
  gzputs(gz, kOrthoDump);
  gzputs(gz, frame2().c_str());  // a second frame (without UNITS/TIME)
  gzclose(gz);
  DumpReader r(p);
  EXPECT_TRUE(r.compressed());
  ASSERT_EQ(r.nframes(), 2u);
  EXPECT_EQ(r.info(1).line, 17);
  EXPECT_EQ(r.info(1).atoms_line, 26);
  EXPECT_EQ(r.frame(1).x, r.frame(0).x);
  EXPECT_EQ(detect_atom_file_kind(p), AtomFileKind::dump);
}

TEST_F(Files, TruncatedFrame) {
  std::string t = std::string(kOrthoDump) + frame2();
  erase_line(t, "1 2 9.5", true);  // drop the last atom line of frame 2 (line 28)
  const auto p = write("t.dump", t);
  DumpReader r(p);  // frame 0 is fine; frame 1 is reported when the index reaches it
  EXPECT_EQ(r.frame(0).size(), 3u);
  expect_error([&] { (void)r.nframes(); }, p, 27, "truncated frame 1 (timestep 100): 2 of 3");
  expect_error([&] { (void)r.frame(1); }, p, 27, "truncated frame 1 (timestep 100): 2 of 3");
}

TEST_F(Files, FrameWithTooFewAtomLinesBeforeNextFrame) {
  std::string t = kOrthoDump;
  erase_line(t, "1 1 0.5");  // frame 1 has 2 atom lines, then frame 2 starts at line 16
  t += frame2();
  const auto p = write("short.dump", t);
  expect_error([&] { DumpReader r(p); }, p, 16, "truncated frame 0 (timestep 100): 2 of 3");
}

TEST_F(Files, MissingItemSection) {
  std::string t = kOrthoDump;
  t.erase(t.find("ITEM: NUMBER OF ATOMS\n3\n"), 24);
  const auto p = write("m.dump", t);
  expect_error([&] { DumpReader r(p); }, p, 11, "missing 'ITEM: NUMBER OF ATOMS' section");
  std::string u = kOrthoDump;
  u.erase(u.find("ITEM: BOX BOUNDS pp pp ff\n"), 26);
  const auto q = write("m2.dump", u);
  expect_error([&] { DumpReader r(q); }, q, 9, "expected an ITEM: line");
}

TEST_F(Files, UnknownItem) {
  std::string t = kOrthoDump;
  t.replace(t.find("ITEM: TIME\n"), 10, "ITEM: TEMPO");
  const auto p = write("u.dump", t);
  expect_error([&] { DumpReader r(p); }, p, 3, "unknown ITEM: section");
}

TEST_F(Files, FewerColumnsThanDeclared) {
  std::string t = kOrthoDump;
  t.replace(t.find("1 1 0.5 -4 19 Ni -1e-3 8"), 24, "1 1 0.5 -4 19 Ni -1e-3");
  const auto p = write("c.dump", t);
  DumpReader r(p);  // the index counts lines only
  expect_error([&] { (void)r.frame(0); }, p, 15, "atom line has 7 values, ITEM: ATOMS declares 8");
}

TEST_F(Files, MoreColumnsThanDeclared) {
  std::string t = kOrthoDump;
  t.replace(t.find("+2.5 9"), 6, "+2.5 9 1");
  const auto p = write("c2.dump", t);
  expect_error([&] { (void)DumpReader(p).frame(0); }, p, 16, "more values than the 8 columns");
}

TEST_F(Files, NonNumericValue) {
  std::string t = kOrthoDump;
  t.replace(t.find("0.5 -4"), 6, "0.5 -4x");
  const auto p = write("n.dump", t);
  expect_error([&] { (void)DumpReader(p).frame(0); }, p, 15, "y: not a number: got '-4x'");
  std::string u = kOrthoDump;
  u.replace(u.find("1 2 9.5"), 7, "1 2.0 9.5");
  const auto q = write("n2.dump", u);
  expect_error([&] { (void)DumpReader(q).frame(0); }, q, 16, "id: not an integer: got '2.0'");
}

TEST_F(Files, NaNValue) {
  std::string t = kOrthoDump;
  t.replace(t.find("-3.25"), 5, "nan");
  const auto p = write("nan.dump", t);
  expect_error([&] { (void)DumpReader(p).frame(0); }, p, 14, "c_pe: non-finite value: got 'nan'");
  std::string u = kOrthoDump;
  u.replace(u.find("9.5 4.5"), 3, "-inf");
  const auto q = write("inf.dump", u);
  expect_error([&] { (void)DumpReader(q).frame(0); }, q, 16, "x: non-finite value");
}

TEST_F(Files, DuplicateAtomIdInDump) {
  std::string t = kOrthoDump;
  t.replace(t.find("1 2 9.5"), 7, "1 3 9.5");
  const auto p = write("d.dump", t);
  expect_error([&] { (void)DumpReader(p).frame(0); }, p, 16, "is also on line 14");
}

TEST_F(Files, NotADump) {
  const auto p = write("x.dump", "hello\n");
  expect_error([&] { DumpReader r(p); }, p, 1, "not a LAMMPS dump file");
  expect_error([&] { DumpReader r(dir / "missing.dump"); }, dir / "missing.dump", 0,
               "file not found");
  const auto b = write("bin.dump", std::string("\x05\0\0\0\0\0\0\0\x10", 9));
  EXPECT_EQ(detect_atom_file_kind(b), AtomFileKind::data);
  expect_error([&] { (void)read_data(b); }, b, 1, "binary file");
}

// ---- data files --------------------------------------------------------------

const char* kData =
    "Test system # title\n"
    "\n"
    "4 atoms\n"
    "2 atom types\n"
    "2 bonds\n"
    "1 bond types\n"
    "\n"
    "0.0 10.0 xlo xhi\n"
    "-1 1 ylo yhi  # comment\n"
    "0 5 zlo zhi\n"
    "0.5 -0.25 0.125 xy xz yz\n"
    "\n"
    "Masses\n"
    "\n"
    "1 12.011  # C\n"
    "2 1.008\n"
    "\n"
    "Pair Coeffs # lj/cut\n"
    "\n"
    "1 0.1 3.4\n"
    "2 0.02 2.5\n"
    "\n"
    "Atoms # molecular\n"
    "\n"
    "3 1 2 1.0 0.0 1.0\n"
    "1 1 1 2.0 0.5 2.0 1 0 -1\n"
    "2 2 1 3.0 -0.5 3.0\n"
    "4 2 2 4.0 0.0 4.0 0 0 0\n"
    "\n"
    "Velocities\n"
    "\n"
    "2 0.1 0.2 0.3\n"
    "1 1 2 3\n"
    "4 0 0 0\n"
    "3 -1 -2 -3\n"
    "\n"
    "Bonds\n"
    "\n"
    "1 1 1 2\n"
    "2 1 3 4\n";

TEST_F(Files, DataFileByHand) {
  const auto p = write("a.data", kData);
  EXPECT_EQ(detect_atom_file_kind(p), AtomFileKind::data);
  const DataFile d = read_data(p);
  EXPECT_EQ(d.title, "Test system # title");
  EXPECT_EQ(d.style, AtomStyle::molecular);
  EXPECT_EQ(d.sections,
            (std::vector<std::string>{"Masses", "Pair Coeffs", "Atoms", "Velocities", "Bonds"}));
  EXPECT_EQ(d.counts.at("bonds"), 2);
  const Atoms& a = d.atoms;
  EXPECT_EQ(a.ntypes, 2);
  EXPECT_EQ(a.box.lo, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(a.box.hi, Eigen::Vector3d(10, 1, 5));
  EXPECT_EQ(a.box.xy, 0.5);
  EXPECT_EQ(a.box.xz, -0.25);
  EXPECT_EQ(a.box.yz, 0.125);
  EXPECT_EQ(a.id, (std::vector<std::int64_t>{1, 2, 3, 4}));
  EXPECT_EQ(a.molecule, (std::vector<std::int64_t>{1, 2, 1, 2}));
  EXPECT_EQ(a.type, (std::vector<int>{1, 1, 2, 2}));
  EXPECT_EQ(a.image, (std::vector<int>{1, 0, -1, 0, 0, 0, 0, 0, 0, 0, 0, 0}));
  // atom 1 unwrapped: x + H·(1,0,−1) = (2 + 10 − (−0.25), 0.5 − 0.125, 2 − 5)
  EXPECT_DOUBLE_EQ(a.x[0], 12.25);
  EXPECT_DOUBLE_EQ(a.x[1], 0.375);
  EXPECT_DOUBLE_EQ(a.x[2], -3.0);
  EXPECT_EQ(a.x[3], 3.0);
  EXPECT_EQ(a.v, (std::vector<double>{1, 2, 3, 0.1, 0.2, 0.3, -1, -2, -3, 0, 0, 0}));
  EXPECT_DOUBLE_EQ(a.type_mass[1], 12.011);
  EXPECT_DOUBLE_EQ(a.mass_of(3), 1.008);
  ASSERT_EQ(a.bonds.size(), 2u);
  EXPECT_EQ(a.bonds[1].atom1, 3);
  EXPECT_EQ(a.bonds[1].atom2, 4);
}

TEST_F(Files, DataMissingAtoms) {
  std::string t = kData;
  t.replace(t.find("4 atoms"), 7, "5 atoms");
  const auto p = write("m.data", t);
  expect_error([&] { (void)read_data(p); }, p, 30,
               "Atoms section has 4 lines, the header declares 5");
}

TEST_F(Files, DataDuplicateId) {
  std::string t = kData;
  t.replace(t.find("2 2 1 3.0"), 9, "3 2 1 3.0");
  const auto p = write("d.data", t);
  expect_error([&] { (void)read_data(p); }, p, 27,
               "duplicate atom id: got '3', expected each atom id once (id 3 is also on line 25)");
}

TEST_F(Files, DataUnknownSection) {
  std::string t = kData;
  t.replace(t.find("Pair Coeffs # lj/cut"), 20, "Pear Coeffs");
  const auto p = write("u.data", t);
  expect_error([&] { (void)read_data(p); }, p, 18, "unknown section: got 'Pear Coeffs'");
}

TEST_F(Files, DataUnknownHeaderLine) {
  std::string t = kData;
  t.replace(t.find("2 bonds"), 7, "2 bnods");
  const auto p = write("h.data", t);
  expect_error([&] { (void)read_data(p); }, p, 5, "unknown header line");
}

TEST_F(Files, DataWrongColumnCount) {
  std::string t = kData;
  t.replace(t.find("2 2 1 3.0 -0.5 3.0"), 18, "2 2 1 3.0 -0.5 3.0 0");
  const auto p = write("w.data", t);
  expect_error([&] { (void)read_data(p); }, p, 27, "Atoms line has 7 values");
}

TEST_F(Files, DataNonNumericAndNaN) {
  std::string t = kData;
  t.replace(t.find("4 2 2 4.0"), 9, "4 2 2 four");
  const auto p = write("nn.data", t);
  expect_error([&] { (void)read_data(p); }, p, 28, "x: not a number: got 'four'");
  std::string u = kData;
  u.replace(u.find("0.1 0.2 0.3"), 11, "0.1 NaN 0.3");
  const auto q = write("nan.data", u);
  expect_error([&] { (void)read_data(q); }, q, 32, "vy: non-finite value");
}

TEST_F(Files, DataBondToMissingAtomAndBadType) {
  std::string t = kData;
  t.replace(t.find("2 1 3 4"), 7, "2 1 3 9");
  const auto p = write("b.data", t);
  expect_error([&] { (void)read_data(p); }, p, 40,
               "Bonds: atom id not in the Atoms section: got '9'");
  std::string u = kData;
  u.replace(u.find("4 2 2 4.0"), 9, "4 2 3 4.0");
  const auto q = write("t.data", u);
  expect_error([&] { (void)read_data(q); }, q, 28, "atom type out of range: got '3'");
}

TEST_F(Files, DataSectionLongerThanDeclared) {
  std::string t = kData;
  t.replace(t.find("2 1.008\n"), 8, "2 1.008\n3 5.0\n");
  const auto p = write("l.data", t);
  expect_error([&] { (void)read_data(p); }, p, 17,
               "expected a section keyword after section Masses");
}

}  // namespace

namespace {

/// A multi-frame dump of random numbers, large enough (≈ 13 MB) for several gzip
/// access points (one per 4 MiB of text).
std::string random_dump(int frames, int natoms) {
  std::mt19937 rng(2024);
  std::uniform_real_distribution<double> u(-50.0, 50.0);
  std::string t;
  for (int f = 0; f < frames; ++f) {
    t += fmt::format(
        "ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{}\nITEM: BOX BOUNDS pp pp pp\n"
        "-50 50\n-50 50\n-50 50\nITEM: ATOMS id type x y z\n",
        100 * f, natoms);
    for (int i = 0; i < natoms; ++i)
      t += fmt::format("{} {} {:.15g} {:.15g} {:.15g}\n", natoms - i, 1 + i % 3, u(rng), u(rng),
                       u(rng));
  }
  return t;
}

TEST_F(Files, GzipRandomAccessMatchesPlainText) {
  const std::string text = random_dump(40, 5000);
  const auto plain = write("r.dump", text);
  // Two gzip members (the second appended with mode "ab"), so seeks also cross a member.
  const std::string gz = dir / "r.dump.gz";
  const std::size_t half = text.find("ITEM: TIMESTEP\n2000\n");
  for (const auto& [mode, a, b] :
       {std::tuple{"wb1", std::size_t{0}, half}, std::tuple{"ab1", half, text.size()}}) {
    gzFile f = gzopen(gz.c_str(), mode);
    ASSERT_EQ(gzwrite(f, text.data() + a, static_cast<unsigned>(b - a)), static_cast<int>(b - a));
    gzclose(f);
  }
  DumpReader p(plain), z(gz);
  EXPECT_TRUE(z.compressed());
  ASSERT_EQ(z.nframes(), 40u);
  // Reference: the plain-text reader (no seeking machinery involved).
  std::mt19937 rng(7);
  for (int k = 0; k < 14; ++k) {
    const std::size_t n = rng() % 40;
    SCOPED_TRACE("frame " + std::to_string(n));
    const Atoms a = z.frame(n), b = p.frame(n);
    EXPECT_EQ(a.timestep, 100 * static_cast<std::int64_t>(n));
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.type, b.type);
    EXPECT_EQ(a.x, b.x);  // the same text: bitwise identical
  }
}

TEST_F(Files, TruncatedGzip) {
  const std::string text = random_dump(3, 2000);
  const std::string gz = dir / "cut.dump.gz";
  gzFile f = gzopen(gz.c_str(), "wb");
  gzwrite(f, text.data(), static_cast<unsigned>(text.size()));
  gzclose(f);
  std::filesystem::resize_file(gz, std::filesystem::file_size(gz) / 2);
  expect_error([&] { (void)DumpReader(gz).nframes(); }, gz, 0, "corrupt or truncated gzip data");
}

}  // namespace

namespace {
TEST_F(Files, DataTypeLabelSectionsAreSkipped) {
  std::string t = kData;
  t.replace(t.find("Masses\n"), 7,
            "Atom Type Labels\n\n1 C\n2 H\n\nBond Type Labels\n\n1 C-H\n\nMasses\n");
  const auto p = write("labels.data", t);
  const DataFile d = read_data(p);
  EXPECT_EQ(d.sections.front(), "Atom Type Labels");
  EXPECT_EQ(d.atoms.size(), 4u);
  EXPECT_DOUBLE_EQ(d.atoms.type_mass[2], 1.008);
}
}  // namespace

namespace {
TEST_F(Files, ReadAtomsPicksTheKindAndFrame) {
  const auto d = write("two.dump", std::string(kOrthoDump) + frame2());
  EXPECT_EQ(read_atoms(d).timestep, 100);
  EXPECT_EQ(read_atoms(d, 0).size(), 3u);
  EXPECT_EQ(read_atoms(d, -2).x, read_atoms(d, 1).x);
  expect_error([&] { (void)read_atoms(d, 2); }, d, 0, "frame index out of range");
  expect_error([&] { (void)read_atoms(d, -3); }, d, 0, "frame index out of range");
  const auto p = write("a.data", kData);
  EXPECT_EQ(read_atoms(p).size(), 4u);
  expect_error([&] { (void)read_atoms(p, 1); }, p, 0, "a data file holds one configuration");
}
}  // namespace

namespace {
TEST_F(Files, FrameWithMoreAtomLinesThanDeclared) {
  std::string t = kOrthoDump;
  t += "4 1 1 1 1 Ni 0 0\n";  // a 4th atom line in a frame that declares 3 (line 17)
  t += frame2();
  const auto p = write("long.dump", t);
  DumpReader r(p);
  expect_error([&] { (void)r.nframes(); }, p, 17, "expected the start of a frame");
}
}  // namespace
