#include "pdcg/body/quasi_harmonic.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/core/units.hpp"

namespace pdcg::body {

QuasiHarmonic quasi_harmonic(const Body& body, const Eigen::Matrix3d& F, double temperature) {
  if (body.kind != BodyKind::delta || body.dimension != 3 || !body.box.periodic[0] ||
      !body.box.periodic[1] || !body.box.periodic[2])
    throw InputError("the quasi-harmonic free energy needs a periodic 3D delta body")
        .key("body")
        .value(fmt::format("{} body, dimension {}", to_string(body.kind), body.dimension))
        .expected("a delta body of a crystal cell periodic along x, y and z")
        .fix("build it with pdcg atoms2pd --density delta from one relaxed frame");
  constexpr std::size_t kMaxAtoms = 3000;  // dense (3N)² Hessian: 648 MB at 3000 atoms
  if (body.size() > kMaxAtoms)
    throw InputError("body too large for the dense quasi-harmonic Hessian")
        .key("body")
        .value(fmt::format("{} atoms", body.size()))
        .expected(fmt::format("at most {} atoms (a supercell of the crystal)", kMaxAtoms));
  if (!(temperature >= 0.0) || !std::isfinite(temperature))
    throw InputError("temperature must be non-negative")
        .key("temperature")
        .value(fmt::format("{}", temperature));
  const double kT = unit_constants(body.units).boltz * temperature;
  const auto& fam = body.families;
  const auto& pot = *body.potential;
  const std::size_t n = body.size(), dim = 3 * n;
  const Eigen::Matrix3d hy = F * fam.h;
  std::vector<double> y(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d v =
        F * Eigen::Vector3d(body.x[3 * i], body.x[3 * i + 1], body.x[3 * i + 2]);
    for (int a = 0; a < 3; ++a) y[3 * i + static_cast<std::size_t>(a)] = v[a];
  }
  // H = ∂²U/∂y∂y from each family's K_bc (theory.md (1.7)): with Y_b = y_j(b) − y_k,
  // H_{j_b j_c} += K_bc, H_{k j_c} −= K_bc, H_{j_b k} −= K_bc, H_{kk} += K_bc. Serial (scatter).
  Eigen::MatrixXd H =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(dim));
  std::vector<double> K, work, t;
  atomistic::FamilyGather gather;
  double U = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto b0 = static_cast<std::size_t>(fam.offset[k]);
    const std::size_t m = static_cast<std::size_t>(fam.offset[k + 1]) - b0;
    if (m == 0) continue;
    K.resize(9 * m * m);
    t.resize(3 * m);
    work.resize(atomistic::Potential::tangent_workspace(static_cast<std::int64_t>(m)));
    const atomistic::FamilyState f = gather(fam, body.type, y, hy, k);
    U += pot.force_state(f, t.data());
    pot.force_state_tangent(f, K.data(), work.data());
    const auto ik = static_cast<Eigen::Index>(3 * k);
    for (std::size_t bj = 0; bj < m; ++bj) {
      const auto ij =
          static_cast<Eigen::Index>(3 * static_cast<std::size_t>(fam.neighbor[b0 + bj]));
      for (std::size_t bc = 0; bc < m; ++bc) {
        const auto ic =
            static_cast<Eigen::Index>(3 * static_cast<std::size_t>(fam.neighbor[b0 + bc]));
        const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> blk(K.data() +
                                                                                 9 * (bj * m + bc));
        H.block<3, 3>(ij, ic) += blk;
        H.block<3, 3>(ik, ic) -= blk;
        H.block<3, 3>(ij, ik) -= blk;
        H.block<3, 3>(ik, ik) += blk;
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j)
      H.block<3, 3>(static_cast<Eigen::Index>(3 * i), static_cast<Eigen::Index>(3 * j)) /=
          std::sqrt(body.mass[i] * body.mass[j]);
  const Eigen::MatrixXd Hs = 0.5 * (H + H.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Hs, Eigen::EigenvaluesOnly);
  const Eigen::VectorXd& w2 = es.eigenvalues();  // ascending; the first 3 are the translations
  QuasiHarmonic q;
  q.smallest_omega2 = w2[3];
  // a translation is ω² = 0 up to round-off of H; a vibration must lie clearly above it
  const double scale = w2.cwiseAbs().maxCoeff();
  if (!(w2[3] > 1e-10 * scale))
    throw NumericalError(
        fmt::format("quasi-harmonic free energy: the lattice is unstable at this F (a vibrational "
                    "eigenvalue ω² = {:.6g}, largest {:.6g}); the free energy does not exist there",
                    w2[3], scale));
  for (Eigen::Index i = 3; i < w2.size(); ++i) q.sum_ln_omega += 0.5 * std::log(w2[i]);
  const double V0 = body.reference_volume();
  const double modes = static_cast<double>(dim - 3);
  q.energy_density = U / V0;
  q.free_energy_density = (U + kT * (q.sum_ln_omega - modes * (kT > 0 ? std::log(kT) : 0.0))) / V0;
  return q;
}

}  // namespace pdcg::body
