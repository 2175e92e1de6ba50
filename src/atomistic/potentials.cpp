// Native potentials: pointwise laws (pair, bond, EAM tables) separate from the family loops.
#include "pdcg/atomistic/potentials.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

#include "eam_tables.hpp"
#include "manybody.hpp"
#include "pdcg/atomistic/eam_spline.hpp"
#include "pdcg/atomistic/lammps_potential.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parse.hpp"

namespace pdcg::atomistic {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

InputError coeff_error(const PotentialSpec& spec, const CoeffLine& c, std::string_view cmd,
                       std::string problem) {
  InputError e(std::move(problem));
  e.source(spec.source).line(c.line_number).key(cmd);
  return e;
}

double number(const PotentialSpec& spec, const CoeffLine& c, std::size_t k, std::string_view field,
              std::string_view cmd = "pair_coeff") {
  const std::string key = std::string(cmd) + " " + std::string(field);
  return parse_double(c.args[k], {spec.source, c.line_number, key});
}

// ---------------------------------------------------------------------------------------
// Pair laws: coefficients per type pair; eval gives φ (shifted) and fpair = −φ'(r)/r, both
// without the special factor, with LAMMPS's operation order.

struct LJCut {
  struct Coeff {
    double cutsq = 0, lj1 = 0, lj2 = 0, lj3 = 0, lj4 = 0, offset = 0;
  };
  static void eval(const Coeff& c, double rsq, double& e, double& fpair) {
    const double r2inv = 1.0 / rsq;
    const double r6inv = r2inv * r2inv * r2inv;
    const double forcelj = r6inv * (c.lj1 * r6inv - c.lj2);
    fpair = forcelj * r2inv;
    e = r6inv * (c.lj3 * r6inv - c.lj4) - c.offset;
  }
  /// h = (d fpair/dr)/r:  fpair = lj1 r⁻¹⁴ − lj2 r⁻⁸  →  h = (−14 lj1 r⁻¹⁶ + 8 lj2 r⁻¹⁰).
  static double dfpair(const Coeff& c, double rsq) {
    const double r2inv = 1.0 / rsq;
    const double r6inv = r2inv * r2inv * r2inv;
    return r6inv * r2inv * r2inv * (-14.0 * c.lj1 * r6inv + 8.0 * c.lj2);
  }
};

struct Morse {
  struct Coeff {
    double cutsq = 0, d0 = 0, alpha = 0, r0 = 0, morse1 = 0, offset = 0;
  };
  static void eval(const Coeff& c, double rsq, double& e, double& fpair) {
    const double r = std::sqrt(rsq);
    const double dr = r - c.r0;
    const double dexp = std::exp(-c.alpha * dr);
    fpair = c.morse1 * (dexp * dexp - dexp) / r;
    e = c.d0 * (dexp * dexp - 2.0 * dexp) - c.offset;
  }
  /// h = (d fpair/dr)/r with fpair = morse1 (d² − d)/r, d = exp(−α(r − r0)), d' = −α d.
  static double dfpair(const Coeff& c, double rsq) {
    const double r = std::sqrt(rsq);
    const double dexp = std::exp(-c.alpha * (r - c.r0));
    const double g = dexp * dexp - dexp;
    const double gp = c.alpha * (dexp - 2.0 * dexp * dexp);
    return c.morse1 * (gp / r - g / rsq) / r;
  }
};

struct Zero {
  struct Coeff {
    double cutsq = 0;
  };
  static void eval(const Coeff&, double, double& e, double& fpair) { e = fpair = 0.0; }
  static double dfpair(const Coeff&, double) { return 0.0; }
};

/// Adds s I + c Y⊗Y to the 3×3 block `k` (row-major): the tangent of t = s(r) Y with
/// c = (ds/dr)/r.
inline void add_radial_block(double* k, const double* y, double s, double c) {
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) k[3 * a + b] += c * y[a] * y[b] + (a == b ? s : 0.0);
}

enum class Mix { geometric, arithmetic, sixthpower };

// Pair::mix_energy / Pair::mix_distance
double mix_energy(Mix m, double eps1, double eps2, double sig1, double sig2) {
  if (m == Mix::sixthpower)
    return (2.0 * std::sqrt(eps1 * eps2) * std::pow(sig1, 3.0) * std::pow(sig2, 3.0) /
            (std::pow(sig1, 6.0) + std::pow(sig2, 6.0)));
  return std::sqrt(eps1 * eps2);
}
double mix_distance(Mix m, double sig1, double sig2) {
  if (m == Mix::geometric) return std::sqrt(sig1 * sig2);
  if (m == Mix::arithmetic) return (0.5 * (sig1 + sig2));
  return std::pow((0.5 * (std::pow(sig1, 6.0) + std::pow(sig2, 6.0))), 1.0 / 6.0);
}

struct Modify {
  bool shift = false;
  Mix mix = Mix::geometric;
};
Modify pair_modify(const PotentialSpec& spec) {
  Modify m;
  const auto& w = spec.pair_modify;
  for (std::size_t k = 0; k + 1 < w.size(); ++k) {
    if (w[k] == "shift") m.shift = w[k + 1] == "yes";
    if (w[k] == "mix")
      m.mix = w[k + 1] == "arithmetic"   ? Mix::arithmetic
              : w[k + 1] == "sixthpower" ? Mix::sixthpower
                                         : Mix::geometric;
  }
  return m;
}

/// Per type pair table, symmetric, (ntypes+1)² entries.
template <class C>
struct TypeTable {
  int n = 0;
  std::vector<C> v;
  std::vector<char> set;
  explicit TypeTable(int ntypes = 0)
      : n(ntypes), v(static_cast<std::size_t>((ntypes + 1) * (ntypes + 1))), set(v.size(), 0) {}
  C& operator()(int i, int j) { return v[static_cast<std::size_t>(i * (n + 1) + j)]; }
  const C& operator()(int i, int j) const { return v[static_cast<std::size_t>(i * (n + 1) + j)]; }
  char& is_set(int i, int j) { return set[static_cast<std::size_t>(i * (n + 1) + j)]; }
  char is_set(int i, int j) const { return set[static_cast<std::size_t>(i * (n + 1) + j)]; }
};

