// Reading LAMMPS potential commands: syntax (comments, continuation, full decks) and the
// bad-input errors, each naming the file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"

using namespace pdcg::atomistic;

namespace {

/// Runs f, expects an InputError, returns it for inspection.
template <class F>
pdcg::InputError input_error(F&& f) {
  try {
    f();
  } catch (const pdcg::InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError thrown";
  return pdcg::InputError("none");
}

std::string write_tmp(const std::string& name, const std::string& text) {
  const auto p = std::filesystem::temp_directory_path() / name;
  std::ofstream(p) << text;
  return p.string();
}

}  // namespace

TEST(PotentialFile, FullDeckKeepsPotentialCommandsOnly) {
  const std::string deck = R"(# a full LAMMPS input deck
units        metal
atom_style   atomic
boundary     p p p
lattice      fcc 3.615
region       box block 0 4 0 4 0 4
create_box   2 box
create_atoms 1 box
mass 1 63.546   # Cu
mass 2 107.87
pair_style   lj/cut &
             5.0
pair_coeff   * * 0.4 2.3
pair_coeff   2 1 0.3 2.4 4.5    # swapped to 1 2 as LAMMPS does
pair_modify  shift yes
velocity     all create 300 4928459
fix          1 all nve
run          1000
)";
  const auto path = write_tmp("pdcg_deck.in", deck);
  const PotentialSpec s = read_potential_commands(path);
  EXPECT_EQ(s.units, pdcg::UnitStyle::metal);
  EXPECT_EQ(s.ntypes, 2);  // from create_box
  EXPECT_EQ(s.pair_style, "lj/cut");
  ASSERT_EQ(s.pair_style_args.size(), 1u);
  EXPECT_EQ(s.pair_style_args[0], "5.0");  // continuation joined
  ASSERT_EQ(s.pair_coeff.size(), 2u);
  EXPECT_EQ(s.pair_coeff[1].i, "1");
  EXPECT_EQ(s.pair_coeff[1].j, "2");
  EXPECT_EQ(s.pair_coeff[1].line_number, 14);
  EXPECT_EQ(s.type_mass[1], 63.546);
  EXPECT_EQ(s.type_mass[2], 107.87);
  EXPECT_EQ(s.lines.size(), 8u);  // units atom_style mass×2 pair_style pair_coeff×2 pair_modify
  EXPECT_EQ(s.pair_modify, (std::vector<std::string>{"shift", "yes"}));
  EXPECT_EQ(make_potential(s)->cutoff(), 5.0);
}

TEST(PotentialFile, SpecialBondsKeywordsAndDefaults) {
  auto s = read_potential_commands_from_string("special_bonds fene\n", "x", 1);
  EXPECT_EQ(s.special_lj, (std::array<double, 3>{0, 1, 1}));
  s = read_potential_commands_from_string("special_bonds lj 0 1 1\n", "x", 1);
  EXPECT_EQ(s.special_lj, (std::array<double, 3>{0, 1, 1}));
  EXPECT_EQ(s.special_coul, (std::array<double, 3>{0, 0, 0}));
  s = read_potential_commands_from_string("special_bonds lj/coul 0.0 0.5 1.0\n", "x", 1);
  EXPECT_EQ(s.special_coul, (std::array<double, 3>{0, 0.5, 1}));
  // each special_bonds command starts from the defaults (LAMMPS Force::set_special)
  s = read_potential_commands_from_string("special_bonds lj 1 1 1\nspecial_bonds coul 0 1 1\n", "x",
                                          1);
  EXPECT_EQ(s.special_lj, (std::array<double, 3>{0, 0, 0}));
  const auto e = input_error(
      [] { read_potential_commands_from_string("special_bonds lj 0 1\n", "sb.in", 1); });
  EXPECT_EQ(e.line_number(), 1);
  const auto e2 = input_error(
      [] { read_potential_commands_from_string("\nspecial_bonds banana\n", "sb.in", 1); });
  EXPECT_EQ(e2.line_number(), 2);
  EXPECT_EQ(e2.bad_value(), "banana");
}

