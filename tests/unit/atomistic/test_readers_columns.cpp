// Readers on any column set and any header: positions chosen axis by axis (`xs yu zu`), what an
// operation needs checked by name (FrameNeeds), and a sweep over column sets, header variants and
// gzip in which every call either succeeds or throws pdcg::InputError (never a crash, never
// another exception). Values worked out by hand from the documented rules.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"
#include "scratch_dir.hpp"

using namespace pdcg::atomistic;

namespace {

class Columns : public ::testing::Test {
 protected:
  pdcg::test::ScratchDir dir{"readers_columns"};
  std::string write(const std::string& name, const std::string& text) {
    const std::string p = dir / name;
    std::ofstream(p) << text;
    return p;
  }
  std::string write_gz(const std::string& name, const std::string& text) {
    const std::string p = dir / name;
    gzFile gz = gzopen(p.c_str(), "wb");
    gzwrite(gz, text.data(), static_cast<unsigned>(text.size()));
    gzclose(gz);
    return p;
  }
  /// Runs f, expects an InputError whose message contains every one of `what` and starts with
  /// `path:line: `.
  template <class F>
  void expect_error(F&& f, const std::string& path, long line, std::vector<std::string> what) {
    try {
      f();
      ADD_FAILURE() << "no InputError; expected: " << what.front();
    } catch (const pdcg::InputError& e) {
      const std::string m = e.what();
      for (const auto& w : what) EXPECT_NE(m.find(w), std::string::npos) << w << "\nin: " << m;
      const std::string where = path + ":" + std::to_string(line) + ": ";
      EXPECT_EQ(m.rfind(where, 0), 0u) << "expected " << where << " at the start of: " << m;
    }
  }
};

/// One frame, orthogonal box x [1, 11], y [-2, 2], z [0, 5] (pp pp ff), atoms given as lines.
std::string frame(const std::string& columns, const std::vector<std::string>& atoms, long step = 0,
                  const std::string& box = "ITEM: BOX BOUNDS pp pp ff\n1 11\n-2 2\n0 5\n") {
  std::string t =
      fmt::format("ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{}\n", step, atoms.size());
  t += box;
  t += "ITEM: ATOMS " + columns + "\n";
  for (const auto& a : atoms) t += a + "\n";
  return t;
}

FrameNeeds needs_all(const char* op = "op") {
  FrameNeeds n;
  n.operation = op;
  return n;
}

TEST_F(Columns, PositionsChosenAxisByAxis) {
  // xs (fractional, wrapped), yu (unwrapped), z (wrapped) with image flags:
  // x = lo + L s + L ix, y as read (unwrapped, no image added), z = z + L iz.
  const auto p = write("mix.dump", frame("id type xs yu z ix iy iz",
                                         {"2 1 0.25 4.5 1.0 1 7 -1", "1 2 0.5 -1.5 2.5 0 0 2"}));
  DumpReader r(p);
  EXPECT_EQ(r.position_columns(0), (std::array<std::string, 3>{"xs", "yu", "z"}));
  const Atoms a = r.frame(0);
  ASSERT_EQ(a.x.size(), 6u);
  // atom 1: x = 1 + 10·0.5 = 6, y = −1.5, z = 2.5 + 5·2 = 12.5
  EXPECT_EQ(a.x[0], 6.0);
  EXPECT_EQ(a.x[1], -1.5);
  EXPECT_EQ(a.x[2], 12.5);
  // atom 2: x = 1 + 10·0.25 + 10·1 = 13.5, y = 4.5 (iy = 7 not added: yu is unwrapped), z = 1 − 5 =
  // −4
  EXPECT_EQ(a.x[3], 13.5);
  EXPECT_EQ(a.x[4], 4.5);
  EXPECT_EQ(a.x[5], -4.0);
  EXPECT_EQ(a.image, (std::vector<int>{0, 0, 2, 1, 7, -1}));
  // the same through frame(n, needs)
  EXPECT_EQ(r.frame(0, needs_all()).x, a.x);
}

TEST_F(Columns, CompleteSetWinsOverPerAxisChoice) {
  // xs ys zs is complete: xu (a lone unwrapped column) stays an extra column
  const auto p = write("c.dump", frame("id xu xs ys zs", {"1 99 0.5 0.25 0.2"}));
  const Atoms a = DumpReader(p).frame(0);
  EXPECT_EQ(a.x, (std::vector<double>{6.0, -1.0, 1.0}));
  EXPECT_EQ(a.extra.at("xu"), std::vector<double>{99.0});
}

TEST_F(Columns, OnlyXForAnOperationAlongX) {
  const auto p = write("x.dump", frame("id xu vx", {"3 2.25 0.5", "1 1.5 -0.5", "2 1.75 0.0"}));
  DumpReader r(p);
  EXPECT_TRUE(r.frame(0).x.empty());  // no operation: positions only when all axes are there
  EXPECT_EQ(r.frame(0).extra.at("xu"), (std::vector<double>{1.5, 1.75, 2.25}));
  FrameNeeds along_x;
  along_x.position = {true, false, false};
  along_x.id = true;
  const Atoms a = r.frame(0, along_x);
  // y, z at the box centre (0, 2.5)
  EXPECT_EQ(a.x, (std::vector<double>{1.5, 0, 2.5, 1.75, 0, 2.5, 2.25, 0, 2.5}));
  EXPECT_EQ(a.id, (std::vector<std::int64_t>{1, 2, 3}));
  // line 9: ITEM: ATOMS
  expect_error([&] { (void)r.frame(0, needs_all("pdcg atoms2pd")); }, p, 9,
               {"pdcg atoms2pd needs columns y (or yu, ys, ysu), z (or zu, zs, zsu) that frame 0 "
                "(timestep 0) does not have",
                "got 'ITEM: ATOMS id xu vx'", "id type x y z"});
}

TEST_F(Columns, MissingColumnsAreNamed) {
  const std::string two =
      frame("id type y z", {"1 1 0 1"}, 0) + frame("id type y z", {"1 1 0 1"}, 10);
  const auto p = write("yz.dump", two);
  DumpReader r(p);
  EXPECT_TRUE(r.frame(1).x.empty());
  // frame 1 starts at line 11; its ITEM: ATOMS is line 19
  expect_error([&] { r.require(1, needs_all("pdcg forces --deformed")); }, p, 19,
               {"pdcg forces --deformed needs column x (or xu, xs, xsu) that frame 1 (timestep 10)",
                "Fix: write the dump with the columns it needs"});
  FrameNeeds t = needs_all();
  t.position = {false, true, true};
  t.type = true;
  t.id = true;
  EXPECT_NO_THROW(r.require(0, t));
  const auto q = write("noid.dump", frame("x y z", {"1 0 1"}));
  t.position = {true, true, true};
  expect_error([&] { (void)DumpReader(q).frame(0, t); }, q, 9, {"needs columns type, id"});
}

TEST_F(Columns, TiltedBoxNeedsOneFractionalSet) {
  const std::string tri = "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 12 2\n0 8 0\n0 6 0\n";
  const auto p = write("t.dump", frame("id type xs yu zu", {"1 1 0.5 1 1"}, 0, tri));
  DumpReader r(p);
  const Atoms a = r.frame(0);  // no operation: no positions, the columns by name
  EXPECT_TRUE(a.x.empty());
  EXPECT_EQ(a.extra.at("xs"), std::vector<double>{0.5});
  expect_error([&] { (void)r.frame(0, needs_all()); }, p, 9,
               {"mixes fractional and other position columns in a tilted box", "xs ys zs"});
  // Cartesian columns mixed per axis are fine in a tilted box
  const auto q = write("t2.dump", frame("id type x yu zu", {"1 1 0.5 1 1"}, 0, tri));
  EXPECT_EQ(DumpReader(q).frame(0, needs_all()).x, (std::vector<double>{0.5, 1, 1}));
}

TEST_F(Columns, ZeroAtoms) {
  const auto p = write("z.dump", frame("id type x y z", {}));
  DumpReader r(p);
  EXPECT_EQ(r.frame(0).size(), 0u);
  EXPECT_EQ(r.info(0).natoms_line, 4);
  expect_error([&] { (void)r.frame(0, needs_all("pdcg atoms2pd")); }, p, 4,
               {"pdcg atoms2pd needs atoms, but frame 0 (timestep 0) has zero atoms"});
}

TEST_F(Columns, BadTypeAndImageValues) {
  const auto p = write("t0.dump", frame("id type x y z", {"1 0 1 1 1"}));
  expect_error([&] { (void)DumpReader(p).frame(0); }, p, 10, {"atom type out of range", "got '0'"});
  const auto q = write("t1.dump", frame("id type x y z", {"1 4294967297 1 1 1"}));
  expect_error([&] { (void)DumpReader(q).frame(0); }, q, 10, {"atom type out of range"});
  const auto m = write("im.dump", frame("id x y z ix iy iz", {"1 1 1 1 0 0 9999999999"}));
  expect_error([&] { (void)DumpReader(m).frame(0); }, m, 10, {"value out of range"});
}

TEST_F(Columns, BoxWithTwoLines) {
  const auto p =
      write("b2.dump", frame("id x y", {"1 1 1"}, 0, "ITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n"));
  expect_error([&] { (void)DumpReader(p); }, p, 8, {"ITEM: BOX BOUNDS has 2 of 3 lines", "2D box"});
}

TEST_F(Columns, XyzFilesAreRefusedByName) {
  // what `dump xyz` writes (type numbers; with dump_modify element, names)
  const std::string xyz = "2\n Atoms. Timestep: 0\n1 0 0 0\n2 0.5 0.5 0\n";
  const std::string names = "2\ncomment\nAr 0 0 0\nAr 0.5 0.5 0\n";
  for (const auto& [name, text] : {std::pair{"a.xyz", xyz}, std::pair{"b.xyz", names}}) {
    const auto p = write(name, text);
    const std::vector<std::string> what{"an xyz file (dump xyz) is not read",
                                        "dump 1 all custom N traj.dump id type x y z"};
    expect_error([&] { (void)read_data(p); }, p, 1, what);
    expect_error([&] { (void)read_atoms(p); }, p, 1, what);
    expect_error([&] { (void)DumpReader(p); }, p, 1, what);
  }
  // a data file whose title is a number still reads
  const auto d = write("n.data",
                       "42\n\n1 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n"
                       "Atoms # atomic\n\n1 1 0.5 0.5 0.5\n");
  EXPECT_EQ(read_data(d).atoms.size(), 1u);
}

TEST_F(Columns, DataFileCountFarBeyondItsLines) {
  // a header count of 10^15 atoms must fail as a short section, not as an allocation
  const auto p =
      write("big.data",
            "t\n\n1000000000000000 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo "
            "zhi\n\nAtoms # atomic\n\n1 1 0.5 0.5 0.5\n");
  expect_error([&] { (void)read_data(p); }, p, 11,
               {"Atoms section has 1 lines, the header declares 1000000000000000"});
  const auto q =
      write("bonds.data",
            "t\n\n1 atoms\n1 atom types\n1000000000000000 bonds\n1 bond types\n0 1 xlo "
            "xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # bond\n\n1 1 1 0.5 0.5 0.5\n\nBonds\n\n"
            "1 1 1 1\n");
  expect_error([&] { (void)read_data(q); }, q, 17, {"Bonds section has 1 lines"});
}

TEST_F(Columns, DataFileSecondAtomsSection) {
  const std::string head = "t\n\n1 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\n";
  const auto p =
      write("two.data",
            head + "Atoms # atomic\n\n1 1 0.5 0.5 0.5\n\nAtoms # atomic\n\n1 1 0.5 0.5 0.5\n");
  expect_error([&] { (void)read_data(p); }, p, 13, {"a second Atoms section"});
  const auto v =
      write("v.data", head + "Velocities\n\n1 0 0 0\n\nAtoms # atomic\n\n1 1 0.5 0.5 0.5\n");
  expect_error([&] { (void)read_data(v); }, v, 9, {"Velocities before Atoms"});
  const auto m = write("m.data", head);  // 1 atom declared, no Atoms section
  expect_error([&] { (void)read_data(m); }, m, 8, {"no Atoms section"});
  // no Masses section, no box lines: LAMMPS's defaults (NaN masses, box −0.5 .. 0.5)
  const auto n =
      write("nm.data", "t\n\n1 atoms\n1 atom types\n\nAtoms # atomic\n\n1 1 0.1 0.2 0.3\n");
  testing::internal::CaptureStderr();
  const auto d = read_data(n);
  const std::string said = testing::internal::GetCapturedStderr();
  // ... with one warning per missing box line, naming the line and the default
  EXPECT_NE(said.find("no 'xlo xhi' header line: LAMMPS's default -0.5 .. 0.5 is used along x"),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("no 'zlo zhi' header line"), std::string::npos) << said;
  EXPECT_TRUE(std::isnan(d.atoms.type_mass.at(1)));
  EXPECT_EQ(d.atoms.box.lo.x(), -0.5);
  EXPECT_EQ(d.atoms.box.hi.z(), 0.5);
}

/// Every call on every variant either works or throws InputError.
template <class F>
void no_crash(F&& f, const std::string& what) {
  try {
    f();
  } catch (const pdcg::InputError&) {
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": not an InputError: " << e.what();
  }
}

TEST_F(Columns, DuplicateColumnThatIsReadIsRefused) {
  // `dump custom ... id x x y z` (two x columns that may hold different things): refused with
  // the line of ITEM: ATOMS (line 9 of the frame) rather than silently taking the first;
  // a duplicated column pdcg does not read (c_pe twice) is kept as extra columns.
  const auto p = write("dup.dump", frame("id type x x y z", {"1 1 2 3 0 0", "2 1 4 5 1 1"}));
  expect_error([&] { (void)DumpReader(p).frame(0); }, p, 9,
               {"column 'x' appears more than once", "each column once"});
  const auto q =
      write("dupc.dump", frame("id type x y z c_pe c_pe", {"1 1 2 0 0 -1 -2", "2 1 4 1 1 -3 -4"}));
  const Atoms a = DumpReader(q).frame(0);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.x[3], 4.0);
}

