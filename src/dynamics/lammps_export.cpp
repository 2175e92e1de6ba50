// A PD body as LAMMPS input: data file, pair table or setfl file, input script
// (docs/dynamics.md, "Running a coarse model in LAMMPS"; the rescaled model: docs/theory.md §4).
#include "pdcg/dynamics/lammps_export.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <ostream>
#include <sstream>
#include <utility>

#include "pdcg/atomistic/families.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/units.hpp"
#include "pdcg/io/atomic_output.hpp"

namespace pdcg::dynamics {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Pair energy E(r) = φ_ε(r) and force F(r) = −dE/dr of types (a, b) from the body's potential
/// (the ε-wrapper of a rescaled body): one family of one bond Y = (r, 0, 0), for which
/// ψ = ½E and t = ½E'(r) e (docs/theory.md (1.4)).
struct PairProbe {
  const atomistic::Potential& pot;
  mutable std::vector<double> t = std::vector<double>(3), K = std::vector<double>(9),
                              w = std::vector<double>(atomistic::Potential::tangent_workspace(1));
  /// The family of an atom of type a with one bond y to a neighbour of type *b.
  static atomistic::FamilyState one_bond(int a, const int* b, const double* y) {
    atomistic::FamilyState s;
    s.type = a;
    s.size = 1;
    s.neighbor_type = b;
    s.bond = y;
    return s;
  }
  void eval(int a, int b, double r, double& e, double& f) const {
    const double y[3] = {r, 0.0, 0.0};
    e = 2.0 * pot.force_state(one_bond(a, &b, y), t.data());
    f = -2.0 * t[0];
  }
  /// dF/dr = −E''(r) = −2 K_xx (K = ½[E'' e⊗e + E'/r (I − e⊗e)]).
  double dforce(int a, int b, double r) const {
    const double y[3] = {r, 0.0, 0.0};
    pot.force_state_tangent(one_bond(a, &b, y), K.data(), w.data());
    return -2.0 * K[0];
  }
};

/// Cubic-spline second derivatives of y on a uniform grid of spacing h with clamped end
/// slopes yp0, ypn (the tridiagonal system of the classical cubic spline, solved by the Thomas
/// algorithm; LAMMPS's PairTable::spline solves the same system).
std::vector<double> spline_second(const std::vector<double>& y, double h, double yp0, double ypn) {
  const std::size_t n = y.size();
  std::vector<double> y2(n), u(n);
  y2[0] = -0.5;
  u[0] = (3.0 / h) * ((y[1] - y[0]) / h - yp0);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double sig = 0.5;  // uniform grid
    const double p = sig * y2[i - 1] + 2.0;
    y2[i] = (sig - 1.0) / p;
    u[i] = (y[i + 1] - y[i]) / h - (y[i] - y[i - 1]) / h;
    u[i] = (6.0 * u[i] / (2.0 * h) - sig * u[i - 1]) / p;
  }
  const double qn = 0.5;
  const double un = (3.0 / h) * (ypn - (y[n - 1] - y[n - 2]) / h);
  y2[n - 1] = (un - qn * u[n - 2]) / (qn * y2[n - 2] + 1.0);
  for (std::size_t k = n - 1; k-- > 0;) y2[k] = y2[k] * y2[k + 1] + u[k];
  return y2;
}

/// r of point i of a table of n points in RSQ spacing, as LAMMPS's read_table recomputes it.
double rsq_knot(double rlo, double rhi, std::int64_t i, std::int64_t n) {
  const int ii = static_cast<int>(i), nn = static_cast<int>(n);
  return std::sqrt(rlo * rlo + (rhi * rhi - rlo * rlo) * ii / (nn - 1));
}

struct PairSetup {
  int a = 0, b = 0;  ///< body types
  double r_lo = 0.0, r_cut = 0.0;
  double r_last = 0.0;  ///< largest r with a non-zero interaction (left limit at r_cut)
  bool zero = false;    ///< no interaction at any distance
};

/// The table's knots as written (r, E, F at the RSQ points LAMMPS recomputes) and the end
/// slopes of F (FPRIME).
struct Knots {
  std::vector<double> r, e, f;
  double fplo = 0.0, fphi = 0.0;
};

Knots knots(const PairProbe& p, const PairSetup& s, std::int64_t n) {
  Knots k;
  k.r.resize(static_cast<std::size_t>(n));
  k.e.resize(k.r.size());
  k.f.resize(k.r.size());
  for (std::int64_t i = 0; i < n; ++i) {
    const auto ii = static_cast<std::size_t>(i);
    k.r[ii] = rsq_knot(s.r_lo, s.r_cut, i, n);
    if (s.zero) continue;
    p.eval(s.a, s.b, std::min(k.r[ii], s.r_last), k.e[ii], k.f[ii]);
  }
  if (!s.zero) {
    k.fplo = p.dforce(s.a, s.b, s.r_lo);
    k.fphi = p.dforce(s.a, s.b, s.r_last);
  }
  return k;
}

