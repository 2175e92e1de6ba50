// Native Stillinger–Weber and Tersoff against embedded LAMMPS (PairSW / PairTersoff run on the
// same atoms at test time): per-atom energies ψ_k against compute pe/atom, PD forces
// Σ_j (t_kj − t_jk) against LAMMPS's forces, on perturbed, triclinic and free-surface cells of
// diamond Si and zincblende SiC with Debian's parameter files; the analytic tangent against
// central differences of force_state; and the parameter-file errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg_test.hpp"
#include "potential_test_util.hpp"
#include "scratch_dir.hpp"

using namespace pdcg::atomistic;
using pdcg::test::diamond;
using pdcg::test::make_triclinic;
using pdcg::test::max_norm_relative_error;
using pdcg::test::slab;

namespace {

struct Errors {
  double energy = 0, force = 0;
};

/// ψ_k and PD forces of the native potential against embedded LAMMPS on `atoms`.
Errors compare(const std::string& commands, const Atoms& atoms, double family_margin = 1.1) {
  const int ntypes = *std::max_element(atoms.type.begin(), atoms.type.end());
  const PotentialSpec spec = read_potential_commands_from_string(commands, "manybody", ntypes);
  const auto pot = make_potential(spec);
  EXPECT_FALSE(pot->style().empty());
  const auto pd = pdcg::test::pd_evaluate(*pot, atoms, family_margin);
  Errors e;
#if PDCG_WITH_LAMMPS
  const LammpsResult ref = LammpsEngine(spec).evaluate(atoms);
  double fmax = 0;
  for (double v : ref.force) fmax = std::max(fmax, std::abs(v));
  EXPECT_GT(fmax, 0.1) << "configuration must be strained for a meaningful force test";
  e.energy = max_norm_relative_error(pd.psi, ref.energy);
  e.force = max_norm_relative_error(pd.force, ref.force);
  std::printf("  [%s] %zu atoms: pe/atom error %.2e, force error %.2e (|f|max %.3g, U %.12g)\n",
              pot->style().c_str(), atoms.size(), e.energy, e.force, fmax, ref.total_energy);
  // same double-precision formulas, different summation order: round-off (the task's 1e-10)
  EXPECT_LT(e.energy, 1e-10) << commands;
  EXPECT_LT(e.force, 1e-10) << commands;
  EXPECT_NEAR(pd.total, ref.total_energy, 1e-10 * std::abs(ref.total_energy));
#else
  ADD_FAILURE() << "embedded LAMMPS not enabled: no reference";
#endif
  double s[3] = {0, 0, 0}, fm = 0;
  for (std::size_t i = 0; i < atoms.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      s[k] += pd.force[3 * i + static_cast<std::size_t>(k)];
      fm = std::max(fm, std::abs(pd.force[3 * i + static_cast<std::size_t>(k)]));
    }
  for (double v : s)  // Σ f = 0: round-off of N terms
    EXPECT_LT(std::abs(v), 1e-11 * fm * static_cast<double>(atoms.size()));
  return e;
}

const std::string kSw = "units metal\npair_style sw\npair_coeff * * Si.sw Si\n";
const std::string kTersoffSi = "units metal\npair_style tersoff\npair_coeff * * Si.tersoff Si\n";
const std::string kTersoffSiC =
    "units metal\npair_style tersoff\npair_coeff * * SiC.tersoff Si C\n";

}  // namespace

// ---------------------------------------------------------------------------------------
// Stillinger–Weber

TEST(NativeStillingerWeber, PerturbedDiamondSi) {
  compare(kSw, diamond(3, 3, 3, 5.431, 0.1, false, 1));
}

TEST(NativeStillingerWeber, TriclinicDiamondSi) {
  Atoms a = diamond(3, 3, 3, 5.431, 0.1, false, 2);
  make_triclinic(a, 2.1, -1.4, 1.2);
  compare(kSw, a);
}

TEST(NativeStillingerWeber, FreeSurfacesSlabAndCluster) {
  compare(kSw, slab(diamond(3, 3, 3, 5.431, 0.1, false, 3)));
  compare(kSw, pdcg::test::cluster(diamond(4, 4, 4, 5.431, 0.1, false, 4), 7.0));
}

TEST(NativeStillingerWeber, SmallPeriodicBoxImagesArePartners) {
  // 2×2×2 cells: 10.9 Å < 2 × 7.54 Å, families hold several images of one atom
  compare(kSw, diamond(2, 2, 2, 5.431, 0.1, false, 5));
}

