#include "pdcg/body/body.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/parallel.hpp"
#include "pdcg/core/log.hpp"
#include "statistics_impl.hpp"

namespace pdcg::body {

std::string_view to_string(BodyKind kind) {
  switch (kind) {
    case BodyKind::delta:
      return "delta";
    case BodyKind::statistical:
      return "statistical";
    case BodyKind::homogenised:
      return "homogenised";
    case BodyKind::rescaled:
      return "rescaled";
  }
  return "delta";
}

BodyKind parse_body_kind(std::string_view name, std::string_view where) {
  if (name == "delta") return BodyKind::delta;
  if (name == "statistical") return BodyKind::statistical;
  if (name == "homogenised" || name == "homogenized") return BodyKind::homogenised;
  if (name == "rescaled") return BodyKind::rescaled;
  throw InputError("unknown body kind")
      .source(where)
      .key("kind")
      .value(name)
      .expected("one of delta, statistical, homogenised, rescaled")
      .fix("the file was not written by a compatible pdcg");
}

double Body::reference_volume() const {
  const Eigen::Matrix3d H = box.h();
  switch (dimension) {
    case 1:
      return H.col(0).norm();
    case 2:
      return H.col(0).cross(H.col(1)).norm();
    default:
      return std::abs(H.determinant());
  }
}

namespace {

/// Every bond type of the configuration needs a bond_coeff line (LAMMPS: "All bond coeffs are
/// not set"); `*` and `N*` reach every bond type the configuration has.
void check_bond_types(const atomistic::PotentialSpec& spec,
                      const std::vector<atomistic::Bond>& bonds, std::string_view source) {
  constexpr int kOpen = 1 << 30;  // upper end of a trailing wildcard: any bond type
  std::vector<std::pair<int, int>> covered;
  for (const auto& c : spec.bond_coeff) {
    int lo, hi;
    atomistic::parse_type_range(c.i, kOpen, lo, hi, spec.source, c.line_number, "bond_coeff");
    covered.emplace_back(lo, hi);
  }
  for (const auto& b : bonds) {
    const bool ok = std::any_of(covered.begin(), covered.end(), [&](const auto& r) {
      return b.type >= r.first && b.type <= r.second;
    });
    if (!ok)
      throw InputError("a bond type of the configuration has no bond_coeff")
          .source(source)
          .key(fmt::format("Bonds (bond of atom ids {} and {})", b.atom1, b.atom2))
          .value(fmt::format("bond type {}", b.type))
          .expected(fmt::format("a bond_coeff line for bond type {} in {}", b.type, spec.source))
          .fix(fmt::format("add `bond_coeff {} …` to {}", b.type, spec.source));
  }
}

}  // namespace

void check_periodic_images(const atomistic::Atoms& atoms, const atomistic::Families& fam,
                           bool assumed, std::string_view source) {
  const auto& p = atoms.box.periodic;
  if (!p[0] && !p[1] && !p[2]) return;
  const std::size_t n = fam.points();
  double direct = std::numeric_limits<double>::infinity();
  double image = std::numeric_limits<double>::infinity();
  std::size_t image_k = 0, image_b = 0;
  for (std::size_t k = 0; k < n; ++k)
    for (auto b = static_cast<std::size_t>(fam.offset[k]);
         b < static_cast<std::size_t>(fam.offset[k + 1]); ++b) {
      const double r = atomistic::bond_vector(fam, atoms.x, k, b).norm();
      const bool shifted =
          fam.shift[3 * b] != 0 || fam.shift[3 * b + 1] != 0 || fam.shift[3 * b + 2] != 0;
      if (!shifted) {
        direct = std::min(direct, r);
      } else if (r < image) {
        image = r;
        image_k = k;
        image_b = b;
      }
    }
  // 0.7 of the closest contact inside the box: a repulsive core r⁻¹² makes that pair ≳ 70
  // times as energetic as the closest contact (LJ: φ(0.7σ) ≈ 256 ε), which no configuration a
  // simulation wrote has; the closest contacts between a periodic crystal or liquid and its
  // images are those inside the box (an extreme over fewer pairs: if anything, larger).
  constexpr double kOverlap = 0.7;
  log::debug("{}: closest pair inside the box {:.6g}, through a periodic image {:.6g}", source,
             direct, image);
  if (!std::isfinite(direct) || !(image < kOverlap * direct)) return;
  const auto j = static_cast<std::size_t>(fam.neighbor[image_b]);
  const std::string what = fmt::format(
      "atom id {} and the image of atom id {} shifted by ({}, {}, {}) box vectors are {:.6g} "
      "apart; the closest pair inside the box is {:.6g} apart",
      atoms.id[image_k], atoms.id[j], int{fam.shift[3 * image_b]}, int{fam.shift[3 * image_b + 1]},
      int{fam.shift[3 * image_b + 2]}, image, direct);
  const std::string periodic_dirs =
      fmt::format("{}{}{}", p[0] ? "x" : "", p[1] ? "y" : "", p[2] ? "z" : "");
  if (!assumed) {
    log::warn(
        "{}: periodic images overlap the atoms (periodic along {}): {}. The energy will be "
        "far from that of any physical configuration; check the box and the boundary",
        source, periodic_dirs, what);
    return;
  }
  throw InputError(
      "periodic images overlap the atoms (nothing states the periodicity, so LAMMPS's default "
      "`boundary p p p` applies): is this a free cluster?")
      .source(source)
      .key("boundary")
      .value(what)
      .expected(
          "a periodic box that holds the configuration without overlapping its images, or "
          "non-periodic directions")
      .fix(
          "a data file does not say which directions are periodic; for a free cluster add "
          "`boundary s s s` to the potential commands file, or pass --boundary \"f f f\" (a "
          "slab: \"p p f\"); for a crystal, check the box bounds");
}

Body make_delta_body(const atomistic::Atoms& atoms_in,
                     std::shared_ptr<const atomistic::Potential> potential,
                     atomistic::PotentialSpec spec, const DeltaBodyOptions& options) {
  if (!potential)
    throw InputError("no potential given").key("potential").fix("give a potential file");
  if (options.dimension < 1 || options.dimension > 3)
    throw InputError("body dimension out of range")
        .key("dimension")
        .value(std::to_string(options.dimension))
        .expected("1, 2 or 3");
  if (atoms_in.size() == 0)
    throw InputError("the configuration has no atoms")
        .source(options.source)
        .fix("check the input file");
  atomistic::Atoms atoms = atoms_in;
  atomistic::sort_by_id(atoms, options.source);
  // A 2D body is LAMMPS's `dimension 2`: the atoms interact in the xy plane only. LAMMPS keeps
  // z periodic in 2D (its dumps say `pp` for z) but makes no ghost atoms along z, so z images
  // are not neighbours; counting them (a thin z box, 1 lattice unit) multiplies the energy.
  if (options.dimension == 2 && atoms.box.periodic[2]) {
    atoms.box.periodic[2] = false;
    log::info("{}: body dimension 2: no periodic images along z (as LAMMPS's `dimension 2`)",
              options.source.empty() ? std::string("atoms") : options.source);
  }
  if (atoms.type.empty())
    throw InputError("the configuration has no atom types")
        .source(options.source)
        .key("type")
        .expected("a `type` column (dump) or the Atoms section of a data file")
        .fix("dump with `dump ... custom ... id type x y z`");
  // Masses: the configuration's own, else the potential file's `mass` commands.
  if (atoms.mass.empty()) {
    if (atoms.type_mass.size() < spec.type_mass.size())
      atoms.type_mass.resize(spec.type_mass.size(), NAN);
    for (std::size_t t = 1; t < spec.type_mass.size(); ++t)
      if (std::isnan(atoms.type_mass[t])) atoms.type_mass[t] = spec.type_mass[t];
  }
  // masses the potential itself sets (EAM files) fill what is still missing
  if (atoms.mass.empty()) {
    const auto pm = potential->type_masses();
    if (atoms.type_mass.size() < pm.size()) atoms.type_mass.resize(pm.size(), NAN);
    for (std::size_t t = 1; t < pm.size(); ++t)
      if (std::isnan(atoms.type_mass[t])) atoms.type_mass[t] = pm[t];
  }
  const int ntypes = potential->ntypes();
  Body body;
  body.kind = BodyKind::delta;
  body.units = spec.units;
  body.dimension = options.dimension;
  body.box = atoms.box;
  body.id = atoms.id;
  body.type = atoms.type;
  body.x = atoms.x;
  body.mass.resize(atoms.size());
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    const int t = atoms.type[i];
    if (t < 1 || t > ntypes)
      throw InputError("atom type is not covered by the potential")
          .source(options.source)
          .key("type of atom id " + std::to_string(atoms.id[i]))
          .value(std::to_string(t))
          .expected("a type in 1.." + std::to_string(ntypes) + " (the potential " +
                    potential->style() + " defines " + std::to_string(ntypes) + ")")
          .fix(
              "use the potential written for this configuration, or add pair_coeff lines for "
              "type " +
              std::to_string(t));
    const double m = atoms.mass_of(i);
    if (!(m > 0.0) || !std::isfinite(m))
      throw InputError("atom has no (positive) mass")
          .source(options.source)
          .key("mass of type " + std::to_string(t) + " (atom id " + std::to_string(atoms.id[i]) +
               ")")
          .value(std::isnan(m) ? "missing" : std::to_string(m))
          .expected("a positive mass from the data file's Masses section or a `mass` command")
          .fix("add `mass " + std::to_string(t) + " <value>` to the potential file");
    body.mass[i] = m;
  }
  // Topology: a bond style needs the molecular bonds, which only data files carry.
  if (!spec.bond_style.empty() && spec.bond_style != "zero" && atoms.bonds.empty())
    throw InputError("the potential has a bond style but the configuration carries no bonds")
        .source(spec.source)
        .line(spec.bond_style_line)
        .key("bond_style")
        .value(spec.bond_style + " with " +
               (options.source.empty() ? std::string("the configuration") : options.source) +
               ", which has no Bonds")
        .expected(
            "a configuration with its molecular bonds: a LAMMPS data file with a Bonds section "
            "(dumps carry no bonds)")
        .fix(
            "build the body from the data file LAMMPS's write_data wrote for this system (it "
            "has the Bonds section); if the system has no bonds, remove bond_style and "
            "bond_coeff");
  if (!atoms.bonds.empty()) {
    if (spec.bond_style.empty())
      // LAMMPS (Force::init) warns the same way and runs: special_bonds still weight the pairs
      log::warn("{}: bonds are defined but no bond style is set ({}): the bonds add no energy",
                options.source, spec.source);
    else
      check_bond_types(spec, atoms.bonds, options.source);
  }
  atomistic::FamilyOptions fo;
  fo.cutoff = options.cutoff > 0.0 ? options.cutoff : potential->cutoff();
  if (!(fo.cutoff > 0.0) && !atoms.bonds.empty())
    fo.cutoff = 1e-9 * atoms.box.lengths().maxCoeff();  // bonds only
  if (!atoms.bonds.empty()) {
    fo.molecular_bonds = &atoms.bonds;
    fo.special_lj = spec.special_lj;
  }
  body.families = atomistic::build_families(atoms, fo);
  check_periodic_images(atoms, body.families, options.periodicity_assumed, options.source);
  body.base_horizon = fo.cutoff;
  body.potential = potential;
  body.base_potential = potential;
  if (spec.ntypes == 0) spec.ntypes = ntypes;
  body.potential_spec = std::move(spec);
  body.provenance.push_back("delta body from " +
                            (options.source.empty() ? std::string("atoms") : options.source) +
                            " with " + potential->style());
  return body;
}