double global_cutoff(const PotentialSpec& spec, std::string_view style) {
  if (spec.pair_style_args.size() < 1)
    throw InputError("pair_style needs a global cutoff")
        .source(spec.source)
        .line(spec.pair_style_line)
        .key("pair_style")
        .value(spec.pair_style)
        .expected(std::string("pair_style ") + std::string(style) + " CUTOFF");
  const double rc = parse_double(spec.pair_style_args[0],
                                 {spec.source, spec.pair_style_line, "pair_style cutoff"});
  if (!(rc > 0.0))
    throw InputError("pair_style cutoff must be positive")
        .source(spec.source)
        .line(spec.pair_style_line)
        .key("pair_style")
        .value(spec.pair_style_args[0])
        .expected("a positive distance");
  return rc;
}

/// Loops over pair_coeff I J ranges as LAMMPS does: i in [ilo,ihi], j in [max(jlo,i), jhi].
template <class F>
void for_pairs(const PotentialSpec& spec, const CoeffLine& c, F&& f) {
  int ilo, ihi, jlo, jhi;
  parse_type_range(c.i, spec.ntypes, ilo, ihi, spec.source, c.line_number, "pair_coeff");
  parse_type_range(c.j, spec.ntypes, jlo, jhi, spec.source, c.line_number, "pair_coeff");
  int count = 0;
  for (int i = ilo; i <= ihi; ++i)
    for (int j = std::max(jlo, i); j <= jhi; ++j) {
      f(i, j);
      ++count;
    }
  if (count == 0)
    throw InputError("pair_coeff sets no type pair")
        .source(spec.source)
        .line(c.line_number)
        .key("pair_coeff")
        .value(c.line)
        .expected("I <= J");
}

void check_args(const PotentialSpec& spec, const CoeffLine& c, std::size_t lo, std::size_t hi,
                std::string_view usage) {
  if (c.args.size() < lo || c.args.size() > hi)
    throw coeff_error(spec, c, "pair_coeff", "wrong number of coefficients")
        .value(c.line)
        .expected(usage);
}

/// Every type t has its own pair_coeff t t (is_set of the table marks the pairs the lines
/// gave; the mixed I ≠ J pairs follow from these).
template <class C>
void require_all_set(const PotentialSpec& spec, const TypeTable<C>& table, std::string_view style) {
  for (int t = 1; t <= spec.ntypes; ++t)
    if (!table.is_set(t, t))
      throw InputError("pair coefficients missing for an atom type")
          .source(spec.source)
          .key("pair_coeff")
          .value(std::to_string(t) + " " + std::to_string(t))
          .expected(std::string("a pair_coeff line for every type (") + std::string(style) + ")")
          .fix("add 'pair_coeff " + std::to_string(t) + " " + std::to_string(t) + " …'");
}

/// Pair::init: init_one(i, j) for every type pair i ≤ j, which sets the coefficients of (i, j)
/// and (j, i) and returns their cutoff; the largest is the style's cutoff (LAMMPS's cutforce).
template <class InitOne>
double init_pairs(int ntypes, InitOne&& init_one) {
  double cutmax = 0.0;
  for (int i = 1; i <= ntypes; ++i)
    for (int j = i; j <= ntypes; ++j) cutmax = std::max(cutmax, init_one(i, j));
  return cutmax;
}

TypeTable<LJCut::Coeff> build_lj(const PotentialSpec& spec, double& cutmax) {
  const int n = spec.ntypes;
  const double cut_global = global_cutoff(spec, "lj/cut");
  const Modify mod = pair_modify(spec);
  TypeTable<double> eps(n), sig(n), cut(n);
  for (const auto& c : spec.pair_coeff) {
    check_args(spec, c, 2, 3, "pair_coeff I J EPSILON SIGMA [CUTOFF]");
    const double e = number(spec, c, 0, "epsilon"), s = number(spec, c, 1, "sigma");
    const double rc = c.args.size() == 3 ? number(spec, c, 2, "cutoff") : cut_global;
    for_pairs(spec, c, [&](int i, int j) {
      eps(i, j) = e;
      sig(i, j) = s;
      cut(i, j) = rc;
      eps.is_set(i, j) = 1;
    });
  }
  require_all_set(spec, eps, "lj/cut");
  TypeTable<LJCut::Coeff> out(n);
  cutmax = init_pairs(n, [&](int i, int j) {
    // PairLJCut::init_one
    if (!eps.is_set(i, j)) {
      eps(i, j) = mix_energy(mod.mix, eps(i, i), eps(j, j), sig(i, i), sig(j, j));
      sig(i, j) = mix_distance(mod.mix, sig(i, i), sig(j, j));
      cut(i, j) = mix_distance(mod.mix, cut(i, i), cut(j, j));
    }
    LJCut::Coeff c;
    c.lj1 = 48.0 * eps(i, j) * std::pow(sig(i, j), 12.0);
    c.lj2 = 24.0 * eps(i, j) * std::pow(sig(i, j), 6.0);
    c.lj3 = 4.0 * eps(i, j) * std::pow(sig(i, j), 12.0);
    c.lj4 = 4.0 * eps(i, j) * std::pow(sig(i, j), 6.0);
    if (mod.shift && (cut(i, j) > 0.0)) {
      const double ratio = sig(i, j) / cut(i, j);
      c.offset = 4.0 * eps(i, j) * (std::pow(ratio, 12.0) - std::pow(ratio, 6.0));
    } else {
      c.offset = 0.0;
    }
    c.cutsq = cut(i, j) * cut(i, j);
    out(i, j) = out(j, i) = c;
    return cut(i, j);
  });
  return out;
}

