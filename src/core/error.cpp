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

void InputError::compose() {
  std::string m;
  if (!source_.empty()) {
    m += source_;
    if (line_ > 0) m += ":" + std::to_string(line_);
    m += ": ";
  } else if (line_ > 0) {
    m += "line " + std::to_string(line_) + ": ";
  }
  if (!key_.empty()) m += key_ + ": ";
  m += problem_;
  if (has_value_) m += ": got '" + value_ + "'";
  if (!expected_.empty()) m += (has_value_ ? ", expected " : ": expected ") + expected_;
  m += ".";
  if (!fix_.empty()) m += " Fix: " + fix_;
  message_ = std::move(m);
}

std::string format_input_warning(std::string_view source, long line, std::string_view message) {
  std::string m(source);
  if (line > 0) m += ":" + std::to_string(line);
  if (!m.empty()) m += ": ";
  m += message;
  return m;
}

}  // namespace pdcg