TableInterpolant interpolant(const PairSetup& s, const Knots& k, TableStyle style) {
  return table_interpolant(style, s.r_lo, s.r_cut, k.e, k.f, k.fplo, k.fphi);
}

struct Errors {
  double force = 0.0, energy = 0.0, force_scale = 0.0, energy_scale = 0.0;
};

/// Largest interpolation errors over 3 points per bin (¼, ½, ¾ of the bin in r²), relative to
/// max(|F(r)|, F_scale) and max(|E(r)|, E_scale); the scales are the largest |F|, |E| at the
/// test points at r ≥ r_scale (the closest reference pair: the distances the body has).
Errors table_errors(const PairProbe& p, const PairSetup& s, const TableInterpolant& t,
                    double r_scale) {
  Errors er;
  if (s.zero) return er;
  const auto n = t.e.size();
  const double r_from = std::min(r_scale, 0.5 * (s.r_lo + s.r_cut));
  // two passes over the test points (scales, then errors): no storage per point
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t i = 0; i + 1 < n; ++i)
      for (double frac : {0.25, 0.5, 0.75}) {
        const double r = std::sqrt(t.rsq_lo + (static_cast<double>(i) + frac) * t.delta);
        if (!(r < s.r_cut) || (pass == 0 && r < r_from)) continue;
        double e, f;
        p.eval(s.a, s.b, std::min(r, s.r_last), e, f);
        if (pass == 0) {
          er.force_scale = std::max(er.force_scale, std::abs(f));
          er.energy_scale = std::max(er.energy_scale, std::abs(e));
          continue;
        }
        double te, tf;
        t.eval(r, te, tf);
        const double fs = std::max(std::abs(f), er.force_scale),
                     es = std::max(std::abs(e), er.energy_scale);
        if (!std::isfinite(te) || !std::isfinite(tf))
          return {kInf, kInf, er.force_scale, er.energy_scale};
        if (fs > 0.0) er.force = std::max(er.force, std::abs(tf - f) / fs);
        if (es > 0.0) er.energy = std::max(er.energy, std::abs(te - e) / es);
      }
  return er;
}

/// Largest r < r_hi with a non-zero interaction (bisection between samples); r_cut the first
/// r beyond it with none. `zero` when there is none at any sampled distance.
PairSetup pair_setup(const PairProbe& p, int a, int b, double r_lo, double r_hi,
                     std::string_view source) {
  PairSetup s;
  s.a = a;
  s.b = b;
  auto nonzero = [&](double r) {
    double e, f;
    p.eval(a, b, r, e, f);
    return e != 0.0 || f != 0.0;
  };
  if (nonzero(r_hi))
    throw InputError("the pair potential does not vanish at its cutoff")
        .source(source)
        .key(fmt::format("types {} {}", a, b))
        .value(fmt::format("non-zero at r = {} (the potential's cutoff, ×(1 + 1e-9))", r_hi))
        .expected("a pair potential that is zero beyond its cutoff (LAMMPS's pair styles are)")
        .fix("report this: the potential's cutoff() is inconsistent with its values");
  constexpr int kSamples = 4096;
  double last = -1.0, next = r_hi;
  for (int i = kSamples; i >= 0; --i) {
    const double r = r_lo + (r_hi - r_lo) * i / kSamples;
    if (nonzero(r)) {
      last = r;
      break;
    }
    next = r;
  }
  if (last < 0.0) {
    s.zero = true;
    s.r_lo = r_lo;
    s.r_cut = r_hi;
    s.r_last = r_hi;
    return s;
  }
  double lo = last, hi = next;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (mid <= lo || mid >= hi) break;
    (nonzero(mid) ? lo : hi) = mid;
  }
  s.r_last = lo;
  s.r_cut = hi;
  s.r_lo = std::min(r_lo, 0.5 * s.r_cut);
  return s;
}

/// LAMMPS uses FPRIME's upper slope only when the last r it recomputes for a table of n
/// points equals the cutoff (PairTable::compute_table); otherwise a secant slope, which would
/// make the spline second order near the cutoff. Moves r_lo by ulps until it does.
PairSetup for_points(PairSetup s, std::int64_t n) {
  for (int it = 0; it < 256 && rsq_knot(s.r_lo, s.r_cut, n - 1, n) != s.r_cut; ++it)
    s.r_lo = std::nextafter(s.r_lo, 0.0);
  return s;
}

double closest_pair(const body::Body& b) {
  double d = kInf;
  const auto& fam = b.families;
  for (std::size_t k = 0; k < b.size(); ++k)
    for (auto bb = static_cast<std::size_t>(fam.offset[k]);
         bb < static_cast<std::size_t>(fam.offset[k + 1]); ++bb)
      d = std::min(d, atomistic::bond_vector(fam, b.x, k, bb).norm());
  return d;
}