// ---------------------------------------------------------------------------------------------
// Rescaled potential

namespace {

class RescaledPotential final : public atomistic::Potential {
 public:
  RescaledPotential(std::shared_ptr<const atomistic::Potential> base, double eps, int d)
      : base_(std::move(base)),
        eps_(eps),
        psi_scale_(std::pow(eps, d)),
        t_scale_(std::pow(eps, d - 1)) {}
  std::string style() const override { return base_->style(); }
  double cutoff() const override { return eps_ * base_->cutoff(); }
  int ntypes() const override { return base_->ntypes(); }
  bool pairwise() const override { return base_->pairwise(); }
  double force_state(const atomistic::FamilyState& family, double* t) const override {
    const auto n3 = static_cast<std::size_t>(3 * family.size);
    const double psi = base_->force_state(base_state(family), t);
    for (std::size_t i = 0; i < n3; ++i) t[i] *= t_scale_;
    return psi_scale_ * psi;
  }
  /// K_ε(Y') = ∂t_ε/∂Y' = ε^(d−2) K(ε⁻¹Y'), forwarded to the base's (analytic) tangent.
  void force_state_tangent(const atomistic::FamilyState& family, double* K,
                           double* workspace) const override {
    base_->force_state_tangent(base_state(family), K, workspace);
    const auto nk = static_cast<std::size_t>(9 * family.size * family.size);
    for (std::size_t i = 0; i < nk; ++i) K[i] *= k_scale_;
  }