TypeTable<Morse::Coeff> build_morse(const PotentialSpec& spec, double& cutmax) {
  const int n = spec.ntypes;
  const double cut_global = global_cutoff(spec, "morse");
  const Modify mod = pair_modify(spec);
  TypeTable<Morse::Coeff> out(n);
  for (const auto& c : spec.pair_coeff) {
    check_args(spec, c, 3, 4, "pair_coeff I J D0 ALPHA R0 [CUTOFF]");
    Morse::Coeff m;
    m.d0 = number(spec, c, 0, "d0");
    m.alpha = number(spec, c, 1, "alpha");
    m.r0 = number(spec, c, 2, "r0");
    const double rc = c.args.size() == 4 ? number(spec, c, 3, "cutoff") : cut_global;
    m.cutsq = rc;  // holds the cutoff until init below
    for_pairs(spec, c, [&](int i, int j) {
      out(i, j) = m;
      out.is_set(i, j) = 1;
    });
  }
  cutmax = init_pairs(n, [&](int i, int j) {
    // PairMorse::init_one: no mixing
    if (!out.is_set(i, j))
      throw InputError("morse coefficients missing for a type pair (LAMMPS does not mix morse)")
          .source(spec.source)
          .key("pair_coeff")
          .value(std::to_string(i) + " " + std::to_string(j))
          .expected("a pair_coeff line for every type pair I <= J");
    Morse::Coeff m = out(i, j);
    const double rc = m.cutsq;
    m.morse1 = 2.0 * m.d0 * m.alpha;
    if (mod.shift) {
      const double alpha_dr = -m.alpha * (rc - m.r0);
      m.offset = m.d0 * (std::exp(2.0 * alpha_dr) - 2.0 * std::exp(alpha_dr));
    } else {
      m.offset = 0.0;
    }
    m.cutsq = rc * rc;
    out(i, j) = out(j, i) = m;
    return rc;
  });
  return out;
}

TypeTable<Zero::Coeff> build_zero(const PotentialSpec& spec, double& cutmax) {
  const int n = spec.ntypes;
  const double cut_global = global_cutoff(spec, "zero");
  const bool nocoeff = spec.pair_style_args.size() > 1 && spec.pair_style_args[1] == "nocoeff";
  TypeTable<double> cut(n);
  for (const auto& c : spec.pair_coeff) {
    const double rc = (!nocoeff && c.args.size() >= 1) ? number(spec, c, 0, "cutoff") : cut_global;
    for_pairs(spec, c, [&](int i, int j) {
      cut(i, j) = rc;
      cut.is_set(i, j) = 1;
    });
  }
  require_all_set(spec, cut, "zero");
  TypeTable<Zero::Coeff> out(n);
  cutmax = init_pairs(n, [&](int i, int j) {
    if (!cut.is_set(i, j)) cut(i, j) = mix_distance(pair_modify(spec).mix, cut(i, i), cut(j, j));
    out(i, j).cutsq = out(j, i).cutsq = cut(i, j) * cut(i, j);
    return cut(i, j);
  });
  return out;
}

// ---------------------------------------------------------------------------------------
// Bond laws: E_b(r) and fbond = −E_b'(r)/r (LAMMPS BondHarmonic / BondFENE).

struct BondTable {
  enum class Style { none, harmonic, fene, zero } style = Style::none;
  struct Coeff {
    double k = kNaN, r0 = kNaN, epsilon = 0, sigma = 0;
  };
  std::vector<Coeff> c;  // index 1..(largest bond type a bond_coeff names explicitly)
  /// bond_coeff lines with a trailing wildcard (`*`, `N*`), in order: (N, coefficients). They
  /// reach bond types beyond c (LAMMPS: up to the configuration's bond type count; the
  /// potential does not know that count, so any type); the last one with N ≤ type wins.
  std::vector<std::pair<int, Coeff>> open;

  bool active() const { return style != Style::none; }

  const Coeff* coeff(int bt) const {
    if (bt < 1) return nullptr;
    if (bt < static_cast<int>(c.size())) return &c[static_cast<std::size_t>(bt)];
    for (auto it = open.rbegin(); it != open.rend(); ++it)
      if (bt >= it->first) return &it->second;
    return nullptr;
  }

  /// Energy of one bond of type `bt` at squared length rsq; writes fbond.
  double eval(int bt, double rsq, double& fbond) const {
    const Coeff* bp = coeff(bt);
    if (!bp) {
      fbond = kNaN;
      return kNaN;  // bond type without coefficients (make_delta_body refuses those)
    }
    const Coeff& b = *bp;
    switch (style) {
      case Style::harmonic: {
        const double r = std::sqrt(rsq);
        const double dr = r - b.r0;
        const double rk = b.k * dr;
        fbond = r > 0.0 ? -2.0 * rk / r : 0.0;
        return rk * dr;
      }
      case Style::fene: {
        constexpr double TWO_1_3 = 1.2599210498948732;
        const double r0sq = b.r0 * b.r0;
        double rlogarg = 1.0 - rsq / r0sq;
        // LAMMPS warns ("FENE bond too long") and clamps; it aborts for rlogarg <= -3
        if (rlogarg < 0.1) rlogarg = 0.1;
        fbond = -b.k / rlogarg;
        double sr6 = 0.0;
        if (rsq < TWO_1_3 * b.sigma * b.sigma) {
          const double sr2 = b.sigma * b.sigma / rsq;
          sr6 = sr2 * sr2 * sr2;
          fbond += 48.0 * b.epsilon * sr6 * (sr6 - 0.5) / rsq;
        }
        double ebond = -0.5 * b.k * r0sq * std::log(rlogarg);
        if (rsq < TWO_1_3 * b.sigma * b.sigma)
          ebond += 4.0 * b.epsilon * sr6 * (sr6 - 1.0) + b.epsilon;
        return ebond;
      }
      case Style::zero:
        fbond = 0.0;
        return 0.0;
      case Style::none:
        break;
    }
    fbond = 0.0;
    return 0.0;
  }

