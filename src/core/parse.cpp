#include "pdcg/core/parse.hpp"

#include <charconv>
#include <cmath>

#include "pdcg/core/error.hpp"

namespace pdcg {

namespace {
InputError located(std::string problem, std::string_view token, const TextLocation& where,
                   std::string_view expected) {
  InputError e(std::move(problem));
  e.source(where.source).line(where.line).value(token).expected(expected);
  if (!where.field.empty()) e.key(where.field);
  return e;
}
}  // namespace

double parse_double(std::string_view token, const TextLocation& where) {
  double v = 0.0;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') ++first;
  auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec == std::errc::result_out_of_range)
    throw located("number out of range", token, where, "a finite double-precision number");
  if (ec != std::errc() || ptr != last)
    throw located("not a number", token, where, "a floating-point number")
        .fix("check that the line has the declared columns and no stray text");
  if (!std::isfinite(v))
    throw located("non-finite value", token, where, "a finite number")
        .fix("the producing run diverged or wrote NaN/Inf; regenerate the file");
  return v;
}

std::int64_t parse_int(std::string_view token, const TextLocation& where) {
  std::int64_t v = 0;
  const char* first = token.data();
  const char* last = token.data() + token.size();
  if (first != last && *first == '+') ++first;
  auto [ptr, ec] = std::from_chars(first, last, v);
  if (ec != std::errc() || ptr != last)
    throw located("not an integer", token, where, "an integer")
        .fix("check that the line has the declared columns and no stray text");
  return v;
}

void split_blanks(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  while (i < n) {
    while (i < n && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i >= n) break;
    std::size_t j = i;
    while (j < n && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    out.emplace_back(line.data() + i, j - i);
    i = j;
  }
}

std::vector<std::string_view> split_blanks(std::string_view line) {
  std::vector<std::string_view> out;
  split_blanks(line, out);
  return out;
}

std::string_view trim(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

namespace {
std::string& command_line_storage() {
  static std::string s;
  return s;
}
}  // namespace

void set_command_line(int argc, const char* const* argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) {
    if (i) s += ' ';
    std::string_view a(argv[i]);
    if (a.find_first_of(" \t\"'") != std::string_view::npos)
      s.append("'").append(a).append("'");
    else
      s += a;
  }
  command_line_storage() = std::move(s);
}

const std::string& command_line() { return command_line_storage(); }

}  // namespace pdcg
