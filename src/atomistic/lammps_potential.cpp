#include "pdcg/atomistic/lammps_potential.hpp"

#include <fmt/format.h>

#include <cmath>
#include <mutex>
#include <vector>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/config.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

#if PDCG_WITH_LAMMPS
#include <library.h>
#endif

#ifdef _OPENMP
#include <omp.h>
#endif

namespace pdcg::atomistic {

#if !PDCG_WITH_LAMMPS
std::unique_ptr<Potential> make_lammps_potential(const PotentialSpec& spec) {
  require_supported_styles(spec, false);  // names the line of a style that is not native
  throw InputError("this build has no embedded LAMMPS for the fallback potential")
      .source(spec.source)
      .fix("rebuild pdcg with -DPDCG_ENABLE_LAMMPS=ON (liblammps), or use make_potential");
}
#else
namespace {

std::string g17(double v) { return fmt::format("{:.17g}", v); }

/// The spec the clusters run: the user's pair part only (molecular bonds are added natively,
/// special_bonds factors come from the families' pair factors).
PotentialSpec pair_part(const PotentialSpec& spec) {
  PotentialSpec p = spec;
  p.bond_style.clear();
  p.bond_style_args.clear();
  p.bond_coeff.clear();
  p.special_lj = p.special_coul = {1.0, 1.0, 1.0};
  // clusters hold no molecular topology: the per-atom attributes the pair part needs
  if (p.atom_style == "full") p.atom_style = "charge";
  if (p.atom_style == "bond" || p.atom_style == "angle" || p.atom_style == "molecular")
    p.atom_style = "atomic";
  return p;
}

/// The commands that set up a cluster instance (before any atom exists).
std::vector<LammpsCommand> cluster_setup(const PotentialSpec& spec, double half) {
  std::vector<LammpsCommand> c{
      {"units " + std::string(to_string(spec.units)), spec.units_line},
      {"atom_style " + spec.atom_style, 0},
      {"atom_modify map array sort 0 0.0", 0},
      {"boundary f f f", 0},
      {fmt::format("region pdcg_box block {0} {1} {0} {1} {0} {1}", g17(-half), g17(half)), 0},
      {fmt::format("create_box {} pdcg_box", spec.ntypes), 0}};
  for (int t = 1; t <= spec.ntypes; ++t) c.push_back({fmt::format("mass {} 1.0", t), 0});
  for (auto& l : lammps_potential_command_lines(spec)) c.push_back(std::move(l));
  c.push_back({"compute pdcg_pe all pe/atom", 0});
  c.push_back({"thermo_style custom step pe", 0});
  return c;
}

double type_charge(const PotentialSpec& spec, int t) {
  const auto k = static_cast<std::size_t>(t);
  return k < spec.type_charge.size() && !std::isnan(spec.type_charge[k]) ? spec.type_charge[k]
                                                                         : 0.0;
}

/// One LAMMPS instance holding a free cluster in a cube [-half, half]³.
class Cluster {
 public:
  Cluster(const PotentialSpec& spec, double half) : spec_(spec), half_(half) {
#ifdef _OPENMP
    const int threads = omp_get_max_threads();
#endif
    const char* args[] = {"pdcg", "-log", "none", "-screen", "none", "-nocite"};
    lmp_ = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    if (!lmp_) throw InputError("liblammps failed to start").fix("check the LAMMPS installation");
    for (const auto& c : cluster_setup(spec, half)) cmd(c.text);
    charged_ = spec.atom_style == "charge" || spec.atom_style == "full";
  }
  ~Cluster() { lammps_close(lmp_); }
  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

  double half() const { return half_; }

