#include "pdcg/atomistic/lammps_potential.hpp"

#include <fmt/format.h>

#include <cmath>
#include <mutex>
#include <vector>

#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
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
  throw InputError("pair style has no native implementation and embedded LAMMPS is off")
      .source(spec.source)
      .line(spec.pair_style_line)
      .key("pair_style")
      .value(spec.pair_style)
      .expected("lj/cut, morse, zero, eam, eam/alloy or eam/fs")
      .fix("rebuild pdcg with -DPDCG_ENABLE_LAMMPS=ON");
}
#else
namespace {

std::string g17(double v) { return fmt::format("{:.17g}", v); }

/// One LAMMPS instance holding a free cluster in a cube [-half, half]³.
class Cluster {
 public:
  Cluster(const PotentialSpec& spec, double half) : half_(half) {
#ifdef _OPENMP
    const int threads = omp_get_max_threads();
#endif
    const char* args[] = {"pdcg", "-log", "none", "-screen", "none", "-nocite"};
    lmp_ = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
#ifdef _OPENMP
    omp_set_num_threads(threads);
#endif
    if (!lmp_) throw InputError("liblammps failed to start").fix("check the LAMMPS installation");
    cmd("units " + std::string(to_string(spec.units)));
    cmd("atom_style atomic");
    cmd("atom_modify map array sort 0 0.0");
    cmd("boundary f f f");
    cmd(fmt::format("region pdcg_box block {0} {1} {0} {1} {0} {1}", g17(-half), g17(half)));
    cmd(fmt::format("create_box {} pdcg_box", spec.ntypes));
    for (int t = 1; t <= spec.ntypes; ++t) cmd(fmt::format("mass {} 1.0", t));
    for (const auto& c : lammps_potential_commands(spec)) cmd(c);
    cmd("compute pdcg_pe all pe/atom");
    cmd("thermo_style custom step pe");
  }
  ~Cluster() { lammps_close(lmp_); }
  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;

  double half() const { return half_; }

  /// Replaces the atoms by `types`/`x` (ids 1..n) and evaluates.
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
  void* lmp_ = nullptr;
  double half_;
  std::vector<int> ids_;
};

class LammpsPotential final : public Potential {
 public:
  explicit LammpsPotential(const PotentialSpec& spec) : spec_(spec) {
    // r_c per type pair by bisection on dimer energies; the family cutoff is 2 max r_c.
    Cluster probe(spec_, 100.0);
    double rc = 0.0;
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
      }
    if (rc == 0.0)
      throw InputError("pair style gives no interaction at any distance")
          .source(spec_.source)
          .key("pair_style")
          .value(spec_.pair_style);
    cutoff_ = 2.0 * rc;
    // The working cluster is created now: potential files may be temporary (model files
    // extract their embedded copies only while the potential is constructed).
    cluster_ = std::make_unique<Cluster>(spec_, 4.0 * cutoff_);
    log::info(
        "pair_style {}: no native force states; embedded LAMMPS by central differences of "
        "pe/atom on clusters (slow), measured r_c = {:.6g}, family cutoff 2 r_c = {:.6g}",
        spec_.pair_style, rc, cutoff_);
  }

  std::string style() const override { return spec_.pair_style + " (embedded LAMMPS)"; }
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
          "cluster box of half-width {:.6g} (4 × the family cutoff); the deformation is too large "
          "for the force-state fallback",
          spec_.pair_style, longest, cluster_->half()));
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
  PotentialSpec spec_;
  double cutoff_ = 0.0;
  mutable std::mutex mutex_;
  mutable std::unique_ptr<Cluster> cluster_;
  mutable std::vector<int> types_;
  mutable std::vector<double> x_;
};

}  // namespace

std::unique_ptr<Potential> make_lammps_potential(const PotentialSpec& spec) {
  if (!spec.bond_style.empty())
    throw InputError("embedded-LAMMPS force states support pair styles only")
        .source(spec.source)
        .line(spec.bond_style_line)
        .key("bond_style")
        .value(spec.bond_style)
        .expected("a native pair style (lj/cut, morse, eam*) with bonds, or no bond_style");
  if (spec.pair_style.rfind("hybrid", 0) == 0)
    throw InputError("pair_style hybrid is not supported by the force-state fallback")
        .source(spec.source)
        .line(spec.pair_style_line)
        .key("pair_style")
        .value(spec.pair_style);
  (void)LammpsEngine(spec);  // validates style and potential files before LAMMPS could abort
  return std::make_unique<LammpsPotential>(spec);
}
#endif

}  // namespace pdcg::atomistic
