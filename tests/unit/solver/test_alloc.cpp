// Zero allocations in the hot loops (docs/performance.md): the residual evaluation f(u), the
// residual + tangent assembly into K's pattern, and the matrix-free operator (its
// evaluation and the product K v) must not touch the heap once the scratch buffers exist
// (first call). A counting global
// operator new (all forms) and a counting malloc/calloc/realloc (Eigen and libgomp
// allocate through malloc, not operator new) are active in this executable only;
// counting is switched on around the calls under test.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/model.hpp"
#include "pdcg/solver/rupture.hpp"

extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void __libc_free(void*);

namespace {
std::atomic<bool> counting{false};
std::atomic<long> n_new{0}, n_malloc{0};
}  // namespace

extern "C" void* malloc(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++n_malloc;
  return __libc_malloc(n);
}
extern "C" void* calloc(std::size_t a, std::size_t b) {
  if (counting.load(std::memory_order_relaxed)) ++n_malloc;
  return __libc_calloc(a, b);
}
extern "C" void* realloc(void* p, std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++n_malloc;
  return __libc_realloc(p, n);
}
extern "C" void free(void* p) { __libc_free(p); }

namespace {
void* counted_new(std::size_t n) {
  if (counting.load(std::memory_order_relaxed)) ++n_new;
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* counted_new_aligned(std::size_t n, std::align_val_t al) {
  if (counting.load(std::memory_order_relaxed)) ++n_new;
  void* p = nullptr;
  const std::size_t a = std::max(static_cast<std::size_t>(al), sizeof(void*));
  if (posix_memalign(&p, a, n ? n : 1) != 0) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return counted_new(n); }
void* operator new[](std::size_t n) { return counted_new(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_new(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted_new(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new(std::size_t n, std::align_val_t a) { return counted_new_aligned(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted_new_aligned(n, a); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { __libc_free(p); }

using namespace pdcg::solver;

namespace {

struct Counts {
  long news, mallocs;
};
template <class Fn>
Counts count(Fn&& fn) {
  n_new = 0;
  n_malloc = 0;
  counting = true;
  fn();
  counting = false;
  return {n_new.load(), n_malloc.load()};
}

// A holed plate / cube with weak-form boundary rows, at a random large deformation.
void check(int dim, Kinematics kin, ModelOptions mo) {
  GridSpec g;
  g.dimension = dim;
  g.spacing = dim == 2 ? 1.0 / 16 : 1.0 / 6;
  g.holes.push_back({Vec3(0.5, 0.5, 0.5), dim == 2 ? 0.2 : 0.25});
  const auto D = Discretization::grid(g);
  const auto mat = make_neo_hookean({1.0, 10.0}, kin);
  const Model M(D, *mat, mo);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(-1, 1);
  Eigen::VectorXd u(M.dofs()), f(M.dofs());
  for (std::size_t i = 0; i < D.size(); ++i)
    for (int a = 0; a < dim; ++a)
      u[dim * i + a] = 0.3 * D.positions()[i](a) * (a == 0 ? 1 : -0.3) + 0.05 * g.spacing * U(rng);
  SparseRow K;
  // First calls size the scratch (stencil stresses/tangents) and K's pattern.
  ASSERT_TRUE(M.internal_force(u, f));
  ASSERT_TRUE(M.internal_force_and_tangent(u, f, K));
  // Matrix-free operator: the first evaluation and product size their scratch.
  Eigen::VectorXd v = u, Jv(M.dofs());
  ASSERT_TRUE(M.internal_force_and_operator(u, f));
  M.apply_tangent(v, Jv);
  for (int rep = 0; rep < 3; ++rep) {
    bool ok = false;
    const Counts r = count([&] { ok = M.internal_force(u, f); });
    EXPECT_TRUE(ok);
    EXPECT_EQ(r.news, 0) << "operator new calls in the residual evaluation";
    EXPECT_EQ(r.mallocs, 0) << "malloc calls in the residual evaluation";
    const Counts t = count([&] { ok = M.internal_force_and_tangent(u, f, K); });
    EXPECT_TRUE(ok);
    EXPECT_EQ(t.news, 0) << "operator new calls in the tangent assembly";
    EXPECT_EQ(t.mallocs, 0) << "malloc calls in the tangent assembly";
    const Counts o = count([&] { ok = M.internal_force_and_operator(u, f); });
    EXPECT_TRUE(ok);
    EXPECT_EQ(o.news, 0) << "operator new calls in the matrix-free operator evaluation";
    EXPECT_EQ(o.mallocs, 0) << "malloc calls in the matrix-free operator evaluation";
    const Counts p = count([&] { M.apply_tangent(v, Jv); });
    EXPECT_EQ(p.news, 0) << "operator new calls in the matrix-free product";
    EXPECT_EQ(p.mallocs, 0) << "malloc calls in the matrix-free product";
  }
}

}  // namespace

TEST(Allocation, CounterSeesAllocations) {
  // The counters work: a vector allocation and an Eigen vector are seen.
  const Counts c = count([] {
    std::vector<double> v(100, 1.0);
    Eigen::VectorXd e = Eigen::VectorXd::Ones(100);
    EXPECT_GT(v[0] + e[0], 0.0);
  });
  EXPECT_GE(c.news, 1);
  EXPECT_GE(c.mallocs, 1);
}

TEST(Allocation, ResidualAndTangentPlaneStrainWeak) { check(2, Kinematics::plane_strain, {}); }
TEST(Allocation, ResidualAndTangentPlaneStressWeak) { check(2, Kinematics::plane_stress, {}); }
TEST(Allocation, ResidualAndTangent3DWeak) { check(3, Kinematics::three_d, {}); }
TEST(Allocation, ResidualAndTangentClassicalEnergy) {
  check(2, Kinematics::plane_strain, {Correspondence::classical, BoundaryForm::energy});
}

// Dynamic fracture checks the criterion after every time step: a check that breaks nothing
// allocates nothing (the criterion goes into a scratch array sized at the first call).
TEST(Allocation, RuptureCheckWithoutBreaksAllocatesNothing) {
  GridSpec g;
  g.spacing = 1.0 / 16;
  g.cracks.push_back({Vec3(0.0, 0.5, 0), Vec3(0.3, 0.5, 0)});
  auto D = Discretization::grid(g);
  const auto mat = make_neo_hookean({1.0, 100.0}, Kinematics::plane_stress);
  Model M(D, *mat, {});
  for (auto crit : {RuptureCriterion::bond_stretch, RuptureCriterion::principal_stretch,
                    RuptureCriterion::energy_density, RuptureCriterion::fracture_energy}) {
    RuptureOptions ro;
    ro.criterion = crit;
    ro.critical = crit == RuptureCriterion::energy_density ? 10.0 : 3.0;  // never reached
    ro.fracture_energy = 100.0;  // fracture_energy: ψ_c ≫ Ψ at 5 % strain, never reached
    ro.anchor_detached = false;
    Rupture R(D, M, ro);
    Eigen::VectorXd u(M.dofs());
    for (std::size_t i = 0; i < D.size(); ++i) {
      u[2 * i] = 0.0;
      u[2 * i + 1] = 0.05 * D.positions()[i].y();
    }
    R.break_exceeding(u);  // sizes the scratch
    for (int rep = 0; rep < 3; ++rep) {
      RupturePass p;
      const Counts c = count([&] { p = R.break_exceeding(u); });
      EXPECT_EQ(p.broken, 0u);
      EXPECT_EQ(c.news, 0) << "operator new calls in a rupture check without breaks";
      EXPECT_EQ(c.mallocs, 0) << "malloc calls in a rupture check without breaks";
    }
  }
}
