// Small potentials written in the tests as the models under test (closed forms we can check
// by hand), and configurations built in code.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <memory>
#include <random>
#include <string>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/atomistic/potential.hpp"

namespace pdcg::test {

/// φ(r) = ½ c (r − r0)²; ψ_k = ½ Σ_j φ(r_kj).
class Springs final : public atomistic::Potential {
 public:
  Springs(double c, double r0, double rc) : c_(c), r0_(r0), rc_(rc) {}
  std::string style() const override { return "test springs"; }
  double cutoff() const override { return rc_; }
  int ntypes() const override { return 2; }
  bool pairwise() const override { return true; }
  double force_state(const atomistic::FamilyState& f, double* t) const override {
    double psi = 0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double r = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
      psi += 0.25 * c_ * (r - r0_) * (r - r0_);
      const double s = 0.5 * c_ * (r - r0_) / r;
      for (int k = 0; k < 3; ++k) t[3 * b + k] = s * y[k];
    }
    return psi;
  }

 private:
  double c_, r0_, rc_;
};

/// Many-body (EAM-like): ψ_k = −√ρ_k + ½ Σ_j ½ c (r − r0)², ρ_k = Σ_j e^{−β r}.
class Glue final : public atomistic::Potential {
 public:
  Glue(double c, double r0, double beta, double rc) : c_(c), r0_(r0), beta_(beta), rc_(rc) {}
  std::string style() const override { return "test glue"; }
  double cutoff() const override { return rc_; }
  int ntypes() const override { return 2; }
  double force_state(const atomistic::FamilyState& f, double* t) const override {
    double rho = 0, pair = 0;
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double r = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
      rho += std::exp(-beta_ * r);
      pair += 0.25 * c_ * (r - r0_) * (r - r0_);
    }
    const double dF = -0.5 / std::sqrt(rho);
    for (std::int64_t b = 0; b < f.size; ++b) {
      const double* y = f.bond + 3 * b;
      const double r = std::sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
      const double s = (dF * (-beta_) * std::exp(-beta_ * r) + 0.5 * c_ * (r - r0_)) / r;
      for (int k = 0; k < 3; ++k) t[3 * b + k] = s * y[k];
    }
    return -std::sqrt(rho) + pair;
  }

 private:
  double c_, r0_, beta_, rc_;
};

/// Simple cubic lattice n0×n1×n2 of spacing h, random displacements of amplitude `jitter`,
/// types alternating 1/2, mass 1 (type 1) and 2 (type 2).
inline atomistic::Atoms cubic_lattice(int n0, int n1, int n2, double h, double jitter,
                                      bool periodic, unsigned seed = 7) {
  atomistic::Atoms a;
  a.box.lo = {0, 0, 0};
  a.box.hi = {n0 * h, n1 * h, n2 * h};
  a.box.periodic = {periodic, periodic, periodic};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::int64_t id = 1;
  for (int i = 0; i < n0; ++i)
    for (int j = 0; j < n1; ++j)
      for (int k = 0; k < n2; ++k) {
        a.id.push_back(id++);
        a.type.push_back(1 + static_cast<int>(id % 2));
        a.x.insert(a.x.end(),
                   {(i + 0.5) * h + u(rng), (j + 0.5) * h + u(rng), (k + 0.5) * h + u(rng)});
      }
  a.type_mass = {NAN, 1.0, 2.0};
  return a;
}

inline Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  return q.normalized().toRotationMatrix();
}

/// Random F with det F > 0 and principal stretches in [0.5, 2]: F = R diag(λ) Qᵀ.
inline Eigen::Matrix3d random_deformation(std::mt19937& rng, double lo = 0.5, double hi = 2.0) {
  std::uniform_real_distribution<double> u(lo, hi);
  return random_rotation(rng) * Eigen::Vector3d(u(rng), u(rng), u(rng)).asDiagonal() *
         random_rotation(rng).transpose();
}

}  // namespace pdcg::test
