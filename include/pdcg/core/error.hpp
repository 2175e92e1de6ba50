/// \file
/// Error conventions of pdcg.
///
/// Two kinds of failure reach a user:
///  - pdcg::InputError: the user's input is wrong (file, command line, scene
///    key). Always checked, also in Release builds. The message names the
///    source (file or option), the line or key, the bad value, what was
///    expected and how to fix it. The CLI maps it to exit code 2.
///  - pdcg::NumericalError: a computation failed (Newton divergence, singular
///    family, NaN). The message is a diagnosis: where, which quantity, its
///    value, and what to try. The CLI maps it to exit code 1.
/// Internal invariants use PDCG_ASSERT (debug builds only), in the spirit of
/// deal.II's AssertThrow / Assert split.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace pdcg {

/// Base of every pdcg exception.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad user input. Build it fluently, then throw:
/// \code
///   throw InputError("not a number")
///       .source(path).line(lineno).key("x").value(token)
///       .expected("a floating-point number").fix("check the column count");
/// \endcode
/// what() is "<source>:<line>: <key>: <problem>: got '<value>', expected
/// <expected>. Fix: <fix>" with empty parts left out.
class InputError : public Error {
 public:
  explicit InputError(std::string problem);

  InputError& source(std::string_view file_or_option);
  InputError& line(long line_number);
  InputError& key(std::string_view key_or_command);
  InputError& value(std::string_view bad_value);
  InputError& expected(std::string_view what_was_expected);
  InputError& fix(std::string_view how_to_fix);

  const char* what() const noexcept override { return message_.c_str(); }

  const std::string& problem() const noexcept { return problem_; }
  const std::string& source_name() const noexcept { return source_; }
  long line_number() const noexcept { return line_; }
  const std::string& key_name() const noexcept { return key_; }
  const std::string& bad_value() const noexcept { return value_; }

 private:
  void compose();
  std::string problem_, source_, key_, value_, expected_, fix_, message_;
  long line_ = 0;
  bool has_value_ = false;
};

/// Numerical failure with a diagnosis.
class NumericalError : public Error {
 public:
  using Error::Error;
};

/// A warning that the caller may turn into an error or log; not thrown by default.
std::string format_input_warning(std::string_view source, long line, std::string_view message);

}  // namespace pdcg

/// Internal invariant (debug builds only). Never use for user input.
#ifndef NDEBUG
#define PDCG_ASSERT(cond, msg)                                                                  \
  do {                                                                                          \
    if (!(cond))                                                                                \
      throw ::pdcg::Error(std::string("internal error (please report): ") + (msg) + " [" #cond \
                          "] at " __FILE__ ":" + std::to_string(__LINE__));                     \
  } while (false)
#else
#define PDCG_ASSERT(cond, msg) \
  do {                         \
  } while (false)
#endif
