#include "pdcg/dispersion/plan.hpp"

#include <fmt/format.h>

#include "pdcg/body/lattice.hpp"
#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"
#include "pdcg/dispersion/body_dispersion.hpp"
#include "pdcg/dispersion/crystal.hpp"
#include "pdcg/dispersion/model.hpp"

namespace pdcg::dispersion {

DispersionPlan::DispersionPlan() = default;
DispersionPlan::DispersionPlan(DispersionPlan&&) noexcept = default;
DispersionPlan& DispersionPlan::operator=(DispersionPlan&&) noexcept = default;
DispersionPlan::~DispersionPlan() = default;

Eigen::VectorXd DispersionPlan::omega(const Eigen::Vector3d& k) const {
  return crystal_ ? crystal_->omega(k) : point_->omega(k);
}

std::string DispersionPlan::description() const {
  return crystal_ ? crystal_->description() : point_->description();
}

std::vector<std::pair<double, std::string>> DispersionPlan::corners() const {
  std::vector<std::pair<double, std::string>> out;
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (!labels[i].empty() &&
        (i == 0 || labels[i] != labels[i - 1] || kappa[i].first != kappa[i - 1].first))
      out.emplace_back(kappa[i].first, labels[i]);
  return out;
}

void check_one_point_lattice(const body::Body& body, bool cell, const std::string& mode,
                             bool lattice_given, const std::string& source,
                             const DispersionOptionNames& n) {
  if (cell) return;  // every atom of the box is a basis atom: any crystal
  const auto lat = body::detect_lattice(body);
  if (lat.bravais()) return;
  if (!lat.perfect) {
    log::info(
        "{}: the dispersion is that of one point and its family as if it were a Bravais "
        "lattice site",
        lat.summary);
    return;
  }
  const std::string what = fmt::format(
      "{} — one-point dispersion gives 3 branches: the {} optical branches are missing and the "
      "acoustic ones are those of atoms that move without their basis partners",
      lat.summary, 3 * (lat.basis - 1));
  const std::string fix = fmt::format(
      "use {} without {}/{} (e.g. {}): all 3n branches of the primitive cell along a labelled "
      "path; or {} for the folded branches of the whole periodic box",
      n.path, n.lattice, n.a, n.path_auto, n.cell);
  if (mode == n.path && !lattice_given)
    throw InputError("cannot tell the Bravais lattice: the crystal has a basis")
        .source(source)
        .key(n.path)
        .value(what)
        .expected("a Bravais lattice (one atom per primitive cell) for the neighbour-shell guess")
        .fix(fmt::format("{}; or pass {} and {} for the one-point curves anyway", fix, n.lattice,
                         n.a));
  log::warn("{}: {}. Fix: {}", mode, what, fix);
}

DispersionPlan plan_dispersion(const body::Body& body, const DispersionRequest& r,
                               const DispersionOptionNames& n) {
  DispersionPlan plan;
  std::string lattice = r.lattice;
  double a = r.a;
  const bool explicit_lattice = !r.lattice.empty() && r.a > 0;
  bool crystal_path = false;  // the path comes from the classified crystal
  if (!r.path.empty() && !r.cell && !explicit_lattice) {
    // the crystal decides: its lattice (and orientation) from body::detect_lattice; a crystal
    // with a basis gets its primitive cell's 3n branches, a Bravais lattice the one-point ones
    const auto info = body::detect_lattice(body);
    if (!info.perfect)
      throw InputError(fmt::format("{} needs a perfect crystal: high-symmetry paths and branches "
                                   "belong to a primitive cell",
                                   n.path))
          .source(r.source)
          .key(n.path)
          .value(info.summary)
          .expected(
              "a body whose every atom is one of n equally populated lattice sites "
              "(no vacancies, interstitials, surfaces, displaced atoms or random species)")
          .fix(fmt::format(
              "compute the dispersion of the perfect crystal's body (e.g. the ordered alloy, "
              "before the defect); for this body use {} (folded branches of the whole "
              "periodic box), or {} and {} for the one-point curves of the {}'s "
              "environment",
              n.cell, n.lattice, n.a, n.point));
    // every atom its own class: the box holds no lattice translation. A body of one primitive
    // cell looks like this (a few atoms); a random alloy or a disordered box of many atoms does
    // too, and its "primitive cell" would be the whole box — refused above 16 atoms.
    if (info.basis > 16 && static_cast<std::size_t>(info.basis) == body.size())
      throw InputError(fmt::format("{} needs a perfect crystal: no two of the body's atoms are "
                                   "lattice translates of each other",
                                   n.path))
          .source(r.source)
          .key(n.path)
          .value(fmt::format("{} atoms, {} different environments (a random alloy, an amorphous "
                             "or perturbed box: not a perfect crystal)",
                             body.size(), info.basis))
          .expected(
              "a perfect crystal: atoms repeated by lattice translations inside the box "
              "(a primitive cell of at most 16 atoms is accepted as the whole box)")
          .fix(fmt::format(
              "compute the dispersion of the ordered crystal's body; for this box as it is use "
              "{} (its 3N folded branches, the box taken as the repeating cell)",
              n.cell));
    if (!info.bravais()) {
      const auto cl = classify_lattice(info, body.dimension, r.source);
      log::info("{} ({})", cl.summary, info.summary);
      const std::string spec = r.path == "auto" ? default_path(cl.lattice) : r.path;
      for (const auto& p : labelled_path(cl.points, cl.lattice, spec, r.nk)) {
        plan.kappa.emplace_back(p.s, p.kappa);
        plan.labels.push_back(p.label);
      }
      plan.lattice = cl.lattice;
      plan.a = cl.a;
      crystal_path = true;
      if (body.homogenisation) {
        log::info(
            "homogenised body: the model has 3 degrees of freedom per point, so 3 branches — "
            "the atoms of the point (all {} basis sites) move together (no optical branches)",
            info.basis);
      } else {
        plan.crystal_ = std::make_unique<CrystalDispersion>(body, info);
      }
    }
  }
  if (!crystal_path) {
    check_one_point_lattice(body, r.cell, r.path.empty() ? n.direction : n.path, explicit_lattice,
                            r.source, n);
    const std::size_t rep = r.cell ? 0 : representative_atom(body, r.point);
    if (!r.path.empty()) {
      if (lattice.empty() || !(a > 0)) {
        const auto g = detect_lattice(body, rep);
        if (lattice.empty()) lattice = g.lattice;
        if (!(a > 0)) a = g.a;
        log::info("lattice {} with a = {:.6g} (nearest neighbours: {} at {:.6g})", lattice, a,
                  g.coordination, g.nearest);
      }
      const std::string spec = r.path == "auto" ? default_path(lattice) : r.path;
      for (const auto& p : labelled_path(symmetry_points(lattice, a), lattice, spec, r.nk)) {
        plan.kappa.emplace_back(p.s, p.kappa);
        plan.labels.push_back(p.label);
      }
      plan.lattice = lattice;
      plan.a = a;
    }
  }
  if (!plan.crystal_) plan.point_ = std::make_unique<BodyDispersion>(body, r.point, r.cell);
  if (r.path.empty()) {
    double kmax = r.kmax;
    if (!(kmax > 0)) {
      // zone edge along the direction (chain: π/h; fcc [100]: 2π/a; fcc [111]: √3π/a)
      kmax = zone_edge(body, plan.point_->representative_atom(), r.direction, n.direction,
                       r.direction_text);
    }
    for (int i = 0; i <= r.nk; ++i) {
      const double k = kmax * i / r.nk;
      plan.kappa.emplace_back(k, k * r.direction);
    }
  }
  return plan;
}

}  // namespace pdcg::dispersion