  /// Replaces the atoms by `types`/`x` (ids 1..n), with the charges of their types.
  void set(const std::vector<int>& types, const std::vector<double>& x) {
    cmd("delete_atoms group all");
    ids_.resize(types.size());
    for (std::size_t i = 0; i < ids_.size(); ++i) ids_[i] = static_cast<int>(i + 1);
    lammps_create_atoms(lmp_, static_cast<int>(types.size()), ids_.data(), types.data(), x.data(),
                        nullptr, nullptr, 0);
    const int n = lammps_extract_setting(lmp_, "nlocal");
    if (n != static_cast<int>(types.size()))
      throw NumericalError(fmt::format(
          "embedded LAMMPS kept {} of {} cluster atoms (a bond longer than the cluster box?)", n,
          types.size()));
    if (charged_) {
      const auto* type = static_cast<const int*>(lammps_extract_atom(lmp_, "type"));
      auto* q = static_cast<double*>(lammps_extract_atom(lmp_, "q"));
      for (int i = 0; i < n; ++i) q[i] = type_charge(spec_, type[i]);
    }
  }
  /// ψ of the atom with id `id` after moving atom `moved` (id) by delta along d (0 = none).
  double energy(int id) {
    cmd("run 0 post no");
    const auto* tag = static_cast<const int*>(lammps_extract_atom(lmp_, "id"));
    const auto* pe = static_cast<const double*>(
        lammps_extract_compute(lmp_, "pdcg_pe", LMP_STYLE_ATOM, LMP_TYPE_VECTOR));
    const int n = lammps_extract_setting(lmp_, "nlocal");
    for (int i = 0; i < n; ++i)
      if (tag[i] == id) return pe[i];
    throw NumericalError("embedded LAMMPS lost the centre atom of a cluster");
  }
  /// Runs `run 0` and returns per-atom energies and forces by id (1-based: index id − 1).
  void evaluate_all(std::vector<double>& pe_by_id, std::vector<double>& f_by_id) {
    cmd("run 0 post no");
    const auto* tag = static_cast<const int*>(lammps_extract_atom(lmp_, "id"));
    const auto* pe = static_cast<const double*>(
        lammps_extract_compute(lmp_, "pdcg_pe", LMP_STYLE_ATOM, LMP_TYPE_VECTOR));
    auto** f = static_cast<double**>(lammps_extract_atom(lmp_, "f"));
    const int n = lammps_extract_setting(lmp_, "nlocal");
    pe_by_id.assign(static_cast<std::size_t>(n), 0.0);
    f_by_id.assign(3 * static_cast<std::size_t>(n), 0.0);
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(tag[i] - 1);
      pe_by_id[k] = pe[i];
      for (int d = 0; d < 3; ++d) f_by_id[3 * k + static_cast<std::size_t>(d)] = f[i][d];
    }
  }
  void move(int id, int d, double delta) {
    const auto* tag = static_cast<const int*>(lammps_extract_atom(lmp_, "id"));
    auto** x = static_cast<double**>(lammps_extract_atom(lmp_, "x"));
    const int n = lammps_extract_setting(lmp_, "nlocal");
    for (int i = 0; i < n; ++i)
      if (tag[i] == id) {
        x[i][d] += delta;
        return;
      }
  }