std::string header(const body::Body& b, const LammpsExportOptions& o, std::string_view source) {
  return fmt::format(
      "pdcg export-lammps of {} ({} body, ε = {}, dimension {}, units {}, {} points){}", source,
      body::to_string(b.kind), b.epsilon, b.dimension, to_string(b.units), b.size(),
      o.command_line.empty() ? std::string() : ": " + o.command_line);
}

}  // namespace

void TableInterpolant::eval(double r, double& energy, double& force) const {
  const double rsq = r * r;
  const auto n = static_cast<std::int64_t>(e.size());
  auto i = static_cast<std::int64_t>((rsq - rsq_lo) / delta);
  i = std::clamp<std::int64_t>(i, 0, n - 2);
  const auto ii = static_cast<std::size_t>(i);
  const double rsq_i = rsq_lo + static_cast<double>(i) * delta;
  const double b = (rsq - rsq_i) / delta;
  if (style == TableStyle::linear) {
    energy = e[ii] + b * (e[ii + 1] - e[ii]);
    force = r * (f[ii] + b * (f[ii + 1] - f[ii]));
    return;
  }
  const double a = 1.0 - b, d6 = delta * delta / 6.0;
  energy =
      a * e[ii] + b * e[ii + 1] + ((a * a * a - a) * e2[ii] + (b * b * b - b) * e2[ii + 1]) * d6;
  force = r * (a * f[ii] + b * f[ii + 1] +
               ((a * a * a - a) * f2[ii] + (b * b * b - b) * f2[ii + 1]) * d6);
}

TableInterpolant table_interpolant(TableStyle style, double r_lo, double r_cut,
                                   std::span<const double> e, std::span<const double> f,
                                   double fplo, double fphi) {
  TableInterpolant t;
  t.style = style;
  const auto n = e.size();
  if (n < 2 || f.size() != n)
    throw InputError("a pair table needs at least 2 points with an energy and a force each");
  t.rsq_lo = r_lo * r_lo;
  t.delta = (r_cut * r_cut - t.rsq_lo) / static_cast<double>(n - 1);
  t.e.assign(e.begin(), e.end());
  t.f.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    t.f[i] = f[i] / std::sqrt(t.rsq_lo + static_cast<double>(i) * t.delta);
  if (style == TableStyle::spline) {
    const double r0 = r_lo, rc = r_cut;
    // dE/d(r²) = −F/2r; d(F/r)/d(r²) = (F'/r − F/r²)/2r (PairTable::compute_table's end slopes)
    t.e2 = spline_second(t.e, t.delta, -f[0] / (2.0 * r0), -f[n - 1] / (2.0 * rc));
    const double fp0 = (fplo / r0 - f[0] / (r0 * r0)) / (2.0 * r0);
    const double fpn = (fphi / rc - f[n - 1] / (rc * rc)) / (2.0 * rc);
    t.f2 = spline_second(t.f, t.delta, fp0, fpn);
  }
  return t;
}

void check_exportable(const body::Body& b, std::string_view source) {
  auto refuse = [&](std::string problem, std::string key, std::string value, std::string why,
                    std::string fix) {
    throw InputError(std::move(problem))
        .source(source)
        .key(key)
        .value(value)
        .expected(why)
        .fix(fix);
  };
  if (!b.potential)
    refuse("the body has no potential", "potential", "none", "a body built with a potential",
           "build the body with `pdcg atoms2pd --potential`");
  if (b.units == UnitStyle::none)
    refuse("unit style `none` has no LAMMPS equivalent", "units", "none",
           "a LAMMPS unit style (lj, metal, real, si)",
           "add a `units` command to the potential commands and rebuild the body");
  if (b.statistics)
    refuse("a statistical body cannot be exported to LAMMPS", "kind",
           std::string(body::to_string(b.kind)),
           "a delta or rescaled body: the energy of a statistical body is an expectation over "
           "the positions of both atoms of every bond (docs/theory.md §2), which depends on "
           "each atom's covariance and on the bond's direction, not on the distance alone, so "
           "it is no pair potential or EAM model LAMMPS can evaluate",
           "export the delta body (or its rescaled form) and let LAMMPS sample the temperature");
  for (const auto& line : b.potential_spec.lines)
    if (line.rfind("kspace_style", 0) == 0)
      refuse("a long-range k-space term cannot be exported", "kspace_style", line,
             "short-range interactions only: a pair table ends at a finite cutoff, and the "
             "rescaled long-range sum is not a LAMMPS k-space style",
             "export a model without kspace_style");
  if (!b.families.bond_type.empty() || !b.families.pair_factor.empty())
    refuse("molecular bonds and special_bonds factors are not exported (not implemented)",
           "bond_style",
           b.potential_spec.bond_style.empty() ? "special_bonds" : b.potential_spec.bond_style,
           "a body without molecular bonds: the rescaled bond energies would need the Bonds "
           "topology and a bond_style table, which export-lammps does not write yet",
           "export a body without bonds");
  const auto& base = b.base_potential ? *b.base_potential : *b.potential;
  if (base.pairwise() || base.eam_view()) return;
  if (base.style().find("(embedded LAMMPS)") != std::string::npos)
    refuse(
        "pair styles evaluated through embedded LAMMPS are not exported (not implemented)",
        "pair_style", base.style(),
        "a native pair style (lj/cut, morse, zero) or native EAM: the embedded fallback does not "
        "declare its energy a sum of pair terms to the exporter, so it cannot be tabulated "
        "safely (a many-body style tabulated as pairs would be silently wrong)",
        "for a rescaled pair style, run the rescaled model with `pdcg md`; for ε = 1, run "
        "LAMMPS on the original pair_style");
  refuse("the potential cannot be represented in LAMMPS after rescaling", "pair_style",
         base.style(),
         "a pair potential (ψ_k = ½Σφ(r): pair_style table) or native EAM (eam, eam/alloy, "
         "eam/fs: setfl file). Three-body and bond-order potentials (sw, tersoff, MEAM, …) have "
         "force states that are not central pair forces (state-based, docs/theory.md §1); "
         "their rescaled energy ε^d ψ(Y/ε) is no LAMMPS pair table, and only some styles "
         "could absorb ε into their parameters",
         "run the rescaled model with `pdcg md`, or export the delta body (ε = 1) by running "
         "LAMMPS on the original potential");
}