  /// h = (d fbond/dr)/r for bond type bt at squared length rsq (consistent with eval,
  /// including FENE's clamp of the log argument, where the derivative of the clamped
  /// term is 0).
  double dfbond(int bt, double rsq) const {
    const Coeff* bp = coeff(bt);
    if (!bp) return kNaN;
    const Coeff& b = *bp;
    switch (style) {
      case Style::harmonic: {
        // fbond = −2k(r − r0)/r  →  d fbond/dr = −2k r0/r²
        const double r = std::sqrt(rsq);
        return r > 0.0 ? -2.0 * b.k * b.r0 / (rsq * r) : 0.0;
      }
      case Style::fene: {
        constexpr double TWO_1_3 = 1.2599210498948732;
        const double r0sq = b.r0 * b.r0;
        const double rlogarg = 1.0 - rsq / r0sq;
        double h = 0.0;
        // −k/rlogarg, d/dr = −2k r/(r0² rlogarg²)
        if (rlogarg >= 0.1) h = -2.0 * b.k / (r0sq * rlogarg * rlogarg);
        if (rsq < TWO_1_3 * b.sigma * b.sigma) {
          // 48ε σ¹² r⁻¹⁴ − 24ε σ⁶ r⁻⁸  →  h = (−672 ε sr12 + 192 ε sr6)/r⁴
          const double sr2 = b.sigma * b.sigma / rsq;
          const double sr6 = sr2 * sr2 * sr2;
          h += (-672.0 * b.epsilon * sr6 * sr6 + 192.0 * b.epsilon * sr6) / (rsq * rsq);
        }
        return h;
      }
      case Style::zero:
      case Style::none:
        break;
    }
    return 0.0;
  }

  /// K_bb += ½ ∂²E_b/∂Y∂Y = −½ fbond I − ½ h Y⊗Y for every molecular bond (block-diagonal).
  void add_tangent(const FamilyState& f, double* K) const {
    if (!active() || !f.bond_type) return;
    const std::int64_t n = f.size;
    for (std::int64_t b = 0; b < n; ++b) {
      const int bt = f.bond_type[b];
      if (bt <= 0) continue;
      const double* y = f.bond + 3 * b;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      double fbond;
      eval(bt, rsq, fbond);
      add_radial_block(K + static_cast<std::size_t>((b * n + b) * 9), y, -0.5 * fbond,
                       -0.5 * dfbond(bt, rsq));
    }
  }

  /// ψ += ½ E_b and t += ½ ∂E_b/∂Y = −½ fbond Y for every molecular bond of the family.
  double add(const FamilyState& f, double* t) const {
    if (!active() || !f.bond_type) return 0.0;
    double psi = 0.0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const int bt = f.bond_type[b];
      if (bt <= 0) continue;
      const double* y = f.bond + 3 * b;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      double fbond;
      psi += 0.5 * eval(bt, rsq, fbond);
      const double s = -0.5 * fbond;
      t[3 * b] += s * y[0];
      t[3 * b + 1] += s * y[1];
      t[3 * b + 2] += s * y[2];
    }
    return psi;
  }
};

/// The native bond styles, one line each (docs/potentials.md); any other bond style goes through
/// embedded LAMMPS.
struct NativeBondStyle {
  std::string_view name;
  BondTable::Style style;
};
constexpr NativeBondStyle kNativeBondStyles[] = {
    {"harmonic", BondTable::Style::harmonic},
    {"fene", BondTable::Style::fene},
    {"zero", BondTable::Style::zero},
};

const NativeBondStyle* find_native_bond_style(std::string_view name) {
  for (const auto& e : kNativeBondStyles)
    if (e.name == name) return &e;
  return nullptr;
}

BondTable build_bonds(const PotentialSpec& spec) {
  BondTable bt;
  if (spec.bond_style.empty()) return bt;
  const auto* entry = find_native_bond_style(spec.bond_style);
  if (!entry)
    throw InputError("bond style has no native implementation")
        .source(spec.source)
        .line(spec.bond_style_line)
        .key("bond_style")
        .value(spec.bond_style)
        .expected(native_bond_style_names())
        .fix("evaluate this model through embedded LAMMPS (LammpsEngine)");
  bt.style = entry->style;
  int maxtype = 1;
  for (const auto& c : spec.bond_coeff) {
    int lo, hi;
    parse_type_range(c.i, 1 << 20, lo, hi, spec.source, c.line_number, "bond_coeff");
    if (c.i.find('*') == std::string::npos || !c.i.ends_with('*')) maxtype = std::max(maxtype, hi);
  }
  bt.c.assign(static_cast<std::size_t>(maxtype + 1), {});
  for (const auto& c : spec.bond_coeff) {
    int lo, hi;
    parse_type_range(c.i, 1 << 20, lo, hi, spec.source, c.line_number, "bond_coeff");
    hi = std::min(hi, maxtype);  // a trailing wildcard reaches further through `open`
    BondTable::Coeff k;
    auto usage = [&](std::size_t n, std::string_view u) {
      if (c.args.size() != n)
        throw coeff_error(spec, c, "bond_coeff", "wrong number of coefficients")
            .value(c.line)
            .expected(u);
    };
    if (bt.style == BondTable::Style::harmonic) {
      usage(2, "bond_coeff N K R0");
      k.k = number(spec, c, 0, "K", "bond_coeff");
      k.r0 = number(spec, c, 1, "r0", "bond_coeff");
    } else if (bt.style == BondTable::Style::fene) {
      usage(4, "bond_coeff N K R0 EPSILON SIGMA");
      k.k = number(spec, c, 0, "K", "bond_coeff");
      k.r0 = number(spec, c, 1, "R0", "bond_coeff");
      k.epsilon = number(spec, c, 2, "epsilon", "bond_coeff");
      k.sigma = number(spec, c, 3, "sigma", "bond_coeff");
    } else {
      k.k = k.r0 = 0.0;
    }
    for (int t = lo; t <= hi; ++t) bt.c[static_cast<std::size_t>(t)] = k;
    if (c.i.ends_with('*')) bt.open.emplace_back(lo, k);
  }
  for (std::size_t t = 1; t < bt.c.size(); ++t)
    if (std::isnan(bt.c[t].k))
      throw InputError("bond coefficients missing for a bond type")
          .source(spec.source)
          .key("bond_coeff")
          .value(std::to_string(t))
          .expected("a bond_coeff line for every bond type")
          .fix("add 'bond_coeff " + std::to_string(t) + " …'");
  return bt;
}

