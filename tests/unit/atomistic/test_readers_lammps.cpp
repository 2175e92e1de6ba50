// Acceptance tests of the dump and data-file readers against LAMMPS itself:
// LAMMPS (embedded through its C library API) runs a few MD steps in a
// triclinic periodic box, writes dumps / data files in several flavours, and
// the positions, image flags, velocities, forces, types, masses, bonds and box
// that LAMMPS held in memory at each dumped step are the reference.
#if PDCG_WITH_LAMMPS

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <tuple>

#include "lammps_driver.hpp"
#include "pdcg/atomistic/data_file.hpp"
#include "pdcg/atomistic/dump_reader.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"

using namespace pdcg::atomistic;
using pdcg::test::all_close;
using pdcg::test::Lammps;
using pdcg::test::ScratchDir;

namespace {

/// What LAMMPS held at one dumped timestep.
struct Reference {
  std::int64_t step = 0;
  Lammps::BoxData box;
  std::vector<double> x_wrapped, x_unwrapped, v, f;
  std::vector<int> image, type;
};

Reference snapshot(const Lammps& lmp, std::int64_t step) {
  Reference r;
  r.step = step;
  r.box = lmp.box();
  r.x_wrapped = lmp.gather_double("x", 3);
  r.x_unwrapped = lmp.unwrapped_positions();
  r.v = lmp.gather_double("v", 3);
  r.f = lmp.gather_double("f", 3);
  r.image = lmp.gather_int("image", 3);
  r.type = lmp.gather_int("type", 1);
  return r;
}

double box_scale(const Lammps::BoxData& b) { return (b.hi - b.lo).maxCoeff(); }

void expect_box(const Box& got, const Lammps::BoxData& want) {
  // Tolerance 1e-13·L: the dump stores the bounding box with 17 digits; undoing
  // the bounding-box shift (lo = lo_bound − min(0, xy, xz, xy+xz)) costs a few ulps of L.
  const double tol = 1e-13 * box_scale(want);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(got.lo[k], want.lo[k], tol) << "lo[" << k << "]";
    EXPECT_NEAR(got.hi[k], want.hi[k], tol) << "hi[" << k << "]";
    EXPECT_EQ(got.periodic[static_cast<std::size_t>(k)], want.periodic[k] != 0);
  }
  EXPECT_NEAR(got.xy, want.xy, tol);
  EXPECT_NEAR(got.xz, want.xz, tol);
  EXPECT_NEAR(got.yz, want.yz, tol);
}

std::vector<std::int64_t> one_to_n(std::size_t n) {
  std::vector<std::int64_t> ids(n);
  for (std::size_t i = 0; i < n; ++i) ids[i] = static_cast<std::int64_t>(i + 1);
  return ids;
}