TEST(NativeStillingerWeber, CompressedAndStretched) {
  // more partners within r_c (compressed) and bonds near the cutoff (stretched)
  compare(kSw, diamond(3, 3, 3, 5.0, 0.15, false, 6));
  compare(kSw, diamond(3, 3, 3, 6.2, 0.15, false, 7));
}

TEST(NativeStillingerWeber, TwoElementFileGaN) {
  // GaN.sw: two elements, all 8 triples, different two-body cutoffs per pair
  compare("units metal\npair_style sw\npair_coeff * * GaN.sw Ga N\n",
          diamond(3, 3, 3, 4.5, 0.1, true, 8));
  // three types, two of them the same element
  Atoms a = diamond(3, 3, 3, 4.5, 0.1, true, 9);
  for (std::size_t i = 0; i < a.size(); i += 3) a.type[i] = a.type[i] == 1 ? 3 : a.type[i];
  compare("units metal\npair_style sw\npair_coeff * * GaN.sw Ga N Ga\n", a);
}

TEST(NativeStillingerWeber, RealUnitsConvertTheEnergy) {
  // LAMMPS converts a metal-units file to real units (factor 23.060549)
  compare("units real\npair_style sw\npair_coeff * * Si.sw Si\n",
          diamond(2, 2, 2, 5.431, 0.1, false, 10));
}

TEST(NativeStillingerWeber, ThreebodyOffIsTheTwoBodyPart) {
  // LAMMPS ≥ 2023's `threebody off`; Debian's LAMMPS has no keyword: the reference is sw with
  // a file whose λ = 0 (no three-body energy), which Debian's LAMMPS evaluates.
  pdcg::test::ScratchDir dir("sw3b");
  {
    std::ifstream in(*find_potential_file("Si.sw"));
    std::ofstream out(dir / "Si0.sw");
    std::string line;
    while (std::getline(in, line)) {
      const auto p = line.find("21.0  1.20");
      if (p != std::string::npos) line.replace(p, 10, "0.0  1.20");
      out << line << '\n';
    }
  }
  const Atoms at = diamond(2, 2, 2, 5.431, 0.1, false, 11);
  const auto off = make_potential(read_potential_commands_from_string(
      "units metal\npair_style sw threebody off\npair_coeff * * Si.sw Si\n", "off", 1));
  EXPECT_TRUE(off->pairwise());
  EXPECT_NEAR(off->cutoff(), 2.0951 * 1.80, 1e-12);  // a σ, one cutoff (no three-body reach)
  const auto pd = pdcg::test::pd_evaluate(*off, at);
  const std::string zero =
      "units metal\npair_style sw\npair_coeff * * " + (dir / "Si0.sw") + " Si\n";
  const Errors e = compare(zero, at);
  (void)e;
#if PDCG_WITH_LAMMPS
  const LammpsResult ref =
      LammpsEngine(read_potential_commands_from_string(zero, "zero", 1)).evaluate(at);
  EXPECT_LT(max_norm_relative_error(pd.psi, ref.energy), 1e-10);
  EXPECT_LT(max_norm_relative_error(pd.force, ref.force), 1e-10);
#endif
  // `threebody on` is the default
  const auto on = make_potential(read_potential_commands_from_string(
      "units metal\npair_style sw threebody on\npair_coeff * * Si.sw Si\n", "on", 1));
  EXPECT_FALSE(on->pairwise());
  EXPECT_NEAR(on->cutoff(), 2.0 * 2.0951 * 1.80, 1e-12);
}

// ---------------------------------------------------------------------------------------
// Tersoff

TEST(NativeTersoff, PerturbedDiamondSi) {
  compare(kTersoffSi, diamond(3, 3, 3, 5.431, 0.1, false, 21));
}

TEST(NativeTersoff, TriclinicDiamondSi) {
  Atoms a = diamond(3, 3, 3, 5.431, 0.1, false, 22);
  make_triclinic(a, -1.9, 1.3, 0.8);
  compare(kTersoffSi, a);
}

TEST(NativeTersoff, FreeSurfacesSlabAndCluster) {
  compare(kTersoffSi, slab(diamond(3, 3, 3, 5.431, 0.1, false, 23)));
  compare(kTersoffSi, pdcg::test::cluster(diamond(4, 4, 4, 5.431, 0.1, false, 24), 7.0));
}

