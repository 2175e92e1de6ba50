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

std::vector<std::size_t> FrameRange::indices() const {
  std::vector<std::size_t> out;
  for (std::size_t i = first; i <= last; i += stride) out.push_back(i);
  return out;
}

FrameRange parse_frame_range(std::string_view text, std::size_t nframes, std::string_view option) {
  const std::string valid = nframes == 0 ? std::string("none (the file has no frames)")
                                         : "frames 0 to " + std::to_string(nframes - 1);
  auto fail = [&](const std::string& problem) {
    return InputError(problem)
        .key(option)
        .value(text)
        .expected("N or A:B[:S] within " + valid)
        .fix("e.g. 0:-1 for all frames, 10:99:2 for every second frame from 10 to 99");
  };
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= text.size(); ++i)
    if (i == text.size() || text[i] == ':') {
      parts.push_back(text.substr(start, i - start));
      start = i + 1;
    }
  if (parts.empty() || parts.size() > 3) throw fail("malformed frame selection");
  const TextLocation at{"", 0, option};
  auto resolve = [&](std::string_view p) -> std::size_t {
    std::int64_t v = 0;
    try {
      v = parse_int(trim(p), at);
    } catch (const InputError&) {
      throw fail("frame index is not an integer");
    }
    if (v < 0) v += static_cast<std::int64_t>(nframes);
    if (v < 0 || v >= static_cast<std::int64_t>(nframes)) throw fail("frame index out of range");
    return static_cast<std::size_t>(v);
  };
  FrameRange r;
  r.first = resolve(parts[0]);
  r.last = parts.size() >= 2 ? resolve(parts[1]) : r.first;
  if (parts.size() == 3) {
    std::int64_t s = 0;
    try {
      s = parse_int(trim(parts[2]), at);
    } catch (const InputError&) {
      throw fail("stride is not an integer");
    }
    if (s < 1) throw fail("stride must be at least 1");
    r.stride = static_cast<std::size_t>(s);
  }
  if (r.last < r.first) throw fail("last frame before first frame");
  return r;
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
