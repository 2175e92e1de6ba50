/// \file
/// Strict number parsing for readers: every failure is an InputError that
/// names the file, the line, the field, and the token.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pdcg {

/// Where a token came from, for error messages.
struct TextLocation {
  std::string_view source;  ///< file name or option
  long line = 0;            ///< 1-based line number, 0 if unknown
  std::string_view field;   ///< column or key name
};

/// Parses a finite double (NaN and Inf are rejected: they are never valid input).
double parse_double(std::string_view token, const TextLocation& where);
/// Parses a signed 64-bit integer.
std::int64_t parse_int(std::string_view token, const TextLocation& where);

/// Splits on blanks (spaces, tabs, CR). Views point into `line`.
std::vector<std::string_view> split_blanks(std::string_view line);
/// Same, into a caller-owned vector (no allocation once it has capacity).
void split_blanks(std::string_view line, std::vector<std::string_view>& out);
/// Strips leading/trailing blanks.
std::string_view trim(std::string_view s);

/// A selection of frames "A:B[:S]": A, A+S, … up to and including B (0-based), or "N" for
/// one frame. Negative A or B count from the end (−1 = last frame).
struct FrameRange {
  std::size_t first = 0, last = 0, stride = 1;
  std::vector<std::size_t> indices() const;
};
/// Parses and checks a selection against the number of frames; throws InputError naming
/// `option`, the text and the valid range.
FrameRange parse_frame_range(std::string_view text, std::size_t nframes, std::string_view option);

/// The process command line, recorded by the CLI and written into every file.
void set_command_line(int argc, const char* const* argv);
const std::string& command_line();

}  // namespace pdcg
