// Live heap bytes of a benchmark executable: malloc, calloc, realloc, free and the aligned
// allocators are replaced by counting versions (operator new, Eigen and libgomp allocate
// through malloc), live_bytes = Σ malloc_usable_size of the blocks alive. Include in ONE
// translation unit of an executable (it defines the C allocation functions), after all
// other headers (Eigen / mm_malloc.h must declare posix_memalign first).
#pragma once

#include <malloc.h>

#include <atomic>
#include <cerrno>
#include <cstddef>

extern "C" void* __libc_malloc(std::size_t);
extern "C" void* __libc_calloc(std::size_t, std::size_t);
extern "C" void* __libc_realloc(void*, std::size_t);
extern "C" void* __libc_memalign(std::size_t, std::size_t);
extern "C" void __libc_free(void*);

namespace {
std::atomic<long long> live_bytes{0};
inline void* counted(void* p) {
  if (p) live_bytes += static_cast<long long>(malloc_usable_size(p));
  return p;
}
}  // namespace

extern "C" void* malloc(std::size_t n) { return counted(__libc_malloc(n)); }
extern "C" void* calloc(std::size_t a, std::size_t b) { return counted(__libc_calloc(a, b)); }
extern "C" void* realloc(void* p, std::size_t n) {
  if (p) live_bytes -= static_cast<long long>(malloc_usable_size(p));
  return counted(__libc_realloc(p, n));
}
extern "C" void free(void* p) {
  if (p) live_bytes -= static_cast<long long>(malloc_usable_size(p));
  __libc_free(p);
}
extern "C" int posix_memalign(void** out, std::size_t al, std::size_t n) {
  void* p = __libc_memalign(al, n);
  if (!p) return ENOMEM;
  *out = counted(p);
  return 0;
}
extern "C" void* aligned_alloc(std::size_t al, std::size_t n) {
  return counted(__libc_memalign(al, n));
}
extern "C" void* memalign(std::size_t al, std::size_t n) { return counted(__libc_memalign(al, n)); }