TEST_F(Columns, SweepNeverCrashes) {
  const std::vector<std::string> column_sets{"id type x y z",
                                             "type x y z",
                                             "id x y z",
                                             "x",
                                             "id type xs ys zs",
                                             "id type xu yu zu",
                                             "id type y z",
                                             "id type xs yu",
                                             "id id type x x y z",
                                             "id type x y z c_pe v_a f_1[2] element",
                                             "id type x y z ix iy iz",
                                             "id type xsu ysu zsu ix",
                                             "id mol q mass vx vy vz fx fy fz x y z"};
  const std::vector<std::string> boxes{
      "ITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n0 10\n",
      "ITEM: BOX BOUNDS xy xz yz pp pp pp\n-1 11 1\n0 10 -1\n0 10 0.5\n",
      "ITEM: BOX BOUNDS xy xz yz pp pp pp\n0 10\n0 10\n0 10\n",  // tilts named, not given
      "ITEM: BOX BOUNDS pp pp pp\n0 10 1\n0 10 1\n0 10 1\n",     // tilts given, not named
      "ITEM: BOX BOUNDS pp pp pp\n0 10\n0 10\n",                 // two lines
      "ITEM: BOX BOUNDS pp pp\n0 10\n0 10\n-0.5 0.5\n",          // two flags
      "ITEM: BOX BOUNDS\n0 10\n0 10\n-0.5 0.5\n",                // 2D-like, no flags
      "",                                                        // no BOX BOUNDS
  };
  const std::vector<std::string> tokens{"1", "2.5", "-3e-1", "x", "nan", "0", "-7", "1e400", ""};
  std::size_t cases = 0, read = 0;
  for (std::size_t ci = 0; ci < column_sets.size(); ++ci)
    for (std::size_t bi = 0; bi < boxes.size(); ++bi)
      for (int variant = 0; variant < 6; ++variant) {
        const auto ncol = pdcg::split_blanks(column_sets[ci]).size();
        std::vector<std::string> atoms;
        const int natoms = variant == 5 ? 0 : 3;
        for (int i = 0; i < natoms; ++i) {
          std::string line;
          for (std::size_t j = 0; j < ncol; ++j) {
            // variant 1: a bad token; variant 2: a value missing; others: numbers
            std::string t = std::to_string(i + 1 + static_cast<int>(j) % 3);
            if (variant == 1 && i == 1 && j == ncol - 1) t = tokens[(ci + bi) % tokens.size()];
            if (variant == 2 && i == 2 && j == ncol - 1) continue;
            line += (j ? " " : "") + t;
          }
          atoms.push_back(line);
        }
        std::string text = frame(column_sets[ci], atoms, 0, boxes[bi]);
        if (variant == 3) text.replace(text.find("NUMBER OF ATOMS\n3"), 17, "NUMBER OF ATOMS\n5");
        if (variant == 4) text.replace(text.find("NUMBER OF ATOMS\n3"), 17, "NUMBER OF ATOMS\n2");
        text += frame(column_sets[ci], atoms, 10, boxes[bi]).substr(0, 90);  // truncated frame
        for (bool gz : {false, true}) {
          const std::string name = fmt::format("s{}_{}_{}{}", ci, bi, variant, gz ? ".gz" : "");
          const std::string p = gz ? write_gz(name, text) : write(name, text);
          ++cases;
          no_crash(
              [&] {
                DumpReader r(p);
                (void)r.position_columns(0);
                const Atoms a = r.frame(0);
                EXPECT_TRUE(a.x.empty() || a.x.size() == 3 * a.size()) << name;
                FrameNeeds n;
                n.type = n.id = true;
                const Atoms b = r.frame(0, n);
                EXPECT_EQ(b.x.size(), 3 * b.size()) << name;
                ++read;
                (void)r.nframes();
              },
              name);
          no_crash([&] { (void)read_atoms(p, 0); }, name);
          no_crash([&] { (void)read_atoms(p, -1); }, name);
        }
      }
  EXPECT_EQ(cases, column_sets.size() * boxes.size() * 6 * 2);
  EXPECT_GT(read, 20u);  // the sweep reaches the frames, not only the header errors
}