std::string style_name(const PotentialSpec& spec) {
  std::string s = spec.pair_style.empty() ? std::string("none") : spec.pair_style;
  if (!spec.bond_style.empty()) s += " + bond " + spec.bond_style;
  return s;
}

// ---------------------------------------------------------------------------------------
// Family loops

/// Atom types outside 1..ntypes cannot be evaluated (and must not index the tables): the
/// family gets NaN energy and force states, which the callers' finiteness checks report.
bool types_out_of_range(const FamilyState& f, int ntypes, double* t) {
  bool bad = f.type < 1 || f.type > ntypes;
  for (std::int64_t b = 0; b < f.size && !bad; ++b)
    bad = f.neighbor_type[b] < 1 || f.neighbor_type[b] > ntypes;
  if (bad) std::fill(t, t + 3 * f.size, kNaN);
  return bad;
}

// The vector LJ kernel (PairModel::half_pair_simd) is compiled for AVX2 + FMA either by the
// build's own -march (PDCG_NATIVE / PDCG_ARCH) or, in the portable default build on x86-64 with
// GCC/Clang, as a function with target("avx2,fma") chosen at run time when the CPU has both
// (function multiversioning by hand). Other CPUs take the scalar loop; results agree to
// round-off (FMA contraction), well inside the 1e-13 of the dynamics tests.
#if !defined(__AVX2__) && defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PDCG_AVX2_DISPATCH 1
#define PDCG_TARGET_AVX2 __attribute__((target("avx2,fma")))
inline bool cpu_has_avx2_fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}
#else
#define PDCG_TARGET_AVX2
constexpr bool cpu_has_avx2_fma() { return true; }
#endif

template <class Law>
class PairModel final : public Potential {
 public:
  PairModel(const PotentialSpec& spec, TypeTable<typename Law::Coeff> table, double cutoff,
            BondTable bonds)
      : style_(style_name(spec)),
        ntypes_(spec.ntypes),
        table_(std::move(table)),
        cutoff_(cutoff),
        bonds_(std::move(bonds)) {}
  std::string style() const override { return style_; }
  double cutoff() const override { return cutoff_; }
  int ntypes() const override { return ntypes_; }
  bool pairwise() const override { return true; }
  bool has_pair_kernel() const override { return !bonds_.active(); }

  double half_pair_forces(const HalfFamilies& h, std::int64_t k0, std::int64_t k1, const double* y,
                          double* f) const override {
    // one type and no special factors (the common case) hoist the coefficient lookup and the
    // factor test out of the pair loop
#if defined(__AVX2__) || defined(PDCG_AVX2_DISPATCH)
    if (std::is_same_v<Law, LJCut> && ntypes_ == 1 && !h.factor && cpu_has_avx2_fma())
      return h.energy ? half_pair_simd<true>(h, k0, k1, y, f)
                      : half_pair_simd<false>(h, k0, k1, y, f);
#endif
    if (!h.energy) {
      if (ntypes_ == 1 && !h.factor) return half_pair_loop<true, false, false>(h, k0, k1, y, f);
      if (!h.factor) return half_pair_loop<false, false, false>(h, k0, k1, y, f);
      return half_pair_loop<false, true, false>(h, k0, k1, y, f);
    }
    if (ntypes_ == 1 && !h.factor) return half_pair_loop<true, false, true>(h, k0, k1, y, f);
    if (!h.factor) return half_pair_loop<false, false, true>(h, k0, k1, y, f);
    return half_pair_loop<false, true, true>(h, k0, k1, y, f);
  }

  /// Vector variant of half_pair_loop (one type, no special factors), chosen when the build
  /// targets AVX2 or wider (PDCG_NATIVE): two passes per block of up to kChunk half bonds of a
  /// point k: (1) the pair law for every bond as the branch-free weight `rsq < cutsq ? 1 : 0`
  /// into per-bond force vectors t (no stores to shared points, so the compiler vectorises it
  /// over bonds: `omp simd`, gathers of the neighbour positions); (2) the scalar scatter
  /// f_j −= t_b, f_k += Σ t_b in bond order (a block may name a point twice through two
  /// images). Same operations per bond as the scalar loop, so the same forces; bonds beyond
  /// the cutoff (the families' skin) cost the law's arithmetic but no branch.
  template <bool kEnergy>
  PDCG_TARGET_AVX2 double half_pair_simd(const HalfFamilies& h, std::int64_t k0, std::int64_t k1,
                                         const double* y, double* f) const {
    constexpr std::int64_t kChunk = 64;
    alignas(64) double tx[kChunk], ty[kChunk], tz[kChunk], te[kChunk];
    const auto c = table_.v[static_cast<std::size_t>(ntypes_ + 2)];  // (1, 1)
    double energy = 0.0;
    for (std::int64_t k = k0; k < k1; ++k) {
      const double xk = y[3 * k], yk = y[3 * k + 1], zk = y[3 * k + 2];
      double fx = 0.0, fy = 0.0, fz = 0.0, e = 0.0;
      for (std::int64_t b0 = h.offset[k]; b0 < h.offset[k + 1]; b0 += kChunk) {
        const std::int64_t m = std::min(kChunk, h.offset[k + 1] - b0);
        const std::int32_t* nb = h.neighbor + b0;
#pragma omp simd reduction(+ : fx, fy, fz)
        for (std::int64_t q = 0; q < m; ++q) {
          const std::int64_t j = nb[q];
          const double dx = y[3 * j] - xk, dy = y[3 * j + 1] - yk, dz = y[3 * j + 2] - zk;
          const double rsq = dx * dx + dy * dy + dz * dz;
          // the law is finite at any r² > 1e-100; w = 0 beyond the cutoff
          const double w = rsq < c.cutsq ? 1.0 : 0.0;
          double ep, fpair;
          Law::eval(c, rsq, ep, fpair);
          const double s = -w * fpair;  // φ'(r)/r
          if constexpr (kEnergy) te[q] = w * ep;
          tx[q] = s * dx;
          ty[q] = s * dy;
          tz[q] = s * dz;
          fx += s * dx;
          fy += s * dy;
          fz += s * dz;
        }
        for (std::int64_t q = 0; q < m; ++q) {
          double* fj = f + 3 * static_cast<std::int64_t>(nb[q]);
          if constexpr (kEnergy) e += te[q];
          fj[0] -= tx[q];
          fj[1] -= ty[q];
          fj[2] -= tz[q];
        }
      }
      f[3 * k] += fx;
      f[3 * k + 1] += fy;
      f[3 * k + 2] += fz;
      energy += e;
    }
    return energy;
  }

