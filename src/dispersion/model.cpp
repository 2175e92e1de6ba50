#include "pdcg/dispersion/model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <sstream>

#include "pdcg/core/error.hpp"

namespace pdcg::dispersion {

using cd = std::complex<double>;

LinearisedFamilies::LinearisedFamilies(const atomistic::Potential& potential,
                                       const atomistic::Families& fam, std::span<const double> x,
                                       std::span<const int> type,
                                       std::span<const std::int32_t> atoms)
    : families_(&fam) {
  const std::size_t n = fam.points();
  if (x.size() != 3 * n)
    throw Error("LinearisedFamilies: positions do not match the families (" +
                std::to_string(x.size() / 3) + " positions, " + std::to_string(n) + " points)");
  start_.assign(n, -1);
  bond_start_.assign(n, -1);
  std::vector<std::int32_t> list(atoms.begin(), atoms.end());
  if (list.empty())
    for (std::size_t k = 0; k < n; ++k) list.push_back(static_cast<std::int32_t>(k));
  std::int64_t total = 0;
  for (auto k : list) {
    const auto kk = static_cast<std::size_t>(k);
    if (start_[kk] >= 0) continue;
    start_[kk] = total;
    const std::int64_t nb = fam.offset[kk + 1] - fam.offset[kk];
    total += nb * nb * 9;
    bond_start_[kk] = static_cast<std::int64_t>(xi_.size());
    xi_.resize(xi_.size() + static_cast<std::size_t>(3 * nb));
    atomistic::family_bond_vectors(fam, x, kk, xi_.data() + bond_start_[kk]);
  }
  k_.assign(static_cast<std::size_t>(total), 0.0);
  std::vector<int> ntype(fam.bonds());
  for (std::size_t b = 0; b < fam.bonds(); ++b)
    ntype[b] = type[static_cast<std::size_t>(fam.neighbor[b])];
  std::int64_t max_nb = 0;
  for (std::size_t k = 0; k < n; ++k) max_nb = std::max(max_nb, fam.offset[k + 1] - fam.offset[k]);
  std::vector<double> work(atomistic::Potential::tangent_workspace(max_nb));
  for (std::size_t k = 0; k < n; ++k) {
    if (start_[k] < 0) continue;
    const auto b0 = static_cast<std::size_t>(fam.offset[k]);
    const atomistic::FamilyState f =
        atomistic::family_state(fam, k, type[k], ntype.data() + b0, xi_.data() + bond_start_[k]);
    potential.force_state_tangent(f, k_.data() + start_[k], work.data());
  }
}

std::span<const double> LinearisedFamilies::tangent(std::size_t k) const {
  if (start_[k] < 0) return {};
  const std::int64_t nb = families_->offset[k + 1] - families_->offset[k];
  return {k_.data() + start_[k], static_cast<std::size_t>(nb * nb * 9)};
}

std::span<const double> LinearisedFamilies::bonds(std::size_t k) const {
  if (bond_start_[k] < 0) return {};
  const std::int64_t nb = families_->offset[k + 1] - families_->offset[k];
  return {xi_.data() + bond_start_[k], static_cast<std::size_t>(3 * nb)};
}

LinearisedFamilies::Atom LinearisedFamilies::atom(std::size_t k, const char* not_linearised) const {
  if (start_[k] < 0) throw Error(not_linearised);
  Atom a;
  a.n = families_->offset[k + 1] - families_->offset[k];
  a.K = k_.data() + start_[k];
  a.xi = xi_.data() + bond_start_[k];
  return a;
}

namespace {

double signed_sqrt(double w2) { return w2 >= 0 ? std::sqrt(w2) : -std::sqrt(-w2); }

Eigen::Matrix3d block(const LinearisedFamilies::Atom& at, std::int64_t b, std::int64_t c) {
  Eigen::Matrix3d m;
  const double* p = at.block(b, c);
  for (int a = 0; a < 3; ++a)
    for (int d = 0; d < 3; ++d) m(a, d) = p[3 * a + d];
  return m;
}

}  // namespace

Eigen::Vector3d point_omega(const LinearisedFamilies& lin,
                            std::span<const std::pair<std::int32_t, double>> atoms,
                            std::span<const double> mass, const Eigen::Vector3d& kappa,
                            double mvv2e) {
  Eigen::Matrix3cd D = Eigen::Matrix3cd::Zero();
  double M = 0.0;
  for (const auto& [k, w] : atoms) {
    const auto kk = static_cast<std::size_t>(k);
    const LinearisedFamilies::Atom at = lin.atom(kk, "point_omega: atom was not linearised");
    const std::int64_t n = at.n;
    std::vector<cd> phase(static_cast<std::size_t>(n));
    for (std::int64_t b = 0; b < n; ++b) {
      const double* xi = at.xi + 3 * b;
      const double arg = kappa[0] * xi[0] + kappa[1] * xi[1] + kappa[2] * xi[2];
      phase[static_cast<std::size_t>(b)] = cd(std::cos(arg) - 1.0, std::sin(arg));
    }
    for (std::int64_t b = 0; b < n; ++b)
      for (std::int64_t c = 0; c < n; ++c) {
        if (at.zero_block(b, c)) continue;
        D += w * std::conj(phase[static_cast<std::size_t>(b)]) *
             phase[static_cast<std::size_t>(c)] * block(at, b, c).cast<cd>();
      }
    M += w * mass[kk];
  }
  // D is Hermitian up to round-off; symmetrise before the eigen solve.
  const Eigen::Matrix3cd H = 0.5 * (D + D.adjoint()) / (M * mvv2e);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3cd> es(H, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d w2 = es.eigenvalues();
  return {signed_sqrt(w2[0]), signed_sqrt(w2[1]), signed_sqrt(w2[2])};
}

Eigen::VectorXd cell_omega(const LinearisedFamilies& lin, std::span<const double> mass,
                           const Eigen::Vector3d& kappa, double mvv2e) {
  const auto& fam = lin.families();
  const auto N = static_cast<Eigen::Index>(fam.points());
  Eigen::MatrixXcd D = Eigen::MatrixXcd::Zero(3 * N, 3 * N);
  for (Eigen::Index k = 0; k < N; ++k) {
    const auto kk = static_cast<std::size_t>(k);
    const LinearisedFamilies::Atom at = lin.atom(kk, "cell_omega: every atom must be linearised");
    const std::int64_t n = at.n;
    const auto b0 = static_cast<std::size_t>(fam.offset[kk]);
    const double* xis = at.xi;
    for (std::int64_t b = 0; b < n; ++b) {
      const std::size_t bb = b0 + static_cast<std::size_t>(b);
      const double* xb = xis + 3 * b;
      const cd eb = std::polar(1.0, kappa[0] * xb[0] + kappa[1] * xb[1] + kappa[2] * xb[2]);
      const Eigen::Index jb = fam.neighbor[bb];
      for (std::int64_t c = 0; c < n; ++c) {
        if (at.zero_block(b, c)) continue;
        const Eigen::Matrix3cd Kbc = block(at, b, c).cast<cd>();
        const std::size_t cc = b0 + static_cast<std::size_t>(c);
        const double* xc = xis + 3 * c;
        const cd ec = std::polar(1.0, kappa[0] * xc[0] + kappa[1] * xc[1] + kappa[2] * xc[2]);
        const Eigen::Index jc = fam.neighbor[cc];
        // B_b^H K B_c with B_b a = a_jb e_b − a_k
        D.block<3, 3>(3 * jb, 3 * jc) += std::conj(eb) * ec * Kbc;
        D.block<3, 3>(3 * jb, 3 * k) -= std::conj(eb) * Kbc;
        D.block<3, 3>(3 * k, 3 * jc) -= ec * Kbc;
        D.block<3, 3>(3 * k, 3 * k) += Kbc;
      }
    }
  }
  for (Eigen::Index p = 0; p < N; ++p)
    for (Eigen::Index q = 0; q < N; ++q)
      D.block<3, 3>(3 * p, 3 * q) /=
          mvv2e * std::sqrt(mass[static_cast<std::size_t>(p)] * mass[static_cast<std::size_t>(q)]);
  const Eigen::MatrixXcd H = 0.5 * (D + D.adjoint());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXcd> es(H, Eigen::EigenvaluesOnly);
  Eigen::VectorXd w(3 * N);
  for (Eigen::Index i = 0; i < 3 * N; ++i) w[i] = signed_sqrt(es.eigenvalues()[i]);
  return w;
}

std::vector<SymmetryPoint> symmetry_points(const std::string& lattice, double a, double c) {
  const double u = 2.0 * std::numbers::pi / a;
  using V = Eigen::Vector3d;
  if (lattice == "fcc")
    return {{"G", V(0, 0, 0)},           {"X", u * V(1, 0, 0)},   {"L", u * V(0.5, 0.5, 0.5)},
            {"K", u * V(0.75, 0.75, 0)}, {"W", u * V(1, 0.5, 0)}, {"U", u * V(1, 0.25, 0.25)}};
  if (lattice == "bcc")
    return {{"G", V(0, 0, 0)},
            {"H", u * V(1, 0, 0)},
            {"N", u * V(0.5, 0.5, 0)},
            {"P", u * V(0.5, 0.5, 0.5)}};
  if (lattice == "sc")
    return {{"G", V(0, 0, 0)},
            {"X", u * V(0.5, 0, 0)},
            {"M", u * V(0.5, 0.5, 0)},
            {"R", u * V(0.5, 0.5, 0.5)}};
  // triangular lattice a1 = a(1,0), a2 = a(1/2, √3/2): reciprocal b1 = u(1, −1/√3),
  // b2 = u(0, 2/√3); M = b2/2 (edge centre), K = (b1 + 2b2)/3 = u(1/3, 1/√3) (the corner on the
  // zone edge through M, so that M–K runs along the edge)
  const double r3 = std::sqrt(3.0);
  if (lattice == "hex")
    return {{"G", V(0, 0, 0)}, {"M", u * V(0, 1.0 / r3, 0)}, {"K", u * V(1.0 / 3.0, 1.0 / r3, 0)}};
  if (lattice == "hcp") {
    if (!(c > 0))
      throw InputError("the hexagonal (hcp) lattice needs its c axis")
          .key("--lattice")
          .value(lattice)
          .expected("c > 0 (told from the body's primitive vectors)")
          .fix("leave --lattice out: the lattice and c are found from the crystal");
    const V A(0, 0, std::numbers::pi / c), M = u * V(0, 1.0 / r3, 0),
                                           K = u * V(1.0 / 3.0, 1.0 / r3, 0);
    return {{"G", V(0, 0, 0)}, {"M", M}, {"K", K}, {"A", A}, {"L", M + A}, {"H", K + A}};
  }
  if (lattice == "chain") return {{"G", V(0, 0, 0)}, {"X", u * V(0.5, 0, 0)}};
  throw InputError("unknown lattice")
      .key("--lattice")
      .value(lattice)
      .expected("one of fcc, bcc, sc, hex, chain (hcp: found from the body, not by name)")
      .fix("name the Bravais lattice of the body");
}

std::string default_path(const std::string& lattice) {
  if (lattice == "fcc") return "G-X-W-K-G-L-U-W-L-K|U-X";
  if (lattice == "bcc") return "G-H-N-G-P-H|P-N";
  if (lattice == "sc") return "G-X-M-G-R-X|M-R";
  if (lattice == "hcp") return "G-M-K-G-A-L-H-A|L-M|K-H";
  if (lattice == "hex") return "G-M-K-G";
  if (lattice == "chain") return "G-X";
  throw InputError("no default path for this lattice")
      .key("--path")
      .value(lattice)
      .expected("fcc, bcc, sc, hcp, hex or chain")
      .fix("name the path, e.g. --path G-X");
}

std::vector<PathPoint> labelled_path(const std::vector<SymmetryPoint>& points,
                                     const std::string& lattice, const std::string& labels,
                                     int nk) {
  auto find = [&](std::string label) {
    if (label == "Γ") label = "G";
    auto it = std::find_if(points.begin(), points.end(),
                           [&](const SymmetryPoint& p) { return p.label == label; });
    if (it == points.end()) {
      std::string valid;
      for (const auto& p : points) valid += (valid.empty() ? "" : ", ") + p.label;
      throw InputError("path label unknown for this lattice")
          .key("--path")
          .value(label)
          .expected("one of " + valid + " for lattice " + lattice)
          .fix(
              "write the path as labels joined by '-' ('|' for a jump), e.g. G-X-L-G, or "
              "--path auto");
    }
    return *it;
  };
  // pieces separated by '|', each a chain of labels joined by '-'
  std::vector<std::vector<SymmetryPoint>> pieces;
  std::stringstream ps(labels);
  for (std::string piece; std::getline(ps, piece, '|');) {
    std::vector<SymmetryPoint> corners;
    std::stringstream ss(piece);
    for (std::string label; std::getline(ss, label, '-');) corners.push_back(find(label));
    if (corners.size() < 2)
      throw InputError("a path (and every piece between '|') needs at least two points")
          .key("--path")
          .value(labels)
          .expected("e.g. G-X or G-X-W|U-X");
    pieces.push_back(corners);
  }
  if (pieces.empty() || nk < 1)
    throw InputError("a path needs at least two points")
        .key("--path")
        .value(labels)
        .expected("e.g. G-X");
  std::vector<PathPoint> out;
  double s = 0.0;
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    const auto& corners = pieces[p];
    if (p == 0)
      out.push_back({0.0, corners[0].kappa, corners[0].label});
    else  // the jump: the previous piece's end and this piece's start share s
      out.push_back({s, corners[0].kappa, corners[0].label});
    if (p > 0) {
      out[out.size() - 2].label += "|" + corners[0].label;
      out.back().label = out[out.size() - 2].label;
    }
    for (std::size_t seg = 0; seg + 1 < corners.size(); ++seg) {
      const Eigen::Vector3d d = corners[seg + 1].kappa - corners[seg].kappa;
      for (int i = 1; i <= nk; ++i) {
        const Eigen::Vector3d k = corners[seg].kappa + d * (static_cast<double>(i) / nk);
        out.push_back({s + d.norm() * i / nk, k, i == nk ? corners[seg + 1].label : ""});
      }
      s += d.norm();
    }
  }
  return out;
}

std::vector<std::pair<double, Eigen::Vector3d>> path(const std::string& lattice, double a,
                                                     const std::string& labels, int nk) {
  std::vector<std::pair<double, Eigen::Vector3d>> out;
  for (const auto& p : labelled_path(symmetry_points(lattice, a), lattice, labels, nk))
    out.emplace_back(p.s, p.kappa);
  return out;
}

}  // namespace pdcg::dispersion
