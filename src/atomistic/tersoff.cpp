// Native Tersoff (pair_style tersoff [shift δ]) as a state-based PD constitutive model.
//
// Formulas, parameter checks and cutoffs are those of LAMMPS's PairTersoff (setup_params,
// repulsive, zeta, force_zeta, ters_fc, ters_fa, ters_bij, ters_gijk and their derivatives);
// the per-atom energy is LAMMPS's pe/atom attribution: Pair::ev_tally splits the repulsive
// pair energy V_R ½–½ and the attractive energy ½ b_ij f_A(r_ij) of the ordered pair (i, j)
// ½–½ between i and j, so
//   ψ_k = ½ Σ_j V_R(r_kj) + ¼ Σ_j b_kj f_A(r_kj) + ¼ Σ_j b_jk f_A(r_jk),
// where b_jk, the bond order of the pair (j, k) seen from j, depends on j's bonds
// Y_jl = Y_kl − Y_kj: the family reaches 2 r_c. With `shift δ` every distance r that enters
// a radial function (cutoffs included) is r + δ; angles are those of the bond vectors.
// docs/potentials.md ("Three-body and bond-order styles") derives t_kj and the tangent;
// docs/theory.md §1 is the PD form.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "manybody.hpp"
#include "manybody_file.hpp"
#include "manybody_geometry.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/core/parse.hpp"
#include "short_list_sweep.hpp"

