#include "pdcg/atomistic/families.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "pdcg/core/error.hpp"
#include "pdcg/core/parallel.hpp"

namespace pdcg::atomistic {

namespace {

constexpr int kMaxShift = 127;  ///< Families::shift is int8

struct Entry {
  std::int32_t atom;
  std::array<std::int32_t, 3> shift;
  Eigen::Vector3d pos;
};

struct Candidate {
  std::int32_t j;
  std::array<std::int32_t, 3> shift;
  bool operator<(const Candidate& o) const {
    if (j != o.j) return j < o.j;
    return shift < o.shift;
  }
  bool operator==(const Candidate& o) const { return j == o.j && shift == o.shift; }
};

}  // namespace

Families build_families(const Atoms& atoms, const FamilyOptions& options) {
  const double rc = options.cutoff;
  if (!(rc > 0.0) || !std::isfinite(rc))
    throw InputError("family cutoff must be positive")
        .key("cutoff")
        .value(std::to_string(rc))
        .expected("a positive distance")
        .fix("check the potential's cutoff");
  const std::size_t n = atoms.size();
  const Box& box = atoms.box;
  const Eigen::Matrix3d H = box.h();
  const Eigen::Vector3d heights = box.heights();

  Families fam;
  fam.h = H;
  fam.offset.assign(n + 1, 0);
  if (n == 0) return fam;

  // Image shells needed along each periodic direction: the cutoff sphere spans at most
  // rc/height_k in fractional coordinate k.
  std::array<int, 3> shells{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    if (box.periodic[static_cast<std::size_t>(k)])
      shells[static_cast<std::size_t>(k)] =
          static_cast<int>(std::min(std::ceil(rc / heights[k]), 1e9));
  for (int k = 0; k < 3; ++k)
    if (shells[static_cast<std::size_t>(k)] > kMaxShift)
      throw InputError("periodic box much smaller than the cutoff")
          .key("box")
          .value(fmt::format("height {} along direction {}, cutoff {}", heights[k], k, rc))
          .expected(fmt::format(
              "box heights of at least cutoff/{} (image shifts are stored in one byte)", kMaxShift))
          .fix("replicate the configuration (LAMMPS `replicate`) or use a smaller cutoff");

  const Eigen::Matrix3d Hinv = box.h_inverse();
  // Positions may be unwrapped (data files and dumps with image flags give x + H·image), so
  // two neighbours can be several box lengths apart. The search runs on the positions wrapped
  // into the box along the periodic directions, x_i − H w_i with w_i = ⌊s_i⌋, and a pair found
  // at shift n between wrapped positions is the shift n + w_i − w_j between the given ones.
  std::vector<Eigen::Vector3d> frac(n);
  std::vector<std::array<std::int32_t, 3>> wrap(n, {0, 0, 0});
  std::vector<Eigen::Vector3d> xw(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d x(atoms.x[3 * i], atoms.x[3 * i + 1], atoms.x[3 * i + 2]);
    frac[i] = Hinv * (x - box.lo);
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k)
      if (box.periodic[static_cast<std::size_t>(k)] && std::isfinite(frac[i][k])) {
        w[k] = std::floor(frac[i][k]);
        if (std::abs(w[k]) > 1e9)
          throw InputError("atom far outside the periodic box")
              .key(fmt::format("x of atom id {}", atoms.id[i]))
              .value(fmt::format("{} box lengths along direction {}", w[k], k))
              .expected("positions within a few box lengths of the box")
              .fix("check the positions and the box of the configuration");
        wrap[i][static_cast<std::size_t>(k)] = static_cast<std::int32_t>(w[k]);
      }
    frac[i] -= w;
    xw[i] = x - H * w;
  }

  // Fractional range of the originals, then the margin where images can matter.
  Eigen::Vector3d smin = frac[0], smax = frac[0];
  for (const auto& s : frac) {
    smin = smin.cwiseMin(s);
    smax = smax.cwiseMax(s);
  }
  Eigen::Vector3d margin;
  for (int k = 0; k < 3; ++k) margin[k] = rc / heights[k];

  // Originals plus the images within `margin` of the originals' range.
  std::vector<Entry> entries;
  entries.reserve(n * 2);
  for (std::size_t i = 0; i < n; ++i)
    entries.push_back({static_cast<std::int32_t>(i), {0, 0, 0}, xw[i]});
  for (int a = -shells[0]; a <= shells[0]; ++a)
    for (int b = -shells[1]; b <= shells[1]; ++b)
      for (int c = -shells[2]; c <= shells[2]; ++c) {
        if (a == 0 && b == 0 && c == 0) continue;
        const Eigen::Vector3d sh(a, b, c);
        const Eigen::Vector3d cart = H * sh;
        for (std::size_t i = 0; i < n; ++i) {
          const Eigen::Vector3d s = frac[i] + sh;
          if ((s.array() < (smin - margin).array()).any() ||
              (s.array() > (smax + margin).array()).any())
            continue;
          entries.push_back({static_cast<std::int32_t>(i), {a, b, c}, xw[i] + cart});
        }
      }

  // Cartesian cell list over the bounding box of all entries, cells of edge >= rc.
  Eigen::Vector3d lo = entries[0].pos, hi = entries[0].pos;
  for (const auto& e : entries) {
    lo = lo.cwiseMin(e.pos);
    hi = hi.cwiseMax(e.pos);
  }
  std::array<std::int64_t, 3> nc{};
  for (int k = 0; k < 3; ++k)
    nc[static_cast<std::size_t>(k)] =
        std::max<std::int64_t>(1, static_cast<std::int64_t>(std::floor((hi[k] - lo[k]) / rc)));
  // Cap the number of cells (sparse, elongated systems): at most ~8 entries' worth.
  while (nc[0] * nc[1] * nc[2] > static_cast<std::int64_t>(8 * entries.size() + 64)) {
    auto& m = *std::max_element(nc.begin(), nc.end());
    m = std::max<std::int64_t>(1, m / 2);
  }
  Eigen::Vector3d cell;
  for (int k = 0; k < 3; ++k)
    cell[k] = std::max((hi[k] - lo[k]) / static_cast<double>(nc[static_cast<std::size_t>(k)]), rc);
  auto cell_of = [&](const Eigen::Vector3d& p, int k) {
    auto c = static_cast<std::int64_t>(std::floor((p[k] - lo[k]) / cell[k]));
    return std::clamp<std::int64_t>(c, 0, nc[static_cast<std::size_t>(k)] - 1);
  };
  const std::int64_t ncell = nc[0] * nc[1] * nc[2];
  std::vector<std::int64_t> head(static_cast<std::size_t>(ncell + 1), 0);
  std::vector<std::int64_t> cell_index(entries.size());
  for (std::size_t e = 0; e < entries.size(); ++e) {
    const auto& p = entries[e].pos;
    cell_index[e] = (cell_of(p, 0) * nc[1] + cell_of(p, 1)) * nc[2] + cell_of(p, 2);
    ++head[static_cast<std::size_t>(cell_index[e] + 1)];
  }
  std::partial_sum(head.begin(), head.end(), head.begin());
  std::vector<std::int64_t> fill(head.begin(), head.end() - 1);
  std::vector<std::int32_t> sorted(entries.size());
  for (std::size_t e = 0; e < entries.size(); ++e)
    sorted[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell_index[e])]++)] =
        static_cast<std::int32_t>(e);

  const double rc2 = rc * rc;
  std::vector<std::vector<Candidate>> lists(n);
