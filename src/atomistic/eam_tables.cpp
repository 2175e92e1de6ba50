// EAM potential files (DYNAMO funcfl / setfl, Finnis–Sinclair) read and converted exactly as
// LAMMPS's PairEAM, PairEAMAlloy and PairEAMFS (read_file, file2array, array2spline,
// interpolate), so that the splines are bit-identical.
#include "eam_tables.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "pdcg/atomistic/eam_spline.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::atomistic {

namespace {

/// LAMMPS TextFileReader semantics: skip_line reads one raw line; next_values(n) reads
/// non-blank lines (comments after `#` removed) until they hold >= n words; next_dvector reads
/// whole lines until n numbers are read (extra numbers on the last line are dropped).
class TableReader {
 public:
  explicit TableReader(std::string path) : path_(std::move(path)), in_(path_) {
    if (!in_)
      throw InputError("cannot open EAM potential file")
          .source(path_)
          .expected("a readable file")
          .fix("check the path and permissions");
  }
  void skip_line() {
    if (!raw()) eof("a header line");
  }
  std::vector<std::string> next_values(std::size_t n, std::string_view what) {
    std::vector<std::string> words;
    while (words.size() < n) {
      if (!raw()) eof(what);
      for (auto w : split_blanks(strip(line_))) words.emplace_back(w);
    }
    return words;
  }
  void next_dvector(double* out, int n, std::string_view what) {
    int i = 0;
    while (i < n) {
      if (!raw()) eof(what);
      for (auto w : split_blanks(strip(line_))) {
        if (i >= n) break;
        out[i++] = parse_double(w, {path_, lineno_, what});
      }
    }
  }
  int to_int(const std::string& w, std::string_view what) const {
    return static_cast<int>(parse_int(w, {path_, lineno_, what}));
  }
  double to_double(const std::string& w, std::string_view what) const {
    return parse_double(w, {path_, lineno_, what});
  }
  const std::string& path() const { return path_; }
  long line() const { return lineno_; }
  /// The header's counts are checked against the file's size before the tables are sized:
  /// every value takes at least two bytes (a digit and a separator), so a corrupted Nrho or
  /// Nr (10⁹) is an InputError, not a many-gigabyte allocation.
  void require_values(double n, std::string_view what) const {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(path_, ec);
    if (!ec && 2.0 * n > static_cast<double>(bytes))
      throw InputError("EAM potential file is too short for its header")
          .source(path_)
          .line(lineno_)
          .key(what)
          .value(fmt::format("{:.0f} table values declared, the file has {} bytes", n, bytes))
          .expected("at least as many values as Nrho, Nr and the element count declare")
          .fix("the file is truncated or its header (Nrho, Nr, Nelements) is wrong");
  }