  template <bool kSingleType, bool kFactor, bool kEnergy>
  double half_pair_loop(const HalfFamilies& h, std::int64_t k0, std::int64_t k1, const double* y,
                        double* f) const {
    const int n1 = ntypes_ + 1;
    double energy = 0.0;
    const auto c1 =
        kSingleType ? table_.v[static_cast<std::size_t>(n1 + 1)] : typename Law::Coeff{};  // (1, 1)
    for (std::int64_t k = k0; k < k1; ++k) {
      const double xk = y[3 * k], yk = y[3 * k + 1], zk = y[3 * k + 2];
      const auto* row = table_.v.data() + h.type[k] * n1;
      double fx = 0.0, fy = 0.0, fz = 0.0, e = 0.0;
      const std::int32_t* nb = h.neighbor;
      for (std::int64_t b = h.offset[k], b1 = h.offset[k + 1]; b < b1; ++b) {
        const std::int64_t j = nb[b];
        const double* yj = y + 3 * j;
        const double dx = yj[0] - xk, dy = yj[1] - yk, dz = yj[2] - zk;
        const double rsq = dx * dx + dy * dy + dz * dz;
        const auto& c = kSingleType ? c1 : row[h.type[j]];
        const double factor = kFactor ? h.factor[b] : 1.0;
        if ((!kFactor || factor != 0.0) && rsq < c.cutsq) {
          double ep, fpair;
          Law::eval(c, rsq, ep, fpair);
          const double s = kFactor ? -factor * fpair : -fpair;  // φ'(r)/r
          if constexpr (kEnergy) e += kFactor ? factor * ep : ep;
          const double sx = s * dx, sy = s * dy, sz = s * dz;
          fx += sx;
          fy += sy;
          fz += sz;
          double* fj = f + 3 * j;
          fj[0] -= sx;
          fj[1] -= sy;
          fj[2] -= sz;
        }
      }
      f[3 * k] += fx;
      f[3 * k + 1] += fy;
      f[3 * k + 2] += fz;
      energy += e;
    }
    return energy;
  }

  double force_state(const FamilyState& f, double* t) const override {
    if (types_out_of_range(f, ntypes_, t)) return kNaN;
    double psi = 0.0;
    const int n1 = ntypes_ + 1;
    const auto* row = table_.v.data() + f.type * n1;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      const double factor = f.pair_factor ? f.pair_factor[b] : 1.0;
      const auto& c = row[f.neighbor_type[b]];
      double s = 0.0;
      if (factor != 0.0 && rsq < c.cutsq) {
        double e, fpair;
        Law::eval(c, rsq, e, fpair);
        psi += 0.5 * factor * e;
        s = -0.5 * factor * fpair;  // ½ φ'(r)/r
      }
      t[3 * b] = s * y[0];
      t[3 * b + 1] = s * y[1];
      t[3 * b + 2] = s * y[2];
    }
    return psi + bonds_.add(f, t);
  }

  /// Analytic: K_jj = ½ factor [φ'/r I + (d(φ'/r)/dr)/r Y⊗Y] (+ bonds), K_jm = 0 for j ≠ m.
  void force_state_tangent(const FamilyState& f, double* K, double*) const override {
    const std::int64_t n = f.size;
    std::fill(K, K + static_cast<std::size_t>(n * n * 9), 0.0);
    if (types_out_of_range(f, ntypes_, K)) {
      std::fill(K, K + static_cast<std::size_t>(n * n * 9), kNaN);
      return;
    }
    const int n1 = ntypes_ + 1;
    const auto* row = table_.v.data() + f.type * n1;
    for (std::int64_t b = 0; b < n; ++b) {
      const double* y = f.bond + 3 * b;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      const double factor = f.pair_factor ? f.pair_factor[b] : 1.0;
      const auto& c = row[f.neighbor_type[b]];
      if (factor != 0.0 && rsq < c.cutsq) {
        double e, fpair;
        Law::eval(c, rsq, e, fpair);
        add_radial_block(K + static_cast<std::size_t>((b * n + b) * 9), y, -0.5 * factor * fpair,
                         -0.5 * factor * Law::dfpair(c, rsq));
      }
    }
    bonds_.add_tangent(f, K);
  }

 private:
  std::string style_;
  int ntypes_;
  TypeTable<typename Law::Coeff> table_;
  double cutoff_;
  BondTable bonds_;
};

class EamModel final : public Potential {
 public:
  EamModel(const PotentialSpec& spec, EamTables tables, BondTable bonds)
      : style_(style_name(spec)),
        e_(std::move(tables)),
        bonds_(std::move(bonds)),
        view_(make_eam_view(e_)) {}
  const EamView* eam_view() const override { return bonds_.active() ? nullptr : &view_; }
  std::string style() const override { return style_; }
  double cutoff() const override { return e_.cutmax; }
  int ntypes() const override { return e_.ntypes; }
  std::vector<double> type_masses() const override { return e_.type_mass; }

