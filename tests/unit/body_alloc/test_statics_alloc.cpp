// Zero allocations per iteration of molecular statics (include/pdcg/body/statics.hpp): a
// relaxation of 40 iterations allocates exactly as often as one of 4 from the same start (the
// set-up — working copy of the body, families, Evaluator, work vectors — is the same; the
// iterations add nothing). Counting global operator new and malloc/calloc/realloc (Eigen and
// libgomp allocate through malloc) are active in this executable only, switched on around the
// calls under test.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/statics.hpp"
#include "pdcg/body/surface.hpp"

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

using namespace pdcg;
using namespace pdcg::body;

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

Slab lj_slab() {
  auto spec = atomistic::read_potential_commands_from_string(
      "units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\nmass 1 1.0\n", "lj", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  atomistic::Atoms at;
  const double a = 1.55;
  at.box.lo = {0, 0, 0};
  at.box.hi = {a, a, a};
  const double b[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  for (int i = 0; i < 4; ++i) {
    at.id.push_back(i + 1);
    at.type.push_back(1);
    at.x.insert(at.x.end(), {b[i][0] * a, b[i][1] * a, b[i][2] * a});
  }
  at.type_mass = {NAN, 1.0};
  SlabOptions so;
  so.normal = {1, 0, 0};
  return make_slab(make_delta_body(at, pot, spec), so);
}

}  // namespace

TEST(StaticsAlloc, IterationsAllocateNothing) {
  const Slab s = lj_slab();
  for (MinStyle style : {MinStyle::cg, MinStyle::fire}) {
    StaticsOptions o;
    o.style = style;
    o.force_tolerance = 1e-30;  // never reached: every run stops at its iteration limit
    o.skin = 1.0;               // surface atoms move < 0.1: no family rebuild
    std::vector<double> y = s.slab.x;
    o.max_iterations = 2;
    (void)relax(s.slab, y, o);  // warm-up: thread pool, per-thread bond buffers
    StaticsResult r4, r40;
    o.max_iterations = 4;
    std::vector<double> y4 = s.slab.x, y40 = s.slab.x;
    const Counts c4 = count([&] { r4 = relax(s.slab, y4, o); });
    o.max_iterations = 40;
    const Counts c40 = count([&] { r40 = relax(s.slab, y40, o); });
    ASSERT_EQ(r4.iterations, 4);
    ASSERT_EQ(r40.iterations, 40);
    ASSERT_EQ(r4.rebuilds, 0);
    ASSERT_EQ(r40.rebuilds, 0);
    EXPECT_GT(r40.evaluations, r4.evaluations);
    EXPECT_GT(c4.news + c4.mallocs, 0);  // the counters work: the set-up allocates
    EXPECT_EQ(c40.news, c4.news);
    EXPECT_EQ(c40.mallocs, c4.mallocs);
  }
}
