// Native Stillinger–Weber (pair_style sw) as a state-based PD constitutive model.
//
// Formulas, parameter derivation and cutoffs are those of LAMMPS's PairSW (setup_params,
// twobody, threebody); the per-atom energy is LAMMPS's pe/atom attribution (Pair::ev_tally
// splits φ2 ½–½, Pair::ev_tally3 splits each φ3 ⅓–⅓–⅓):
//   ψ_k = ½ Σ_j φ2(r_kj) + ⅓ Σ_{j<l} φ3(k; j, l) + ⅓ Σ_{i} Σ_{l≠k} φ3(i; k, l),
// where the last sum runs over the triplets centred at a neighbour i of k. Those are functions
// of k's own bonds (Y_ik = −Y_ki, Y_il = Y_kl − Y_ki), so the family reaches 2 r_c.
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
#include "short_list_sweep.hpp"

namespace pdcg::atomistic::detail {

namespace {

/// Partners of one atom within the largest cutoff r_c that force_state handles (stack
/// arrays: it allocates nothing). 512 within r_c = 3.77 Å is ≈ 45× the density of Si; a
/// family beyond it gets NaN (reported by the callers' finiteness checks).
constexpr std::int64_t kMaxNear = 512;

/// PairSW::Param with the derived quantities of PairSW::setup_params.
struct Param {
  double epsilon, sigma, littlea, lambda, gamma, costheta, biga, bigb, powerp, powerq, tol;
  double cut, cutsq, sigma_gamma, lambda_epsilon, lambda_epsilon2, c1, c2, c3, c4, c5, c6;
};

/// PairSW::twobody: fforce = −φ2'(r)/r, eng = φ2(r).
inline void twobody(const Param& p, double rsq, double& fforce, double& eng) {
  const double r = std::sqrt(rsq);
  const double rinvsq = 1.0 / rsq;
  const double rp = std::pow(r, -p.powerp);
  const double rq = std::pow(r, -p.powerq);
  const double rainv = 1.0 / (r - p.cut);
  const double rainvsq = rainv * rainv * r;
  const double expsrainv = std::exp(p.sigma * rainv);
  fforce = (p.c1 * rp - p.c2 * rq + (p.c3 * rp - p.c4 * rq) * rainvsq) * expsrainv * rinvsq;
  eng = (p.c5 * rp - p.c6 * rq) * expsrainv;
}

/// φ2''(r) of φ2 = P(r) e(r), P = c5 r^−p − c6 r^−q, e = exp(σ/(r − a σ)).
inline double twobody_d2(const Param& p, double r) {
  const double rp = std::pow(r, -p.powerp), rq = std::pow(r, -p.powerq);
  const double P = p.c5 * rp - p.c6 * rq;
  const double P1 = (-p.powerp * p.c5 * rp + p.powerq * p.c6 * rq) / r;
  const double P2 =
      (p.powerp * (p.powerp + 1.0) * p.c5 * rp - p.powerq * (p.powerq + 1.0) * p.c6 * rq) / (r * r);
  const double rho = 1.0 / (r - p.cut);
  const double e = std::exp(p.sigma * rho);
  const double e1 = -p.sigma * rho * rho * e;
  const double e2 = p.sigma * rho * rho * rho * (2.0 + p.sigma * rho) * e;
  return P2 * e + 2.0 * P1 * e1 + P * e2;
}

/// PairSW::threebody energy facrad = λε_ijk exp(γσ_ij/(r1 − a_ij σ_ij)) exp(γσ_ik/(r2 − …))
/// (cos θ − cos θ0)² and its partial derivatives in (r1, r2, cos θ).
template <bool kSecond>
inline double threebody(const Param& ij, const Param& ik, const Param& ijk, const Angle& g,
                        Partials1& d1, Partials2& d2) {
  const double rainv1 = 1.0 / (g.r1 - ij.cut);
  const double gsrainv1 = ij.sigma_gamma * rainv1;
  const double expgsrainv1 = std::exp(gsrainv1);
  const double rainv2 = 1.0 / (g.r2 - ik.cut);
  const double gsrainv2 = ik.sigma_gamma * rainv2;
  const double expgsrainv2 = std::exp(gsrainv2);
  const double delcs = g.c - ijk.costheta;
  const double delcssq = delcs * delcs;
  const double facexp = expgsrainv1 * expgsrainv2;
  const double facrad = ijk.lambda_epsilon * facexp * delcssq;
  // d/dr exp(γσ/(r − c)) = −γσ/(r − c)² exp(…): multiplier m = −gsrainv·rainv
  const double m1 = -gsrainv1 * rainv1, m2 = -gsrainv2 * rainv2;
  d1.f1 = facrad * m1;
  d1.f2 = facrad * m2;
  d1.fc = ijk.lambda_epsilon2 * facexp * delcs;
  if constexpr (kSecond) {
    // d²/dr² exp(γσρ) = γσρ³(2 + γσρ) exp(…), ρ = 1/(r − c)
    const double q1 = gsrainv1 * rainv1 * rainv1 * (2.0 + gsrainv1);
    const double q2 = gsrainv2 * rainv2 * rainv2 * (2.0 + gsrainv2);
    d2.f11 = facrad * q1;
    d2.f22 = facrad * q2;
    d2.f12 = facrad * m1 * m2;
    d2.fcc = ijk.lambda_epsilon2 * facexp;
    d2.f1c = d1.fc * m1;
    d2.f2c = d1.fc * m2;
  }
  return facrad;
}

class StillingerWeber final : public Potential {
 public:
  explicit StillingerWeber(const PotentialSpec& spec) : ntypes_(spec.ntypes), n1_(spec.ntypes + 1) {
    style_ = "sw";
    const auto& a = spec.pair_style_args;
    for (std::size_t k = 0; k < a.size(); ++k) {
      // `threebody on|off` (LAMMPS ≥ 8Feb2023; Debian's 29Sep2021 has no keyword)
      if (a[k] == "threebody" && k + 1 < a.size() && (a[k + 1] == "on" || a[k + 1] == "off")) {
        threebody_ = a[k + 1] == "on";
        ++k;
        continue;
      }
      throw pair_style_argument_error(spec, "sw", a[k],
                                      "no argument, or 'threebody on' / 'threebody off'");
    }
    if (!threebody_) style_ = "sw threebody off";
    const TripleFormat format{
        "sw",
        "Stillinger-Weber",
        {"epsilon", "sigma", "a", "lambda", "gamma", "costheta0", "A", "B", "p", "q", "tol"}};
    const TripleTable table = read_triple_table(spec, format);
    for_each_entry(table, params_, [&](int i, int j, int k, const double* v, Param& p) {
      p.epsilon = v[0] * table.energy_factor;
      p.sigma = v[1];
      p.littlea = v[2];
      p.lambda = v[3];
      p.gamma = v[4];
      p.costheta = v[5];
      p.biga = v[6];
      p.bigb = v[7];
      p.powerp = v[8];
      p.powerq = v[9];
      p.tol = v[10];
      if (p.epsilon < 0.0 || p.sigma < 0.0 || p.littlea < 0.0 || p.lambda < 0.0 || p.gamma < 0.0 ||
          p.biga < 0.0 || p.bigb < 0.0 || p.powerp < 0.0 || p.powerq < 0.0 || p.tol < 0.0)
        throw entry_error(table, i, j, k, "Illegal Stillinger-Weber parameter")
            .expected("epsilon, sigma, a, lambda, gamma, A, B, p, q, tol all >= 0");
      setup(p);
    });
    check_symmetry(table);
    cutmax_ = 0.0;
    for (const Param& p : params_) cutmax_ = std::max(cutmax_, std::sqrt(p.cutsq));
    cutmaxsq_ = cutmax_ * cutmax_;
    // type triple → parameter index
    pidx_ = table.type_triple_index(ntypes_);
  }