TEST(NativeTersoff, CompressedSiHasManyBondOrderPartners) {
  compare(kTersoffSi, diamond(2, 2, 2, 4.6, 0.15, false, 25));
}

TEST(NativeTersoff, ZincblendeSiCTwoTypes) {
  // SiC.tersoff: 8 triples, cutoffs per triple (R = 1.95 / 2.36 / 2.85), b_ij from (i, j, j)
  Atoms a = diamond(3, 3, 3, 4.36, 0.1, true, 26);
  compare(kTersoffSiC, a);
  make_triclinic(a, 1.1, 0.7, -0.9);
  compare(kTersoffSiC, a);
  compare(kTersoffSiC, slab(diamond(3, 3, 3, 4.36, 0.1, true, 27)));
}

TEST(NativeTersoff, OtherFilesAndRepeatedElements) {
  // SiCGe.tersoff: elements Si(B), Si(C), Si(D), C, Ge with the mixed triples of Si(D)–C and
  // Si(D)–Ge only (LAMMPS refuses Si(D) C Ge: "missing an entry"); three types Ge Si(D) Ge
  Atoms a = diamond(3, 3, 3, 5.5, 0.1, true, 28);
  for (std::size_t i = 0; i < a.size(); i += 4) a.type[i] = 3;
  compare("units metal\npair_style tersoff\npair_coeff * * SiCGe.tersoff Ge Si(D) Ge\n", a);
  // BNC.tersoff (B, N, C) mapped B N B on a compressed zincblende cell
  Atoms b = diamond(3, 3, 3, 3.62, 0.08, true, 29);
  for (std::size_t i = 0; i < b.size(); i += 5) b.type[i] = 3;
  compare("units metal\npair_style tersoff\npair_coeff * * BNC.tersoff B N B\n", b);
  // m = 1 (ζ's exponent linear in r_ij − r_ik): GaN.tersoff
  compare("units metal\npair_style tersoff\npair_coeff * * GaN.tersoff Ga N\n",
          diamond(3, 3, 3, 4.5, 0.1, true, 32));
}

TEST(NativeTersoff, ShiftKeyword) {
  for (const char* delta : {"0.05", "-0.04"}) {
    const std::string cmds = std::string("units metal\npair_style tersoff shift ") + delta +
                             "\npair_coeff * * Si.tersoff Si\n";
    compare(cmds, diamond(3, 3, 3, 5.431, 0.1, false, 30));
  }
}

TEST(NativeTersoff, FamiliesWiderThanTheCutoffCarryNothingExtra) {
  // the family radius 2 r_c is enough: a 1.5× wider family gives the same result
  compare(kTersoffSiC, diamond(3, 3, 3, 4.36, 0.1, true, 31), 1.5);
}

// ---------------------------------------------------------------------------------------
// Analytic tangent against central differences of force_state (Potential's default)