#pragma omp parallel for schedule(dynamic, 256)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    const Eigen::Vector3d& p = entries[i].pos;
    const std::int64_t ci = cell_of(p, 0), cj = cell_of(p, 1), ck = cell_of(p, 2);
    auto& out = lists[i];
    for (std::int64_t a = std::max<std::int64_t>(0, ci - 1); a <= std::min(nc[0] - 1, ci + 1); ++a)
      for (std::int64_t b = std::max<std::int64_t>(0, cj - 1); b <= std::min(nc[1] - 1, cj + 1);
           ++b)
        for (std::int64_t c = std::max<std::int64_t>(0, ck - 1); c <= std::min(nc[2] - 1, ck + 1);
             ++c) {
          const std::int64_t id = (a * nc[1] + b) * nc[2] + c;
          for (std::int64_t s = head[static_cast<std::size_t>(id)];
               s < head[static_cast<std::size_t>(id + 1)]; ++s) {
            const auto e = static_cast<std::size_t>(sorted[static_cast<std::size_t>(s)]);
            if (e == i) continue;
            if ((entries[e].pos - p).squaredNorm() < rc2) {
              const auto& wi = wrap[i];
              const auto& wj = wrap[static_cast<std::size_t>(entries[e].atom)];
              const auto& sh = entries[e].shift;
              out.push_back(
                  {entries[e].atom,
                   {sh[0] + wi[0] - wj[0], sh[1] + wi[1] - wj[1], sh[2] + wi[2] - wj[2]}});
            }
          }
        }
  }

  // Molecular bonds (always in the family, minimum-image shift) and special factors.
  std::vector<std::unordered_map<std::int32_t, double>> special;  // per atom: partner -> factor
  std::vector<std::vector<std::pair<Candidate, int>>> bonded(n);
  if (options.molecular_bonds && !options.molecular_bonds->empty()) {
    std::unordered_map<std::int64_t, std::int32_t> index;
    index.reserve(n);
    for (std::size_t i = 0; i < n; ++i) index[atoms.id[i]] = static_cast<std::int32_t>(i);
    auto lookup = [&](std::int64_t id) {
      auto it = index.find(id);
      if (it == index.end())
        throw InputError("bond names an atom id that is not in the configuration")
            .key("Bonds")
            .value(std::to_string(id))
            .expected("ids of existing atoms")
            .fix("check that the data file's Bonds section matches its Atoms section");
      return it->second;
    };
    std::vector<std::vector<std::int32_t>> graph(n);
    for (const Bond& bd : *options.molecular_bonds) {
      const std::int32_t i = lookup(bd.atom1), j = lookup(bd.atom2);
      const Eigen::Vector3d d(
          atoms.x[3 * static_cast<std::size_t>(j)] - atoms.x[3 * static_cast<std::size_t>(i)],
          atoms.x[3 * static_cast<std::size_t>(j) + 1] -
              atoms.x[3 * static_cast<std::size_t>(i) + 1],
          atoms.x[3 * static_cast<std::size_t>(j) + 2] -
              atoms.x[3 * static_cast<std::size_t>(i) + 2]);
      const Eigen::Vector3d m = box.minimum_image_exact(d);
      const Eigen::Vector3d sh = Hinv * (m - d);
      const std::array<std::int32_t, 3> s{static_cast<std::int32_t>(std::lround(sh[0])),
                                          static_cast<std::int32_t>(std::lround(sh[1])),
                                          static_cast<std::int32_t>(std::lround(sh[2]))};
      bonded[static_cast<std::size_t>(i)].push_back({{j, s}, bd.type});
      bonded[static_cast<std::size_t>(j)].push_back({{i, {-s[0], -s[1], -s[2]}}, bd.type});
      graph[static_cast<std::size_t>(i)].push_back(j);
      graph[static_cast<std::size_t>(j)].push_back(i);
    }
    // 1-2, 1-3, 1-4 partners by breadth-first search over the bond graph (as LAMMPS's
    // special list: by atom, for every image).
    special.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      std::vector<std::int32_t> frontier{static_cast<std::int32_t>(i)};
      std::unordered_map<std::int32_t, int> depth{{static_cast<std::int32_t>(i), 0}};
      for (int d = 1; d <= 3; ++d) {
        std::vector<std::int32_t> next;
        for (auto a : frontier)
          for (auto b : graph[static_cast<std::size_t>(a)])
            if (!depth.count(b)) {
              depth[b] = d;
              next.push_back(b);
            }
        frontier.swap(next);
      }
      for (auto [a, d] : depth)
        if (d > 0) special[i][a] = options.special_lj[static_cast<std::size_t>(d - 1)];
    }
  }

  // Merge, sort, compact into CSR.
  for (std::size_t i = 0; i < n; ++i) {
    auto& l = lists[i];
    for (auto& [c, t] : bonded[i]) l.push_back(c);
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    fam.offset[i + 1] = fam.offset[i] + static_cast<std::int64_t>(l.size());
  }
  const auto nb = static_cast<std::size_t>(fam.offset[n]);
  if (nb > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InputError("too many bonds for the 32-bit bond index")
        .key("bonds")
        .value(std::to_string(nb))
        .expected("at most 2147483647 bonds in all (about 4·10⁷ atoms at 54 bonds per atom)")
        .fix("split the configuration, or use a smaller cutoff");
  fam.neighbor.resize(nb);
  fam.shift.resize(3 * nb);
  fam.reverse.resize(nb);
  const bool molecular = !special.empty();
  if (molecular) {
    fam.pair_factor.assign(nb, 1.0);
    fam.bond_type.assign(nb, 0);
  }
  const Eigen::Vector3d half_length = 0.5 * box.lengths();
  auto beyond_half_box = [&](std::size_t i, const Candidate& c) {
    const auto j = static_cast<std::size_t>(c.j);
    const Eigen::Vector3d d =
        Eigen::Vector3d(atoms.x[3 * j] - atoms.x[3 * i], atoms.x[3 * j + 1] - atoms.x[3 * i + 1],
                        atoms.x[3 * j + 2] - atoms.x[3 * i + 2]) +
        H * Eigen::Vector3d(c.shift[0], c.shift[1], c.shift[2]);
    for (int k = 0; k < 3; ++k)
      if (box.periodic[static_cast<std::size_t>(k)] && std::abs(d[k]) > half_length[k]) return true;
    return false;
  };
  for (std::size_t i = 0; i < n; ++i) {
    auto b = static_cast<std::size_t>(fam.offset[i]);
    for (const auto& c : lists[i]) {
      fam.neighbor[b] = c.j;
      for (int k = 0; k < 3; ++k) {
        const std::int32_t sk = c.shift[static_cast<std::size_t>(k)];
        if (sk < -kMaxShift || sk > kMaxShift)
          throw InputError("periodic image shift does not fit in one byte")
              .key(fmt::format("x of atom id {}", atoms.id[i]))
              .value(fmt::format("image shift {} along direction {}", sk, k))
              .expected(fmt::format("shifts within ±{} box lengths", kMaxShift))
              .fix(
                  "wrap the positions into the box (unwrapped by more than 127 box lengths?), or "
                  "replicate a box far smaller than the cutoff");
        fam.shift[3 * b + static_cast<std::size_t>(k)] = static_cast<std::int8_t>(sk);
      }
      if (molecular) {
        // LAMMPS weights a special partner (by atom id, any image) only when the pair passes
        // Domain::minimum_image_check: every Cartesian component of the separation within half
        // the box length along the periodic directions. A farther image within the cutoff is
        // an ordinary neighbour (factor 1), as in every NPair build.
        auto it = special[i].find(c.j);
        if (it != special[i].end() && !beyond_half_box(i, c)) fam.pair_factor[b] = it->second;
        for (auto& [bc, t] : bonded[i])
          if (bc == c) fam.bond_type[b] = t;
      }
      ++b;
    }
  }
  // reverse[b]: bond (j → i, −shift) in the sorted family of j (binary search).
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    for (auto b = static_cast<std::size_t>(fam.offset[i]);
         b < static_cast<std::size_t>(fam.offset[i + 1]); ++b) {
      const Candidate want{static_cast<std::int32_t>(i),
                           {-fam.shift[3 * b], -fam.shift[3 * b + 1], -fam.shift[3 * b + 2]}};
      const auto& l = lists[static_cast<std::size_t>(fam.neighbor[b])];
      auto it = std::lower_bound(l.begin(), l.end(), want);
      PDCG_ASSERT(it != l.end() && *it == want, "family asymmetry");
      fam.reverse[b] = static_cast<std::int32_t>(
          fam.offset[static_cast<std::size_t>(fam.neighbor[b])] + (it - l.begin()));
    }
  }
  return fam;
}

