#include "pdcg/core/log.hpp"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <atomic>

namespace pdcg::log {
namespace {

std::atomic<Level> g_level{Level::info};

spdlog::logger& logger() {
  static std::shared_ptr<spdlog::logger> instance = [] {
    auto l = spdlog::stderr_color_mt("pdcg");
    l->set_pattern("%^[%l]%$ %v");
    l->set_level(spdlog::level::trace);  // filtering is done by g_level
    return l;
  }();
  return *instance;
}

spdlog::level::level_enum to_spdlog(Level l) {
  switch (l) {
    case Level::trace: return spdlog::level::trace;
    case Level::debug: return spdlog::level::debug;
    case Level::info: return spdlog::level::info;
    case Level::warn: return spdlog::level::warn;
    case Level::error: return spdlog::level::err;
    case Level::off: return spdlog::level::off;
  }
  return spdlog::level::info;
}

}  // namespace

void set_level(Level l) { g_level = l; }
Level level() { return g_level.load(std::memory_order_relaxed); }

void write(Level l, std::string_view message) {
  if (l < g_level.load(std::memory_order_relaxed) || l == Level::off) return;
  logger().log(to_spdlog(l), "{}", message);
}

}  // namespace pdcg::log