class DumpVsLammps : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new ScratchDir("dumps");
    Lammps lmp;
    const std::string d = dir_->path().string() + "/";
    // 320 atoms of a hot LJ fcc crystal in a tilted periodic box: within 30 steps
    // many atoms cross the periodic boundaries (checked below), so image flags matter.
    lmp.run(R"(
units lj
atom_style atomic
atom_modify map array
boundary p p p
lattice fcc 0.8442
region box prism 0 4 0 4 0 5 1.3 -0.9 0.7 units lattice
create_box 2 box
create_atoms 1 box
set type 1 type/fraction 2 0.3 12345
mass 1 1.0
mass 2 2.5
velocity all create 6.0 87287 loop geom
pair_style lj/cut 2.5
pair_coeff * * 1.0 1.0
timestep 0.01
fix 1 all nve
)");
    // Shuffled column orders; %20.15g keeps 15 significant digits (the default
    // %g keeps 6, far from the 1e-12 the test asks for).
    lmp.run("dump A all custom/gz 10 " + d +
            "a.dump.gz vz ix zs id fy xs iz type ys vx iy fx vy fz\n"
            "dump_modify A format float %20.15g\n"
            "dump B all custom 10 " +
            d +
            "b.dump zu id xu mass type yu\n"
            "dump_modify B format float %20.15g\n"
            "dump C all custom/gz 10 " +
            d +
            "c.dump.gz xsu id ysu zsu type\n"
            "dump_modify C format float %20.15g\n"
            "dump D all custom 10 " +
            d +
            "d.dump y iy x id iz z ix type\n"
            "dump_modify D format float %20.15g sort id\n"
            "dump E all atom 10 " +
            d +
            "e.dump\n"
            // dump atom knows only "format line": id type xs ys zs ix iy iz
            "dump_modify E image yes format line \"%d %d %20.15g %20.15g %20.15g %d %d %d\"\n");
    refs_ = new std::vector<Reference>;
    lmp.run("run 0");
    refs_->push_back(snapshot(lmp, 0));
    for (int k = 1; k <= 3; ++k) {
      lmp.run("run 10");
      refs_->push_back(snapshot(lmp, 10 * k));
    }
    lmp.run("undump A\nundump B\nundump C\nundump D\nundump E");
  }
  static void TearDownTestSuite() {
    delete refs_;
    delete dir_;
  }
  static std::string file(const std::string& name) { return *dir_ / name; }
  static inline ScratchDir* dir_ = nullptr;
  static inline std::vector<Reference>* refs_ = nullptr;

  /// Every frame of `path` against the reference, visiting frames out of order
  /// (random access, backwards seeks through gzip).
  static void check_positions(const std::string& path, bool expect_image) {
    DumpReader dump(path);
    ASSERT_EQ(dump.nframes(), refs_->size());
    for (std::size_t n : {std::size_t{3}, std::size_t{0}, std::size_t{2}, std::size_t{1}}) {
      SCOPED_TRACE(path + " frame " + std::to_string(n));
      const Reference& ref = (*refs_)[n];
      const Atoms a = dump.frame(n);
      EXPECT_EQ(a.timestep, ref.step);
      expect_box(a.box, ref.box);
      ASSERT_EQ(a.size(), ref.type.size());
      EXPECT_EQ(a.id, one_to_n(a.size()));
      EXPECT_EQ(a.type, ref.type);
      // ≤ 1e-12·L (the acceptance bound): 15 significant digits leave ≤ 5e-15 relative
      // per coordinate; scaled → Cartesian and unwrapping add a few ulps of L.
      EXPECT_TRUE(all_close(a.x, ref.x_unwrapped, {1e-12 * box_scale(ref.box), 0.0}));
      if (expect_image)
        EXPECT_EQ(a.image, ref.image);
      else
        EXPECT_TRUE(a.image.empty());
    }
  }
};

TEST_F(DumpVsLammps, AtomsCrossBoundaries) {
  // The test is only meaningful if image flags are exercised.
  const auto& last = refs_->back().image;
  const auto crossed = std::count_if(last.begin(), last.end(), [](int m) { return m != 0; });
  EXPECT_GT(crossed, 10);
}

TEST_F(DumpVsLammps, ScaledWithImageFlagsGzip) {
  check_positions(file("a.dump.gz"), true);
  DumpReader dump(file("a.dump.gz"));
  EXPECT_TRUE(dump.compressed());
  EXPECT_EQ(dump.columns().size(), 14u);
  for (std::size_t n = 0; n < dump.nframes(); ++n) {
    const Atoms a = dump.frame(n);
    // 15 significant digits: relative error ≤ 5e-15 per value.
    EXPECT_TRUE(all_close(a.v, (*refs_)[n].v, {0.0, 1e-14}));
    EXPECT_TRUE(all_close(a.f, (*refs_)[n].f, {0.0, 1e-14}));
    EXPECT_TRUE(a.extra.empty());
  }
}

TEST_F(DumpVsLammps, UnwrappedCartesianPlain) {
  check_positions(file("b.dump"), false);
  DumpReader dump(file("b.dump"));
  EXPECT_FALSE(dump.compressed());
  const Atoms a = dump.frame(2);
  ASSERT_EQ(a.mass.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.mass[i], a.type[i] == 1 ? 1.0 : 2.5);
}