TEST(PotentialFile, UnknownAtomTypeInPairCoeff) {
  const std::string text =
      "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\npair_coeff 1 3 1.0 1.0\n";
  const auto e = input_error([&] { read_potential_commands_from_string(text, "types.in", 2); });
  EXPECT_EQ(e.source_name(), "types.in");
  EXPECT_EQ(e.line_number(), 3);
  EXPECT_EQ(e.key_name(), "pair_coeff");
  EXPECT_EQ(e.bad_value(), "3");
  EXPECT_NE(std::string(e.what()).find("1..2"), std::string::npos) << e.what();
  // the same check when the type count becomes known later (data file read afterwards)
  PotentialSpec s = read_potential_commands_from_string(text, "types.in");
  EXPECT_EQ(s.ntypes, 3);
  const auto e2 = input_error([&] { check_atom_types(s, 2); });
  EXPECT_EQ(e2.line_number(), 3);
}

TEST(PotentialFile, MalformedNumber) {
  const std::string text = "pair_style lj/cut 2.5\npair_coeff 1 1 1.0x 1.0\n";
  const auto s = read_potential_commands_from_string(text, "num.in");
  const auto e = input_error([&] { make_potential(s); });
  EXPECT_EQ(e.line_number(), 2);
  EXPECT_EQ(e.bad_value(), "1.0x");
  const auto e2 =
      input_error([] { read_potential_commands_from_string("mass 1 abc\n", "num.in"); });
  EXPECT_EQ(e2.line_number(), 1);
  EXPECT_EQ(e2.bad_value(), "abc");
  const auto e3 = input_error([] {
    make_potential(read_potential_commands_from_string(
        "pair_style lj/cut nan\npair_coeff 1 1 1 1\n", "num.in"));
  });
  EXPECT_EQ(e3.line_number(), 1);
}

TEST(PotentialFile, MissingPotentialFile) {
  const std::string text =
      "units metal\npair_style eam/alloy\npair_coeff * * NoSuchFile.eam.alloy Cu\n";
  const auto e = input_error([&] { read_potential_commands_from_string(text, "eam.in"); });
  EXPECT_EQ(e.source_name(), "eam.in");
  EXPECT_EQ(e.line_number(), 3);
  EXPECT_EQ(e.bad_value(), "NoSuchFile.eam.alloy");
}

TEST(PotentialFile, PotentialFilesFoundByNameInLammpsDirectory) {
  // by name: found in $LAMMPS_POTENTIALS or the LAMMPS potentials directory (the file says
  // UNITS: metal, which LAMMPS requires)
  const auto s = read_potential_commands_from_string(
      "units metal\npair_style eam/alloy\npair_coeff * * Cu_mishin1.eam.alloy Cu\n", "x");
  EXPECT_EQ(s.ntypes, 1);
  EXPECT_TRUE(find_potential_file("Cu_mishin1.eam.alloy").has_value());
  EXPECT_FALSE(find_potential_file("surely/not/here.eam").has_value());
}

TEST(PotentialFile, UnsupportedStyleWithoutLammps) {
  const std::string text =
      "units metal\npair_style tersoff/mod\npair_coeff * * Si.tersoff.mod Si\n";
  const auto s = read_potential_commands_from_string(text, "si.in");
  const auto e = input_error([&] { require_supported_styles(s, /*lammps_enabled=*/false); });
  EXPECT_EQ(e.line_number(), 2);
  EXPECT_EQ(e.bad_value(), "tersoff/mod");
  EXPECT_NO_THROW(require_supported_styles(s, true));
  // native styles need no LAMMPS
  EXPECT_NO_THROW(require_supported_styles(
      read_potential_commands_from_string("pair_style morse 3\n", "x"), false));
  for (const char* native : {"units metal\npair_style tersoff\npair_coeff * * Si.tersoff Si\n",
                             "units metal\npair_style sw\npair_coeff * * Si.sw Si\n"})
    EXPECT_NO_THROW(
        require_supported_styles(read_potential_commands_from_string(native, "x"), false));
    // non-native styles: force states through embedded LAMMPS when it is built in
#if !PDCG_WITH_LAMMPS
  EXPECT_THROW(make_potential(s), pdcg::InputError);
#endif
}

