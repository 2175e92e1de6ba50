#pragma once
// Exceptions out of OpenMP regions.
//
// An exception may not leave an OpenMP structured block: the runtime calls std::terminate,
// which ends the process with "terminate called after throwing ..." instead of the clear
// message of a pdcg::Error. A loop whose body can throw (a potential refusing a configuration,
// a numerical failure) runs each iteration through ParallelExceptions::capture; once one
// iteration has thrown, the remaining iterations of every thread are skipped, and rethrow()
// after the region throws the first exception caught, unchanged.
//
//   ParallelExceptions errors;
//   #pragma omp parallel for
//   for (...) errors.capture([&] { ...may throw... });
//   errors.rethrow();
//
// The happy path costs one relaxed atomic load per iteration (the try block is free).

#include <atomic>
#include <exception>
#include <mutex>
#include <utility>

namespace pdcg {

class ParallelExceptions {
 public:
  template <class Body>
  void capture(Body&& body) noexcept {
    if (failed_.load(std::memory_order_relaxed)) return;
    try {
      body();
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!first_) first_ = std::current_exception();
      failed_.store(true, std::memory_order_relaxed);
    }
  }

  bool failed() const { return failed_.load(std::memory_order_relaxed); }

  /// Throws the first exception captured (if any); the object is reset.
  void rethrow() {
    if (!failed_.load()) return;
    failed_.store(false);
    if (auto e = std::exchange(first_, nullptr)) std::rethrow_exception(e);
  }

 private:
  std::atomic<bool> failed_{false};
  std::mutex mutex_;
  std::exception_ptr first_;
};

}  // namespace pdcg
