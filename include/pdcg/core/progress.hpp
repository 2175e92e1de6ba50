/// \file
/// Progress reporting for long loops: steps done, rate, ETA.
///
/// On a terminal (stderr is a TTY) the line is redrawn in place at most a few
/// times per second. When stderr is not a TTY (CI logs, files) a plain line is
/// printed at most every `plain_interval` seconds and at the end, so logs
/// stay short. Silent when the log level is above info (--quiet).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace pdcg {

class Progress {
 public:
  /// \param label  what is being counted ("steps", "frames", ...)
  /// \param total  number of units expected (0 if unknown: no ETA)
  Progress(std::string label, std::uint64_t total, double plain_interval_seconds = 30.0);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Records that `done` units are finished (cheap when nothing is drawn).
  void update(std::uint64_t done, const std::string& extra = {});
  /// Prints the final line of a completed loop (done = total). Not called (the loop was left by
  /// an exception or a failure): the destructor prints the last count with "stopped", so a
  /// failed run never reads 100 %.
  void finish(const std::string& extra = {});

  /// The text of the current status, e.g. "steps 40/100 (40%) 12.3/s ETA 4.9 s".
  std::string status(std::uint64_t done, const std::string& extra = {}) const;

  /// Called on every update() and finish() of every Progress (label, units done, total; total
  /// 0 if unknown), before any throttling: how an embedding program (the Python module) sees
  /// the progress of long calls. Process-wide; an empty function removes it. An exception the
  /// observer throws leaves update()/finish() and ends the loop like any other error.
  using Observer =
      std::function<void(const std::string& label, std::uint64_t done, std::uint64_t total)>;
  static void set_observer(Observer observer);

  /// Forces TTY or plain mode (tests).
  void set_terminal(bool is_terminal) { terminal_ = is_terminal; }

 private:
  using clock = std::chrono::steady_clock;
  std::string label_;
  std::uint64_t total_;
  double plain_interval_;
  clock::time_point start_, last_draw_;
  std::uint64_t done_ = 0;
  bool terminal_;
  bool finished_ = false;
  bool drawn_ = false;
};

}  // namespace pdcg
