// bench_body_memory: bytes per atom / point and per bond held by each body kind
// (docs/performance.md, "Memory"), measured as live heap bytes (counting malloc, live_bytes.hpp)
// against the data each must hold. FCC LJ crystal (ρ = 0.8442, lj/cut 2.5, periodic), n³ cells (4n³
// atoms).
//   bench_body_memory [n = 12]
// One key=value line per body kind; roofline.sh turns them into the memory table.
//
// Minimum data ("must hold"), per atom: position 24 B, mass 8 B, type 4 B, id 8 B (44 B);
// per bond: neighbour index 4 B + periodic image 4 B (three small shifts, packed) = 8 B
// (the bond vector ξ = x_j + H n − x_k and the reverse bond are derivable); CSR offset 8 B
// per atom. Statistical (Gaussian): + the symmetric covariance, 6 doubles per atom.
// Rescaled: as delta (ε and the wrapped potential are O(1)). Homogenised: + per point
// position, volume, mass (40 B) and CSR offset (8 B), per (point, atom) weight 8 B + atom 4 B.
// Evaluator (work arrays): per bond the force state t (24 B, returned to the caller), per atom
// deformed position, force, energy (56 B).
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/body/statistics.hpp"
#include "pdcg/coarsen/homogenise.hpp"
#include "pdcg/coarsen/kernels.hpp"
#include "pdcg/coarsen/rescale.hpp"
// last: it defines malloc & co. after the system headers declared them
#include "live_bytes.hpp"

namespace {
template <class V>
double cap(const V& v) {
  return static_cast<double>(v.capacity() * sizeof(typename V::value_type));
}
void line(const char* kind, long long bytes, double min, std::size_t atoms, std::size_t bonds,
          std::size_t points, std::size_t entries) {
  std::printf(
      "kind=%s atoms=%zu bonds=%zu points=%zu entries=%zu bytes=%lld min_bytes=%.0f "
      "bytes_per_atom=%.1f bytes_per_bond=%.2f min_per_atom=%.1f ratio=%.2f\n",
      kind, atoms, bonds, points, entries, bytes, min, static_cast<double>(bytes) / atoms,
      static_cast<double>(bytes) / bonds, min / atoms, static_cast<double>(bytes) / min);
}
}  // namespace

int main(int argc, char** argv) {
  using namespace pdcg;
  const int n = argc > 1 ? std::atoi(argv[1]) : 12;
  const double a = std::cbrt(4.0 / 0.8442);
  atomistic::Atoms at;
  at.box.hi = {n * a, n * a, n * a};
  const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  std::int64_t id = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const auto& b : basis) {
          at.id.push_back(++id);
          at.type.push_back(1);
          at.x.insert(at.x.end(),
                      {(i + b[0] + 0.1) * a, (j + b[1] + 0.1) * a, (k + b[2] + 0.1) * a});
        }
  const auto spec = atomistic::read_potential_commands_from_string(
      "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n", "bench", 1);
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);

  long long l0 = live_bytes;
  const body::Body delta = body::make_delta_body(at, pot, spec);
  const long long b_delta = live_bytes - l0;
  const std::size_t N = delta.size(), B = delta.families.bonds();
  const double min_atomic = 44.0 * N + 8.0 * B + 8.0 * (N + 1);
  line("delta", b_delta, min_atomic, N, B, 0, 0);
  const auto& F = delta.families;
  std::printf(
      "arrays delta: id=%.0f type=%.0f x=%.0f mass=%.0f fam_offset=%.0f neighbor=%.0f shift=%.0f "
      "reverse=%.0f pair_factor=%.0f bond_type=%.0f (bytes by capacity)\n",
      cap(delta.id), cap(delta.type), cap(delta.x), cap(delta.mass), cap(F.offset), cap(F.neighbor),
      cap(F.shift), cap(F.reverse), cap(F.pair_factor), cap(F.bond_type));

  l0 = live_bytes;
  {
    body::Evaluator ev(delta);
    ev.reference();
    line("evaluator", live_bytes - l0, 24.0 * B + 56.0 * N, N, B, 0, 0);
  }

  l0 = live_bytes;
  {
    body::Body s = delta;
    body::make_statistical(s, body::isotropic_gaussian(s, 0.05));
    line("statistical", live_bytes - l0, min_atomic + 48.0 * N, N, B, 0, 0);
  }

  l0 = live_bytes;
  {
    const body::Body r = coarsen::rescale(delta, 2.0);
    line("rescaled", live_bytes - l0, min_atomic, N, r.families.bonds(), 0, 0);
  }

  l0 = live_bytes;
  {
    const body::Body h = coarsen::homogenise_on_grid(
        delta, coarsen::make_kernel("wendland-c2", 2.0 * a), {.spacing = a});
    const auto& H = *h.homogenisation;
    const std::size_t P = H.size(), E = H.atom.size();
    const double min_h = 44.0 * h.size() + 8.0 * h.families.bonds() + 8.0 * (h.size() + 1) +
                         48.0 * P + 12.0 * E;
    line("homogenised", live_bytes - l0, min_h, h.size(), h.families.bonds(), P, E);
  }
  return 0;
}