namespace {
/// Richardson-extrapolated central differences of force_state, step h and h/2: truncation
/// O(h⁴) ≈ 1e-15 of the entries at h = 1e-4 Å, round-off O(ε |t| / h) ≈ 1e-11.
void richardson_tangent(const Potential& pot, const FamilyState& f, double* K, double h) {
  const std::int64_t n = f.size;
  std::vector<double> y(f.bond, f.bond + 3 * n), tp(static_cast<std::size_t>(3 * n)), tm(tp.size()),
      tp2(tp.size()), tm2(tp.size());
  FamilyState g = f;
  g.bond = y.data();
  for (std::int64_t m = 0; m < n; ++m)
    for (int b = 0; b < 3; ++b) {
      const auto idx = static_cast<std::size_t>(3 * m + b);
      y[idx] = f.bond[idx] + h;
      pot.force_state(g, tp.data());
      y[idx] = f.bond[idx] - h;
      pot.force_state(g, tm.data());
      y[idx] = f.bond[idx] + 0.5 * h;
      pot.force_state(g, tp2.data());
      y[idx] = f.bond[idx] - 0.5 * h;
      pot.force_state(g, tm2.data());
      y[idx] = f.bond[idx];
      for (std::int64_t j = 0; j < n; ++j)
        for (int a = 0; a < 3; ++a) {
          const auto q = static_cast<std::size_t>(3 * j + a);
          const double d1 = (tp[q] - tm[q]) / (2.0 * h), d2 = (tp2[q] - tm2[q]) / h;
          K[static_cast<std::size_t>((j * n + m) * 9 + 3 * a + b)] = (4.0 * d2 - d1) / 3.0;
        }
    }
}

enum class Reference { fd_default, richardson };

double tangent_error(const std::string& commands, const Atoms& atoms, Reference ref,
                     int families = 8) {
  const int ntypes = *std::max_element(atoms.type.begin(), atoms.type.end());
  const auto pot = make_potential(read_potential_commands_from_string(commands, "t", ntypes));
  FamilyOptions opt;
  opt.cutoff = pot->cutoff() * 1.05;
  const Families fam = build_families(atoms, opt);
  std::vector<double> Y(3 * fam.bonds());
  deformed_bonds(fam, atoms.x, fam.h, Y);
  double worst = 0.0;
  const std::size_t step = std::max<std::size_t>(1, fam.points() / families);
  for (std::size_t k = 0; k < fam.points(); k += step) {
    const std::int64_t b0 = fam.offset[k], n = fam.offset[k + 1] - b0;
    std::vector<int> nt(static_cast<std::size_t>(n));
    for (std::int64_t b = 0; b < n; ++b)
      nt[static_cast<std::size_t>(b)] =
          atoms.type[static_cast<std::size_t>(fam.neighbor[static_cast<std::size_t>(b0 + b)])];
    FamilyState f;
    f.type = atoms.type[k];
    f.size = n;
    f.neighbor_type = nt.data();
    f.bond = Y.data() + 3 * b0;
    const auto nn = static_cast<std::size_t>(9 * n * n);
    std::vector<double> Ka(nn, -1.0), Kf(nn), work(Potential::tangent_workspace(n));
    pot->force_state_tangent(f, Ka.data(), work.data());
    if (ref == Reference::fd_default)
      pot->Potential::force_state_tangent(f, Kf.data(), work.data());
    else
      richardson_tangent(*pot, f, Kf.data(), 1e-4);
    double scale = 0.0, diff = 0.0, asym = 0.0;
    for (std::int64_t j = 0; j < n; ++j)
      for (std::int64_t m = 0; m < n; ++m)
        for (int a = 0; a < 3; ++a)
          for (int c = 0; c < 3; ++c) {
            const auto i = static_cast<std::size_t>((j * n + m) * 9 + 3 * a + c);
            const auto it = static_cast<std::size_t>((m * n + j) * 9 + 3 * c + a);
            scale = std::max(scale, std::abs(Kf[i]));
            diff = std::max(diff, std::abs(Ka[i] - Kf[i]));
            asym = std::max(asym, std::abs(Ka[i] - Ka[it]));
          }
    EXPECT_GT(scale, 0.0);
    EXPECT_LE(asym, 1e-12 * scale) << "the tangent is a Hessian: symmetric";
    worst = std::max(worst, diff / scale);
  }
  std::printf("  [%s] worst relative tangent difference vs %s %.2e\n", pot->style().c_str(),
              ref == Reference::fd_default ? "Potential's central differences" : "Richardson FD",
              worst);
  if (ref == Reference::fd_default)
    // the default's step s = 6e-6 |Y|: truncation O(s²) and round-off O(ε|t|/s) ≈ 1e-9 of the
    // entries here; 1e-8 is the task's bound
    EXPECT_LT(worst, 1e-8) << commands;
  else
    // measured ≤ 3e-10 (round-off of the four force_state calls at h = 1e-4 Å)
    EXPECT_LT(worst, 2e-9) << commands;
  return worst;
}
}  // namespace

TEST(NativeManyBodyTangent, StillingerWeberSi) {
  for (const auto ref : {Reference::fd_default, Reference::richardson}) {
    tangent_error(kSw, diamond(2, 2, 2, 5.431, 0.1, false, 41), ref);
    tangent_error(kSw, diamond(2, 2, 2, 5.0, 0.15, false, 42), ref);
  }
}

TEST(NativeManyBodyTangent, StillingerWeberGaN) {
  for (const auto ref : {Reference::fd_default, Reference::richardson})
    tangent_error("units metal\npair_style sw\npair_coeff * * GaN.sw Ga N\n",
                  diamond(2, 2, 2, 4.5, 0.1, true, 43), ref);
}