namespace pdcg::atomistic::detail {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double MY_PI2 = kPi / 2.0;  // LAMMPS math_const MY_PI2, MY_PI4
constexpr double MY_PI4 = kPi / 4.0;
/// Partners within the largest cutoff that force_state handles without allocating (stack
/// arrays); ≈ 45× the density of Si within 3.2 Å. Beyond it the family gets NaN.
constexpr std::int64_t kMaxNear = 512;

/// PairTersoff::Param with the derived quantities of PairTersoff::setup_params.
struct Param {
  double powerm, gamma, lam3, c, d, h, powern, beta, lam2, bigb, bigr, bigd, lam1, biga;
  double cut, cutsq, c1, c2, c3, c4;
  int powermint;
};

// --- radial functions of r (already shifted) ------------------------------------------
/// f_C and its first two derivatives (ters_fc, ters_fc_d).
inline void fc3(double r, const Param& p, double& fc, double& d1, double& d2) {
  if (r < p.bigr - p.bigd) {
    fc = 1.0;
    d1 = d2 = 0.0;
    return;
  }
  if (r > p.bigr + p.bigd) {
    fc = d1 = d2 = 0.0;
    return;
  }
  const double x = MY_PI2 * (r - p.bigr) / p.bigd;
  fc = 0.5 * (1.0 - std::sin(x));
  d1 = -(MY_PI4 / p.bigd) * std::cos(x);
  d2 = 0.5 * std::sin(x) * (MY_PI2 / p.bigd) * (MY_PI2 / p.bigd);
}
inline double ters_fc(double r, const Param& p) {
  if (r < p.bigr - p.bigd) return 1.0;
  if (r > p.bigr + p.bigd) return 0.0;
  return 0.5 * (1.0 - std::sin(MY_PI2 * (r - p.bigr) / p.bigd));
}

/// V_R = f_C A e^{−λ1 r} (PairTersoff::repulsive) and its derivatives.
template <bool kSecond = true>
inline double repulsive(const Param& p, double r, double& d1, double& d2) {
  double fc, fc1, fc2;
  fc3(r, p, fc, fc1, fc2);
  const double e = std::exp(-p.lam1 * r);
  d1 = p.biga * e * (fc1 - fc * p.lam1);
  if constexpr (kSecond) d2 = p.biga * e * (fc2 - 2.0 * p.lam1 * fc1 + p.lam1 * p.lam1 * fc);
  return fc * p.biga * e;
}

/// f_A = −B e^{−λ2 r} f_C (ters_fa, ters_fa_d) and its derivatives.
template <bool kSecond = true>
inline double attractive_fa(const Param& p, double r, double& d1, double& d2) {
  if (r > p.bigr + p.bigd) {
    d1 = d2 = 0.0;
    return 0.0;
  }
  double fc, fc1, fc2;
  fc3(r, p, fc, fc1, fc2);
  const double e = std::exp(-p.lam2 * r);
  d1 = p.bigb * e * (p.lam2 * fc - fc1);
  if constexpr (kSecond) d2 = p.bigb * e * (-p.lam2 * p.lam2 * fc + 2.0 * p.lam2 * fc1 - fc2);
  return -p.bigb * e * fc;
}

/// b(ζ) (ters_bij, with LAMMPS's asymptotic branches) and its derivatives (ters_bij_d and
/// the derivative of each branch).
template <bool kSecond = true>
inline double bij(double zeta, const Param& p, double& d1, double& d2) {
  const double tmp = p.beta * zeta;
  const double n = p.powern, bb = p.beta * p.beta;
  if (tmp > p.c1) {
    d1 = p.beta * -0.5 * std::pow(tmp, -1.5);
    if constexpr (kSecond) d2 = bb * 0.75 * std::pow(tmp, -2.5);
    return 1.0 / std::sqrt(tmp);
  }
  if (tmp > p.c2) {
    d1 =
        p.beta * (-0.5 * std::pow(tmp, -1.5) * (1.0 - (1.0 + 1.0 / (2.0 * n)) * std::pow(tmp, -n)));
    if constexpr (kSecond)
      d2 = bb * (0.75 * std::pow(tmp, -2.5) -
                 (n + 0.5) * (n + 1.5) / (2.0 * n) * std::pow(tmp, -n - 2.5));
    return (1.0 - std::pow(tmp, -n) / (2.0 * n)) / std::sqrt(tmp);
  }
  if (tmp < p.c4) {
    d1 = d2 = 0.0;
    return 1.0;
  }
  if (tmp < p.c3) {
    d1 = -0.5 * p.beta * std::pow(tmp, n - 1.0);
    if constexpr (kSecond) d2 = -0.5 * bb * (n - 1.0) * std::pow(tmp, n - 2.0);
    return 1.0 - std::pow(tmp, n) / (2.0 * n);
  }
  const double tmp_n = std::pow(tmp, n);
  const double P = 1.0 + tmp_n;
  const double Pm = std::pow(P, -1.0 - 1.0 / (2.0 * n));
  d1 = -0.5 * Pm * tmp_n / zeta;
  if constexpr (kSecond)
    d2 = -0.5 * bb * Pm * std::pow(tmp, n - 2.0) * ((n - 1.0) - (n + 0.5) * tmp_n / P);
  return std::pow(P, -1.0 / (2.0 * n));
}

/// One term of ζ_ij: z = f_C(r2) g(cos θ) exp[(λ3 (r1 − r2))^m] (PairTersoff::zeta, with the
/// clamp of the exponent at ±69.0776) and its partial derivatives in (r1, r2, cos θ). The
/// derivatives of the exponential are ters_zetaterm_d's (also where the value is clamped).
/// r1, r2: the (shifted) lengths the radial functions see; c = cos θ.
template <bool kSecond>
inline double zeta_term(const Param& p, double r1, double r2, double c, Partials1& d1,
                        Partials2& d2) {
  double fc, fc1, fc2;
  fc3(r2, p, fc, fc1, fc2);
  const double dr = r1 - r2;
  double arg;
  if (p.powermint == 3)
    arg = (p.lam3 * dr) * (p.lam3 * dr) * (p.lam3 * dr);
  else
    arg = p.lam3 * dr;
  double ex;
  if (arg > 69.0776)
    ex = 1.e30;
  else if (arg < -69.0776)
    ex = 0.0;
  else
    ex = std::exp(arg);
  const double l3 = p.lam3 * p.lam3 * p.lam3;
  double ex1, ex2;
  if (p.powermint == 3) {
    ex1 = 3.0 * l3 * dr * dr * ex;
    ex2 = (6.0 * l3 * dr + 9.0 * l3 * l3 * dr * dr * dr * dr) * ex;
  } else {
    ex1 = p.lam3 * ex;
    ex2 = p.lam3 * p.lam3 * ex;
  }
  // g(c) = γ(1 + c²/d² − c²/(d² + (h − c)²)), ters_gijk(_d)
  const double tc = p.c * p.c, td = p.d * p.d;
  const double hcth = p.h - c;
  const double D = td + hcth * hcth;
  const double gv = p.gamma * (1.0 + tc / td - tc / D);
  const double g1 = p.gamma * (-2.0 * tc * hcth) / (D * D);
  d1.f1 = fc * gv * ex1;
  d1.f2 = fc1 * gv * ex - fc * gv * ex1;
  d1.fc = fc * g1 * ex;
  if constexpr (kSecond) {
    const double g2 = 2.0 * p.gamma * tc * (D - 4.0 * hcth * hcth) / (D * D * D);
    d2.f11 = fc * gv * ex2;
    d2.f22 = fc2 * gv * ex - 2.0 * fc1 * gv * ex1 + fc * gv * ex2;
    d2.f12 = fc1 * gv * ex1 - fc * gv * ex2;
    d2.fcc = fc * g2 * ex;
    d2.f1c = fc * g1 * ex1;
    d2.f2c = fc1 * g1 * ex - fc * g1 * ex1;
  }
  return fc * gv * ex;
}

class Tersoff final : public Potential {
 public:
  explicit Tersoff(const PotentialSpec& spec) : ntypes_(spec.ntypes), n1_(spec.ntypes + 1) {
    const auto& a = spec.pair_style_args;
    style_ = "tersoff";
    for (std::size_t k = 0; k < a.size(); ++k) {
      if (a[k] == "shift" && k + 1 < a.size()) {
        shift_ = parse_double(a[k + 1], {spec.source, spec.pair_style_line, "pair_style shift"});
        style_ = fmt::format("tersoff shift {}", a[k + 1]);
        ++k;
        continue;
      }
      throw pair_style_argument_error(spec, "tersoff", a[k], "no argument, or 'shift DELTA'");
    }
    const TripleFormat format{"tersoff",
                              "Tersoff",
                              {"m", "gamma", "lambda3", "c", "d", "costheta0", "n", "beta",
                               "lambda2", "B", "R", "D", "lambda1", "A"}};
    const TripleTable table = read_triple_table(spec, format);
    for_each_entry(table, params_, [&](int i, int j, int k, const double* v, Param& p) {
      p.powerm = v[0];
      p.gamma = v[1];
      p.lam3 = v[2];
      p.c = v[3];
      p.d = v[4];
      p.h = v[5];
      p.powern = v[6];
      p.beta = v[7];
      p.lam2 = v[8];
      p.bigb = v[9] * table.energy_factor;
      p.bigr = v[10];
      p.bigd = v[11];
      p.lam1 = v[12];
      p.biga = v[13] * table.energy_factor;
      p.powermint = static_cast<int>(p.powerm);
      // PairTersoff::read_file
      if (p.c < 0.0 || p.d < 0.0 || p.powern < 0.0 || p.beta < 0.0 || p.lam2 < 0.0 ||
          p.bigb < 0.0 || p.bigr < 0.0 || p.bigd < 0.0 || p.bigd > p.bigr || p.lam1 < 0.0 ||
          p.biga < 0.0 || p.powerm - p.powermint != 0.0 || (p.powermint != 3 && p.powermint != 1) ||
          p.gamma < 0.0)
        throw entry_error(table, i, j, k, "Illegal Tersoff parameter")
            .expected(
                "m = 1 or 3; c, d, n, beta, lambda2, B, R, D <= R, lambda1, A, gamma "
                ">= 0");
      // PairTersoff::setup_params
      p.cut = p.bigr + p.bigd;
      p.cutsq = p.cut * p.cut;
      p.c1 = std::pow(2.0 * p.powern * 1.0e-16, -1.0 / p.powern);
      p.c2 = std::pow(2.0 * p.powern * 1.0e-8, -1.0 / p.powern);
      p.c3 = 1.0 / p.c2;
      p.c4 = 1.0 / p.c1;
    });
    const int ne = table.nelements();
    // LAMMPS computes V_R of a pair once, with the entry of whichever atom its tag parity
    // picks: entries (i, j, j) and (j, i, i) that differ there give id-dependent results.
    // pdcg gives each atom half of V_R with its own entry (the mean) and says so.
    double worst = 0.0;
    int wi = 0, wj = 0;
    auto rel = [](double x, double y) {
      return x == y ? 0.0 : std::abs(x - y) / std::max(std::abs(x), std::abs(y));
    };
    for (int i = 0; i < ne; ++i)
      for (int j = 0; j < ne; ++j) {
        const Param& x = params_[table.index(i, j, j)];
        const Param& y = params_[table.index(j, i, i)];
        const double d = std::max(
            {rel(x.biga, y.biga), rel(x.lam1, y.lam1), rel(x.bigr, y.bigr), rel(x.bigd, y.bigd)});
        if (d > worst) {
          worst = d;
          wi = i;
          wj = j;
        }
      }
    symmetric_repulsive_ = worst == 0.0;
    if (worst > 0.0)
      log::warn(
          "{}:{}: repulsive parameters (A, lambda1, R, D) of '{}' and '{}' differ "
          "(relative {:.2g}): LAMMPS evaluates V_R of such a pair with one of them, picked "
          "by atom-id parity; pdcg gives each atom half of V_R with its own entry (the "
          "mean), so energies differ from LAMMPS by up to that relative amount",
          table.file, table.line[table.index(wi, wj, wj)], table.triple_name(wi, wj, wj),
          table.triple_name(wj, wi, wi), worst);
    cutmax_ = 0.0;
    for (const Param& p : params_) cutmax_ = std::max(cutmax_, p.cut);
    cutmaxsq_ = cutmax_ * cutmax_;
    reachsq_ = std::max(cutmax_ - shift_, 0.0) * std::max(cutmax_ - shift_, 0.0);
    pidx_ = table.type_triple_index(ntypes_);
  }