 private:
  bool raw() {
    if (!std::getline(in_, line_)) return false;
    ++lineno_;
    return true;
  }
  static std::string_view strip(std::string_view s) {
    const auto h = s.find('#');
    return h == std::string_view::npos ? s : s.substr(0, h);
  }
  [[noreturn]] void eof(std::string_view what) const {
    throw InputError("EAM potential file ends early")
        .source(path_)
        .line(lineno_)
        .key(what)
        .expected("the number of values the header declares")
        .fix("the file is truncated or its header (Nrho, Nr) is wrong");
  }
  std::string path_;
  std::ifstream in_;
  std::string line_;
  long lineno_ = 0;
};

struct Grid {
  int nrho = 0, nr = 0;
  double drho = 0, dr = 0, cut = 0;
};

Grid read_grid(TableReader& rd) {
  auto v = rd.next_values(5, "Nrho drho Nr dr cutoff");
  Grid g;
  g.nrho = rd.to_int(v[0], "Nrho");
  g.drho = rd.to_double(v[1], "drho");
  g.nr = rd.to_int(v[2], "Nr");
  g.dr = rd.to_double(v[3], "dr");
  g.cut = rd.to_double(v[4], "cutoff");
  if (g.nrho <= 0 || g.nr <= 0 || g.dr <= 0.0)
    throw InputError("invalid EAM grid")
        .source(rd.path())
        .line(rd.line())
        .key("Nrho drho Nr dr cutoff")
        .expected("positive Nrho, Nr and dr");
  if (g.nrho < 5 || g.nr < 5)
    throw InputError("EAM grid too small for LAMMPS's splines")
        .source(rd.path())
        .line(rd.line())
        .expected("Nrho, Nr >= 5");
  return g;
}

struct Funcfl {
  std::string file;
  double mass = 0;
  Grid g;
  std::vector<double> frho, zr, rhor;  // 1-based
};

/// Energy conversion factor LAMMPS applies to a potential file (utils::get_conversion_factor
/// with the conversion PotentialFileReader picks): 1 unless the file's UNITS: tag is metal and
/// the units real (23.060549 kcal/mol per eV) or the reverse. Mismatches LAMMPS refuses are
/// refused earlier (read_potential_commands, check_file_units).
double energy_conversion(const std::string& path, UnitStyle units) {
  const std::string tag = potential_file_units(path);
  if (tag == "metal" && units == UnitStyle::real) return 23.060549;
  if (tag == "real" && units == UnitStyle::metal) return 1.0 / 23.060549;
  return 1.0;
}

Funcfl read_funcfl(const std::string& name, const std::string& path, UnitStyle units) {
  TableReader rd(path);
  Funcfl f;
  f.file = name;
  rd.skip_line();
  auto v = rd.next_values(2, "Z mass");
  rd.to_int(v[0], "Z");
  f.mass = rd.to_double(v[1], "mass");
  f.g = read_grid(rd);
  rd.require_values(double(f.g.nrho) + 2.0 * double(f.g.nr), "Nrho drho Nr dr cutoff");
  f.frho.assign(static_cast<std::size_t>(f.g.nrho + 1), 0.0);
  f.zr.assign(static_cast<std::size_t>(f.g.nr + 1), 0.0);
  f.rhor.assign(static_cast<std::size_t>(f.g.nr + 1), 0.0);
  rd.next_dvector(&f.frho[1], f.g.nrho, "F(rho)");
  rd.next_dvector(&f.zr[1], f.g.nr, "Z(r)");
  rd.next_dvector(&f.rhor[1], f.g.nr, "rho(r)");
  // PairEAM::read_file: F scales with the energy, Z(r) with its square root (φ ∝ Z_i Z_j)
  if (const double conv = energy_conversion(path, units); conv != 1.0) {
    const double sqrt_conv = std::sqrt(conv);
    for (int i = 1; i <= f.g.nrho; ++i) f.frho[static_cast<std::size_t>(i)] *= conv;
    for (int j = 1; j <= f.g.nr; ++j) f.zr[static_cast<std::size_t>(j)] *= sqrt_conv;
  }
  return f;
}

struct Setfl {
  std::vector<std::string> elements;
  std::vector<double> mass;
  Grid g;
  std::vector<std::vector<double>> frho;               // [element][1..nrho]
  std::vector<std::vector<std::vector<double>>> rhor;  // [i][j or 0][1..nr]
  std::vector<std::vector<std::vector<double>>> z2r;   // [i][j<=i][1..nr]
};

Setfl read_setfl(const std::string& path, bool fs, UnitStyle units) {
  TableReader rd(path);
  Setfl s;
  rd.skip_line();
  rd.skip_line();
  rd.skip_line();
  auto v = rd.next_values(1, "Nelements Element1 …");
  const int ne = rd.to_int(v[0], "Nelements");
  if (ne < 1 || static_cast<int>(v.size()) != ne + 1)
    throw InputError("incorrect element names in EAM potential file")
        .source(path)
        .line(rd.line())
        .key("Nelements Element1 …")
        .expected("the element count followed by that many names");
  s.elements.assign(v.begin() + 1, v.end());
  s.g = read_grid(rd);
  const auto nrho = static_cast<std::size_t>(s.g.nrho), nr = static_cast<std::size_t>(s.g.nr);
  {
    const double e = ne, per_element = double(nrho) + double(nr) * (fs ? e : 1.0);
    rd.require_values(e * per_element + e * (e + 1.0) / 2.0 * double(nr), "Nrho drho Nr dr cutoff");
  }
  s.mass.resize(static_cast<std::size_t>(ne));
  s.frho.assign(static_cast<std::size_t>(ne), std::vector<double>(nrho + 1, 0.0));
  s.rhor.assign(static_cast<std::size_t>(ne),
                std::vector<std::vector<double>>(fs ? static_cast<std::size_t>(ne) : 1,
                                                 std::vector<double>(nr + 1, 0.0)));
  s.z2r.assign(static_cast<std::size_t>(ne),
               std::vector<std::vector<double>>(static_cast<std::size_t>(ne),
                                                std::vector<double>(nr + 1, 0.0)));
  for (std::size_t i = 0; i < static_cast<std::size_t>(ne); ++i) {
    auto w = rd.next_values(2, "Z mass");
    rd.to_int(w[0], "Z");
    s.mass[i] = rd.to_double(w[1], "mass");
    rd.next_dvector(&s.frho[i][1], s.g.nrho, "F(rho)");
    for (auto& r : s.rhor[i]) rd.next_dvector(&r[1], s.g.nr, "rho(r)");
  }
  for (std::size_t i = 0; i < static_cast<std::size_t>(ne); ++i)
    for (std::size_t j = 0; j <= i; ++j) rd.next_dvector(&s.z2r[i][j][1], s.g.nr, "r*phi(r)");
  // Energies: F and r·φ × the conversion factor. PairEAMFS::read_file converts every table
  // point; PairEAMAlloy::read_file loops `j < nrho`, `k < nr` and leaves the last point of F
  // and r·φ unconverted. Both are reproduced (LAMMPS is the reference; the alloy quirk shows
  // only where ρ̄ reaches the last interval of F or beyond, and near the cutoff of r·φ).
  if (const double conv = energy_conversion(path, units); conv != 1.0) {
    const int last_f = fs ? s.g.nrho : s.g.nrho - 1, last_z = fs ? s.g.nr : s.g.nr - 1;
    for (auto& f : s.frho)
      for (int j = 1; j <= last_f; ++j) f[static_cast<std::size_t>(j)] *= conv;
    for (std::size_t i = 0; i < static_cast<std::size_t>(ne); ++i)
      for (std::size_t j = 0; j <= i; ++j)
        for (int k = 1; k <= last_z; ++k) s.z2r[i][j][static_cast<std::size_t>(k)] *= conv;
  }
  return s;
}

std::string resolve(const PotentialSpec& spec, const CoeffLine& c, const std::string& name) {
  auto p = find_potential_file(name);
  if (!p)
    throw InputError("potential file not found")
        .source(spec.source)
        .line(c.line_number)
        .key("pair_coeff")
        .value(name)
        .expected(
            "a readable EAM file (path, $LAMMPS_POTENTIALS, or the LAMMPS potentials directory)");
  return *p;
}

/// type2z2r as PairEAM::file2array: lower-triangular index of the element pair.
void fill_type2z2r(EamTables& t, const std::vector<int>& map) {
  const int n1 = t.ntypes + 1;
  t.type2z2r.assign(static_cast<std::size_t>(n1 * n1), 0);
  for (int i = 1; i <= t.ntypes; ++i)
    for (int j = 1; j <= t.ntypes; ++j) {
      int irow = map[static_cast<std::size_t>(i)], icol = map[static_cast<std::size_t>(j)];
      if (irow == -1 || icol == -1) continue;
      if (irow < icol) std::swap(irow, icol);
      int n = 0;
      for (int m = 0; m < irow; ++m) n += m + 1;
      n += icol;
      t.type2z2r[static_cast<std::size_t>(i * n1 + j)] = n;
    }
}

void array2spline(EamTables& t, const std::vector<std::vector<double>>& frho,
                  const std::vector<std::vector<double>>& rhor,
                  const std::vector<std::vector<double>>& z2r) {
  t.rdr = 1.0 / t.dr;
  t.rdrho = 1.0 / t.drho;
  t.frho_spline.resize(frho.size());
  t.rhor_spline.resize(rhor.size());
  t.z2r_spline.resize(z2r.size());
  for (std::size_t i = 0; i < frho.size(); ++i)
    eam_interpolate(t.nrho, t.drho, frho[i], t.frho_spline[i]);
  for (std::size_t i = 0; i < rhor.size(); ++i)
    eam_interpolate(t.nr, t.dr, rhor[i], t.rhor_spline[i]);
  for (std::size_t i = 0; i < z2r.size(); ++i) eam_interpolate(t.nr, t.dr, z2r[i], t.z2r_spline[i]);
}

InputError unmapped(const PotentialSpec& spec, int type) {
  return InputError(
             "atom type not mapped to an EAM element (NULL needs pair_style hybrid, not native)")
      .source(spec.source)
      .key("pair_coeff")
      .value(std::to_string(type))
      .expected("an element (or funcfl file) for every atom type")
      .fix("map every type in pair_coeff, or use pair_style hybrid through embedded LAMMPS");
}

}  // namespace

