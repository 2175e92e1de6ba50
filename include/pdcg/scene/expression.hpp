/// \file
/// Scalar expressions in the load factor t for scene values, e.g. "0.5*t",
/// "1e-3*sin(3.14159*t)". Grammar: + − * / ^, unary ±, parentheses, numbers,
/// the variable t, functions sin cos tan exp log sqrt abs.
#pragma once

#include <functional>
#include <string>

namespace pdcg::scene {

/// Parses `text`; throws InputError (naming `where`) on a syntax error.
std::function<double(double)> parse_expression(const std::string& text, const std::string& where);

}  // namespace pdcg::scene