  std::string style() const override { return style_; }
  /// b_jk of a neighbour j depends on j's partners: 2 (r_c − δ), r_c = max(R + D).
  double cutoff() const override { return 2.0 * std::max(cutmax_ - shift_, 0.0); }
  int ntypes() const override { return ntypes_; }

  double force_state(const FamilyState& f, double* t) const override {
    return evaluate<false>(f, t, nullptr, nullptr);
  }
  bool has_manybody_kernel() const override { return true; }
  /// Unshifted distance below which r + δ is within the largest cutoff.
  double short_cutoff() const override { return std::max(cutmax_ - shift_, 0.0); }

  /// PairTersoff::compute over short lists: V_R of each owned pair once (½ with each end's
  /// entry, as force_state); for each centre i and partner j the bond order ζ_ij (one pass
  /// over the partners l, keeping ∇ζ's terms), then ½ b(ζ_ij) f_A(r̃_ij) and its forces on i,
  /// j and every l (LAMMPS recomputes ζ's terms in a second pass; here they are kept). With
  /// fixed families, ψ_j's quarter uses ζ over the l that are j's family partners.
  double manybody_forces(const ShortLists& s, std::int64_t k0, std::int64_t k1, const double* y,
                         double* f, bool& applicable) const override {
    std::int32_t sj[kMaxNear], lst[kMaxNear];
    bool lpart[kMaxNear];
    double sd[3 * kMaxNear], su[3 * kMaxNear], sr[kMaxNear], sir[kMaxNear], srt[kMaxNear],
        gvs[3 * kMaxNear];
    const int* type = s.type;
    const double* xr = s.reference;
    double energy = 0.0;
    Partials1 d1;
    Partials2 d2;
    auto partner = [&](SweepCentre& centre, std::int32_t j, double dx, double dy, double dz,
                       double rsq, bool owned) {
      const double r = std::sqrt(rsq), rt = r + shift_;
      if (rt * rt >= cutmaxsq_) return true;
      if (owned) {  // repulsive V_R(r̃), ½ with the entry of each end
        const int ti = centre.type, tj = type[j];
        const int pij = pidx_[static_cast<std::size_t>((ti * n1_ + tj) * n1_ + tj)];
        const int pji = pidx_[static_cast<std::size_t>((tj * n1_ + ti) * n1_ + ti)];
        const bool once = pij == pji || symmetric_repulsive_;
        double dv = 0.0;  // dV_R/dr̃ of the pair
        for (const int pk : {pij, pji}) {
          const Param& p = params_[static_cast<std::size_t>(pk)];
          const double w = once ? 1.0 : 0.5;
          if (rt * rt < p.cutsq) {
            double v1, v2;
            energy += w * repulsive<false>(p, rt, v1, v2);
            dv += w * v1;
          }
          if (once) break;
        }
        add_pair_force(centre, f, j, dv / r, dx, dy, dz);
      }
      const std::int64_t ns = keep_partner(centre, j, dx, dy, dz, sj, sd, kMaxNear);
      if (ns < 0) return false;
      sr[ns] = r;
      const double ir = 1.0 / r;
      sir[ns] = ir;
      su[3 * ns] = dx * ir;
      su[3 * ns + 1] = dy * ir;
      su[3 * ns + 2] = dz * ir;
      srt[ns] = rt;
      return true;
    };
    auto bond_orders = [&](SweepCentre& centre) {
      const int ti = centre.type;
      const std::int64_t ns = centre.kept;
      double* fi = centre.f;
      for (std::int64_t a = 0; a < ns; ++a) {
        const std::int32_t j = sj[a];
        const int tj = type[j];
        const Param& pij = P(ti, tj, tj);
        const double rt1 = srt[a], r1 = sr[a];
        if (rt1 * rt1 >= pij.cutsq) continue;
        const double* u = sd + 3 * a;
        const double* uh = su + 3 * a;
        const double xj = xr[3 * j], yj = xr[3 * j + 1], zj = xr[3 * j + 2];
        // ζ_ij and its gradient terms; ζp, gzp: the same over the l that are j's family
        // partners (ψ_j's view of b_ij, fixed families; = ζ unless atoms moved by more than
        // the families' skin)
        double zeta = 0.0, gzu[3] = {0.0, 0.0, 0.0};
        double zp = 0.0, gzp[3] = {0.0, 0.0, 0.0};
        std::int64_t nl = 0, np = 0;
        for (std::int64_t b = 0; b < ns; ++b) {
          if (b == a) continue;
          const std::int32_t l = sj[b];
          const Param& pijl = P(ti, tj, type[l]);
          if (srt[b] * srt[b] >= pijl.cutsq) continue;
          const double ex = xr[3 * l] - xj, ey = xr[3 * l + 1] - yj, ez = xr[3 * l + 2] - zj;
          const bool partner = ex * ex + ey * ey + ez * ez < s.family_cutsq;
          const double* vh = su + 3 * b;
          const double c = uh[0] * vh[0] + uh[1] * vh[1] + uh[2] * vh[2];
          const double z = zeta_term<false>(pijl, rt1, srt[b], c, d1, d2);
          zeta += z;
          // ∇_u z = f1 û + fc (v̂ − c û)/r1, ∇_v z = f2 v̂ + fc (û − c v̂)/r2 (Angle)
          const double ca = d1.fc * sir[a], cb = d1.fc * sir[b];
          double* gv = gvs + 3 * nl;
          double gu[3];
          for (int k = 0; k < 3; ++k) {
            gu[k] = d1.f1 * uh[k] + ca * (vh[k] - c * uh[k]);
            gzu[k] += gu[k];
            gv[k] = d1.f2 * vh[k] + cb * (uh[k] - c * vh[k]);
          }
          if (partner) {
            zp += z;
            for (int k = 0; k < 3; ++k) gzp[k] += gu[k];
            ++np;
          }
          lpart[nl] = partner;
          lst[nl++] = l;
        }
        double b1, b2, fa1, fa2;
        const double bz = bij<false>(zeta, pij, b1, b2);
        const double fa = attractive_fa<false>(pij, rt1, fa1, fa2);
        double bp = bz, bp1 = b1;  // ψ_j's view
        if (np != nl) bp = bij<false>(zp, pij, bp1, b2);
        // E = ¼ b(ζ) f_A + ¼ b(ζp) f_A (ψ_i's and ψ_j's quarters; ½ b f_A when ζp = ζ)
        energy += 0.25 * (bz + bp) * fa;
        const double sz = 0.25 * b1 * fa, szp = 0.25 * bp1 * fa;  // ∂E/∂ζ, ∂E/∂ζp
        const double sr1 = 0.25 * (bz + bp) * fa1 / r1;           // ∂E/∂r̃ along Y/r
        // ∂E/∂u = sr1 u + sz Σ ∇_u z + szp Σ_partners ∇_u z; ∂E/∂v_l = (sz [+ szp]) ∇_v z_l;
        // f_j = −∂E/∂u, f_l = −∂E/∂v_l
        double gU[3];
        for (int c = 0; c < 3; ++c) gU[c] = sr1 * u[c] + sz * gzu[c] + szp * gzp[c];
        for (std::int64_t m = 0; m < nl; ++m) {
          double* fl = f + 3 * lst[m];
          const double* gv = gvs + 3 * m;
          const double sl = lpart[m] ? sz + szp : sz;
          for (int c = 0; c < 3; ++c) {
            fl[c] -= sl * gv[c];
            fi[c] += sl * gv[c];
          }
        }
        double* fj = f + 3 * j;
        for (int c = 0; c < 3; ++c) {
          fj[c] -= gU[c];
          fi[c] += gU[c];
        }
      }
    };
    if (!sweep_short_lists(s, k0, k1, y, reachsq_, f, partner, bond_orders)) applicable = false;
    return energy;
  }