TEST(PotentialFile, TypeRanges) {
  int lo, hi;
  parse_type_range("*", 4, lo, hi, "x", 1, "c");
  EXPECT_EQ(lo, 1);
  EXPECT_EQ(hi, 4);
  parse_type_range("2*", 4, lo, hi, "x", 1, "c");
  EXPECT_EQ(lo, 2);
  parse_type_range("*3", 4, lo, hi, "x", 1, "c");
  EXPECT_EQ(hi, 3);
  EXPECT_THROW(parse_type_range("0", 4, lo, hi, "x", 1, "c"), pdcg::InputError);
  EXPECT_THROW(parse_type_range("2*5", 4, lo, hi, "x", 1, "c"), pdcg::InputError);
  EXPECT_THROW(parse_type_range("a", 4, lo, hi, "x", 1, "c"), pdcg::InputError);
}

TEST(PotentialFile, VariablesAreRejectedWithAClearMessage) {
  const auto e = input_error(
      [] { read_potential_commands_from_string("pair_style lj/cut ${rc}\n", "v.in", 1); });
  EXPECT_EQ(e.line_number(), 1);
  EXPECT_EQ(e.key_name(), "pair_style");
  // variables elsewhere in a deck do not matter
  EXPECT_NO_THROW(read_potential_commands_from_string(
      "variable t equal 300\nvelocity all create ${t} 1\npair_style zero 2\npair_coeff * *\n",
      "v.in", 1));
}

TEST(PotentialFile, CommentsQuotesAndContinuation) {
  const auto s = read_potential_commands_from_string(
      "pair_style lj/cut 2.5 # comment & not a continuation\n"
      "pair_coeff 1 1 &\n  1.0 &\n  1.0 # trailing\n",
      "c.in");
  ASSERT_EQ(s.pair_coeff.size(), 1u);
  EXPECT_EQ(s.pair_coeff[0].args, (std::vector<std::string>{"1.0", "1.0"}));
  EXPECT_EQ(s.pair_coeff[0].line_number, 2);
  EXPECT_EQ(s.pair_style_args, (std::vector<std::string>{"2.5"}));
}

TEST(PotentialFile, WildcardMassesWaitForTheTypeCount) {
  PotentialSpec s =
      read_potential_commands_from_string("mass * 2.0\nmass 2 3.0\npair_style zero 2\n", "m.in");
  EXPECT_EQ(s.ntypes, 2);  // from the explicit type
  EXPECT_EQ(s.type_mass[1], 2.0);
  EXPECT_EQ(s.type_mass[2], 3.0);
  s = read_potential_commands_from_string("mass * 2.0\npair_style zero 2\npair_coeff * *\n",
                                          "m.in");
  EXPECT_EQ(s.ntypes, 0);  // unknown until the configuration is read
  check_atom_types(s, 3);
  ASSERT_EQ(s.type_mass.size(), 4u);
  EXPECT_EQ(s.type_mass[3], 2.0);
  PotentialSpec t = read_potential_commands_from_string("mass 3 1.0\n", "m.in");
  EXPECT_THROW(check_atom_types(t, 2), pdcg::InputError);
}

// `boundary` as LAMMPS's Domain::set_boundary reads it: p periodic (on both sides), f, s, m
// and lo/hi pairs non-periodic; kept as the configuration's periodicity, not replayed.
TEST(PotentialFile, BoundaryCommand) {
  auto s = read_potential_commands_from_string(
      "units lj\nboundary p fs m\npair_style lj/cut 2.5\npair_coeff * * 1 1\n", "b.in", 1);
  ASSERT_TRUE(s.periodic.has_value());
  EXPECT_EQ(*s.periodic, (std::array<bool, 3>{true, false, false}));
  EXPECT_EQ(s.boundary, "p fs m");
  EXPECT_EQ(s.boundary_line, 2);
  for (const auto& l : s.lines) EXPECT_EQ(l.find("boundary"), std::string::npos) << l;
  // a full deck: the last boundary before read_data
  s = read_potential_commands_from_string(
      "units lj\nboundary s s s\nread_data x.data\npair_style lj/cut 2.5\npair_coeff * * 1 1\n",
      "deck.in", 1);
  EXPECT_EQ(*s.periodic, (std::array<bool, 3>{false, false, false}));
  // none: unknown (LAMMPS's default p p p is decided by the caller)
  s = read_potential_commands_from_string("pair_style lj/cut 2.5\npair_coeff * * 1 1\n", "x", 1);
  EXPECT_FALSE(s.periodic.has_value());
  for (const char* bad : {"boundary p p\n", "boundary p p x\n", "boundary pf p p\n",
                          "boundary fp p p\n", "boundary ppp p p\n"}) {
    const auto e =
        input_error([&] { (void)read_potential_commands_from_string(bad, "bad.in", 1); });
    EXPECT_EQ(e.line_number(), 1) << bad;
    EXPECT_NE(std::string(e.what()).find("boundary"), std::string::npos) << e.what();
  }
  EXPECT_EQ(parse_boundary("p p f", "--boundary", 0, "--boundary"),
            (std::array<bool, 3>{true, true, false}));
  EXPECT_THROW((void)parse_boundary("p p", "--boundary", 0, "--boundary"), pdcg::InputError);
}