  std::string style() const override { return style_; }
  /// A three-body energy of atom k reaches the far end of a triplet centred at a neighbour:
  /// 2 r_c (r_c: the largest short-range cutoff of the file).
  double cutoff() const override { return threebody_ ? 2.0 * cutmax_ : cutmax_; }
  int ntypes() const override { return ntypes_; }
  bool pairwise() const override { return !threebody_; }

  double force_state(const FamilyState& f, double* t) const override {
    return evaluate<false>(f, t, nullptr);
  }
  bool has_manybody_kernel() const override { return true; }
  double short_cutoff() const override { return cutmax_; }

  /// PairSW::compute over short lists: φ2 of each owned pair once (½ with each end's entry,
  /// as force_state), φ3(i; j, l) of each triplet j < l once at its centre i, with the
  /// forces −∇φ3 on j and l and their negative sum on i (Newton's third law); a triplet whose
  /// ends are not family partners counts ⅓ (ψ_i's share only, as the fixed-family ψ).
  double manybody_forces(const ShortLists& s, std::int64_t k0, std::int64_t k1, const double* y,
                         double* f, bool& applicable) const override {
    std::int32_t sj[kMaxNear];
    double sd[3 * kMaxNear], srsq[kMaxNear], sr[kMaxNear];
    double tu[3 * kMaxNear], tir[kMaxNear], tex[kMaxNear], tm[kMaxNear];
    const int* type = s.type;
    const double* xr = s.reference;
    double energy = 0.0;
    auto partner = [&](SweepCentre& centre, std::int32_t j, double dx, double dy, double dz,
                       double rsq, bool owned) {
      if (owned) {
        const int ti = centre.type, tj = type[j];
        const int pij = pidx_[static_cast<std::size_t>((ti * n1_ + tj) * n1_ + tj)];
        const int pji = pidx_[static_cast<std::size_t>((tj * n1_ + ti) * n1_ + ti)];
        double fpair = 0.0;  // −φ2'/r of the pair (Σ of the two halves)
        if (symmetric2_ || pij == pji) {
          const Param& p = params_[static_cast<std::size_t>(pij)];
          if (rsq < p.cutsq) {
            double eng;
            twobody(p, rsq, fpair, eng);
            energy += eng;
          }
        } else {
          for (const int pk : {pij, pji}) {
            const Param& p = params_[static_cast<std::size_t>(pk)];
            if (rsq < p.cutsq) {
              double ff, eng;
              twobody(p, rsq, ff, eng);
              fpair += 0.5 * ff;
              energy += 0.5 * eng;
            }
          }
        }
        add_pair_force(centre, f, j, -fpair, dx, dy, dz);  // (dφ2/dr)/r = −fpair
      }
      if (!threebody_) return true;
      const std::int64_t ns = keep_partner(centre, j, dx, dy, dz, sj, sd, kMaxNear);
      if (ns < 0) return false;
      srsq[ns] = rsq;
      sr[ns] = std::sqrt(rsq);
      return true;
    };
    auto triplets = [&](SweepCentre& centre) {
      const int ti = centre.type;
      const std::int64_t ns = centre.kept;
      double* fi = centre.f;
      // per partner within its (i, j, j) cutoff: unit vector, 1/r, and the radial factor of
      // φ3, exp(γσ/(r − aσ)) with its log-derivative (PairSW::threebody evaluates these per
      // triplet; they depend on the pair only)
      std::int64_t nt = 0;
      for (std::int64_t a = 0; a < ns; ++a) {
        const int tj = type[sj[a]];
        const Param& pij = P(ti, tj, tj);
        if (srsq[a] >= pij.cutsq) continue;
        const double ir = 1.0 / sr[a];
        const double rainv = 1.0 / (sr[a] - pij.cut);
        const double gsrainv = pij.sigma_gamma * rainv;
        sj[nt] = sj[a];
        tu[3 * nt] = sd[3 * a] * ir;
        tu[3 * nt + 1] = sd[3 * a + 1] * ir;
        tu[3 * nt + 2] = sd[3 * a + 2] * ir;
        tir[nt] = ir;
        tex[nt] = std::exp(gsrainv);
        tm[nt++] = -gsrainv * rainv;
      }
      for (std::int64_t a = 0; a + 1 < nt; ++a) {
        const std::int32_t j = sj[a];
        const int tj = type[j];
        const double xj = xr[3 * j], yj = xr[3 * j + 1], zj = xr[3 * j + 2];
        const double* ua = tu + 3 * a;
        double fj[3] = {0.0, 0.0, 0.0};
        for (std::int64_t b = a + 1; b < nt; ++b) {
          const std::int32_t l = sj[b];
          const int tl = type[l];
          // fixed families: ψ_j and ψ_l hold their thirds of φ3(i; j, l) only if j and l are
          // family partners (ψ_i always: both are in i's family)
          const double ex = xr[3 * l] - xj, ey = xr[3 * l + 1] - yj, ez = xr[3 * l + 2] - zj;
          const double w = ex * ex + ey * ey + ez * ez < s.family_cutsq ? 1.0 : 1.0 / 3.0;
          const double* ub = tu + 3 * b;
          const double c = ua[0] * ub[0] + ua[1] * ub[1] + ua[2] * ub[2];
          const double facexp = tex[a] * tex[b];
          // φ3 = λε (c − c0)² facexp, its partials in r1, r2 (φ3 m) and c; for a file whose
          // (i, j, l) and (i, l, j) differ, the mean over both orders (see check_symmetry)
          double e3, dc;
          {
            const Param& p = P(ti, tj, tl);
            const double delcs = c - p.costheta;
            e3 = p.lambda_epsilon * facexp * delcs * delcs;
            dc = p.lambda_epsilon2 * facexp * delcs;
          }
          if (!symmetric3_) {
            const Param& p = P(ti, tl, tj);
            const double delcs = c - p.costheta;
            e3 = 0.5 * (e3 + p.lambda_epsilon * facexp * delcs * delcs);
            dc = 0.5 * (dc + p.lambda_epsilon2 * facexp * delcs);
          }
          e3 *= w;
          dc *= w;
          energy += e3;
          const double f1 = e3 * tm[a], f2 = e3 * tm[b];
          // ∇_u φ3 = f1 û + dc (v̂ − c û)/r1, ∇_v φ3 = f2 v̂ + dc (û − c v̂)/r2
          const double ca = dc * tir[a], cb = dc * tir[b];
          double* fl = f + 3 * l;
          for (int k = 0; k < 3; ++k) {
            const double gu = f1 * ua[k] + ca * (ub[k] - c * ua[k]);
            const double gv = f2 * ub[k] + cb * (ua[k] - c * ub[k]);
            fj[k] -= gu;
            fl[k] -= gv;
            fi[k] += gu + gv;
          }
        }
        double* fjp = f + 3 * j;
        fjp[0] += fj[0];
        fjp[1] += fj[1];
        fjp[2] += fj[2];
      }
    };
    if (!sweep_short_lists(s, k0, k1, y, cutmaxsq_, f, partner, triplets)) applicable = false;
    return energy;
  }

