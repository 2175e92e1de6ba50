#include "pdcg/dispersion/crystal.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "pdcg/core/error.hpp"
#include "pdcg/core/units.hpp"

namespace pdcg::dispersion {

namespace {

using cd = std::complex<double>;
using V = Eigen::Vector3d;

/// d-dimensional measure of the vectors (length, area, volume).
double measure(const std::vector<V>& p) {
  if (p.size() == 1) return p[0].norm();
  if (p.size() == 2) return p[0].cross(p[1]).norm();
  return std::abs(p[0].cross(p[1]).dot(p[2]));
}

/// Every vector of `p` is an integer combination of `cand` and both cells have the same
/// measure: the two sets generate the same lattice.
bool same_lattice(const std::vector<V>& p, const std::vector<V>& cand, double rel) {
  if (p.size() != cand.size()) return false;
  const double m = measure(p);
  if (!(m > 0) || std::abs(measure(cand) - m) > rel * m) return false;
  Eigen::MatrixXd C(3, static_cast<Eigen::Index>(cand.size()));
  for (std::size_t i = 0; i < cand.size(); ++i) C.col(static_cast<Eigen::Index>(i)) = cand[i];
  const auto qr = C.colPivHouseholderQr();
  for (const auto& v : p) {
    const Eigen::VectorXd n = qr.solve(v);
    if ((C * n - v).norm() > rel * 1e3 * v.norm()) return false;
    for (Eigen::Index i = 0; i < n.size(); ++i)
      if (std::abs(n[i] - std::round(n[i])) > 1e3 * rel) return false;
  }
  return true;
}

}  // namespace

CrystalLattice classify_lattice(const body::LatticeInfo& info, int dimension,
                                const std::string& source) {
  const int d = std::clamp(dimension, 1, 3);
  auto refuse = [&](const std::string& what) {
    return InputError("the crystal's lattice is not one with labelled high-symmetry paths")
        .source(source)
        .key("--path")
        .value(what)
        .expected(
            "translations of an fcc, bcc, sc or hexagonal (hcp) lattice in 3D, a "
            "triangular lattice in 2D, a chain in 1D")
        .fix(
            "use --direction (any lattice), or --cell for folded branches of the periodic "
            "cell");
  };
  if (!info.perfect || static_cast<int>(info.primitive.size()) != d)
    throw refuse(info.summary + (info.perfect ? " (no primitive vectors found)" : ""));
  const std::vector<V>& p = info.primitive;
  const double rel = 1e-6;  // positions written with ≥ 7 significant digits stay within it
  // translations Σ n_i p_i, |n_i| ≤ 3, shortest first
  std::vector<V> t;
  const int r = 3;
  for (int i = -r; i <= r; ++i)
    for (int j = (d > 1 ? -r : 0); j <= (d > 1 ? r : 0); ++j)
      for (int k = (d > 2 ? -r : 0); k <= (d > 2 ? r : 0); ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        V v = i * p[0];
        if (d > 1) v += j * p[1];
        if (d > 2) v += k * p[2];
        t.push_back(v);
      }
  std::sort(t.begin(), t.end(),
            [](const V& a, const V& b) { return a.squaredNorm() < b.squaredNorm(); });
  const double l1 = t.front().norm();
  auto of_length = [&](double l) {
    std::vector<V> s;
    for (const auto& v : t)
      if (std::abs(v.norm() - l) <= rel * l) s.push_back(v);
    return s;
  };
  const std::size_t z1 = of_length(l1).size();
  CrystalLattice out;
  out.basis = info.basis;
  // cube axes among the translations of length a: e1, e2 ⟂ e1, e3 = e1 × e2
  auto cube = [&](double a, Eigen::Matrix3d& R) {
    const auto s = of_length(a);
    if (s.empty()) return false;
    const V e1 = s[0] / a;
    for (const auto& v : s)
      if (std::abs(v.dot(e1)) <= rel * a) {
        const V e2 = v / a;
        R.col(0) = e1;
        R.col(1) = e2;
        R.col(2) = e1.cross(e2);
        return true;
      }
    return false;
  };
  Eigen::Matrix3d R;
  if (d == 3) {
    const double a_fcc = std::sqrt(2.0) * l1, a_bcc = 2.0 * l1 / std::sqrt(3.0);
    if (z1 == 12 && cube(a_fcc, R)) {
      const double h = a_fcc / 2;
      if (same_lattice(
              p, {h * (R.col(1) + R.col(2)), h * (R.col(0) + R.col(2)), h * (R.col(0) + R.col(1))},
              rel)) {
        out.lattice = "fcc";
        out.a = a_fcc;
      }
    }
    if (out.lattice.empty() && z1 == 8 && cube(a_bcc, R)) {
      const double h = a_bcc / 2;
      if (same_lattice(p,
                       {h * (-R.col(0) + R.col(1) + R.col(2)), h * (R.col(0) - R.col(1) + R.col(2)),
                        h * (R.col(0) + R.col(1) - R.col(2))},
                       rel)) {
        out.lattice = "bcc";
        out.a = a_bcc;
      }
    }
    if (out.lattice.empty() && z1 == 6 && cube(l1, R) &&
        same_lattice(p, {l1 * R.col(0), l1 * R.col(1), l1 * R.col(2)}, rel)) {
      out.lattice = "sc";
      out.a = l1;
    }
  }
  if (out.lattice.empty() && d >= 2) {
    // a hexagon: two translations of equal length at 60°; for hcp also c normal to them
    const std::size_t n = std::min<std::size_t>(t.size(), 60);
    for (std::size_t i = 0; i < n && out.lattice.empty(); ++i) {
      const V a1 = t[i];
      const double a = a1.norm();
      for (std::size_t j = 0; j < n && out.lattice.empty(); ++j) {
        const V a2 = t[j];
        if (std::abs(a2.norm() - a) > rel * a || std::abs(a1.dot(a2) - 0.5 * a * a) > rel * a * a)
          continue;
        const V normal = a1.cross(a2).normalized();
        R.col(0) = a1 / a;
        R.col(2) = normal;
        R.col(1) = normal.cross(R.col(0));
        if (d == 2) {
          if (same_lattice(p, {a1, a2}, rel)) {
            out.lattice = "hex";
            out.a = a;
          }
          continue;
        }
        for (const auto& c : t)
          if (std::abs(c.dot(a1)) <= rel * a * c.norm() &&
              std::abs(c.dot(a2)) <= rel * a * c.norm()) {
            if (same_lattice(p, {a1, a2, c}, rel)) {
              out.lattice = "hcp";
              out.a = a;
              out.c = c.norm();
              R.col(2) = c.normalized();
              R.col(1) = R.col(2).cross(R.col(0));
            }
            break;  // the shortest translation along the normal
          }
      }
    }
  }
  if (out.lattice.empty() && d == 1) {
    out.lattice = "chain";
    out.a = p[0].norm();
    R.col(0) = p[0] / out.a;
    R.col(1) = R.col(0).unitOrthogonal();
    R.col(2) = R.col(0).cross(R.col(1));
  }
  if (out.lattice.empty())
    throw refuse(
        fmt::format("{} shortest translations of length {:.6g} (primitive cell measure "
                    "{:.6g})",
                    z1, l1, measure(p)));
  out.frame = R;
  for (auto sp : symmetry_points(out.lattice, out.a, out.c)) {
    sp.kappa = R * sp.kappa;
    out.points.push_back(sp);
  }
  out.summary =
      fmt::format("{} lattice, a = {:.6g}{}, {} basis atom{} per primitive cell", out.lattice,
                  out.a, out.lattice == "hcp" ? fmt::format(", c = {:.6g}", out.c) : "", out.basis,
                  out.basis == 1 ? "" : "s");
  return out;
}

CrystalDispersion::CrystalDispersion(const body::Body& b, const body::LatticeInfo& info)
    : body_(b), class_of_(info.class_of) {
  if (b.statistics || b.homogenisation)
    throw InputError("primitive-cell dispersion is for delta and rescaled bodies")
        .key("body kind")
        .value(std::string(body::to_string(b.kind)))
        .expected("a delta or rescaled body of a perfect crystal")
        .fix(
            "the homogenised model has 3 degrees of freedom per point: its dispersion is the "
            "one-point one (--point)");
  if (!b.potential) throw InputError("the body has no potential to linearise").key("potential");
  if (!info.perfect || info.basis < 1 || class_of_.size() != b.size())
    throw InputError("not a perfect crystal: no primitive cell to compute the dispersion of")
        .key("--path")
        .value(info.summary)
        .expected("a body whose every atom is one of n equally populated lattice sites")
        .fix("build the body from the perfect crystal, or use --direction / --cell");
  rep_.assign(static_cast<std::size_t>(info.basis), b.size());
  for (std::size_t k = 0; k < b.size(); ++k) {
    const auto c = static_cast<std::size_t>(class_of_[k]);
    if (rep_[c] == b.size()) rep_[c] = k;
  }
  std::vector<std::int32_t> atoms;
  for (auto r : rep_) {
    atoms.push_back(static_cast<std::int32_t>(r));
    mass_.push_back(b.mass[r]);
  }
  mvv2e_ = unit_constants(b.units).mvv2e;
  lin_ = std::make_unique<LinearisedFamilies>(*b.potential, b.families, b.x, b.type, atoms);
  description_ =
      fmt::format("primitive cell of {} basis atom{} ({} branches, {} body)", rep_.size(),
                  rep_.size() == 1 ? "" : "s", 3 * rep_.size(), body::to_string(b.kind));
}

Eigen::MatrixXcd CrystalDispersion::dynamical_matrix(const Eigen::Vector3d& kappa) const {
  const auto& fam = lin_->families();
  const auto n = static_cast<Eigen::Index>(rep_.size());
  Eigen::MatrixXcd D = Eigen::MatrixXcd::Zero(3 * n, 3 * n);
  std::vector<cd> e;
  std::vector<Eigen::Index> cls;
  for (Eigen::Index c = 0; c < n; ++c) {
    const std::size_t r = rep_[static_cast<std::size_t>(c)];
    const auto K = lin_->tangent(r);
    const std::int64_t nb = fam.offset[r + 1] - fam.offset[r];
    const auto b0 = static_cast<std::size_t>(fam.offset[r]);
    const double* xis = lin_->bonds(r).data();
    e.resize(static_cast<std::size_t>(nb));
    cls.resize(static_cast<std::size_t>(nb));
    for (std::int64_t b = 0; b < nb; ++b) {
      const double* x = xis + 3 * b;
      e[static_cast<std::size_t>(b)] =
          std::polar(1.0, kappa[0] * x[0] + kappa[1] * x[1] + kappa[2] * x[2]);
      cls[static_cast<std::size_t>(b)] =
          class_of_[static_cast<std::size_t>(fam.neighbor[b0 + static_cast<std::size_t>(b)])];
    }
    for (std::int64_t b = 0; b < nb; ++b) {
      const cd eb = std::conj(e[static_cast<std::size_t>(b)]);
      const Eigen::Index jb = cls[static_cast<std::size_t>(b)];
      for (std::int64_t dd = 0; dd < nb; ++dd) {
        const double* q = K.data() + (b * nb + dd) * 9;
        bool zero = true;
        for (int i = 0; i < 9 && zero; ++i) zero = q[i] == 0.0;
        if (zero) continue;
        Eigen::Matrix3d Kbd;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) Kbd(i, j) = q[3 * i + j];
        const cd ed = e[static_cast<std::size_t>(dd)];
        const Eigen::Index jd = cls[static_cast<std::size_t>(dd)];
        // B_bᴴ K_bd B_d with B_b a = a_{c(j_b)} e^{iκ·ξ_b} − a_c
        D.block<3, 3>(3 * jb, 3 * jd) += (eb * ed) * Kbd.cast<cd>();
        D.block<3, 3>(3 * jb, 3 * c) -= eb * Kbd.cast<cd>();
        D.block<3, 3>(3 * c, 3 * jd) -= ed * Kbd.cast<cd>();
        D.block<3, 3>(3 * c, 3 * c) += Kbd.cast<cd>();
      }
    }
  }
  for (Eigen::Index p = 0; p < n; ++p)
    for (Eigen::Index q = 0; q < n; ++q)
      D.block<3, 3>(3 * p, 3 * q) /= mvv2e_ * std::sqrt(mass_[static_cast<std::size_t>(p)] *
                                                        mass_[static_cast<std::size_t>(q)]);
  return D;
}

