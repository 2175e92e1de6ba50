#include "parallel_module.hpp"

#if PDCG_HAVE_PETSC
#include <dlfcn.h>

#include <string>

#include "pdcg/core/error.hpp"

namespace pdcg::cli {

const parallel::Api& parallel_module() {
#ifdef PDCG_PARALLEL_LINKED
  return *pdcg_parallel_api();
#else
  static const parallel::Api* api = [] {
    // found through the executable's run path ($ORIGIN/../lib installed, the build tree's
    // src/parallel), as its linked libraries are; never closed
    void* h = dlopen(PDCG_PARALLEL_LIBRARY, RTLD_NOW | RTLD_LOCAL);
    if (!h)
      throw Error(std::string("cannot load pdcg's PETSc module ") + PDCG_PARALLEL_LIBRARY + ": " +
                  dlerror());
    using Entry = const parallel::Api* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(h, "pdcg_parallel_api"));
    if (!entry) throw Error(std::string("pdcg's PETSc module has no entry point: ") + dlerror());
    return entry();
  }();
  return *api;
#endif
}

}  // namespace pdcg::cli
#endif
