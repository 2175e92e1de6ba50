/// \file
/// Scalar expressions in the load factor t for scene values, e.g. "0.5*t",
/// "1e-3*sin(3.14159*t)". Grammar: + − * / ^, unary ±, parentheses, numbers,
/// the variable t, the constant pi, functions sin cos tan exp log sqrt abs.
/// The general form takes other variable names (e.g. x, y, z for initial fields).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace pdcg::scene {

/// Parses `text`; throws InputError (naming `where`) on a syntax error.
std::function<double(double)> parse_expression(const std::string& text, const std::string& where);

/// Expression in the named variables; the function takes their values in that order.
std::function<double(const double*)> parse_expression(const std::string& text,
                                                      const std::string& where,
                                                      const std::vector<std::string>& variables);

}  // namespace pdcg::scene