  /// Analytic: the blocks of ½φ2 (j = m), and for every triplet the 2×2 blocks of its two
  /// local vectors, mapped to the bonds they combine.
  void force_state_tangent(const FamilyState& f, double* K, double* work) const override {
    evaluate<true>(f, work, K);
  }

 private:
  static void setup(Param& p) {
    // PairSW::setup_params
    p.cut = p.sigma * p.littlea;
    double rtmp = p.cut;
    if (p.tol > 0.0) {
      if (p.tol > 0.01) p.tol = 0.01;
      if (p.gamma < 1.0)
        rtmp = rtmp + p.gamma * p.sigma / std::log(p.tol);
      else
        rtmp = rtmp + p.sigma / std::log(p.tol);
    }
    p.cutsq = rtmp * rtmp;
    p.sigma_gamma = p.sigma * p.gamma;
    p.lambda_epsilon = p.lambda * p.epsilon;
    p.lambda_epsilon2 = 2.0 * p.lambda * p.epsilon;
    p.c1 = p.biga * p.epsilon * p.powerp * p.bigb * std::pow(p.sigma, p.powerp);
    p.c2 = p.biga * p.epsilon * p.powerq * std::pow(p.sigma, p.powerq);
    p.c3 = p.biga * p.epsilon * p.bigb * std::pow(p.sigma, p.powerp + 1.0);
    p.c4 = p.biga * p.epsilon * std::pow(p.sigma, p.powerq + 1.0);
    p.c5 = p.biga * p.epsilon * p.bigb * std::pow(p.sigma, p.powerp);
    p.c6 = p.biga * p.epsilon * std::pow(p.sigma, p.powerq);
  }