Eigen::VectorXd CrystalDispersion::omega(const Eigen::Vector3d& kappa) const {
  const Eigen::MatrixXcd D = dynamical_matrix(kappa);
  const Eigen::MatrixXcd H = 0.5 * (D + D.adjoint());  // Hermitian up to round-off
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXcd> es(H, Eigen::EigenvaluesOnly);
  // eigenvalues within round-off of 0 are 0: the acoustic modes at Γ, where the 3n × 3n sums
  // of ±K blocks cancel to ~1e-16 of |λ|_max (measured 1.1e-16 for diamond Si sw,
  // DiamondPhysicalChecks), would otherwise show as ω ≈ ±1e-6 and a spurious "unstable mode"; 1e-12
  // is far above round-off and far below any physical mode (ω < 1e-6 ω_max)
  const double zero = 1e-12 * es.eigenvalues().cwiseAbs().maxCoeff();
  Eigen::VectorXd w(H.rows());
  for (Eigen::Index i = 0; i < H.rows(); ++i) {
    double w2 = es.eigenvalues()[i];
    if (std::abs(w2) <= zero) w2 = 0.0;
    w[i] = w2 >= 0 ? std::sqrt(w2) : -std::sqrt(-w2);
  }
  return w;
}

}  // namespace pdcg::dispersion
