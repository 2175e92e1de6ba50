/// \file
/// Logging: one process-wide logger writing to stderr (spdlog behind the
/// scenes, kept out of this header). Results never go through the log.
#pragma once

#include <fmt/format.h>

#include <string_view>
#include <utility>

namespace pdcg::log {

enum class Level { trace, debug, info, warn, error, off };

/// Sets the threshold (default: info). The CLI maps --verbose to debug and
/// --quiet to warn.
void set_level(Level level);
Level level();

/// Writes one message at the given level (thread-safe).
void write(Level level, std::string_view message);

template <class... Args>
void debug(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::debug) write(Level::debug, fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void info(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::info) write(Level::info, fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void warn(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::warn) write(Level::warn, fmt::format(f, std::forward<Args>(args)...));
}
template <class... Args>
void error(fmt::format_string<Args...> f, Args&&... args) {
  if (level() <= Level::error) write(Level::error, fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace pdcg::log