  double force_state(const FamilyState& f, double* t) const override {
    if (types_out_of_range(f, e_.ntypes, t)) return kNaN;
    const int n1 = e_.ntypes + 1;
    const int kt = f.type;
    // pass 1: host density ρ̄_k = Σ_j ρ_{type(j)→type(k)}(r_kj)
    double rho = 0.0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      if (f.pair_factor && f.pair_factor[b] == 0.0) continue;  // LAMMPS excludes these pairs
      const double* y = f.bond + 3 * b;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      if (rsq < e_.cutforcesq) {
        const int jt = f.neighbor_type[b];
        // LAMMPS's m = min((int) p, nr − 1) and p ≤ 1, without converting a p beyond the int
        // range (a cutoff far past the table) to int: undefined behaviour
        int m = 0;
        bool clamped = false;
        const double p = eam::locate(std::sqrt(rsq), e_.rdr, e_.nr, m, clamped);
        const double* coeff =
            e_.rhor_spline[static_cast<std::size_t>(
                               e_.type2rhor[static_cast<std::size_t>(jt * n1 + kt)])]
                .data() +
            7 * m;
        rho += ((coeff[3] * p + coeff[4]) * p + coeff[5]) * p + coeff[6];
      }
    }
    // embedding energy and F'(ρ̄) (linear beyond ρ_max)
    const eam::Embedding emb = eam::embedding(
        e_.frho_spline[static_cast<std::size_t>(e_.type2frho[static_cast<std::size_t>(kt)])].data(),
        rho, e_.rdrho, e_.nrho, e_.rhomax);
    const double fp = emb.first;
    double psi = emb.value;
    // pass 2: t_kj = (F'_k ρ'_{j→k}(r) + ½ φ'(r)) Y/r, ψ_k += ½ φ(r)
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      double s = 0.0;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      if (rsq < e_.cutforcesq && !(f.pair_factor && f.pair_factor[b] == 0.0)) {
        const int jt = f.neighbor_type[b];
        const double r = std::sqrt(rsq);
        int mm = 0;  // as pass 1: the row without an int conversion of an out-of-range q
        bool clamped = false;
        const double q = eam::locate(r, e_.rdr, e_.nr, mm, clamped);
        const double* c1 = e_.rhor_spline[static_cast<std::size_t>(
                                              e_.type2rhor[static_cast<std::size_t>(jt * n1 + kt)])]
                               .data() +
                           7 * mm;
        const double rhojp = (c1[0] * q + c1[1]) * q + c1[2];
        const double* c2 = e_.z2r_spline[static_cast<std::size_t>(
                                             e_.type2z2r[static_cast<std::size_t>(kt * n1 + jt)])]
                               .data() +
                           7 * mm;
        const double z2p = (c2[0] * q + c2[1]) * q + c2[2];
        const double z2 = ((c2[3] * q + c2[4]) * q + c2[5]) * q + c2[6];
        const double recip = 1.0 / r;
        const double phi = z2 * recip;
        const double phip = z2p * recip - phi * recip;
        psi += 0.5 * phi;
        s = (fp * rhojp + 0.5 * phip) * recip;
      }
      t[3 * b] = s * y[0];
      t[3 * b + 1] = s * y[1];
      t[3 * b + 2] = s * y[2];
    }
    return psi + bonds_.add(f, t);
  }

  /// Analytic second derivative of ψ_k = F_k(ρ̄_k) + ½ Σ_j φ(r_j):
  ///   K_jm = F_k''(ρ̄) g_j g_m e_j⊗e_m
  ///        + δ_jm [ T_j/r I + (T_j'/r − T_j/r²)/r Y_j⊗Y_j ],
  /// T_j = F_k' g_j + ½φ'_j, T_j' = F_k' g_j' + ½φ''_j, g_j = ρ'_{type(j)→type(k)}(r_j).
  /// Second derivatives are those of LAMMPS's cubic spline pieces (d/dr of the derivative
  /// polynomial (c0 q + c1) q + c2, i.e. (2 c0 q + c1)/Δ), 0 where LAMMPS clamps the argument
  /// (beyond the last grid point / ρ_max), so K is the exact derivative of force_state.
  /// Workspace: 3n doubles (g_j e_j).
  void force_state_tangent(const FamilyState& f, double* K, double* work) const override {
    const std::int64_t n = f.size;
    std::fill(K, K + static_cast<std::size_t>(n * n * 9), 0.0);
    if (types_out_of_range(f, e_.ntypes, K)) {
      std::fill(K, K + static_cast<std::size_t>(n * n * 9), kNaN);
      return;
    }
    const int n1 = e_.ntypes + 1;
    const int kt = f.type;
    auto spline_of = [](const std::vector<std::vector<double>>& sp, int which, int m) {
      return sp[static_cast<std::size_t>(which)].data() + 7 * m;
    };
    using eam::locate;
    double rho = 0.0;
    for (std::int64_t b = 0; b < n; ++b) {
      if (f.pair_factor && f.pair_factor[b] == 0.0) continue;
      const double* y = f.bond + 3 * b;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      if (rsq < e_.cutforcesq) {
        const int jt = f.neighbor_type[b];
        int m;
        bool cl;
        const double p = locate(std::sqrt(rsq), e_.rdr, e_.nr, m, cl);
        const double* c =
            spline_of(e_.rhor_spline, e_.type2rhor[static_cast<std::size_t>(jt * n1 + kt)], m);
        rho += ((c[3] * p + c[4]) * p + c[5]) * p + c[6];
      }
    }
    const eam::Embedding emb =
        eam::embedding(spline_of(e_.frho_spline, e_.type2frho[static_cast<std::size_t>(kt)], 0),
                       rho, e_.rdrho, e_.nrho, e_.rhomax);
    const double fp = emb.first, fpp = emb.second;
    double* u = work;  // g_j e_j
    for (std::int64_t b = 0; b < n; ++b) {
      const double* y = f.bond + 3 * b;
      u[3 * b] = u[3 * b + 1] = u[3 * b + 2] = 0.0;
      const double rsq = y[0] * y[0] + y[1] * y[1] + y[2] * y[2];
      if (!(rsq < e_.cutforcesq) || (f.pair_factor && f.pair_factor[b] == 0.0)) continue;
      const int jt = f.neighbor_type[b];
      const double r = std::sqrt(rsq);
      int mm;
      bool cl;
      const double q = locate(r, e_.rdr, e_.nr, mm, cl);
      const double* c1 =
          spline_of(e_.rhor_spline, e_.type2rhor[static_cast<std::size_t>(jt * n1 + kt)], mm);
      const double* c2 =
          spline_of(e_.z2r_spline, e_.type2z2r[static_cast<std::size_t>(kt * n1 + jt)], mm);
      const eam::PairTerms pt = eam::pair_terms(c1, c2, q, cl, r, e_.rdr);
      const double g = pt.g, recip = 1.0 / r;
      const double T = fp * g + 0.5 * pt.phip;
      const double Tp = fp * pt.gp + 0.5 * pt.phipp;
      add_radial_block(K + static_cast<std::size_t>((b * n + b) * 9), y, T * recip,
                       (Tp * recip - T * recip * recip) * recip);
      for (int a = 0; a < 3; ++a) u[3 * b + a] = g * y[a] * recip;
    }
    if (fpp != 0.0)
      for (std::int64_t j = 0; j < n; ++j) {
        const double* uj = u + 3 * j;
        if (uj[0] == 0.0 && uj[1] == 0.0 && uj[2] == 0.0) continue;
        for (std::int64_t mb = 0; mb < n; ++mb) {
          const double* um = u + 3 * mb;
          double* k = K + static_cast<std::size_t>((j * n + mb) * 9);
          for (int a = 0; a < 3; ++a)
            for (int bb = 0; bb < 3; ++bb) k[3 * a + bb] += fpp * uj[a] * um[bb];
        }
      }
    bonds_.add_tangent(f, K);
  }

 private:
  std::string style_;
  EamTables e_;
  BondTable bonds_;
  EamView view_;
};