TEST_F(DumpVsLammps, ScaledUnwrappedGzip) { check_positions(file("c.dump.gz"), false); }

TEST_F(DumpVsLammps, WrappedWithImageFlags) { check_positions(file("d.dump"), true); }

TEST_F(DumpVsLammps, DumpAtomStyle) { check_positions(file("e.dump"), true); }

TEST_F(DumpVsLammps, SequentialFramesMatchWrappedPositionsToo) {
  // d.dump has wrapped x and image flags: x − H·image must give LAMMPS's own x.
  DumpReader dump(file("d.dump"));
  for (std::size_t n = 0; n < dump.nframes(); ++n) {
    const Atoms a = dump.frame(n);
    const Eigen::Matrix3d H = a.box.h();
    std::vector<double> wrapped(a.x.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Eigen::Vector3d m(a.image[3 * i], a.image[3 * i + 1], a.image[3 * i + 2]);
      const Eigen::Vector3d w = Eigen::Vector3d(a.x[3 * i], a.x[3 * i + 1], a.x[3 * i + 2]) - H * m;
      for (int k = 0; k < 3; ++k) wrapped[3 * i + static_cast<std::size_t>(k)] = w[k];
    }
    // Same bound as above: 15 digits plus the unwrap/rewrap round-off.
    EXPECT_TRUE(all_close(wrapped, (*refs_)[n].x_wrapped, {1e-12 * box_scale((*refs_)[n].box), 0}));
  }
}

// ---- data files (write_data) ---------------------------------------------

struct DataRef {
  Lammps::BoxData box;
  std::vector<double> x_unwrapped, v, q, type_mass;
  std::vector<int> image, type, mol;
  std::vector<std::tuple<int, std::int64_t, std::int64_t>> bonds;
};

DataRef data_snapshot(const Lammps& lmp, bool molecular, bool charged) {
  DataRef r;
  r.box = lmp.box();
  r.x_unwrapped = lmp.unwrapped_positions();
  r.v = lmp.gather_double("v", 3);
  r.image = lmp.gather_int("image", 3);
  r.type = lmp.gather_int("type", 1);
  if (molecular) r.mol = lmp.gather_int("molecule", 1);
  if (charged) r.q = lmp.gather_double("q", 1);
  const int ntypes = lammps_extract_setting(lmp.handle(), "ntypes");
  const double* mass = static_cast<double*>(lammps_extract_atom(lmp.handle(), "mass"));
  r.type_mass.assign(mass + 1, mass + 1 + ntypes);
  if (molecular) {
    const auto nbonds = static_cast<std::size_t>(
        *static_cast<std::int64_t*>(lammps_extract_global(lmp.handle(), "nbonds")));
    if (lammps_extract_setting(lmp.handle(), "tagint") == 4) {
      std::vector<int> b(3 * nbonds);
      lammps_gather_bonds(lmp.handle(), b.data());
      for (std::size_t k = 0; k < nbonds; ++k)
        r.bonds.emplace_back(b[3 * k], b[3 * k + 1], b[3 * k + 2]);
    } else {
      std::vector<std::int64_t> b(3 * nbonds);
      lammps_gather_bonds(lmp.handle(), b.data());
      for (std::size_t k = 0; k < nbonds; ++k)
        r.bonds.emplace_back(static_cast<int>(b[3 * k]), b[3 * k + 1], b[3 * k + 2]);
    }
    std::sort(r.bonds.begin(), r.bonds.end());
  }
  return r;
}