namespace {

/// The pair tables: common N for every type pair (LAMMPS's pair_style table has one length).
std::vector<PairTable> write_tables(const body::Body& b, const LammpsExportOptions& o,
                                    const std::filesystem::path& file, double d_min,
                                    std::int64_t& n_out, std::string_view source) {
  const PairProbe probe{*b.potential};
  const int nt = b.potential->ntypes();
  const double rc = b.potential->cutoff() * (1.0 + 1e-9);
  const double r_lo = o.table_inner > 0.0 ? o.table_inner : o.table_inner_fraction * d_min;
  if (!(r_lo > 0.0) || !(r_lo < rc))
    throw InputError("bad inner end of the pair tables")
        .source(source)
        .key("--table-inner")
        .value(fmt::format("{}", r_lo))
        .expected(fmt::format("0 < r_lo < the cutoff {} (the closest reference pair is {})",
                              b.potential->cutoff(), d_min))
        .fix("give --table-inner below the closest pair distance");
  if (r_lo > d_min)
    log::warn(
        "{}: the tables start at r = {} beyond the closest reference pair {}: LAMMPS stops "
        "with \"Pair distance < table inner cutoff\"",
        source, r_lo, d_min);
  std::vector<PairSetup> setups;
  for (int a = 1; a <= nt; ++a)
    for (int c = a; c <= nt; ++c) {
      auto s = pair_setup(probe, a, c, r_lo, rc, source);
      double e, f;
      if (!s.zero) {
        probe.eval(a, c, s.r_lo, e, f);
        if (!std::isfinite(e) || !std::isfinite(f))
          throw InputError("the pair potential is not finite at the inner end of the table")
              .source(source)
              .key(fmt::format("types {} {}", a, c))
              .value(fmt::format("E({}) = {}, F = {}", s.r_lo, e, f))
              .expected("finite energies and forces from the inner end to the cutoff")
              .fix("give a larger --table-inner");
      }
      setups.push_back(s);
    }
  const int order = o.table_style == TableStyle::spline ? 4 : 2;
  std::int64_t n = 1000;
  std::vector<Errors> errs(setups.size());
  for (int attempt = 0;; ++attempt) {
    double worst = 0.0;
    for (std::size_t i = 0; i < setups.size(); ++i) {
      const auto st = for_points(setups[i], n);
      const auto k = knots(probe, st, n);
      errs[i] = table_errors(probe, st, interpolant(st, k, o.table_style), d_min);
      worst = std::max({worst, errs[i].force, errs[i].energy});
    }
    log::info("{}: pair tables of {} points: interpolation error {:.3g} (tolerance {:.3g})", source,
              n, worst, o.table_tolerance);
    if (worst <= o.table_tolerance) break;
    if (n >= o.max_table_points || attempt > 12)
      throw InputError("the pair tables cannot reach the interpolation tolerance")
          .source(source)
          .key("--table-tolerance")
          .value(fmt::format("{:.3g} (error {:.3g} with {} points)", o.table_tolerance, worst, n))
          .expected(fmt::format("a tolerance reachable with at most {} points", o.max_table_points))
          .fix(
              "raise --table-tolerance, use --table-style spline (4th order), or start the "
              "tables further out (--table-inner)");
    // error ∝ N^−order: the N that meets the tolerance with 20 % margin, at least 1.5 N
    const double grow = std::pow(1.2 * worst / o.table_tolerance, 1.0 / order);
    n = std::min(o.max_table_points, static_cast<std::int64_t>(
                                         std::ceil(static_cast<double>(n) * std::max(grow, 1.5))));
  }
  n_out = n;

  io::AtomicTextFile out(file);
  auto& s = out.stream();
  std::vector<PairTable> tables;
  s << "# " << header(b, o, source) << "\n";
  s << fmt::format(
      "# pair potential E(r) of the body's {} ({}), F = -dE/dr; units {}: r [{}], E [{}], F [{}]\n",
      b.kind == body::BodyKind::rescaled ? "rescaled potential eps^d phi(r/eps)" : "potential",
      b.potential->style(), to_string(b.units), unit_names(b.units).length,
      unit_names(b.units).energy, unit_names(b.units).force);
  s << fmt::format(
      "# for pair_style table {} {}: interpolation error |dF| <= err_F max(|F(r)|, F_scale), "
      "|dE| <= err_E max(|E(r)|, E_scale) at every r of the table\n",
      o.table_style == TableStyle::spline ? "spline" : "linear", n);
  for (std::size_t i = 0; i < setups.size(); ++i) {
    const auto st = for_points(setups[i], n);
    PairTable t;
    t.type_i = st.a;
    t.type_j = st.b;
    t.keyword = fmt::format("PAIR_{}_{}", st.a, st.b);
    t.r_lo = st.r_lo;
    t.r_cut = st.r_cut;
    t.points = n;
    t.force_error = errs[i].force;
    t.energy_error = errs[i].energy;
    t.force_scale = errs[i].force_scale;
    t.energy_scale = errs[i].energy_scale;
    const auto k = knots(probe, st, n);
    s << fmt::format(
        "\n# types {} {}: err_F {:.3g} (F_scale {:.6g}), err_E {:.3g} (E_scale {:.6g}){}\n", st.a,
        st.b, t.force_error, t.force_scale, t.energy_error, t.energy_scale,
        st.zero ? "; no interaction" : "");
    s << t.keyword << "\n";
    s << fmt::format("N {} RSQ {:.17g} {:.17g} FPRIME {:.17g} {:.17g}\n\n", n, st.r_lo, st.r_cut,
                     k.fplo, k.fphi);
    for (std::size_t m = 0; m < k.r.size(); ++m)
      s << fmt::format("{} {:.17g} {:.17g} {:.17g}\n", m + 1, k.r[m], k.e[m], k.f[m]);
    tables.push_back(t);
  }
  out.commit();
  return tables;
}

/// setfl file of the (rescaled) EAM model: F_ε = ε^d F on the same ρ grid, ρ_ε(r) = ρ(r/ε) and
/// r·φ_ε(r) = ε^(d+1) (r·φ)(r/ε) on the grid ε·dr (values of the base tables at their knots).
/// One element per LAMMPS type (its mass is the element's: eam/alloy sets type masses).
std::string write_setfl(const body::Body& b, const LammpsExportOptions& o,
                        const std::filesystem::path& file, const LammpsExport& ex,
                        std::string_view source) {
  const auto& base = b.base_potential ? *b.base_potential : *b.potential;
  const auto& v = *base.eam_view();
  const double eps = b.epsilon;
  const double fs = std::pow(eps, b.dimension), zs = std::pow(eps, b.dimension + 1);
  const int n = static_cast<int>(ex.body_type_of_lammps_type.size()) - 1;
  const int stride = v.ntypes + 1;
  auto rho_of = [&](int jt, int kt) { return v.rhor[static_cast<std::size_t>(jt * stride + kt)]; };
  // eam/alloy when every density depends on the emitting type only
  bool fs_form = false;
  for (int jt = 1; jt <= v.ntypes; ++jt)
    for (int kt = 1; kt <= v.ntypes; ++kt)
      for (int m = 1; m <= v.nr && !fs_form; ++m)
        fs_form = rho_of(jt, kt)[7 * m + 6] != rho_of(jt, 1)[7 * m + 6];
  const double dr = eps / v.rdr, drho = 1.0 / v.rdrho, cut = eps * std::sqrt(v.cutforcesq);
  io::AtomicTextFile out(file);
  auto& s = out.stream();
  s << "# " << header(b, o, source) << "\n";
  s << fmt::format("# {}: F x eps^d = {:.17g}, rho(r/eps), r*phi x eps^(d+1) = {:.17g}, dr x eps\n",
                   base.style(), fs, zs);
  s << "# one element per LAMMPS atom type (the element's mass is the type's point mass)\n";
  s << n;
  for (int t = 1; t <= n; ++t) s << " T" << t;
  s << "\n";
  s << fmt::format("{} {:.17g} {} {:.17g} {:.17g}\n", v.nrho, drho, v.nr, dr, cut);
  auto column = [&](const double* rows, int count, double scale) {
    for (int m = 1; m <= count; ++m)
      s << fmt::format("{:.17g}{}", scale * rows[7 * m + 6], m % 5 == 0 || m == count ? "\n" : " ");
  };
  for (int t = 1; t <= n; ++t) {
    const int bt = ex.body_type_of_lammps_type[static_cast<std::size_t>(t)];
    s << fmt::format("0 {:.17g} 0 none\n", ex.lammps_type_mass[static_cast<std::size_t>(t)]);
    column(v.frho[static_cast<std::size_t>(bt)], v.nrho, fs);
    if (fs_form)
      for (int u = 1; u <= n; ++u)
        column(rho_of(bt, ex.body_type_of_lammps_type[static_cast<std::size_t>(u)]), v.nr, 1.0);
    else
      column(rho_of(bt, 1), v.nr, 1.0);
  }
  for (int t = 1; t <= n; ++t)
    for (int u = 1; u <= t; ++u) {
      const int bt = ex.body_type_of_lammps_type[static_cast<std::size_t>(t)],
                bu = ex.body_type_of_lammps_type[static_cast<std::size_t>(u)];
      column(v.z2r[static_cast<std::size_t>(bt * stride + bu)], v.nr, zs);
    }
  out.commit();
  return fs_form ? "eam/fs" : "eam/alloy";
}

/// The pair commands of lj/cut or morse with rescaled coefficients (φ_ε(r) = ε^d φ(r/ε)):
/// lj/cut ε_LJ → ε^d ε_LJ, σ → εσ; morse D0 → ε^d D0, α → α/ε, r0 → ε r0; every cutoff → ε r_c.
/// Needs the LAMMPS types to be the body's types (one mass per type, every type present).
std::string native_pair_lines(const body::Body& b, const LammpsExport& ex,
                              std::string_view source) {
  // a body stores its potential as command lines: the pair_style first, then the parsed spec
  std::string style, text;
  for (const auto& l : b.potential_spec.lines) {
    text += l + "\n";
    std::istringstream words(l);
    std::string cmd;
    if (words >> cmd && cmd == "pair_style") words >> style;
  }
  auto refuse = [&](std::string why) {
    throw InputError("the pair potential cannot be written as its own LAMMPS style")
        .source(source)
        .key("--pair native")
        .value(style.empty() ? std::string("no pair_style") : style)
        .expected(why)
        .fix("use --pair table (the default)");
  };
  const bool lj = style == "lj/cut", morse = style == "morse";
  if (!lj && !morse) refuse("pair_style lj/cut or morse (their rescaled coefficients are known)");
  const auto spec = atomistic::read_potential_commands_from_string(
      text, b.potential_spec.source.empty() ? source : std::string_view(b.potential_spec.source),
      b.potential_spec.ntypes);
  const double eps = b.epsilon, ed = std::pow(eps, b.dimension);
  if (!spec.bond_style.empty()) refuse("no bond_style");
  const int n = static_cast<int>(ex.body_type_of_lammps_type.size()) - 1;
  bool identity = n == spec.ntypes;
  for (int t = 1; t <= n && identity; ++t)
    identity = ex.body_type_of_lammps_type[static_cast<std::size_t>(t)] == t;
  if (!identity)
    refuse(
        "one LAMMPS type per body type (every type present, one point mass per type): the "
        "pair_coeff lines name the body's types");
  auto num = [&](const atomistic::CoeffLine& c, std::size_t k) {
    try {
      return std::stod(c.args.at(k));
    } catch (const std::exception&) {
      throw InputError("not a number").source(spec.source).line(c.line_number).value(c.line);
    }
  };
  std::string out = "pair_style " + spec.pair_style;
  for (const auto& a : spec.pair_style_args) out += fmt::format(" {:.17g}", eps * std::stod(a));
  out += "\n";
  for (const auto& c : spec.pair_coeff) {
    out += fmt::format("pair_coeff {} {}", c.i, c.j);
    if (lj) {
      out += fmt::format(" {:.17g} {:.17g}", ed * num(c, 0), eps * num(c, 1));
      if (c.args.size() > 2) out += fmt::format(" {:.17g}", eps * num(c, 2));
    } else {
      out +=
          fmt::format(" {:.17g} {:.17g} {:.17g}", ed * num(c, 0), num(c, 1) / eps, eps * num(c, 2));
      if (c.args.size() > 3) out += fmt::format(" {:.17g}", eps * num(c, 3));
    }
    out += "\n";
  }
  if (!spec.pair_modify.empty()) {
    out += "pair_modify";
    for (const auto& w : spec.pair_modify) out += " " + w;
    out += "\n";
  }
  return out;
}

}  // namespace

