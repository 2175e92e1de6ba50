#include "pdcg/core/error.hpp"

namespace pdcg {

InputError::InputError(std::string problem) : Error(problem), problem_(std::move(problem)) {
  compose();
}

InputError& InputError::source(std::string_view s) {
  source_ = s;
  compose();
  return *this;
}
InputError& InputError::line(long n) {
  line_ = n;
  compose();
  return *this;
}
InputError& InputError::key(std::string_view k) {
  key_ = k;
  compose();
  return *this;
}
InputError& InputError::value(std::string_view v) {
  value_ = v;
  has_value_ = true;
  compose();
  return *this;
}
InputError& InputError::expected(std::string_view e) {
  expected_ = e;
  compose();
  return *this;
}
InputError& InputError::fix(std::string_view f) {
  fix_ = f;
  compose();
  return *this;
}

// Built with append(): GCC 12 warns falsely (-Wrestrict, GCC bug 105329) on "lit" + string.
void InputError::compose() {
  std::string m;
  if (!source_.empty()) {
    m.append(source_);
    if (line_ > 0) m.append(":").append(std::to_string(line_));
    m.append(": ");
  } else if (line_ > 0) {
    m.append("line ").append(std::to_string(line_)).append(": ");
  }
  if (!key_.empty()) m.append(key_).append(": ");
  m.append(problem_);
  if (has_value_) m.append(": got '").append(value_).append("'");
  if (!expected_.empty()) m.append(has_value_ ? ", expected " : ": expected ").append(expected_);
  m.append(".");
  if (!fix_.empty()) m.append(" Fix: ").append(fix_);
  message_ = std::move(m);
}

std::string format_input_warning(std::string_view source, long line, std::string_view message) {
  std::string m(source);
  if (line > 0) m.append(":").append(std::to_string(line));
  if (!m.empty()) m.append(": ");
  m.append(message);
  return m;
}

}  // namespace pdcg