// Units of potential files as LAMMPS's utils::open_potential: Debian's EAM files say
// `UNITS: metal`; lj (also LAMMPS's default without `units`) and si are refused, real is
// converted; files without a tag are used as they are.
TEST(PotentialFile, PotentialFileUnitsAsLammps) {
  const auto cu = find_potential_file("Cu_u3.eam");
  ASSERT_TRUE(cu.has_value());
  EXPECT_EQ(potential_file_units(*cu), "metal");
  EXPECT_EQ(potential_file_units(*find_potential_file("CuNi.eam.alloy")), "metal");
  auto e = input_error([&] {
    (void)read_potential_commands_from_string("pair_style eam\npair_coeff 1 1 Cu_u3.eam\n",
                                              "nounits.in", 1);
  });
  EXPECT_EQ(e.line_number(), 2);
  EXPECT_NE(std::string(e.what()).find("requires metal units but lj units are in use"),
            std::string::npos)
      << e.what();
  EXPECT_NE(std::string(e.what()).find("add `units metal` to nounits.in"), std::string::npos)
      << e.what();
  e = input_error([&] {
    (void)read_potential_commands_from_string(
        "units si\npair_style eam/fs\npair_coeff * * Fe_mm.eam.fs Fe\n", "si.in", 1);
  });
  EXPECT_NE(std::string(e.what()).find("change line 1 of si.in to `units metal`"),
            std::string::npos)
      << e.what();
  // any style, not only EAM: LAMMPS converts only between metal and real
  e = input_error([&] {
    (void)read_potential_commands_from_string(
        "units lj\npair_style tersoff\npair_coeff * * Si.tersoff Si\n", "t.in", 1);
  });
  EXPECT_NE(std::string(e.what()).find("Si.tersoff (UNITS: metal)"), std::string::npos) << e.what();
  for (const char* u : {"metal", "real"})
    EXPECT_NO_THROW((void)read_potential_commands_from_string(
        std::string("units ") + u + "\npair_style eam/alloy\npair_coeff * * CuNi.eam.alloy Cu Ni\n",
        "ok.in", 2))
        << u;
  // no tag: used as it is (LAMMPS does the same), in any units
  const std::string untagged = write_tmp("pdcg_untagged.eam", "a funcfl file without tags\n");
  EXPECT_EQ(potential_file_units(untagged), "");
  EXPECT_NO_THROW((void)read_potential_commands_from_string(
      "pair_style eam\npair_coeff 1 1 " + untagged + "\n", "untagged.in", 1));
  std::filesystem::remove(untagged);
}

// A molecular deck's angle, dihedral and improper terms would be silently missing from every
// energy and force of a body made of pair and bond families: refused at their line.
TEST(PotentialFile, AngleDihedralImproperStylesAreRefused) {
  for (const std::string cmd : {"angle_style", "dihedral_style", "improper_style"}) {
    const std::string deck = "units real\npair_style lj/cut 10.0\npair_coeff * * 0.1 3.0\n" + cmd +
                             " harmonic\nbond_style harmonic\n";
    const auto e = input_error([&] { read_potential_commands_from_string(deck, "mol.in", 1); });
    EXPECT_EQ(e.line_number(), 4) << cmd;
    EXPECT_EQ(e.key_name(), cmd);
    EXPECT_NE(std::string(e.what()).find("not supported"), std::string::npos) << e.what();
    // `none` and `zero` add no energy: accepted
    EXPECT_NO_THROW(read_potential_commands_from_string(
        "pair_style lj/cut 10.0\npair_coeff * * 0.1 3.0\n" + cmd + " none\n", "mol.in", 1))
        << cmd;
  }
}