void deformed_bonds(const Families& fam, std::span<const double> y, const Eigen::Matrix3d& hd,
                    std::span<double> out) {
  const std::size_t n = fam.points();
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    for (auto b = static_cast<std::size_t>(fam.offset[i]);
         b < static_cast<std::size_t>(fam.offset[i + 1]); ++b) {
      const Eigen::Vector3d v = bond_vector(fam, y, hd, i, b);
      for (int k = 0; k < 3; ++k) out[3 * b + static_cast<std::size_t>(k)] = v[k];
    }
  }
}

std::vector<double> bond_vectors(const Families& fam, std::span<const double> x) {
  std::vector<double> out(3 * fam.bonds());
  deformed_bonds(fam, x, fam.h, out);
  return out;
}

double force_states(const Potential& potential, const Families& fam, std::span<const int> type,
                    std::span<const double> bonds, std::span<double> psi, std::span<double> t) {
  const std::size_t n = fam.points();
  // Neighbour types per bond, gathered once per call into a buffer owned by the caller
  // would avoid this allocation; it is O(bonds) ints and outside the per-atom loop.
  std::vector<int> ntype(fam.bonds());
  for (std::size_t b = 0; b < fam.bonds(); ++b)
    ntype[b] = type[static_cast<std::size_t>(fam.neighbor[b])];
  double total = 0.0;
  ParallelExceptions errors;  // a potential may refuse a configuration (NumericalError)
#pragma omp parallel for schedule(static) reduction(+ : total)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) errors.capture([&] {
    const auto i = static_cast<std::size_t>(ii);
    const auto b0 = static_cast<std::size_t>(fam.offset[i]);
    const FamilyState f = family_state(fam, i, type[i], ntype.data() + b0, bonds.data() + 3 * b0);
    psi[i] = potential.force_state(f, t.data() + 3 * b0);
    total += psi[i];
  });
  errors.rethrow();
  return total;
}

void pd_forces(const Families& fam, std::span<const double> t, std::span<double> f) {
  const std::size_t n = fam.points();
#pragma omp parallel for schedule(static)
  for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
    const auto i = static_cast<std::size_t>(ii);
    double fx = 0, fy = 0, fz = 0;
    for (auto b = static_cast<std::size_t>(fam.offset[i]);
         b < static_cast<std::size_t>(fam.offset[i + 1]); ++b) {
      const auto r = static_cast<std::size_t>(fam.reverse[b]);
      fx += t[3 * b] - t[3 * r];
      fy += t[3 * b + 1] - t[3 * r + 1];
      fz += t[3 * b + 2] - t[3 * r + 2];
    }
    f[3 * i] = fx;
    f[3 * i + 1] = fy;
    f[3 * i + 2] = fz;
  }
}

}  // namespace pdcg::atomistic