 private:
  void cmd(const std::string& c) {
    log::debug("embedded LAMMPS: {}", c);
    lammps_command(lmp_, c.c_str());
  }
  const PotentialSpec& spec_;
  void* lmp_ = nullptr;
  double half_;
  bool charged_ = false;
  std::vector<int> ids_;
};

/// Runs the cluster setup and one evaluation of every type pair as a dimer in `lmp` (a
/// separate process): LAMMPS errors of the commands become InputErrors before liblammps could
/// stop the process.
void check_cluster_commands(const PotentialSpec& spec) {
  auto script = cluster_setup(spec, 100.0);
  for (int a = 1; a <= spec.ntypes; ++a)
    for (int b = a; b <= spec.ntypes; ++b) {
      script.push_back({"delete_atoms group all", 0});
      script.push_back({fmt::format("create_atoms {} single 0 0 0 units box", a), 0});
      // 60 apart: beyond any cutoff (the probe refuses styles reaching 50), so `run 0` checks
      // the coefficients, files and atom attributes without evaluating a pair distance
      script.push_back({fmt::format("create_atoms {} single 60 0 0 units box", b), 0});
      if (spec.atom_style == "charge" || spec.atom_style == "full")
        for (int t = 1; t <= spec.ntypes; ++t)
          script.push_back({fmt::format("set type {} charge {}", t, g17(type_charge(spec, t))), 0});
      script.push_back({"run 0 post no", 0});
    }
  check_lammps_commands(script, spec, "setting up the model in embedded LAMMPS");
}

class LammpsPotential final : public Potential {
 public:
  LammpsPotential(const PotentialSpec& spec, std::unique_ptr<Potential> bonds)
      : spec_(spec), pair_spec_(pair_part(spec)), bonds_(std::move(bonds)) {
    // r_c per type pair by bisection on dimer energies
    Cluster probe(pair_spec_, 100.0);
    double rc = 0.0;
    std::vector<double> rc_pair(static_cast<std::size_t>((spec_.ntypes + 1) * (spec_.ntypes + 1)),
                                0.0);
    for (int a = 1; a <= spec_.ntypes; ++a)
      for (int b = a; b <= spec_.ntypes; ++b) {
        auto dimer = [&](double r) {
          probe.set({a, b}, {0.0, 0.0, 0.0, r, 0.0, 0.0});
          return probe.energy(1);
        };
        double lo = 0.5, hi = 50.0;  // LAMMPS length units; styles cut far below 50
        if (dimer(hi) != 0.0)
          throw InputError("pair style interacts beyond 50 length units: no finite horizon")
              .source(spec_.source)
              .line(spec_.pair_style_line)
              .key("pair_style")
              .value(spec_.pair_style);
        // find an interacting distance first (dimers too close may be zero for some styles)
        double r = hi;
        while (r > 0.05 && dimer(r) == 0.0) r *= 0.8;
        if (dimer(r) == 0.0) continue;  // this type pair does not interact
        lo = r;
        while (hi - lo > 1e-9 * hi) {
          const double mid = 0.5 * (lo + hi);
          (dimer(mid) != 0.0 ? lo : hi) = mid;
        }
        rc = std::max(rc, hi);
        rc_pair[static_cast<std::size_t>(a * (spec_.ntypes + 1) + b)] = lo;
      }
    if (rc == 0.0)
      throw InputError("pair style gives no interaction at any distance")
          .source(spec_.source)
          .key("pair_style")
          .value(spec_.pair_style);
    // Pairwise (ψ_k = ½ Σ_j φ(r_kj))? Measured: ψ_1 of atom 1 with six partners (distances
    // 0.62–0.92 r_c, directions near ±x, ±y, ±z: a bond-order term sees several neighbours,
    // a three-body term angles of 90° and 180°) against the sum of its six dimers, for every
    // centre and partner type. 1e-10 relative: round-off of a sum of six terms is ≈ 1e-15;
    // a many-body style differs by far more (Si.tersoff: 24 %; sw, tersoff and tersoff/mod are
    // classified many-body in test_lammps_engine.cpp).
    pairwise_ = true;
    for (int a = 1; a <= spec_.ntypes && pairwise_; ++a)
      for (int b = 1; b <= spec_.ntypes && pairwise_; ++b) {
        const double r =
            rc_pair[static_cast<std::size_t>(std::min(a, b) * (spec_.ntypes + 1) + std::max(a, b))];
        if (r == 0.0) continue;
        const double dir[6][3] = {{1, 0.05, 0.02},  {-1, 0.03, -0.04}, {0.06, 1, -0.03},
                                  {0.02, -1, 0.05}, {-0.04, 0.02, 1},  {0.03, -0.05, -1}};
        std::vector<int> types{a};
        std::vector<double> x{0.0, 0.0, 0.0};
        double sum = 0.0, largest = 0.0;
        for (int m = 0; m < 6; ++m) {
          const double len =
              (0.62 + 0.06 * m) * r /
              std::sqrt(dir[m][0] * dir[m][0] + dir[m][1] * dir[m][1] + dir[m][2] * dir[m][2]);
          const double y[3] = {len * dir[m][0], len * dir[m][1], len * dir[m][2]};
          probe.set({a, b}, {0.0, 0.0, 0.0, y[0], y[1], y[2]});
          const double e = probe.energy(1);
          sum += e;
          largest = std::max(largest, std::abs(e));
          types.push_back(b);
          x.insert(x.end(), {y[0], y[1], y[2]});
        }
        probe.set(types, x);
        const double all = probe.energy(1);
        if (std::abs(all - sum) > 1e-10 * std::max({largest, std::abs(all), 1e-300}))
          pairwise_ = false;
      }
    // A pairwise style needs families of r_c; LAMMPS splits three-body and bond-order energies
    // over atoms up to 2 r_c apart.
    cutoff_ = pairwise_ ? rc : 2.0 * rc;
    if (bonds_ && !pairwise_)
      throw InputError(
          "molecular bonds with a many-body pair style through embedded LAMMPS: the "
          "special_bonds exclusions of a many-body style cannot be applied per family")
          .source(spec_.source)
          .line(spec_.bond_style_line)
          .key("bond_style")
          .value(spec_.bond_style + " with pair_style " + spec_.pair_style)
          .expected("a pairwise pair style (measured: ψ of a trimer is not the sum of its dimers)")
          .fix("drop the bond_style, or use a pairwise pair style");
    // The working cluster is created now: potential files may be temporary (model files
    // extract their embedded copies only while the potential is constructed).
    // pairwise: a larger box holds many separate dimers per `run 0` (force_state)
    cluster_ = std::make_unique<Cluster>(pair_spec_, (pairwise_ ? 12.0 : 4.0) * cutoff_);
    log::info(
        "pair_style {}: no native force states; embedded LAMMPS {}, measured r_c = {:.6g}, {}, "
        "family cutoff {:.6g}",
        spec_.pair_style,
        pairwise_ ? "forces of separate dimers (analytic)"
                  : "central differences of pe/atom on clusters (slow)",
        rc, pairwise_ ? "pairwise" : "many-body (horizon 2 r_c)", cutoff_);
  }