 private:
  /// The family with its bonds ε⁻¹Y' (the base potential's bonds), held in a thread-local
  /// buffer that grows to the largest family once per thread, then never allocates.
  atomistic::FamilyState base_state(const atomistic::FamilyState& family) const {
    thread_local std::vector<double> z;
    const auto n3 = static_cast<std::size_t>(3 * family.size);
    if (z.size() < n3) z.resize(n3);
    const double inv = 1.0 / eps_;
    for (std::size_t i = 0; i < n3; ++i) z[i] = inv * family.bond[i];
    atomistic::FamilyState f = family;
    f.bond = z.data();
    return f;
  }

  std::shared_ptr<const atomistic::Potential> base_;
  double eps_, psi_scale_, t_scale_, k_scale_ = std::pow(eps_, -1) * t_scale_;
};

}  // namespace

std::shared_ptr<const atomistic::Potential> rescaled_potential(
    std::shared_ptr<const atomistic::Potential> base, double epsilon, int dimension) {
  if (!(epsilon > 0.0) || !std::isfinite(epsilon))
    throw InputError("rescaling factor must be positive")
        .key("factor")
        .value(std::to_string(epsilon))
        .expected("ε > 0 (ε = δ'/δ, the ratio of new to old horizon)")
        .fix("give a positive --factor or --horizon");
  if (epsilon == 1.0) return base;
  return std::make_shared<RescaledPotential>(std::move(base), epsilon, dimension);
}