void expect_data_matches(const DataFile& df, const DataRef& ref) {
  const Atoms& a = df.atoms;
  expect_box(a.box, ref.box);
  ASSERT_EQ(a.size(), ref.type.size());
  EXPECT_EQ(a.id, one_to_n(a.size()));
  EXPECT_EQ(a.type, ref.type);
  EXPECT_EQ(a.image, ref.image);
  // write_data prints 17 significant digits (exact round trip); the bound covers
  // only the unwrap x + H·image, a few ulps of L.
  EXPECT_TRUE(all_close(a.x, ref.x_unwrapped, {1e-13 * box_scale(ref.box), 0.0}));
  // 17 digits round-trip exactly; 1e-15 allows one ulp should LAMMPS format differently.
  EXPECT_TRUE(all_close(a.v, ref.v, {0.0, 1e-15}));
  ASSERT_EQ(a.type_mass.size(), ref.type_mass.size() + 1);
  for (std::size_t t = 0; t < ref.type_mass.size(); ++t)
    EXPECT_DOUBLE_EQ(a.type_mass[t + 1], ref.type_mass[t]);
  if (!ref.mol.empty()) {
    ASSERT_EQ(a.molecule.size(), ref.mol.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.molecule[i], ref.mol[i]);
  }
  if (!ref.q.empty()) {
    EXPECT_TRUE(all_close(a.charge, ref.q, {0.0, 1e-15}));  // as for v
  }
  std::vector<std::tuple<int, std::int64_t, std::int64_t>> bonds;
  for (const auto& b : a.bonds) bonds.emplace_back(b.type, b.atom1, b.atom2);
  std::sort(bonds.begin(), bonds.end());
  EXPECT_EQ(bonds, ref.bonds);
}

TEST(DataFileVsLammps, AtomicTriclinic) {
  ScratchDir dir("data_atomic");
  Lammps lmp;
  lmp.run(R"(
units lj
atom_style atomic
atom_modify map array
lattice fcc 0.8442
region box prism 0 3 0 3 0 4 1.0 -0.7 0.4 units lattice
create_box 3 box
create_atoms 1 box
set type 1 type/fraction 2 0.3 12345
set type 1 type/fraction 3 0.2 54321
mass 1 1.0
mass 2 2.5
mass 3 0.75
velocity all create 2.0 4711 loop geom
displace_atoms all random 0.6 0.6 0.6 4242 units box
)");
  lmp.run("write_data " + dir / "atomic.data");
  const DataRef ref = data_snapshot(lmp, false, false);
  const auto crossed = std::count_if(ref.image.begin(), ref.image.end(), [](int m) { return m; });
  EXPECT_GT(crossed, 5);  // the displacement pushed atoms across boundaries
  const DataFile df = read_data(dir / "atomic.data");
  EXPECT_EQ(df.style, AtomStyle::atomic);
  EXPECT_EQ(df.atoms.ntypes, 3);
  EXPECT_EQ(df.counts.at("atoms"), static_cast<std::int64_t>(ref.type.size()));
  expect_data_matches(df, ref);
}

class MolecularDataVsLammps : public ::testing::TestWithParam<std::string> {};