  /// Pairwise style: ψ_k = ½ Σ_j s_kj φ(r_kj), t_kj = s_kj ½ φ'(r) Y/r. Every partner j with
  /// s > 0 becomes a dimer (a copy of k and j) in the cluster box, the dimers farther apart than
  /// the cutoff from each other, as many per `run 0` as fit: ½φ is the pe/atom of the copy of k
  /// and t_kj = −½ F_j with F_j LAMMPS's force on j (analytic, no finite differences).
  double pairwise_force_state(const FamilyState& f, double* t, double longest) const {
    const auto n = static_cast<std::size_t>(f.size);
    std::fill(t, t + 3 * n, 0.0);
    // atoms of two dimers are at least spacing − 2 longest apart: more than the cutoff
    const double spacing = 2.0 * longest + 1.1 * cutoff_ + 1e-3;
    const double half = cluster_->half();
    // dimer m: copy of k at origin + spacing·(m mod p, ⌊m/p⌋ mod p, ⌊m/p²⌋), its partner
    // within `longest` of it: every atom inside the box [−half, half]³
    const double origin = -half + longest + 1e-3;
    const int per_side =
        std::max(1, static_cast<int>((2.0 * half - 2.0 * longest - 2e-3) / spacing) + 1);
    const std::size_t capacity = static_cast<std::size_t>(per_side) * per_side * per_side;
    double psi = 0.0;
    std::size_t j = 0;
    while (j < n) {
      types_.clear();
      x_.clear();
      slot_.clear();  // partner index of each dimer in this run
      for (; j < n && slot_.size() < capacity; ++j) {
        const double s = f.pair_factor ? f.pair_factor[j] : 1.0;
        if (s == 0.0) continue;  // LAMMPS drops s = 0 pairs from its neighbour lists
        const auto m = static_cast<int>(slot_.size());
        const double c[3] = {origin + spacing * (m % per_side),
                             origin + spacing * ((m / per_side) % per_side),
                             origin + spacing * (m / (per_side * per_side))};
        types_.insert(types_.end(), {f.type, f.neighbor_type[j]});
        x_.insert(x_.end(), {c[0], c[1], c[2], c[0] + f.bond[3 * j], c[1] + f.bond[3 * j + 1],
                             c[2] + f.bond[3 * j + 2]});
        slot_.push_back(static_cast<int>(j));
      }
      if (slot_.empty()) break;
      cluster_->set(types_, x_);
      cluster_->evaluate_all(pe_, f_);
      for (std::size_t m = 0; m < slot_.size(); ++m) {
        const auto b = static_cast<std::size_t>(slot_[m]);
        const double s = f.pair_factor ? f.pair_factor[b] : 1.0;
        psi += s * pe_[2 * m];
        for (std::size_t d = 0; d < 3; ++d) t[3 * b + d] = -0.5 * s * f_[3 * (2 * m + 1) + d];
      }
    }
    if (bonds_) {  // native molecular bonds: ψ_k += ½ Σ_bonded E_b, t_kj += −½ fbond Y
      tb_.assign(3 * n, 0.0);
      FamilyState fb = f;
      fb.pair_factor = nullptr;
      psi += bonds_->force_state(fb, tb_.data());
      for (std::size_t i = 0; i < 3 * n; ++i) t[i] += tb_[i];
    }
    return psi;
  }

  std::string style() const override {
    return spec_.pair_style + " (embedded LAMMPS)" +
           (bonds_ ? " + bond " + spec_.bond_style : std::string());
  }
  double cutoff() const override { return cutoff_; }
  int ntypes() const override { return spec_.ntypes; }