// ---------------------------------------------------------------------------------------------
// Evaluator

Evaluator::Evaluator(const Body& body) : body_(body) {
  if (!body.potential)
    throw InputError("body has no potential").fix("build the body with a potential");
  const std::size_t n = body.size(), nb = body.families.bonds();
  y_.resize(3 * n);
  t_.resize(3 * nb);
  psi_.resize(n);
  f_.resize(3 * n);
  ntype_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b)
    ntype_[b] = body.type[static_cast<std::size_t>(body.families.neighbor[b])];
  scratch_ = std::make_unique<detail::Scratch>();
}

Evaluator::~Evaluator() = default;

Evaluation Evaluator::run(std::span<const double> y, const Eigen::Matrix3d& h_y,
                          const Eigen::Matrix3d& G) {
  const auto& fam = body_.families;
  if (y.size() != 3 * body_.size())
    throw InputError("deformed configuration has the wrong number of atoms")
        .key("positions")
        .value(std::to_string(y.size() / 3))
        .expected(std::to_string(body_.size()) + " atoms with the body's ids");
  Evaluation e;
  if (body_.statistics) {
    e.energy =
        detail::statistical_force_states(body_, *body_.statistics, y, h_y, G, psi_, t_, *scratch_);
  } else {
    // ψ_k and t_b per atom (atomistic::force_states without its per-call type buffer: the
    // partner types are cached once in the constructor). The deformed bonds Y_b of atom k are
    // built in a per-thread buffer (grown once per thread to the largest family), so the
    // evaluator holds no per-bond array besides t, and this loop allocates nothing after the
    // first call.
    const auto& pot = *body_.potential;
    double total = 0.0;
    ParallelExceptions errors;  // a potential may refuse a configuration (NumericalError)
#pragma omp parallel for schedule(static) reduction(+ : total)
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(body_.size()); ++ii) errors.capture([&] {
      const auto i = static_cast<std::size_t>(ii);
      const auto b0 = static_cast<std::size_t>(fam.offset[i]),
                 b1 = static_cast<std::size_t>(fam.offset[i + 1]);
      thread_local std::vector<double> yb;
      if (yb.size() < 3 * (b1 - b0)) yb.resize(3 * (b1 - b0));
      for (std::size_t b = b0; b < b1; ++b) {
        const Eigen::Vector3d v = atomistic::bond_vector(fam, y, h_y, i, b);
        yb[3 * (b - b0)] = v[0];
        yb[3 * (b - b0) + 1] = v[1];
        yb[3 * (b - b0) + 2] = v[2];
      }
      const atomistic::FamilyState f =
          atomistic::family_state(fam, i, body_.type[i], ntype_.data() + b0, yb.data());
      psi_[i] = pot.force_state(f, t_.data() + 3 * b0);
      total += psi_[i];
    });
    errors.rethrow();
    e.energy = total;
  }
  atomistic::pd_forces(fam, t_, f_);
  e.psi = psi_;
  e.t = t_;
  e.forces = f_;
  return e;
}

