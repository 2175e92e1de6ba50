#include "pdcg/core/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "pdcg/core/log.hpp"

namespace pdcg {

namespace {
Progress::Observer& observer() {
  static Progress::Observer o;
  return o;
}
}  // namespace

void Progress::set_observer(Observer o) { observer() = std::move(o); }

Progress::Progress(std::string label, std::uint64_t total, double plain_interval_seconds)
    : label_(std::move(label)),
      total_(total),
      plain_interval_(plain_interval_seconds),
      start_(clock::now()),
      last_draw_(start_),
      terminal_(isatty(fileno(stderr)) != 0) {}

Progress::~Progress() {
  // Not finished: the loop was left early (an exception, a failed step). The last line then
  // shows how far it got, never the total (a failed run must not read 100 %).
  if (finished_ || log::level() > log::Level::info) return;
  if (terminal_ && drawn_) std::fprintf(stderr, "\r\033[K");
  std::fprintf(stderr, "%s\n", status(done_, "stopped").c_str());
}

std::string Progress::status(std::uint64_t done, const std::string& extra) const {
  const double elapsed = std::chrono::duration<double>(clock::now() - start_).count();
  const double rate = elapsed > 0 ? static_cast<double>(done) / elapsed : 0.0;
  std::string s;
  if (total_ > 0) {
    // floor, not round: 199/200 is 99 %, only a complete loop reads 100 %
    s = fmt::format("{} {}/{} ({:.0f}%) {:.3g}/s", label_, done, total_,
                    std::floor(100.0 * static_cast<double>(done) / static_cast<double>(total_)),
                    rate);
    if (rate > 0 && done < total_)
      s += fmt::format(" ETA {:.1f} s", static_cast<double>(total_ - done) / rate);
  } else {
    s = fmt::format("{} {} {:.3g}/s", label_, done, rate);
  }
  s += fmt::format(" elapsed {:.1f} s", elapsed);
  if (!extra.empty()) s += " " + extra;
  return s;
}

void Progress::update(std::uint64_t done, const std::string& extra) {
  done_ = done;
  if (observer()) observer()(label_, done, total_);
  if (log::level() > log::Level::info) return;
  const auto now = clock::now();
  const double since = std::chrono::duration<double>(now - last_draw_).count();
  if (terminal_) {
    if (since < 0.2) return;
    std::fprintf(stderr, "\r\033[K%s", status(done, extra).c_str());
    std::fflush(stderr);
    drawn_ = true;
  } else {
    if (since < plain_interval_) return;
    std::fprintf(stderr, "%s\n", status(done, extra).c_str());
  }
  last_draw_ = now;
}

void Progress::finish(const std::string& extra) {
  if (finished_) return;
  finished_ = true;
  if (observer()) observer()(label_, total_ > 0 ? total_ : done_, total_);
  if (log::level() > log::Level::info) return;
  if (terminal_ && drawn_) std::fprintf(stderr, "\r\033[K");
  std::fprintf(stderr, "%s\n", status(total_ > 0 ? total_ : done_, extra).c_str());
}

}  // namespace pdcg