TEST_F(Columns, DataSweepNeverCrashes) {
  const std::string box = "0 10 xlo xhi\n0 10 ylo yhi\n0 10 zlo zhi\n";
  const std::vector<std::string> headers{"2 atoms\n2 atom types\n" + box,
                                         "2 atoms\n" + box,
                                         "2 atom types\n" + box,
                                         "2 atoms\n2 atom types\n",
                                         "5 atoms\n2 atom types\n" + box + "0 0 0 xy xz yz\n",
                                         "1 atoms\n2 atom types\n" + box};
  const std::vector<std::string> atoms{"Atoms # atomic\n\n1 1 1 1 1\n2 2 2 2 2\n",
                                       "Atoms # full\n\n1 1 1 1 1\n2 2 2 2 2\n",
                                       "Atoms\n\n1 1 1 1 1 0 0 0\n2 2 2 2 2 0 0\n",
                                       "Atoms # charge\n\n1 1 0.5 1 1 1\n2 2 -0.5 2 2 2\n",
                                       "Atoms\n\n1 1 1 1\n2 2 2 2\n",
                                       "Atoms # hybrid\n\n1 1 1 1 1\n2 2 2 2 2\n",
                                       ""};
  const std::vector<std::string> others{"", "Masses\n\n1 1.0\n2 2.0\n",
                                        "Velocities\n\n1 0 0 0\n2 0 0 0\n", "Masses\n\n1 1.0\n",
                                        "Bonds\n\n1 1 1 2\n"};
  for (std::size_t h = 0; h < headers.size(); ++h)
    for (std::size_t a = 0; a < atoms.size(); ++a)
      for (std::size_t o = 0; o < others.size(); ++o)
        for (bool before : {false, true}) {
          const std::string body =
              before ? others[o] + "\n" + atoms[a] : atoms[a] + "\n" + others[o];
          const std::string p = write(fmt::format("d{}_{}_{}_{}.data", h, a, o, before),
                                      "title\n\n" + headers[h] + "\n" + body);
          no_crash([&] { (void)read_data(p); }, p);
          for (auto hint : {AtomStyle::atomic, AtomStyle::bond, AtomStyle::full})
            no_crash([&] { (void)read_data(p, hint); }, p);
        }
}

}  // namespace