TEST_P(MolecularDataVsLammps, BondsChargesMolecules) {
  const std::string style = GetParam();
  const bool charged = style == "full";
  ScratchDir dir("data_" + style);
  Lammps lmp;
  // A simple-cubic lattice (spacing 1) in a box tilted by whole lattice
  // vectors, bonds between nearest neighbours, then random displacements that
  // move atoms across the periodic boundaries.
  lmp.run("units lj\natom_style " + style + R"(
atom_modify map array
lattice sc 1.0
region box prism 0 4 0 4 0 4 1 0 -1 units lattice
create_box 2 box bond/types 2 extra/bond/per/atom 8 extra/special/per/atom 12
create_atoms 1 box
set type 1 type/fraction 2 0.5 777
set atom 1*32 mol 1
set atom 33*64 mol 2
mass 1 1.0
mass 2 3.0
pair_style lj/cut 1.5
pair_coeff * * 1.0 1.0
bond_style harmonic
bond_coeff * 100.0 1.0
create_bonds many all all 1 0.99 1.01
create_bonds single/bond 2 1 64
velocity all create 1.0 99 loop geom
displace_atoms all random 0.45 0.45 0.45 4242 units box
)");
  if (charged) lmp.run("set type 1 charge 0.25\nset type 2 charge -0.5");
  lmp.run("write_data " + dir / "mol.data");
  const DataRef ref = data_snapshot(lmp, true, charged);
  EXPECT_GT(ref.bonds.size(), 150u);  // 3 per atom on a periodic sc lattice, plus one
  const DataFile df = read_data(dir / "mol.data");
  EXPECT_EQ(to_string(df.style), style);
  expect_data_matches(df, ref);

  // Without the "Atoms # style" comment: full (10 columns with image flags) is
  // inferred; bond (9 columns) is ambiguous with charge and needs the hint.
  std::ifstream in(dir / "mol.data");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  const auto pos = text.find("Atoms # " + style);
  ASSERT_NE(pos, std::string::npos);
  text.replace(pos, 8 + style.size(), "Atoms");
  std::ofstream(dir / "plain.data") << text;
  if (charged) {
    expect_data_matches(read_data(dir / "plain.data"), ref);
  } else {
    try {
      (void)read_data(dir / "plain.data");
      ADD_FAILURE() << "expected an ambiguity error";
    } catch (const pdcg::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cannot tell the atom style"), std::string::npos)
          << e.what();
      EXPECT_GT(e.line_number(), 0);
    }
    expect_data_matches(read_data(dir / "plain.data", AtomStyle::bond), ref);
  }
}

INSTANTIATE_TEST_SUITE_P(Styles, MolecularDataVsLammps, ::testing::Values("full", "bond"));

}  // namespace

#endif  // PDCG_WITH_LAMMPS

#if PDCG_WITH_LAMMPS
namespace {

// Non-periodic, shrink-wrapped z (`boundary p p s`): the box changes from frame to
// frame and z must come out non-periodic; xy tilt (allowed with periodic y).
TEST(DumpVsLammpsBoundaries, ShrinkWrappedAndPeriodicFlags) {
  ScratchDir dir("dump_pps");
  Lammps lmp;
  lmp.run(R"(
units lj
atom_style atomic
atom_modify map array
boundary p p s
lattice fcc 0.8442
region box prism 0 4 0 4 0 4 1.0 0.0 0.0 units lattice
create_box 1 box
create_atoms 1 box
mass 1 1.0
velocity all create 3.0 5151 loop geom
pair_style lj/cut 2.5
pair_coeff * * 1.0 1.0
neighbor 0.3 bin
neigh_modify every 1 delay 0 check no
timestep 0.005
fix 1 all nve
)");
  lmp.run("dump A all custom 10 " + dir / "pps.dump" +
          " id type x y z ix iy iz\ndump_modify A format float %20.15g");
  std::vector<Reference> refs;
  lmp.run("run 0");
  refs.push_back(snapshot(lmp, 0));
  for (int k = 1; k <= 2; ++k) {
    lmp.run("run 10");
    refs.push_back(snapshot(lmp, 10 * k));
  }
  lmp.run("undump A");
  EXPECT_NE(refs.front().box.hi.z(), refs.back().box.hi.z());  // the box did shrink-wrap
  DumpReader dump(dir / "pps.dump");
  ASSERT_EQ(dump.nframes(), refs.size());
  for (std::size_t n = 0; n < refs.size(); ++n) {
    SCOPED_TRACE("frame " + std::to_string(n));
    const Atoms a = dump.frame(n);
    expect_box(a.box, refs[n].box);  // includes periodic = (p, p, non-periodic)
    EXPECT_FALSE(a.box.periodic[2]);
    EXPECT_EQ(a.image, refs[n].image);
    // Same bound and reason as the periodic test above.
    EXPECT_TRUE(all_close(a.x, refs[n].x_unwrapped, {1e-12 * box_scale(refs[n].box), 0.0}));
  }
}

}  // namespace
#endif  // PDCG_WITH_LAMMPS