  /// LAMMPS evaluates φ2 of a pair once, with the entry of whichever atom its tag parity picks,
  /// and φ3(i; j, k) with the entry (i, j, k) of whichever neighbour comes first in its list:
  /// a file whose entries differ there gives results that depend on atom ids and neighbour
  /// order. pdcg gives each atom its half of φ2 from its own entry (the mean of the two) and
  /// evaluates φ3 as the mean over both orders, and says so: the result then differs from
  /// LAMMPS's by up to the relative difference of the entries.
  void check_symmetry(const TripleTable& t) {
    const int ne = t.nelements();
    auto rel = [](double x, double y) {
      return x == y ? 0.0 : std::abs(x - y) / std::max(std::abs(x), std::abs(y));
    };
    double worst2 = 0.0, worst3 = 0.0;
    int w2[3] = {0, 0, 0}, w3[3] = {0, 0, 0};
    for (int i = 0; i < ne; ++i)
      for (int j = 0; j < ne; ++j) {
        const Param& a = params_[t.index(i, j, j)];
        const Param& b = params_[t.index(j, i, i)];
        const double d2 =
            std::max({rel(a.epsilon, b.epsilon), rel(a.sigma, b.sigma), rel(a.littlea, b.littlea),
                      rel(a.biga, b.biga), rel(a.bigb, b.bigb), rel(a.powerp, b.powerp),
                      rel(a.powerq, b.powerq), rel(a.cutsq, b.cutsq)});
        if (d2 > worst2) {
          worst2 = d2;
          w2[0] = i, w2[1] = j, w2[2] = j;
        }
        for (int k = 0; k < ne; ++k) {
          const Param& c = params_[t.index(i, j, k)];
          const Param& d = params_[t.index(i, k, j)];
          const double d3 =
              std::max(rel(c.lambda_epsilon, d.lambda_epsilon), rel(c.costheta, d.costheta));
          if (d3 > worst3) {
            worst3 = d3;
            w3[0] = i, w3[1] = j, w3[2] = k;
          }
        }
      }
    // "file:line: <what> of '<entry>' and '<mirror>' differ (relative r): <how LAMMPS and
    // pdcg treat them>, so energies differ …", at the line of the entry
    auto warn_differ = [&t](const char* what, const int(&e)[3], const int(&m)[3], double r,
                            const char* treatment) {
      log::warn(
          "{}:{}: {} of '{}' and '{}' differ (relative {:.2g}): {}, so energies differ "
          "from LAMMPS by up to that relative amount",
          t.file, t.line[t.index(e[0], e[1], e[2])], what, t.triple_name(e[0], e[1], e[2]),
          t.triple_name(m[0], m[1], m[2]), r, treatment);
    };
    if (worst2 > 0.0) {
      symmetric2_ = false;
      warn_differ("two-body parameters", w2, {w2[1], w2[0], w2[0]}, worst2,
                  "LAMMPS evaluates φ2 of such a pair with one of them, picked by atom-id "
                  "parity; pdcg gives each atom half of φ2 with its own entry (the mean)");
    }
    if (worst3 > 0.0) {
      symmetric3_ = false;
      warn_differ("three-body parameters (lambda·epsilon, costheta0)", w3, {w3[0], w3[2], w3[1]},
                  worst3,
                  "LAMMPS's φ3 of such a triplet depends on the order of its neighbour list; "
                  "pdcg uses the mean of φ3 over both orders");
    }
  }