  /// Analytic second derivative of the three groups of terms of ψ_k (docs/potentials.md).
  void force_state_tangent(const FamilyState& f, double* K, double* work) const override {
    evaluate<true>(f, work, K, work + 3 * f.size);
  }

 private:
  const Param& P(int i, int j, int k) const {
    return params_[static_cast<std::size_t>(
        pidx_[static_cast<std::size_t>((i * n1_ + j) * n1_ + k)])];
  }

  /// One bond-order term w b(ζ) f_A(r̃_u) of ψ_k, ζ = Σ_l z(r̃_u, r̃_l, cos θ_l), with its
  /// gradient (and, kTangent, Hessian) scattered through the local-vector maps. `forward`:
  /// centre k, u = Y_j, v_l = Y_l; else centre j, u = −Y_j, v_l = Y_l − Y_j. list[0..nl): the
  /// bonds l; `pj`: the entry of b and f_A; entry_of(l): the entry of l's triple. r̃ = r + δ
  /// enters the radial functions, the true lengths the geometry (manybody_geometry.hpp).
  /// work (kTangent): 3·nl doubles for ∇_{v_l} ζ.
  template <bool kTangent, class EntryOf>
  double bond_order_term(const FamilyState& f, bool forward, std::int64_t j, const double* u,
                         double ru, const Param& pj, const std::int64_t* list, std::int64_t nl,
                         EntryOf&& entry_of, double w, double* t, double* K, double* work) const {
    const std::int64_t n = f.size;
    const double* Y = f.bond;
    const double* yj = Y + 3 * j;
    auto vec_l = [&](std::int64_t l, double* v) {
      const double* yl = Y + 3 * l;
      for (int a = 0; a < 3; ++a) v[a] = forward ? yl[a] : yl[a] - yj[a];
      return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    };
    auto local_l = [&](std::int64_t l) {
      return forward ? LocalVector{l, 1.0} : LocalVector{l, 1.0, j, -1.0};
    };
    const double rut = ru + shift_;  // r̃_u
    Partials1 d1;
    Partials2 d2;
    // pass 1: ζ
    double zeta = 0.0;
    for (std::int64_t q = 0; q < nl; ++q) {
      double v[3];
      const double rv = vec_l(list[q], v);
      const Angle g(u, ru, v, rv);
      zeta += zeta_term<false>(entry_of(list[q]), rut, rv + shift_, g.c, d1, d2);
    }
    double b1, b2, fa1, fa2;
    const double b = bij(zeta, pj, b1, b2);
    const double fa = attractive_fa(pj, rut, fa1, fa2);
    const double s = w * b1 * fa;  // ∂(w b f_A)/∂ζ
    const LocalVector U = forward ? LocalVector{j, 1.0} : LocalVector{j, -1.0};
    double uh[3], gz_u[3] = {0.0, 0.0, 0.0};
    for (int a = 0; a < 3; ++a) uh[a] = u[a] / ru;
    // pass 2: ∇ζ (and ∇²ζ) term by term
    double gu[3], gv[3], huu[9], huv[9], hvv[9];
    for (std::int64_t q = 0; q < nl; ++q) {
      const std::int64_t l = list[q];
      double v[3];
      const double rv = vec_l(l, v);
      const Angle g(u, ru, v, rv);
      zeta_term<kTangent>(entry_of(l), rut, rv + shift_, g.c, d1, d2);
      angle_gradient(g, d1, gu, gv);
      const LocalVector V = local_l(l);
      if constexpr (kTangent)
        for (int a = 0; a < 3; ++a) work[3 * q + a] = gv[a];  // ∇_{v_l} ζ
      for (int a = 0; a < 3; ++a) {
        gz_u[a] += gu[a];
        gv[a] *= s;
      }
      scatter_gradient(t, V, gv);
      if constexpr (kTangent) {
        angle_hessian(g, d1, d2, huu, huv, hvv);
        scatter_pair_hessian(K, n, U, V, huu, huv, hvv, s);
      }
    }
    double gu_tot[3];
    for (int a = 0; a < 3; ++a) gu_tot[a] = w * b * fa1 * uh[a] + s * gz_u[a];
    scatter_gradient(t, U, gu_tot);
    if constexpr (kTangent) {
      // ∇²(w b f_A) = w b' f_A ∇²ζ (above) + w b'' f_A ∇ζ∇ζ + w b' f_A' (∇ζ∇r + ∇r∇ζ)
      //              + w [b f_A'' ∇r∇r + b f_A' ∇²r]
      scatter_radial(K, n, U, u, ru, b * fa1, b * fa2, w);
      const double cbb = w * b2 * fa, cbf = w * b1 * fa1;
      auto outer = [&](const LocalVector& x, const double* gx, const LocalVector& y,
                       const double* gy, double c) {
        if (c == 0.0) return;
        double H[9];
        for (int a = 0; a < 3; ++a)
          for (int e = 0; e < 3; ++e) H[3 * a + e] = c * gx[a] * gy[e];
        scatter_block(K, n, x, y, H, 1.0);
      };
      // local vectors: u (∇ζ = gz_u, ∇r = û) and v_q (∇ζ = work[3q], ∇r = 0)
      outer(U, gz_u, U, gz_u, cbb);
      outer(U, gz_u, U, uh, cbf);
      outer(U, uh, U, gz_u, cbf);
      for (std::int64_t q = 0; q < nl; ++q) {
        const LocalVector V = local_l(list[q]);
        const double* gzq = work + 3 * q;
        outer(U, gz_u, V, gzq, cbb);
        outer(V, gzq, U, gz_u, cbb);
        outer(U, uh, V, gzq, cbf);
        outer(V, gzq, U, uh, cbf);
        for (std::int64_t q2 = 0; q2 < nl; ++q2)
          outer(V, gzq, local_l(list[q2]), work + 3 * q2, cbb);
      }
    }
    return w * b * fa;
  }