void eam_interpolate(int n, double delta, const std::vector<double>& f,
                     std::vector<double>& spline) {
  spline.assign(static_cast<std::size_t>(7 * (n + 1)), 0.0);
  auto s = [&](int m, int k) -> double& { return spline[static_cast<std::size_t>(7 * m + k)]; };
  for (int m = 1; m <= n; m++) s(m, 6) = f[static_cast<std::size_t>(m)];

  s(1, 5) = s(2, 6) - s(1, 6);
  s(2, 5) = 0.5 * (s(3, 6) - s(1, 6));
  s(n - 1, 5) = 0.5 * (s(n, 6) - s(n - 2, 6));
  s(n, 5) = s(n, 6) - s(n - 1, 6);

  for (int m = 3; m <= n - 2; m++)
    s(m, 5) = ((s(m - 2, 6) - s(m + 2, 6)) + 8.0 * (s(m + 1, 6) - s(m - 1, 6))) / 12.0;

  for (int m = 1; m <= n - 1; m++) {
    s(m, 4) = 3.0 * (s(m + 1, 6) - s(m, 6)) - 2.0 * s(m, 5) - s(m + 1, 5);
    s(m, 3) = s(m, 5) + s(m + 1, 5) - 2.0 * (s(m + 1, 6) - s(m, 6));
  }

  s(n, 4) = 0.0;
  s(n, 3) = 0.0;

  for (int m = 1; m <= n; m++) {
    s(m, 2) = s(m, 5) / delta;
    s(m, 1) = 2.0 * s(m, 4) / delta;
    s(m, 0) = 3.0 * s(m, 3) / delta;
  }
}