  double force_state(const FamilyState& f, double* t) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto n = static_cast<std::size_t>(f.size);
    double longest = 0.0, mean = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      const double r =
          std::sqrt(f.bond[3 * j] * f.bond[3 * j] + f.bond[3 * j + 1] * f.bond[3 * j + 1] +
                    f.bond[3 * j + 2] * f.bond[3 * j + 2]);
      longest = std::max(longest, r);
      mean += r;
    }
    if (longest > 0.9 * cluster_->half())
      throw NumericalError(fmt::format(
          "pair_style {} (embedded LAMMPS): a deformed bond of length {:.6g} does not fit the "
          "cluster box of half-width {:.6g} (4 or 12 × the family cutoff); the deformation is too "
          "large "
          "for the force-state fallback",
          spec_.pair_style, longest, cluster_->half()));
    if (pairwise_) return pairwise_force_state(f, t, longest);
    // Many-body style (no special factors: bonds need a pairwise style, make_lammps_potential)
    if (f.pair_factor)
      for (std::size_t j = 0; j < n; ++j)
        if (f.pair_factor[j] != 1.0)
          throw NumericalError(
              "embedded LAMMPS: a special_bonds factor on a many-body pair style (unsupported)");
    types_.assign(1, f.type);
    x_.assign(3, 0.0);
    for (std::size_t j = 0; j < n; ++j) {
      types_.push_back(f.neighbor_type[j]);
      x_.insert(x_.end(), {f.bond[3 * j], f.bond[3 * j + 1], f.bond[3 * j + 2]});
    }
    cluster_->set(types_, x_);
    const double psi = cluster_->energy(1);
    // h = 1e-5 × mean bond: truncation O(h²) and round-off O(ε ψ/h) both ≈ 1e-10 relative
    const double h = n > 0 ? 1e-5 * mean / static_cast<double>(n) : 0.0;
    for (std::size_t j = 0; j < n; ++j)
      for (int d = 0; d < 3; ++d) {
        const int id = static_cast<int>(j + 2);
        cluster_->move(id, d, h);
        const double plus = cluster_->energy(1);
        cluster_->move(id, d, -2.0 * h);
        const double minus = cluster_->energy(1);
        cluster_->move(id, d, h);
        t[3 * j + static_cast<std::size_t>(d)] = (plus - minus) / (2.0 * h);
      }
    return psi;
  }

 private:
  PotentialSpec spec_, pair_spec_;
  std::unique_ptr<Potential> bonds_;  ///< native bond-only model (no pair style); may be null
  double cutoff_ = 0.0;
  bool pairwise_ = false;
  mutable std::mutex mutex_;
  mutable std::unique_ptr<Cluster> cluster_;
  mutable std::vector<int> types_, slot_;
  mutable std::vector<double> x_, tb_, pe_, f_;
};

}  // namespace

std::unique_ptr<Potential> make_lammps_potential(const PotentialSpec& spec) {
  if (spec.pair_style.rfind("hybrid", 0) == 0)
    throw InputError("pair_style hybrid is not supported by the force-state fallback")
        .source(spec.source)
        .line(spec.pair_style_line)
        .key("pair_style")
        .value(spec.pair_style);
  (void)LammpsEngine(spec);  // styles, files, k-space styles: checked before LAMMPS could abort
  if ((spec.atom_style == "charge" || spec.atom_style == "full") && spec.type_charge.empty())
    log::warn(
        "{}: atom_style {} but no charges (no `set type T charge Q` and none taken from a data "
        "file): every charge is 0 in embedded LAMMPS",
        spec.source, spec.atom_style);
  std::unique_ptr<Potential> bonds;
  if (!spec.bond_style.empty()) {
    // an atom style with bonds: LammpsEngine(spec) above requires one
    if (!native_bond_style(spec.bond_style))
      throw InputError("bond style with an embedded-LAMMPS pair style must be native")
          .source(spec.source)
          .line(spec.bond_style_line)
          .key("bond_style")
          .value(spec.bond_style)
          .expected(native_bond_style_names());
    const bool coulomb = spec.pair_style.find("coul") != std::string::npos ||
                         spec.pair_style.find("tip4p") != std::string::npos;
    if (coulomb && spec.special_lj != spec.special_coul)
      throw InputError(
          "special_bonds with different lj and coul factors: pdcg's families carry one "
          "special factor per pair, so a coulomb pair style through embedded LAMMPS needs equal "
          "factors")
          .source(spec.source)
          .key("special_bonds")
          .value(fmt::format("lj {} {} {} coul {} {} {}", spec.special_lj[0], spec.special_lj[1],
                             spec.special_lj[2], spec.special_coul[0], spec.special_coul[1],
                             spec.special_coul[2]))
          .expected("special_bonds lj/coul A B C")
          .fix("use `special_bonds lj/coul A B C`, or compute this model with LAMMPS itself");
    PotentialSpec b = spec;  // bond-only native model
    b.pair_style.clear();
    b.pair_style_args.clear();
    b.pair_coeff.clear();
    b.pair_modify.clear();
    bonds = make_potential(b);
  }
  check_cluster_commands(pair_part(spec));
  return std::make_unique<LammpsPotential>(spec, std::move(bonds));
}
#endif

}  // namespace pdcg::atomistic