  /// φ3(i; j, k) and its partials: one entry (i, j, k), or for a file whose (i, j, k) and
  /// (i, k, j) differ the mean over both orders (see check_symmetry).
  template <bool kSecond>
  double phi3(int ti, int tj, int tk, const Param& ij, const Param& ik, const Angle& g,
              Partials1& d1, Partials2& d2) const {
    const double e = threebody<kSecond>(ij, ik, P(ti, tj, tk), g, d1, d2);
    if (symmetric3_) return e;
    Partials1 e1;
    Partials2 e2;
    const double f = threebody<kSecond>(ij, ik, P(ti, tk, tj), g, e1, e2);
    d1.f1 = 0.5 * (d1.f1 + e1.f1);
    d1.f2 = 0.5 * (d1.f2 + e1.f2);
    d1.fc = 0.5 * (d1.fc + e1.fc);
    if constexpr (kSecond) {
      d2.f11 = 0.5 * (d2.f11 + e2.f11);
      d2.f22 = 0.5 * (d2.f22 + e2.f22);
      d2.fcc = 0.5 * (d2.fcc + e2.fcc);
      d2.f12 = 0.5 * (d2.f12 + e2.f12);
      d2.f1c = 0.5 * (d2.f1c + e2.f1c);
      d2.f2c = 0.5 * (d2.f2c + e2.f2c);
    }
    return 0.5 * (e + f);
  }