TEST(NativeManyBodyTangent, TersoffSi) {
  for (const auto ref : {Reference::fd_default, Reference::richardson})
    tangent_error(kTersoffSi, diamond(2, 2, 2, 5.431, 0.1, false, 44), ref);
  // compressed: bonds in the f_C ramp, whose second derivative jumps at R ± D; the Richardson
  // steps (1e-4 Å) straddle a jump there, the default's (≈ 1.5e-5 Å) do not in this cell
  tangent_error(kTersoffSi, diamond(2, 2, 2, 4.6, 0.15, false, 45), Reference::fd_default);
}

TEST(NativeManyBodyTangent, TersoffSiCAndShift) {
  // SiC.tersoff's g(θ) is steep (c²/d² ≈ 8·10⁷): the default step's round-off reaches 2e-8,
  // so the reference is the Richardson extrapolation at h = 1e-4 Å
  tangent_error(kTersoffSiC, diamond(2, 2, 2, 4.36, 0.1, true, 46), Reference::richardson);
  tangent_error("units metal\npair_style tersoff shift 0.05\npair_coeff * * SiC.tersoff Si C\n",
                diamond(2, 2, 2, 4.36, 0.1, true, 47), Reference::richardson);
}

// ---------------------------------------------------------------------------------------
// Parameter files and pair_coeff: clear InputErrors with file and line

