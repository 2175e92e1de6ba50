/// \file
/// Shared pieces of the libFuzzer harnesses (tests/fuzz/README in docs/testing.md).
///
/// Policy: a reader may reject any input, but only with a pdcg::Error (InputError for bad
/// input, NumericalError for a computation that cannot proceed). Anything else escaping a
/// reader — another exception type, a crash, a sanitizer report, a leak — is a finding:
/// the harness aborts so that libFuzzer saves the input.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::fuzz {

/// A per-process scratch file (readers take paths): <TMPDIR>/pdcg-fuzz-<pid>-<tag><suffix>.
inline std::string scratch_path(std::string_view tag, std::string_view suffix = "") {
  const char* dir = std::getenv("TMPDIR");
  std::string p = (dir && *dir) ? dir : "/tmp";
  p += "/pdcg-fuzz-" + std::to_string(::getpid()) + "-" + std::string(tag) + std::string(suffix);
  return p;
}

/// Writes `size` bytes to `path` (truncating). Aborts on an I/O failure: that is the
/// machine, not the reader.
inline void write_file(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  if (size && std::fwrite(data, 1, size, f) != size) std::abort();
  if (std::fclose(f) != 0) std::abort();
}

/// Runs `body`; a pdcg::Error is an accepted rejection, anything else aborts.
template <class F>
int guarded(F&& body) {
  try {
    body();
  } catch (const pdcg::Error&) {
    // a clear rejection: fine
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pdcg fuzz: non-pdcg exception escaped the reader: %s\n", e.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "pdcg fuzz: unknown exception escaped the reader\n");
    std::abort();
  }
  return 0;
}

}  // namespace pdcg::fuzz

/// Warnings about rejected inputs are noise at 10⁴ runs per second.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  pdcg::log::set_level(pdcg::log::Level::off);
  return 0;
}
