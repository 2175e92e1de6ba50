#include "pdcg/atomistic/atoms.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "pdcg/core/error.hpp"

namespace pdcg::atomistic {

double Atoms::mass_of(std::size_t i) const {
  if (!mass.empty()) return mass[i];
  if (!type.empty()) {
    const auto t = static_cast<std::size_t>(type[i]);
    if (t < type_mass.size()) return type_mass[t];
  }
  return std::numeric_limits<double>::quiet_NaN();
}

namespace {
template <class T>
void permute(std::vector<T>& a, const std::vector<std::size_t>& order, std::size_t width) {
  if (a.empty()) return;
  std::vector<T> out(a.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    for (std::size_t c = 0; c < width; ++c) out[k * width + c] = a[order[k] * width + c];
  a.swap(out);
}
}  // namespace

void sort_by_id(Atoms& atoms, std::string_view source) {
  const std::size_t n = atoms.id.size();
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  const bool sorted = std::is_sorted(atoms.id.begin(), atoms.id.end());
  if (!sorted)
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return atoms.id[a] < atoms.id[b]; });
  for (std::size_t k = 1; k < n; ++k)
    if (atoms.id[order[k]] == atoms.id[order[k - 1]])
      throw InputError("duplicate atom id")
          .source(source)
          .key("id")
          .value(std::to_string(atoms.id[order[k]]))
          .expected("each atom id once per frame")
          .fix("the file merges two systems or is corrupt; renumber the atoms (LAMMPS reset_atoms id)");
  if (sorted) return;
  permute(atoms.id, order, 1);
  permute(atoms.type, order, 1);
  permute(atoms.x, order, 3);
  permute(atoms.image, order, 3);
  permute(atoms.v, order, 3);
  permute(atoms.f, order, 3);
  permute(atoms.molecule, order, 1);
  permute(atoms.charge, order, 1);
  permute(atoms.mass, order, 1);
  for (auto& [name, col] : atoms.extra) permute(col, order, 1);
}

}  // namespace pdcg::atomistic