EamTables build_eam_tables(const PotentialSpec& spec) {
  EamTables t;
  t.ntypes = spec.ntypes;
  const int n1 = t.ntypes + 1;
  std::vector<int> map(static_cast<std::size_t>(n1), -1);
  t.type_mass.assign(static_cast<std::size_t>(n1), std::numeric_limits<double>::quiet_NaN());
  std::vector<std::vector<double>> frho, rhor, z2r;

  if (spec.pair_style == "eam") {
    // PairEAM::coeff: pair_coeff I J FILE, only I == J pairs map a type to a file
    std::vector<Funcfl> files;
    for (const auto& c : spec.pair_coeff) {
      if (c.args.size() != 1)
        throw InputError("wrong number of arguments")
            .source(spec.source)
            .line(c.line_number)
            .key("pair_coeff")
            .value(c.line)
            .expected("pair_coeff I J FILE (pair_style eam)");
      int ilo, ihi, jlo, jhi;
      parse_type_range(c.i, t.ntypes, ilo, ihi, spec.source, c.line_number, "pair_coeff");
      parse_type_range(c.j, t.ntypes, jlo, jhi, spec.source, c.line_number, "pair_coeff");
      std::size_t ifile = 0;
      while (ifile < files.size() && files[ifile].file != c.args[0]) ++ifile;
      if (ifile == files.size())
        files.push_back(read_funcfl(c.args[0], resolve(spec, c, c.args[0]), spec.units));
      int count = 0;
      for (int i = ilo; i <= ihi; ++i)
        for (int j = std::max(jlo, i); j <= jhi; ++j)
          if (i == j) {
            map[static_cast<std::size_t>(i)] = static_cast<int>(ifile);
            t.type_mass[static_cast<std::size_t>(i)] = files[ifile].mass;
            ++count;
          }
      if (count == 0)
        throw InputError("pair_coeff maps no type to the funcfl file (pair_style eam needs I = J)")
            .source(spec.source)
            .line(c.line_number)
            .key("pair_coeff")
            .value(c.line)
            .expected("pair_coeff I I FILE");
    }
    for (int i = 1; i <= t.ntypes; ++i)
      if (map[static_cast<std::size_t>(i)] < 0) throw unmapped(spec, i);
    // PairEAM::init_one: cutmax over all files read
    for (const auto& f : files) t.cutmax = std::max(t.cutmax, f.g.cut);
    // PairEAM::file2array
    const int nfuncfl = static_cast<int>(files.size());
    double rmax = 0.0;
    t.dr = t.drho = t.rhomax = 0.0;
    for (int i = 0; i < nfuncfl; i++) {
      bool active = false;
      for (int j = 1; j <= t.ntypes; j++)
        if (map[static_cast<std::size_t>(j)] == i) active = true;
      if (!active) continue;
      const Funcfl& file = files[static_cast<std::size_t>(i)];
      t.dr = std::max(t.dr, file.g.dr);
      t.drho = std::max(t.drho, file.g.drho);
      rmax = std::max(rmax, (file.g.nr - 1) * file.g.dr);
      t.rhomax = std::max(t.rhomax, (file.g.nrho - 1) * file.g.drho);
    }
    t.nr = static_cast<int>(rmax / t.dr + 0.5);
    t.nrho = static_cast<int>(t.rhomax / t.drho + 0.5);
    const double sixth = 1.0 / 6.0;
    // 4-point Lagrange interpolation of a file's table onto the common grid
    auto lagrange = [&](const std::vector<double>& tab, int nfile, double dfile, double r) {
      double p = r / dfile + 1.0;
      // LAMMPS's max(min((int) p, nfile − 2), 2), without the undefined int conversion of a
      // p beyond the int range
      const int k = std::max(eam::cell(p, std::numeric_limits<int>::min(), nfile - 2), 2);
      p -= k;
      p = std::min(p, 2.0);
      const double cof1 = -sixth * p * (p - 1.0) * (p - 2.0);
      const double cof2 = 0.5 * (p * p - 1.0) * (p - 2.0);
      const double cof3 = -0.5 * p * (p + 1.0) * (p - 2.0);
      const double cof4 = sixth * p * (p * p - 1.0);
      const auto ku = static_cast<std::size_t>(k);
      return cof1 * tab[ku - 1] + cof2 * tab[ku] + cof3 * tab[ku + 1] + cof4 * tab[ku + 2];
    };
    frho.assign(static_cast<std::size_t>(nfuncfl + 1),
                std::vector<double>(static_cast<std::size_t>(t.nrho + 1), 0.0));
    for (int i = 0; i < nfuncfl; i++) {
      const Funcfl& file = files[static_cast<std::size_t>(i)];
      for (int m = 1; m <= t.nrho; m++)
        frho[static_cast<std::size_t>(i)][static_cast<std::size_t>(m)] =
            lagrange(file.frho, file.g.nrho, file.g.drho, (m - 1) * t.drho);
    }
    t.type2frho.assign(static_cast<std::size_t>(n1), nfuncfl);
    for (int i = 1; i <= t.ntypes; i++)
      t.type2frho[static_cast<std::size_t>(i)] = map[static_cast<std::size_t>(i)];
    rhor.assign(static_cast<std::size_t>(nfuncfl),
                std::vector<double>(static_cast<std::size_t>(t.nr + 1), 0.0));
    for (int i = 0; i < nfuncfl; i++) {
      const Funcfl& file = files[static_cast<std::size_t>(i)];
      for (int m = 1; m <= t.nr; m++)
        rhor[static_cast<std::size_t>(i)][static_cast<std::size_t>(m)] =
            lagrange(file.rhor, file.g.nr, file.g.dr, (m - 1) * t.dr);
    }
    t.type2rhor.assign(static_cast<std::size_t>(n1 * n1), 0);
    for (int i = 1; i <= t.ntypes; i++)
      for (int j = 1; j <= t.ntypes; j++)
        t.type2rhor[static_cast<std::size_t>(i * n1 + j)] = map[static_cast<std::size_t>(i)];
    z2r.assign(static_cast<std::size_t>(nfuncfl * (nfuncfl + 1) / 2),
               std::vector<double>(static_cast<std::size_t>(t.nr + 1), 0.0));
    std::size_t n = 0;
    for (int i = 0; i < nfuncfl; i++) {
      const Funcfl& fi = files[static_cast<std::size_t>(i)];
      for (int j = 0; j <= i; j++) {
        const Funcfl& fj = files[static_cast<std::size_t>(j)];
        for (int m = 1; m <= t.nr; m++) {
          const double r = (m - 1) * t.dr;
          const double zri = lagrange(fi.zr, fi.g.nr, fi.g.dr, r);
          const double zrj = lagrange(fj.zr, fj.g.nr, fj.g.dr, r);
          z2r[n][static_cast<std::size_t>(m)] = 27.2 * 0.529 * zri * zrj;
        }
        n++;
      }
    }
    fill_type2z2r(t, map);
  } else {
    const bool fs = spec.pair_style == "eam/fs";
    // PairEAMAlloy/PairEAMFS::coeff: a single pair_coeff * * FILE el1 … elN
    if (spec.pair_coeff.empty())
      throw InputError("no pair_coeff for " + spec.pair_style)
          .source(spec.source)
          .line(spec.pair_style_line)
          .key("pair_coeff")
          .expected("pair_coeff * * FILE ELEMENT…");
    const CoeffLine& c = spec.pair_coeff.back();
    if (c.i != "*" || c.j != "*" || static_cast<int>(c.args.size()) != 1 + t.ntypes)
      throw InputError("incorrect args for pair coefficients")
          .source(spec.source)
          .line(c.line_number)
          .key("pair_coeff")
          .value(c.line)
          .expected("pair_coeff * * FILE followed by one element name (or NULL) per atom type (" +
                    std::to_string(t.ntypes) + ")");
    const Setfl s = read_setfl(resolve(spec, c, c.args[0]), fs, spec.units);
    const int ne = static_cast<int>(s.elements.size());
    for (int i = 1; i <= t.ntypes; ++i) {
      const std::string& el = c.args[static_cast<std::size_t>(i)];
      if (el == "NULL") throw unmapped(spec, i);
      int j = 0;
      while (j < ne && s.elements[static_cast<std::size_t>(j)] != el) ++j;
      if (j == ne)
        throw InputError("no matching element in EAM potential file")
            .source(spec.source)
            .line(c.line_number)
            .key("pair_coeff")
            .value(el)
            .expected("one of the file's elements:" + [&] {
              std::string l;
              for (const auto& e : s.elements) l += " " + e;
              return l;
            }());
      map[static_cast<std::size_t>(i)] = j;
      t.type_mass[static_cast<std::size_t>(i)] = s.mass[static_cast<std::size_t>(j)];
    }
    t.cutmax = s.g.cut;
    t.nrho = s.g.nrho;
    t.nr = s.g.nr;
    t.drho = s.g.drho;
    t.dr = s.g.dr;
    t.rhomax = (t.nrho - 1) * t.drho;
    frho.assign(static_cast<std::size_t>(ne + 1),
                std::vector<double>(static_cast<std::size_t>(t.nrho + 1), 0.0));
    for (int i = 0; i < ne; i++)
      frho[static_cast<std::size_t>(i)] = s.frho[static_cast<std::size_t>(i)];
    t.type2frho.assign(static_cast<std::size_t>(n1), ne);
    for (int i = 1; i <= t.ntypes; i++)
      t.type2frho[static_cast<std::size_t>(i)] = map[static_cast<std::size_t>(i)];
    t.type2rhor.assign(static_cast<std::size_t>(n1 * n1), 0);
    if (fs) {
      for (int i = 0; i < ne; i++)
        for (int j = 0; j < ne; j++)
          rhor.push_back(s.rhor[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]);
      for (int i = 1; i <= t.ntypes; i++)
        for (int j = 1; j <= t.ntypes; j++)
          t.type2rhor[static_cast<std::size_t>(i * n1 + j)] =
              map[static_cast<std::size_t>(i)] * ne + map[static_cast<std::size_t>(j)];
    } else {
      for (int i = 0; i < ne; i++) rhor.push_back(s.rhor[static_cast<std::size_t>(i)][0]);
      for (int i = 1; i <= t.ntypes; i++)
        for (int j = 1; j <= t.ntypes; j++)
          t.type2rhor[static_cast<std::size_t>(i * n1 + j)] = map[static_cast<std::size_t>(i)];
    }
    for (int i = 0; i < ne; i++)
      for (int j = 0; j <= i; j++)
        z2r.push_back(s.z2r[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]);
    fill_type2z2r(t, map);
  }
  t.cutforcesq = t.cutmax * t.cutmax;
  array2spline(t, frho, rhor, z2r);
  return t;
}

EamView make_eam_view(const EamTables& t) {
  auto pick = [](const std::vector<std::vector<double>>& splines, const std::vector<int>& which) {
    std::vector<const double*> out;
    for (int w : which)
      out.push_back(w >= 0 && static_cast<std::size_t>(w) < splines.size()
                        ? splines[static_cast<std::size_t>(w)].data()
                        : nullptr);
    return out;
  };
  return {.ntypes = t.ntypes,
          .nr = t.nr,
          .nrho = t.nrho,
          .rdr = t.rdr,
          .rdrho = t.rdrho,
          .rhomax = t.rhomax,
          .cutforcesq = t.cutforcesq,
          .rhor = pick(t.rhor_spline, t.type2rhor),
          .z2r = pick(t.z2r_spline, t.type2z2r),
          .frho = pick(t.frho_spline, t.type2frho)};
}

}  // namespace pdcg::atomistic