  const Param& P(int i, int j, int k) const {
    return params_[static_cast<std::size_t>(
        pidx_[static_cast<std::size_t>((i * n1_ + j) * n1_ + k)])];
  }

  /// ψ_k and t (kTangent: t is scratch and K is filled).
  template <bool kTangent>
  double evaluate(const FamilyState& f, double* t, double* K) const {
    const FamilyOutput<kTangent> out{t, K, f.size};
    NearBonds<kMaxNear> near;  // bonds within the largest cutoff; |Y|² kept
    if (!out.start(f, ntypes_) || !near.collect(f, [&](double rsq, double& v) {
          v = rsq;
          return rsq < cutmaxsq_;
        }))
      return out.poison();
    const std::int64_t n = f.size;
    const int tk = f.type;
    const double* Y = f.bond;
    // short list of k (PairSW::compute: rsq < cutsq of the entry (k, j, j))
    std::int64_t shrt[kMaxNear];
    double shrt_r[kMaxNear];
    std::int64_t ns = 0;
    double psi = 0.0;
    Partials1 d1;
    Partials2 d2;
    double gu[3], gv[3], huu[9], huv[9], hvv[9];
    constexpr double third = 1.0 / 3.0;
    for (std::int64_t q = 0; q < near.size; ++q) {
      const std::int64_t b = near.bond[q];
      const Param& p = P(tk, f.neighbor_type[b], f.neighbor_type[b]);
      if (near.value[q] >= p.cutsq) continue;
      double fforce, eng;
      twobody(p, near.value[q], fforce, eng);
      psi += 0.5 * eng;
      const double* y = Y + 3 * b;
      for (int a = 0; a < 3; ++a) t[3 * b + a] += -0.5 * fforce * y[a];
      const double r = std::sqrt(near.value[q]);
      if constexpr (kTangent)
        scatter_radial(K, n, {b, 1.0}, y, r, -fforce * r, twobody_d2(p, r), 0.5);
      shrt[ns] = b;
      shrt_r[ns++] = r;
    }
    if (!threebody_) return psi;
    // triplets centred at k: ⅓ φ3(k; j, l) for j < l in the short list
    for (std::int64_t qa = 0; qa + 1 < ns; ++qa) {
      const std::int64_t j = shrt[qa];
      const int tj = f.neighbor_type[j];
      const Param& pij = P(tk, tj, tj);
      for (std::int64_t qb = qa + 1; qb < ns; ++qb) {
        const std::int64_t l = shrt[qb];
        const int tl = f.neighbor_type[l];
        const Angle g(Y + 3 * j, shrt_r[qa], Y + 3 * l, shrt_r[qb]);
        psi += third * phi3<kTangent>(tk, tj, tl, pij, P(tk, tl, tl), g, d1, d2);
        angle_gradient(g, d1, gu, gv);
        const LocalVector U{j, 1.0}, V{l, 1.0};
        for (int a = 0; a < 3; ++a) {
          t[3 * j + a] += third * gu[a];
          t[3 * l + a] += third * gv[a];
        }
        if constexpr (kTangent) {
          angle_hessian(g, d1, d2, huu, huv, hvv);
          scatter_pair_hessian(K, n, U, V, huu, huv, hvv, third);
        }
      }
    }
    // triplets centred at a neighbour i with k as one end: ⅓ φ3(i; k, l), u = Y_ik = −Y_ki,
    // w = Y_il = Y_kl − Y_ki
    for (std::int64_t q = 0; q < near.size; ++q) {
      const std::int64_t i = near.bond[q];
      const int ti = f.neighbor_type[i];
      const Param& pik = P(ti, tk, tk);
      if (near.value[q] >= pik.cutsq) continue;  // k is not in i's short list
      const double* yi = Y + 3 * i;
      const double u[3] = {-yi[0], -yi[1], -yi[2]};
      const double ru = std::sqrt(near.value[q]);
      for (std::int64_t l = 0; l < n; ++l) {
        if (l == i) continue;
        const double* yl = Y + 3 * l;
        const double w[3] = {yl[0] - yi[0], yl[1] - yi[1], yl[2] - yi[2]};
        const double wsq = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        if (wsq >= cutmaxsq_) continue;  // most of the family: no entry lookup
        const int tl = f.neighbor_type[l];
        const Param& pil = P(ti, tl, tl);
        if (wsq >= pil.cutsq) continue;
        const Angle g(u, ru, w, std::sqrt(wsq));
        psi += third * phi3<kTangent>(ti, tk, tl, pik, pil, g, d1, d2);
        angle_gradient(g, d1, gu, gv);
        const LocalVector U{i, -1.0}, W{l, 1.0, i, -1.0};
        for (int a = 0; a < 3; ++a) gu[a] *= third, gv[a] *= third;
        scatter_gradient(t, U, gu);
        scatter_gradient(t, W, gv);
        if constexpr (kTangent) {
          angle_hessian(g, d1, d2, huu, huv, hvv);
          scatter_pair_hessian(K, n, U, W, huu, huv, hvv, third);
        }
      }
    }
    return psi;
  }

  std::string style_;
  int ntypes_, n1_;
  bool threebody_ = true;
  bool symmetric3_ = true;  ///< entries (i, j, k) and (i, k, j) agree in their three-body part
  bool symmetric2_ = true;  ///< entries (i, j, j) and (j, i, i) agree in their two-body part
  std::vector<Param> params_;
  std::vector<int> pidx_;
  double cutmax_ = 0.0, cutmaxsq_ = 0.0;
};

}  // namespace

std::unique_ptr<Potential> make_stillinger_weber(const PotentialSpec& spec) {
  return std::make_unique<StillingerWeber>(spec);
}

}  // namespace pdcg::atomistic::detail