LammpsExport export_lammps(const body::Body& b, std::span<const double> velocities,
                           const std::filesystem::path& dir, const LammpsExportOptions& o,
                           std::string_view source) {
  check_exportable(b, source);
  const std::size_t n = b.size();
  if (!velocities.empty() && velocities.size() != 3 * n)
    throw InputError("velocities do not match the body")
        .source(source)
        .value(fmt::format("{} values", velocities.size()))
        .expected(fmt::format("3 × {} (one velocity per point)", n));
  if (!(o.table_tolerance > 0.0) || !std::isfinite(o.table_tolerance))
    throw InputError("bad table tolerance")
        .key("--table-tolerance")
        .value(fmt::format("{}", o.table_tolerance))
        .expected("a positive relative error, e.g. 1e-10");
  for (double m : b.mass)
    if (!(m > 0.0) || !std::isfinite(m))
      throw InputError("a point has no positive mass")
          .source(source)
          .key("mass")
          .value(fmt::format("{}", m));
  if (b.homogenisation)
    log::warn(
        "{}: homogenised body: its atomic layer is exported (the points `pdcg md` moves); "
        "the continuum points of the homogenisation are not",
        source);
  LammpsExport ex;
  ex.closest_pair = closest_pair(b);
  if (!std::isfinite(ex.closest_pair))
    throw InputError("the body has no pairs within its families")
        .source(source)
        .expected("points with neighbours within the horizon");

  // LAMMPS types: one per (body type, mass), ordered by body type then mass
  std::map<std::pair<int, double>, int> type_of;
  for (std::size_t k = 0; k < n; ++k) type_of.emplace(std::make_pair(b.type[k], b.mass[k]), 0);
  ex.body_type_of_lammps_type.push_back(0);
  ex.lammps_type_mass.push_back(0.0);
  for (auto& [key, t] : type_of) {
    t = static_cast<int>(ex.body_type_of_lammps_type.size());
    ex.body_type_of_lammps_type.push_back(key.first);
    ex.lammps_type_mass.push_back(key.second);
  }
  const int ntypes = static_cast<int>(ex.body_type_of_lammps_type.size()) - 1;
  log::info("{}: {} LAMMPS atom type(s) for the body's types and point masses", source, ntypes);

  std::filesystem::create_directories(dir);
  const std::string prefix = o.prefix;
  const auto& base = b.base_potential ? *b.base_potential : *b.potential;
  const bool eam = !base.pairwise();
  std::string pair_lines;
  if (!eam && o.pair_form == PairForm::native) {
    pair_lines = native_pair_lines(b, ex, source);
    ex.pair_style = pair_lines.substr(11, pair_lines.find('\n') - 11);
  } else if (!eam) {
    std::int64_t npoints = 0;
    const auto table_file = dir / (prefix + ".table");
    ex.tables = write_tables(b, o, table_file, ex.closest_pair, npoints, source);
    ex.files.push_back(table_file);
    ex.pair_style = fmt::format("table {} {}",
                                o.table_style == TableStyle::spline ? "spline" : "linear", npoints);
    pair_lines = "pair_style " + ex.pair_style + "\n";
    for (int i = 1; i <= ntypes; ++i)
      for (int j = i; j <= ntypes; ++j) {
        int a = ex.body_type_of_lammps_type[static_cast<std::size_t>(i)],
            c = ex.body_type_of_lammps_type[static_cast<std::size_t>(j)];
        if (a > c) std::swap(a, c);
        pair_lines += fmt::format("pair_coeff {} {} {} PAIR_{}_{}\n", i, j,
                                  table_file.filename().string(), a, c);
      }
  } else {
    const auto setfl = dir / (prefix + ".eam.setfl");
    ex.pair_style = write_setfl(b, o, setfl, ex, source);
    ex.files.push_back(setfl);
    pair_lines = "pair_style " + ex.pair_style + "\npair_coeff * * " + setfl.filename().string();
    for (int t = 1; t <= ntypes; ++t) pair_lines += fmt::format(" T{}", t);
    pair_lines += "\n";
  }

  // pair commands
  {
    const auto path = dir / (prefix + ".pair");
    io::AtomicTextFile out(path);
    auto& s = out.stream();
    s << "# " << header(b, o, source) << "\n";
    if (!eam && o.pair_form == PairForm::native)
      s << fmt::format("# pair_style {} with rescaled coefficients (eps = {}, d = {}): exact\n",
                       ex.pair_style, b.epsilon, b.dimension);
    if (!eam && o.pair_form == PairForm::table) {
      double ef = 0.0, ee = 0.0;
      for (const auto& t : ex.tables) {
        ef = std::max(ef, t.force_error);
        ee = std::max(ee, t.energy_error);
      }
      s << fmt::format(
          "# tabulation error (as LAMMPS interpolates): forces {:.3g}, energies {:.3g} relative to "
          "max(|value(r)|, its largest magnitude at r >= {:.6g}); tolerance {:.3g}\n",
          ef, ee, ex.closest_pair, o.table_tolerance);
      s << fmt::format(
          "# the tables start at r = {:.6g}: closer pairs stop LAMMPS (\"Pair distance < "
          "table inner cutoff\")\n",
          ex.tables.empty() ? 0.0 : ex.tables.front().r_lo);
    }
    s << pair_lines;
    out.commit();
    ex.files.push_back(path);
  }

  // data file
  atomistic::Box box = b.box;
  std::array<bool, 3> periodic = box.periodic;
  if (b.dimension == 2) periodic[2] = true;  // LAMMPS's 2d: z periodic, no z images
  const double margin = std::max(b.horizon(), 1e-6 * (box.hi - box.lo).norm());
  for (int c = 0; c < 3; ++c) {
    if (periodic[static_cast<std::size_t>(c)] && !(b.dimension == 2 && c == 2)) continue;
    for (std::size_t k = 0; k < n; ++k) {
      box.lo[c] = std::min(box.lo[c], b.x[3 * k + static_cast<std::size_t>(c)] - margin);
      box.hi[c] = std::max(box.hi[c], b.x[3 * k + static_cast<std::size_t>(c)] + margin);
    }
  }
  {
    const auto path = dir / (prefix + ".data");
    io::AtomicTextFile out(path);
    auto& s = out.stream();
    s << "LAMMPS data file: " << header(b, o, source) << "\n\n";
    s << fmt::format("{} atoms\n{} atom types\n\n", n, ntypes);
    s << fmt::format("{:.17g} {:.17g} xlo xhi\n{:.17g} {:.17g} ylo yhi\n{:.17g} {:.17g} zlo zhi\n",
                     box.lo[0], box.hi[0], box.lo[1], box.hi[1], box.lo[2], box.hi[2]);
    if (box.triclinic())
      s << fmt::format("{:.17g} {:.17g} {:.17g} xy xz yz\n", box.xy, box.xz, box.yz);
    s << "\nMasses\n\n";
    for (int t = 1; t <= ntypes; ++t)
      s << fmt::format("{} {:.17g}\n", t, ex.lammps_type_mass[static_cast<std::size_t>(t)]);
    s << "\nAtoms # atomic\n\n";
    atomistic::Box wrap_box = b.box;
    wrap_box.periodic = b.box.periodic;
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d x(b.x[3 * k], b.x[3 * k + 1], b.x[3 * k + 2]);
      Eigen::Vector3i image(0, 0, 0);
      const Eigen::Vector3d w = wrap_box.wrap(x, image);
      s << fmt::format("{} {} {:.17g} {:.17g} {:.17g} {} {} {}\n", b.id[k],
                       type_of.at({b.type[k], b.mass[k]}), w[0], w[1], w[2], image[0], image[1],
                       image[2]);
    }
    s << "\nVelocities\n\n";
    for (std::size_t k = 0; k < n; ++k) {
      const double* vk = velocities.empty() ? nullptr : velocities.data() + 3 * k;
      s << fmt::format("{} {:.17g} {:.17g} {:.17g}\n", b.id[k], vk ? vk[0] : 0.0, vk ? vk[1] : 0.0,
                       vk ? vk[2] : 0.0);
    }
    out.commit();
    ex.files.push_back(path);
  }

  // input script
  {
    const auto path = dir / ("in." + prefix);
    io::AtomicTextFile out(path);
    auto& s = out.stream();
    auto bnd = [&](int c) { return periodic[static_cast<std::size_t>(c)] ? "p" : "m"; };
    s << "# " << header(b, o, source) << "\n";
    s << fmt::format(
        "# Run in this directory: lmp -in in.{} [-var steps N] [-var dt DT] "
        "[-var dump_every K]\n",
        prefix);
    s << "# The body's points are the atoms; velocity Verlet (fix nve) is the integrator of "
         "`pdcg md`.\n# LAMMPS rebuilds neighbour lists; a PD body keeps its reference families "
         "(docs/dynamics.md).\n";
    s << fmt::format("units {}\ndimension {}\nboundary {} {} {}\natom_style atomic\n",
                     to_string(b.units), b.dimension == 2 ? 2 : 3, bnd(0), bnd(1), bnd(2));
    s << fmt::format("read_data {}.data\ninclude {}.pair\n", prefix, prefix);
    s << "neigh_modify every 1 delay 0 check yes\n";
    s << fmt::format(
        "variable dt index {:.17g}\nvariable steps index {}\nvariable dump_every "
        "index 0\n",
        o.dt, o.steps);
    s << "timestep ${dt}\nfix integrate all nve\n";
    if (b.dimension == 2) s << "fix plane all enforce2d\n";
    s << "thermo_style custom step time ke pe etotal\nthermo_modify format float %.15g\n"
         "thermo 100\n";
    s << "if \"${dump_every} > 0\" then &\n"
         "  \"dump trajectory all custom ${dump_every} trajectory.dump id type xu yu zu vx vy vz\" "
         "&\n"
         "  \"dump_modify trajectory format float %.17g sort id\"\n";
    s << "run ${steps}\n";
    out.commit();
    ex.files.push_back(path);
  }
  return ex;
}

}  // namespace pdcg::dynamics