namespace {
/// Writes `text` to dir/name and returns the path.
std::string write(const pdcg::test::ScratchDir& dir, const std::string& name,
                  const std::string& text) {
  std::ofstream(dir / name) << text;
  return dir / name;
}

std::string file_text(const std::string& name) {
  std::ifstream in(*find_potential_file(name));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Runs make_potential on the commands and returns the InputError it must throw.
pdcg::InputError error_of(const std::string& commands, int ntypes) {
  try {
    (void)make_potential(read_potential_commands_from_string(commands, "model.in", ntypes));
  } catch (const pdcg::InputError& e) {
    return e;
  }
  ADD_FAILURE() << "expected an InputError for\n" << commands;
  return pdcg::InputError("none");
}

/// SiC.tersoff without the entry of `triple` (its two lines).
std::string without_entry(const std::string& text, const std::string& triple) {
  std::istringstream in(text);
  std::string line, out;
  bool skip_next = false;
  while (std::getline(in, line)) {
    if (skip_next) {
      skip_next = false;
      continue;
    }
    std::istringstream w(line);
    std::string a, b, c;
    w >> a >> b >> c;
    if (a + " " + b + " " + c == triple) {
      skip_next = true;
      continue;
    }
    out += line + "\n";
  }
  return out;
}
}  // namespace

TEST(ManyBodyFileErrors, MissingElementTripleNamesFileAndTriple) {
  pdcg::test::ScratchDir dir("mb_missing");
  const std::string path =
      write(dir, "SiC.tersoff", without_entry(file_text("SiC.tersoff"), "Si C C"));
  const auto e = error_of("units metal\npair_style tersoff\npair_coeff * * " + path + " Si C\n", 2);
  EXPECT_EQ(e.source_name(), path);
  EXPECT_EQ(e.bad_value(), "Si C C");
  EXPECT_NE(std::string(e.what()).find("missing an entry"), std::string::npos) << e.what();
  // the fix: add the entry or map fewer elements, naming the pair_coeff line
  EXPECT_NE(std::string(e.what()).find("add the entry"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("pair_coeff (line 3"), std::string::npos) << e.what();
  // the same file is fine for Si alone (LAMMPS skips entries of unmapped elements)
  EXPECT_NO_THROW(make_potential(read_potential_commands_from_string(
      "units metal\npair_style tersoff\npair_coeff * * " + path + " Si\n", "model.in", 1)));
  // Stillinger-Weber: GaN.sw without its one-line entry "Ga N N"
  std::string gan;
  {
    std::istringstream in(file_text("GaN.sw"));
    std::string line;
    while (std::getline(in, line))
      if (line.rfind("Ga N  N ", 0) != 0) gan += line + "\n";
  }
  ASSERT_LT(gan.size(), file_text("GaN.sw").size());
  const std::string sw = write(dir, "GaN.sw", gan);
  const auto es = error_of("units metal\npair_style sw\npair_coeff * * " + sw + " Ga N\n", 2);
  EXPECT_EQ(es.source_name(), sw);
  EXPECT_EQ(es.bad_value(), "Ga N N");
  EXPECT_NE(std::string(es.what()).find("add the entry"), std::string::npos) << es.what();
}

TEST(ManyBodyFileErrors, TruncatedFilesNameTheLine) {
  pdcg::test::ScratchDir dir("mb_trunc");
  // Si.sw cut inside its only entry: the entry starts on the line of "Si Si Si"
  std::string sw = file_text("Si.sw");
  const auto entry = sw.find("Si Si Si");
  const long entry_line = 1 + std::count(sw.begin(), sw.begin() + static_cast<long>(entry), '\n');
  const std::string cut = sw.substr(0, sw.find("7.049556277"));
  const std::string p1 = write(dir, "Si.sw", cut);
  auto e = error_of("units metal\npair_style sw\npair_coeff * * " + p1 + " Si\n", 1);
  EXPECT_EQ(e.source_name(), p1);
  EXPECT_EQ(e.line_number(), entry_line);
  EXPECT_NE(std::string(e.what()).find("ends inside an entry"), std::string::npos) << e.what();
  // SiC.tersoff cut after its first four entries: the C Si Si entry... is missing, and the
  // fifth is half there
  const std::string ters = file_text("SiC.tersoff");
  std::size_t pos = ters.find("Si  C   C");
  pos = ters.find('\n', pos);  // keep the first line of the Si C C entry only
  const std::string p2 = write(dir, "SiC.tersoff", ters.substr(0, pos + 1));
  e = error_of("units metal\npair_style tersoff\npair_coeff * * " + p2 + " Si C\n", 2);
  EXPECT_EQ(e.source_name(), p2);
  EXPECT_GT(e.line_number(), 0);
  EXPECT_NE(std::string(e.what()).find("ends inside an entry"), std::string::npos) << e.what();
  // an empty file has no entries at all
  const std::string p3 = write(dir, "empty.sw", "# nothing\n");
  e = error_of("units metal\npair_style sw\npair_coeff * * " + p3 + " Si\n", 1);
  EXPECT_NE(std::string(e.what()).find("element not in"), std::string::npos) << e.what();
}

TEST(ManyBodyFileErrors, UnknownElementNamesThePairCoeffLine) {
  const auto e = error_of("units metal\npair_style sw\npair_coeff * * Si.sw Ge\n", 1);
  EXPECT_EQ(e.source_name(), "model.in");
  EXPECT_EQ(e.line_number(), 3);
  EXPECT_EQ(e.bad_value(), "Ge");
  EXPECT_NE(std::string(e.what()).find("Si"), std::string::npos) << "lists the file's elements";
  const auto e2 = error_of("units metal\npair_style tersoff\npair_coeff * * SiC.tersoff Si N\n", 2);
  EXPECT_EQ(e2.bad_value(), "N");
}

TEST(ManyBodyFileErrors, MalformedEntries) {
  pdcg::test::ScratchDir dir("mb_bad");
  const std::string sw = file_text("Si.sw");
  // a value that is not a number
  std::string bad = sw;
  bad.replace(bad.find("7.049556277"), 11, "7.0495x6277");
  std::string p = write(dir, "num.sw", bad);
  auto e = error_of("units metal\npair_style sw\npair_coeff * * " + p + " Si\n", 1);
  EXPECT_EQ(e.source_name(), p);
  EXPECT_GT(e.line_number(), 0);
  EXPECT_EQ(e.bad_value(), "7.0495x6277");
  // an extra value (two entries run together)
  bad = sw;
  bad.replace(bad.find("0.0 0.0"), 7, "0.0 0.0 1.0");
  p = write(dir, "extra.sw", bad);
  e = error_of("units metal\npair_style sw\npair_coeff * * " + p + " Si\n", 1);
  EXPECT_NE(std::string(e.what()).find("has 15 words"), std::string::npos) << e.what();
  // a duplicate entry
  p = write(dir, "dup.sw", sw + "\n" + sw.substr(sw.find("Si Si Si")));
  e = error_of("units metal\npair_style sw\npair_coeff * * " + p + " Si\n", 1);
  EXPECT_NE(std::string(e.what()).find("duplicate"), std::string::npos) << e.what();
  // an illegal (negative) parameter, as LAMMPS's check
  bad = sw;
  bad.replace(bad.find("2.1683"), 6, "-2.168");
  p = write(dir, "neg.sw", bad);
  e = error_of("units metal\npair_style sw\npair_coeff * * " + p + " Si\n", 1);
  EXPECT_NE(std::string(e.what()).find("Illegal Stillinger-Weber parameter"), std::string::npos);
  EXPECT_EQ(e.key_name(), "Si Si Si");
  // Tersoff m must be 1 or 3
  std::string t = file_text("Si.tersoff");
  t.replace(t.find("3.0 1.0 1.3258"), 3, "2.0");
  p = write(dir, "m.tersoff", t);
  e = error_of("units metal\npair_style tersoff\npair_coeff * * " + p + " Si\n", 1);
  EXPECT_NE(std::string(e.what()).find("Illegal Tersoff parameter"), std::string::npos);
}

namespace {
/// `text` with the first occurrence of `value` after the start of the entry `triple` replaced.
std::string replace_in_entry(std::string text, const std::string& triple, const std::string& value,
                             const std::string& by) {
  const auto at = text.find(triple);
  text.replace(text.find(value, at), value.size(), by);
  return text;
}
pdcg::test::PdResult native(const std::string& cmds, const Atoms& at, int ntypes) {
  const auto pot = make_potential(read_potential_commands_from_string(cmds, "x", ntypes));
  return pdcg::test::pd_evaluate(*pot, at);
}
}  // namespace

TEST(ManyBodyAsymmetricFiles, TersoffRepulsiveEntriesDifferEachAtomUsesItsOwn) {
  // LAMMPS evaluates V_R of a pair with the entry of the atom its tag parity picks, so a file
  // whose (Si, C, C) and (C, Si, Si) repulsive parameters differ (Debian's SiC_1989.tersoff
  // and SiC_1994.tersoff, by 1e-7) gives id-dependent results. pdcg gives each atom half of
  // V_R with its own entry and warns: with A(C Si Si) changed, the C atoms see the file
  // where both entries have the new A, the Si atoms the original one, and the forces are
  // the mean of the two (V_R is linear in A).
  pdcg::test::ScratchDir dir("mb_asym");
  const std::string orig = file_text("SiC.tersoff");
  const std::string asym = replace_in_entry(orig, "C   Si  Si", "1597.3111", "1650.0000");
  const std::string both = replace_in_entry(asym, "Si  C   C", "1597.3111", "1650.0000");
  const auto cmds = [&](const std::string& name, const std::string& text) {
    return "units metal\npair_style tersoff\npair_coeff * * " + write(dir, name, text) + " Si C\n";
  };
  const Atoms at = diamond(2, 2, 2, 4.36, 0.1, true, 51);
  const auto ra = native(cmds("asym.tersoff", asym), at, 2);
  const auto r0 = native(cmds("orig.tersoff", orig), at, 2);
  const auto r1 = native(cmds("both.tersoff", both), at, 2);
  double e = 0.0, s = 0.0;
  for (std::size_t i = 0; i < at.size(); ++i) {
    const double expect = at.type[i] == 1 ? r0.psi[i] : r1.psi[i];
    e = std::max(e, std::abs(ra.psi[i] - expect));
    s = std::max(s, std::abs(expect));
  }
  EXPECT_LT(e, 1e-13 * s);  // the same operations: round-off
  std::vector<double> mean(ra.force.size());
  for (std::size_t i = 0; i < mean.size(); ++i) mean[i] = 0.5 * (r0.force[i] + r1.force[i]);
  EXPECT_LT(max_norm_relative_error(ra.force, mean), 1e-12);     // linear in A: round-off
  EXPECT_GT(max_norm_relative_error(r1.force, r0.force), 1e-3);  // the change matters
  compare(cmds("both.tersoff", both), at);  // the symmetric modified file is LAMMPS's
}

TEST(ManyBodyAsymmetricFiles, StillingerWeberThreeBodyEntriesDifferMeanOverOrders) {
  // φ3(i; j, k) takes λ, cos θ0 from the entry (i, j, k) of the neighbour that comes first in
  // LAMMPS's list (Debian's CdTeZnSeHgS0.sw has λ(Cd Cd Te) ≠ λ(Cd Te Cd)): pdcg evaluates
  // the mean over both orders, which is linear in λ: the mean of the two symmetric files.
  pdcg::test::ScratchDir dir("mb_asym3");
  const std::string orig = file_text("GaN.sw");
  const std::string asym = replace_in_entry(orig, "Ga Ga N", "32.5", "40.0");
  const std::string both = replace_in_entry(asym, "Ga N  Ga", "32.5", "40.0");
  const auto cmds = [&](const std::string& name, const std::string& text) {
    return "units metal\npair_style sw\npair_coeff * * " + write(dir, name, text) + " Ga N\n";
  };
  const Atoms at = diamond(2, 2, 2, 4.5, 0.1, true, 52);
  const auto ra = native(cmds("asym.sw", asym), at, 2);
  const auto r0 = native(cmds("orig.sw", orig), at, 2);
  const auto r1 = native(cmds("both.sw", both), at, 2);
  std::vector<double> psi(ra.psi.size()), f(ra.force.size());
  for (std::size_t i = 0; i < psi.size(); ++i) psi[i] = 0.5 * (r0.psi[i] + r1.psi[i]);
  for (std::size_t i = 0; i < f.size(); ++i) f[i] = 0.5 * (r0.force[i] + r1.force[i]);
  EXPECT_LT(max_norm_relative_error(ra.psi, psi), 1e-13);  // linear in λ: round-off
  EXPECT_LT(max_norm_relative_error(ra.force, f), 1e-12);
  EXPECT_GT(max_norm_relative_error(r1.psi, r0.psi), 1e-3);  // the change matters
  compare(cmds("both.sw", both), at);
}

TEST(ManyBodyFileErrors, PairCoeffForms) {
  // I,J must be * *; one element per type; NULL needs hybrid; keyword typos; units
  auto e = error_of("units metal\npair_style sw\npair_coeff 1 1 Si.sw Si\n", 1);
  EXPECT_EQ(e.line_number(), 3);
  e = error_of("units metal\npair_style sw\npair_coeff * * Si.sw Si\n", 2);
  EXPECT_EQ(e.line_number(), 3);
  e = error_of("units metal\npair_style tersoff\npair_coeff * * Si.tersoff Si NULL\n", 2);
  EXPECT_NE(std::string(e.what()).find("NULL"), std::string::npos);
  e = error_of("units metal\npair_style sw threebody maybe\npair_coeff * * Si.sw Si\n", 1);
  EXPECT_EQ(e.line_number(), 2);
  e = error_of("units metal\npair_style tersoff shfit 0.1\npair_coeff * * Si.tersoff Si\n", 1);
  EXPECT_EQ(e.bad_value(), "shfit");
  e = error_of("units lj\npair_style sw\npair_coeff * * Si.sw Si\n", 1);
  EXPECT_NE(std::string(e.what()).find("requires metal units"), std::string::npos) << e.what();
  e = error_of("units metal\npair_style sw\npair_coeff * * no_such_file.sw Si\n", 1);
  EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  e = error_of(
      "units metal\natom_style bond\npair_style sw\npair_coeff * * Si.sw Si\nbond_style harmonic\n"
      "bond_coeff 1 1.0 1.0\n",
      1);
  EXPECT_EQ(e.key_name(), "bond_style");
}

TEST(ManyBodyFileErrors, EveryDebianFileLoads) {
  // all sw and tersoff files of the LAMMPS potentials directory with all their elements
  const std::vector<std::pair<std::string, std::string>> files = {
      {"sw", "Si.sw Si"},
      {"sw", "GaN.sw Ga N"},
      {"sw", "CdTe.sw Cd Te"},
      {"sw", "CdTeZnSeHgS0.sw Cd Te Zn Se Hg S"},
      {"tersoff", "Si.tersoff Si"},
      {"tersoff", "SiC.tersoff Si C"},
      {"tersoff", "SiCGe.tersoff Si(D) C"},
      {"tersoff", "SiCGe.tersoff Si(D) Ge"},
      {"tersoff", "SiCGe.tersoff Si(B)"},
      {"tersoff", "SiCGe.tersoff Si(C)"},
      {"tersoff", "BNC.tersoff B N C"},
      {"tersoff", "GaN.tersoff Ga N"},
      {"tersoff", "Ge.tersoff Ge"},
      {"tersoff", "SiC_1989.tersoff Si C"},
      {"tersoff", "SiC_1990.tersoff Si C"},
      {"tersoff", "SiC_1994.tersoff Si C"},
      {"tersoff", "SiC_Erhart-Albe.tersoff Si C"},
      {"tersoff", "SiO.tersoff Si O"}};
  for (const auto& [style, args] : files) {
    const int n = static_cast<int>(std::count(args.begin(), args.end(), ' '));
    EXPECT_NO_THROW(make_potential(read_potential_commands_from_string(
        "units metal\npair_style " + style + "\npair_coeff * * " + args + "\n", "deb", n)))
        << args;
  }
}
