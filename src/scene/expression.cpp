#include "pdcg/scene/expression.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <vector>

#include "pdcg/core/error.hpp"

namespace pdcg::scene {
namespace {

using Fn = std::function<double(const double*)>;

class Parser {
 public:
  Parser(const std::string& s, const std::string& where, const std::vector<std::string>& vars)
      : s_(s), where_(where), vars_(vars) {}
  Fn parse() {
    Fn f = expr();
    skip();
    if (p_ != s_.size()) fail("unexpected character");
    return f;
  }

 private:
  [[noreturn]] void fail(const std::string& what) {
    throw InputError("cannot parse the expression: " + what + " at position " +
                     std::to_string(p_ + 1))
        .key(where_)
        .value(s_)
        .expected(
            fmt::format("a number or an expression in {}, e.g. \"0.5*{}\" (+ - * / ^, pi, sin cos "
                        "tan exp log sqrt abs)",
                        fmt::join(vars_, ", "), vars_.empty() ? "1" : vars_.front()));
  }
  void skip() {
    while (p_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[p_]))) ++p_;
  }
  bool eat(char c) {
    skip();
    if (p_ < s_.size() && s_[p_] == c) {
      ++p_;
      return true;
    }
    return false;
  }
  // Bounds: the parser recurses per nesting level and evaluation recurses per operation
  // (nested closures), so a pathological input (thousands of '(' or '-', or of '+1') would
  // overflow the stack; scene expressions are a few operations deep.
  static constexpr int kMaxDepth = 64;
  static constexpr int kMaxOperations = 1000;
  void operation() {
    if (++operations_ > kMaxOperations)
      fail(
          fmt::format("more than {} operations (an expression this long is not a scene "
                      "expression)",
                      kMaxOperations));
  }
  Fn expr() {
    Fn a = term();
    for (;;) {
      if (eat('+')) {
        operation();
        Fn b = term();
        a = [a, b](const double* t) { return a(t) + b(t); };
      } else if (eat('-')) {
        operation();
        Fn b = term();
        a = [a, b](const double* t) { return a(t) - b(t); };
      } else {
        return a;
      }
    }
  }
  Fn term() {
    Fn a = unary();
    for (;;) {
      if (eat('*')) {
        operation();
        Fn b = unary();
        a = [a, b](const double* t) { return a(t) * b(t); };
      } else if (eat('/')) {
        operation();
        Fn b = unary();
        a = [a, b](const double* t) { return a(t) / b(t); };
      } else {
        return a;
      }
    }
  }
  // power binds tighter than unary minus: -2^2 = -4; right-associative.
  Fn power() {
    Fn a = primary();
    if (eat('^')) {
      operation();
      Fn b = unary();
      return [a, b](const double* t) { return std::pow(a(t), b(t)); };
    }
    return a;
  }
  Fn unary() {
    struct Level {
      int& d;
      ~Level() { --d; }
    } level{++depth_};
    if (depth_ > kMaxDepth)
      fail(fmt::format("nested more than {} levels deep (parentheses, signs, powers)", kMaxDepth));
    if (eat('-')) {
      operation();
      Fn a = unary();
      return [a](const double* t) { return -a(t); };
    }
    if (eat('+')) return unary();
    return power();
  }
  Fn primary() {
    skip();
    if (eat('(')) {
      Fn a = expr();
      if (!eat(')')) fail("missing ')'");
      return a;
    }
    if (p_ < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[p_])) || s_[p_] == '.')) {
      const char* b = s_.c_str() + p_;
      char* e = nullptr;
      const double v = std::strtod(b, &e);
      if (e == b) fail("bad number");
      p_ += static_cast<std::size_t>(e - b);
      return [v](const double*) { return v; };
    }
    std::string name;
    while (p_ < s_.size() && (std::isalpha(static_cast<unsigned char>(s_[p_])) || s_[p_] == '_'))
      name += s_[p_++];
    for (std::size_t k = 0; k < vars_.size(); ++k)
      if (name == vars_[k]) return [k](const double* t) { return t[k]; };
    if (name == "pi") return [](const double*) { return M_PI; };
    double (*f)(double) = nullptr;
    if (name == "sin")
      f = [](double x) { return std::sin(x); };
    else if (name == "cos")
      f = [](double x) { return std::cos(x); };
    else if (name == "tan")
      f = [](double x) { return std::tan(x); };
    else if (name == "exp")
      f = [](double x) { return std::exp(x); };
    else if (name == "log")
      f = [](double x) { return std::log(x); };
    else if (name == "sqrt")
      f = [](double x) { return std::sqrt(x); };
    else if (name == "abs")
      f = [](double x) { return std::abs(x); };
    if (!f)
      fail(name.empty() ? "expected a number, a variable or a function"
                        : "unknown name '" + name + "'");
    if (!eat('(')) fail("expected '(' after " + name);
    Fn a = expr();
    if (!eat(')')) fail("missing ')'");
    return [f, a](const double* t) { return f(a(t)); };
  }
  const std::string& s_;
  int depth_ = 0;
  int operations_ = 0;
  std::string where_;
  std::vector<std::string> vars_;
  std::size_t p_ = 0;
};

}  // namespace

std::function<double(double)> parse_expression(const std::string& text, const std::string& where) {
  Fn f = Parser(text, where, {"t"}).parse();
  return [f](double t) { return f(&t); };
}

std::function<double(const double*)> parse_expression(const std::string& text,
                                                      const std::string& where,
                                                      const std::vector<std::string>& variables) {
  return Parser(text, where, variables).parse();
}

}  // namespace pdcg::scene