  template <bool kTangent>
  double evaluate(const FamilyState& f, double* t, double* K, double* work) const {
    const FamilyOutput<kTangent> out{t, K, f.size};
    NearBonds<kMaxNear> near;  // bonds with r̃ = r + δ below the largest cutoff; r̃ kept
    if (!out.start(f, ntypes_) || !near.collect(f, [&](double rsq, double& r) {
          if (rsq >= reachsq_) return false;
          r = std::sqrt(rsq) + shift_;
          return r * r < cutmaxsq_;
        }))
      return out.poison();
    const std::int64_t n = f.size;
    const int tk = f.type;
    const double* Y = f.bond;
    double psi = 0.0;
    std::int64_t list[kMaxNear];
    // terms centred at k: ½ V_R(r̃_kj) + ¼ b_kj f_A(r̃_kj)
    for (std::int64_t q = 0; q < near.size; ++q) {
      const std::int64_t j = near.bond[q];
      const int tj = f.neighbor_type[j];
      const Param& pj = P(tk, tj, tj);
      const double rt = near.value[q];
      if (rt * rt >= pj.cutsq) continue;
      const double* yj = Y + 3 * j;
      const double rlen = rt - shift_;
      double v1, v2;
      psi += 0.5 * repulsive(pj, rt, v1, v2);
      for (int a = 0; a < 3; ++a) t[3 * j + a] += 0.5 * v1 * yj[a] / rlen;
      if constexpr (kTangent) scatter_radial(K, n, {j, 1.0}, yj, rlen, v1, v2, 0.5);
      std::int64_t nl = 0;
      for (std::int64_t q2 = 0; q2 < near.size; ++q2) {
        if (q2 == q) continue;
        const std::int64_t l = near.bond[q2];
        const double r2 = near.value[q2];
        if (r2 * r2 >= P(tk, tj, f.neighbor_type[l]).cutsq) continue;
        list[nl++] = l;
      }
      psi += bond_order_term<kTangent>(
          f, true, j, yj, rlen, pj, list, nl,
          [&](std::int64_t l) -> const Param& { return P(tk, tj, f.neighbor_type[l]); }, 0.25, t, K,
          work);
    }
    // terms centred at a neighbour j: ¼ b_jk f_A(r̃_jk), b_jk from j's bonds Y_kl − Y_kj
    for (std::int64_t q = 0; q < near.size; ++q) {
      const std::int64_t j = near.bond[q];
      const int tj = f.neighbor_type[j];
      const Param& pjk = P(tj, tk, tk);
      const double rt = near.value[q];
      if (rt * rt >= pjk.cutsq) continue;
      const double* yj = Y + 3 * j;
      const double u[3] = {-yj[0], -yj[1], -yj[2]};
      std::int64_t nl = 0;
      for (std::int64_t l = 0; l < n; ++l) {
        if (l == j) continue;
        const double* yl = Y + 3 * l;
        const double w[3] = {yl[0] - yj[0], yl[1] - yj[1], yl[2] - yj[2]};
        const double wsq = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        if (wsq >= reachsq_) continue;  // beyond every cutoff: no sqrt, no entry lookup
        const double rw = std::sqrt(wsq) + shift_;
        if (rw * rw >= cutmaxsq_ || rw * rw >= P(tj, tk, f.neighbor_type[l]).cutsq) continue;
        if (nl == kMaxNear) return out.poison();
        list[nl++] = l;
      }
      psi += bond_order_term<kTangent>(
          f, false, j, u, rt - shift_, pjk, list, nl,
          [&](std::int64_t l) -> const Param& { return P(tj, tk, f.neighbor_type[l]); }, 0.25, t, K,
          work);
    }
    return psi;
  }

  std::string style_;
  int ntypes_, n1_;
  double shift_ = 0.0;
  bool symmetric_repulsive_ = true;  ///< (i, j, j) and (j, i, i) agree in A, λ1, R, D
  std::vector<Param> params_;
  std::vector<int> pidx_;
  double cutmax_ = 0.0, cutmaxsq_ = 0.0;
  double reachsq_ = 0.0;  ///< (r_c − δ)²: unshifted r² beyond which r + δ ≥ every cutoff
};

}  // namespace

std::unique_ptr<Potential> make_tersoff(const PotentialSpec& spec) {
  return std::make_unique<Tersoff>(spec);
}

}  // namespace pdcg::atomistic::detail
