#include "pdcg/coarsen/kernels.hpp"

#include <cmath>

#include "pdcg/core/error.hpp"

namespace pdcg::coarsen {

namespace {

template <std::size_t I = 0>
bool try_make(std::string_view name, double width, Kernel& out) {
  if constexpr (I < std::variant_size_v<Kernel>) {
    using K = std::variant_alternative_t<I, Kernel>;
    if (name == K::name) {
      out = K{width};  // every kernel is an aggregate of its width
      return true;
    }
    return try_make<I + 1>(name, width, out);
  } else {
    return false;
  }
}

template <std::size_t I = 0>
void names(std::vector<std::string>& out) {
  if constexpr (I < std::variant_size_v<Kernel>) {
    out.emplace_back(std::variant_alternative_t<I, Kernel>::name);
    names<I + 1>(out);
  }
}

}  // namespace

std::vector<std::string> kernel_names() {
  std::vector<std::string> n;
  names(n);
  return n;
}

Kernel make_kernel(std::string_view name, double width) {
  std::string list;
  for (const auto& n : kernel_names()) list += (list.empty() ? "" : ", ") + n;
  if (!(width > 0.0) || !std::isfinite(width))
    throw InputError("kernel width must be positive")
        .key("width")
        .value(std::to_string(width))
        .expected("a positive length (support radius; σ for the Gaussian)")
        .fix("give --width larger than the lattice spacing");
  Kernel k;
  if (!try_make(name, width, k))
    throw InputError("unknown kernel").key("kernel").value(name).expected("one of " + list);
  return k;
}

std::string_view kernel_name(const Kernel& k) {
  return std::visit([](const auto& v) { return std::decay_t<decltype(v)>::name; }, k);
}

double kernel_width(const Kernel& k) {
  return std::visit([](const auto& v) { return v.width(); }, k);
}

}  // namespace pdcg::coarsen