Evaluation Evaluator::reference() {
  return run(body_.x, body_.families.h, Eigen::Matrix3d::Identity());
}

Evaluation Evaluator::deformed(std::span<const double> y, const Eigen::Matrix3d& h_deformed) {
  return run(y, h_deformed, Eigen::Matrix3d::Identity());
}

Evaluation Evaluator::deformed(std::span<const double> y) { return deformed(y, body_.families.h); }

Evaluation Evaluator::homogeneous(const Eigen::Matrix3d& F) {
  const std::size_t n = body_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d xi(body_.x[3 * i], body_.x[3 * i + 1], body_.x[3 * i + 2]);
    const Eigen::Vector3d yi = F * xi;
    for (int k = 0; k < 3; ++k) y_[3 * i + static_cast<std::size_t>(k)] = yi[k];
  }
  return run(y_, F * body_.families.h, F);
}

Eigen::Matrix3d Evaluator::stress(const Eigen::Matrix3d& F) {
  const auto& fam = body_.families;
  const std::size_t n = body_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d yi =
        F * Eigen::Vector3d(body_.x[3 * i], body_.x[3 * i + 1], body_.x[3 * i + 2]);
    for (int k = 0; k < 3; ++k) y_[3 * i + static_cast<std::size_t>(k)] = yi[k];
  }
  Eigen::Matrix3d du_df = Eigen::Matrix3d::Zero();
  if (body_.statistics) {
    detail::statistical_force_states(body_, *body_.statistics, y_, F * fam.h, F, psi_, t_,
                                     *scratch_, &du_df);
  } else {
    run(y_, F * fam.h, F);
    double acc[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
#pragma omp parallel for schedule(static) reduction(+ : acc[:9])
    for (std::int64_t ii = 0; ii < static_cast<std::int64_t>(n); ++ii) {
      const auto i = static_cast<std::size_t>(ii);
      for (auto b = static_cast<std::size_t>(fam.offset[i]);
           b < static_cast<std::size_t>(fam.offset[i + 1]); ++b) {
        const Eigen::Vector3d xi = atomistic::bond_vector(fam, body_.x, fam.h, i, b);
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            acc[3 * r + c] += t_[3 * b + static_cast<std::size_t>(r)] * xi[c];
      }
    }
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) du_df(r, c) = acc[3 * r + c];
  }
  return du_df / body_.reference_volume();
}

std::vector<double> Evaluator::point_energies() const {
  if (!body_.homogenisation)
    throw InputError("point energies need a homogenised body").fix("run `pdcg homogenize` first");
  const auto& h = *body_.homogenisation;
  std::vector<double> e(h.size(), 0.0);
#pragma omp parallel for schedule(static)
  for (std::int64_t p = 0; p < static_cast<std::int64_t>(h.size()); ++p) {
    double s = 0.0;
    for (auto c = h.offset[static_cast<std::size_t>(p)];
         c < h.offset[static_cast<std::size_t>(p) + 1]; ++c)
      s += h.weight[static_cast<std::size_t>(c)] *
           psi_[static_cast<std::size_t>(h.atom[static_cast<std::size_t>(c)])];
    e[static_cast<std::size_t>(p)] = s;
  }
  return e;
}

}  // namespace pdcg::body