template <class Law, auto build_table>
std::unique_ptr<Potential> make_pair_model(const PotentialSpec& spec, BondTable&& bonds) {
  double cutmax = 0.0;
  auto table = build_table(spec, cutmax);
  return std::make_unique<PairModel<Law>>(spec, std::move(table), cutmax, std::move(bonds));
}

std::unique_ptr<Potential> make_eam_model(const PotentialSpec& spec, BondTable&& bonds) {
  return std::make_unique<EamModel>(spec, build_eam_tables(spec), std::move(bonds));
}

template <std::unique_ptr<Potential> (*make_manybody)(const PotentialSpec&)>
std::unique_ptr<Potential> make_manybody_model(const PotentialSpec& spec, BondTable&& bonds) {
  if (bonds.active())
    throw InputError("molecular bonds with a three-body or bond-order pair style are not native")
        .source(spec.source)
        .line(spec.bond_style_line)
        .key("bond_style")
        .value(spec.bond_style)
        .expected("pair_style " + spec.pair_style + " without bond_style")
        .fix("drop the bond_style (sw and tersoff need no bonds)");
  return make_manybody(spec);
}

/// The native pair styles, one line each (docs/potentials.md): the name LAMMPS gives the
/// style and the factory of its Potential. Every other style goes through embedded LAMMPS
/// (make_lammps_potential); the names listed in messages come from this table.
struct NativePairStyle {
  std::string_view name;
  std::unique_ptr<Potential> (*make)(const PotentialSpec&, BondTable&&);
};
constexpr NativePairStyle kNativePairStyles[] = {
    {"lj/cut", make_pair_model<LJCut, build_lj>},
    {"morse", make_pair_model<Morse, build_morse>},
    {"zero", make_pair_model<Zero, build_zero>},
    {"eam", make_eam_model},
    {"eam/alloy", make_eam_model},
    {"eam/fs", make_eam_model},
    {"sw", make_manybody_model<detail::make_stillinger_weber>},
    {"tersoff", make_manybody_model<detail::make_tersoff>},
};

const NativePairStyle* find_native_pair_style(std::string_view name) {
  for (const auto& e : kNativePairStyles)
    if (e.name == name) return &e;
  return nullptr;
}

template <class Table>
std::string names_of(const Table& table) {
  std::string out;
  for (const auto& e : table) {
    if (!out.empty()) out += ", ";
    out += e.name;
  }
  return out;
}

}  // namespace

bool native_pair_style(std::string_view style) { return find_native_pair_style(style) != nullptr; }
bool native_bond_style(std::string_view style) { return find_native_bond_style(style) != nullptr; }
std::string native_pair_style_names() { return names_of(kNativePairStyles); }
std::string native_bond_style_names() { return names_of(kNativeBondStyles); }

std::unique_ptr<Potential> make_potential(const PotentialSpec& spec) {
  if (spec.ntypes <= 0)
    throw InputError("number of atom types unknown")
        .source(spec.source)
        .key("ntypes")
        .expected("pair_coeff/mass commands naming the types, or the data file's type count")
        .fix("pass the configuration's number of atom types to read_potential_commands");
  if (spec.pair_style.empty() && spec.bond_style.empty())
    throw InputError("no pair_style and no bond_style")
        .source(spec.source)
        .expected("at least one interaction style");
  BondTable bonds = build_bonds(spec);
  const std::string& ps = spec.pair_style;
  if (ps.empty()) {
    // bonds only: no pair interaction; cutoff 0 (families hold the molecular bonds only)
    TypeTable<Zero::Coeff> table(spec.ntypes);
    return std::make_unique<PairModel<Zero>>(spec, std::move(table), 0.0, std::move(bonds));
  }
  if (const auto* entry = find_native_pair_style(ps)) return entry->make(spec, std::move(bonds));
  require_supported_styles(spec);
  // Any other style LAMMPS knows: force states by central differences of LAMMPS's per-atom
  // energies on clusters (include/pdcg/atomistic/lammps_potential.hpp).
  return make_lammps_potential(spec);
}

FamilyOptions family_options(const Potential& potential, const PotentialSpec& spec,
                             const std::vector<Bond>* bonds) {
  FamilyOptions o;
  o.cutoff = potential.cutoff();
  if (bonds && !bonds->empty()) {
    o.molecular_bonds = bonds;
    o.special_lj = spec.special_lj;
  }
  return o;
}

}  // namespace pdcg::atomistic
