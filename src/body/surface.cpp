// Surface energy of a crystal plane (include/pdcg/body/surface.hpp, docs/fracture.md).
#include "pdcg/body/surface.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/core/log.hpp"

namespace pdcg::body {

double energy_per_area_to_j_per_m2(UnitStyle style) {
  // energy/length³ in GPa × 1e9 Pa/GPa × the length unit in metres
  const double gpa = energy_density_to_gpa(style);
  switch (style) {
    case UnitStyle::metal:
    case UnitStyle::real:
      return gpa * 1e9 * 1e-10;
    case UnitStyle::si:
      return gpa * 1e9;
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

namespace {

struct Translation {
  Eigen::Vector3i m;
  Eigen::Vector3d v;  // H m
};

}  // namespace

Slab make_slab(const Body& body, const SlabOptions& o) {
  if (body.kind != BodyKind::delta || body.statistics || body.homogenisation || body.epsilon != 1.0)
    throw InputError("a surface needs a delta body")
        .key("body kind")
        .value(std::string(to_string(body.kind)))
        .expected("a delta body of a periodic crystal (pdcg atoms2pd --density delta)");
  if (body.dimension != 3 || !body.box.periodic[0] || !body.box.periodic[1] ||
      !body.box.periodic[2])
    throw InputError("a surface needs a crystal periodic in x, y and z")
        .key("boundary")
        .value(fmt::format("dimension {}, periodic {} {} {}", body.dimension, body.box.periodic[0],
                           body.box.periodic[1], body.box.periodic[2]))
        .expected("a 3-D body of a bulk crystal with `boundary p p p`")
        .fix("build the body from the periodic bulk crystal; pdcg cuts the slab itself");
  if (!body.families.bond_type.empty() || !body.families.pair_factor.empty())
    throw InputError("a surface of a body with molecular bonds")
        .key("families")
        .value("molecular bonds / special_bonds factors")
        .expected("a crystal of atoms (pair or many-body potential)");
  const double nn = o.normal.norm();
  if (!(nn > 0.0) || !o.normal.allFinite())
    throw InputError("bad plane normal")
        .key("normal")
        .value(fmt::format("{} {} {}", o.normal[0], o.normal[1], o.normal[2]))
        .expected("a nonzero vector");
  if (o.search < 1 || o.search > 40)
    throw InputError("bad search range")
        .key("search")
        .value(std::to_string(o.search))
        .expected("1..40");
  const Eigen::Vector3d n = o.normal / nn;
  const Eigen::Matrix3d H = body.box.h();

  // Lattice translations H m within the search range: in-plane ones and the least height.
  std::vector<Translation> inplane;
  double d0 = std::numeric_limits<double>::infinity();
  Translation up{Eigen::Vector3i::Zero(),
                 Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity())};
  const int S = o.search;
  for (int i = -S; i <= S; ++i)
    for (int j = -S; j <= S; ++j)
      for (int k = -S; k <= S; ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        const Eigen::Vector3i m(i, j, k);
        const Eigen::Vector3d v = H * m.cast<double>();
        const double z = n.dot(v);
        if (std::abs(z) <= 1e-9 * v.norm()) {
          inplane.push_back({m, v});
        } else if (z > 0.0) {
          // least height; among equal heights the shortest vector
          if (z < d0 * (1.0 - 1e-9) || (z <= d0 * (1.0 + 1e-9) && v.norm() < up.v.norm())) {
            if (z < d0 * (1.0 - 1e-9)) d0 = z;
            up = {m, v};
          }
        }
      }
  std::sort(inplane.begin(), inplane.end(),
            [](const Translation& a, const Translation& b) { return a.v.norm() < b.v.norm(); });
  if (inplane.size() < 2 || !std::isfinite(d0))
    throw InputError("the plane is not a lattice plane of the body's box")
        .key("normal")
        .value(fmt::format("{:.6g} {:.6g} {:.6g}", n[0], n[1], n[2]))
        .expected(fmt::format(
            "a normal with two independent box translations H m (|m_i| ≤ {}) in the plane", S))
        .fix(
            "give Miller indices of a crystal whose box edges are whole lattice periods along "
            "the cube axes, or a larger --search");
  Translation a1 = inplane[0], a2{};
  bool found = false;
  for (std::size_t q = 1; q < inplane.size(); ++q)
    if (a1.v.cross(inplane[q].v).norm() > 1e-9 * a1.v.norm() * inplane[q].v.norm()) {
      a2 = inplane[q];
      found = true;
      break;
    }
  if (!found)
    throw InputError(
        "the plane is not a lattice plane of the body's box (one in-plane lattice direction "
        "within the search range)")
        .key("normal")
        .value(fmt::format("{:.6g} {:.6g} {:.6g}", n[0], n[1], n[2]))
        .fix("give a larger --search, or a plane of lower indices");
  if (a1.v.cross(a2.v).dot(n) < 0.0) std::swap(a1, a2);
  const double area = a1.v.cross(a2.v).norm();

  // Height j d0 ≥ the requested thickness; a3 = j a30 with its in-plane part reduced.
  const double want = o.min_thickness > 0.0 ? o.min_thickness : 4.0 * body.potential->cutoff();
  const int jrep = std::max(1, static_cast<int>(std::ceil(want / d0 * (1.0 - 1e-12))));
  Eigen::Vector3i m3 = jrep * up.m;
  {
    Eigen::Matrix<double, 3, 2> A;
    A.col(0) = a1.v;
    A.col(1) = a2.v;
    const Eigen::Vector3d v3 = H * m3.cast<double>();
    const Eigen::Vector2d c = A.colPivHouseholderQr().solve(v3 - n * n.dot(v3));
    m3 -= static_cast<int>(std::lround(c[0])) * a1.m + static_cast<int>(std::lround(c[1])) * a2.m;
  }
  Eigen::Matrix3i M;
  M.col(0) = a1.m;
  M.col(1) = a2.m;
  M.col(2) = m3;
  const Eigen::Matrix3d Hs = H * M.cast<double>();
  const double detM = M.cast<double>().determinant();
  const auto copies = static_cast<std::int64_t>(std::llround(std::abs(detM)));
  if (copies < 1 || std::abs(detM - static_cast<double>(copies)) > 1e-6)
    throw NumericalError(fmt::format("slab cell: det M = {} is not a positive integer", detM));
  const std::int64_t natoms = copies * static_cast<std::int64_t>(body.size());
  if (natoms > 20'000'000)
    throw InputError("slab cell too large")
        .key("atoms")
        .value(std::to_string(natoms))
        .fix("use a smaller --thickness or a smaller periodic body (one unit cell is enough)");

  // Atoms of the slab cell: every image x_k + H t whose fractional coordinates u in the slab
  // cell lie in [−δ, 1 − δ) (δ = 1e-7: an atom on a face is taken exactly once).
  const Eigen::Matrix3d Hs_inv = Hs.inverse(), H_inv = H.inverse();
  Eigen::Vector3d tmin = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d tmax = -tmin;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d u((c & 1) ? 1 : 0, (c & 2) ? 1 : 0, (c & 4) ? 1 : 0);
    const Eigen::Vector3d s = H_inv * (Hs * u);
    tmin = tmin.cwiseMin(s);
    tmax = tmax.cwiseMax(s);
  }
  constexpr double delta = 1e-7;
  std::vector<Eigen::Vector3d> u;
  std::vector<std::size_t> src;
  u.reserve(static_cast<std::size_t>(natoms));
  for (std::size_t k = 0; k < body.size(); ++k) {
    const Eigen::Vector3d xk(body.x[3 * k], body.x[3 * k + 1], body.x[3 * k + 2]);
    Eigen::Vector3d sk = H_inv * (xk - body.box.lo);
    for (int c = 0; c < 3; ++c) sk[c] -= std::floor(sk[c]);
    const Eigen::Vector3d xk0 = H * sk;  // wrapped, relative to lo
    for (auto t0 = static_cast<int>(std::floor(tmin[0])) - 1; t0 <= std::ceil(tmax[0]) + 1; ++t0)
      for (auto t1 = static_cast<int>(std::floor(tmin[1])) - 1; t1 <= std::ceil(tmax[1]) + 1; ++t1)
        for (auto t2 = static_cast<int>(std::floor(tmin[2])) - 1; t2 <= std::ceil(tmax[2]) + 1;
             ++t2) {
          const Eigen::Vector3d p = xk0 + H * Eigen::Vector3d(t0, t1, t2);
          const Eigen::Vector3d uk = Hs_inv * p;
          if ((uk.array() >= -delta).all() && (uk.array() < 1.0 - delta).all()) {
            u.push_back(uk);
            src.push_back(k);
          }
        }
  }
  if (static_cast<std::int64_t>(u.size()) != natoms)
    throw NumericalError(fmt::format(
        "slab cell: found {} atoms, expected {} ({} copies of the body's {}): atoms too close "
        "to the cell faces",
        u.size(), natoms, copies, body.size()));

  if (d0 * jrep < 2.0 * body.potential->cutoff())
    log::warn(
        "slab height {:.6g} is below twice the interaction range {:.6g}: the two surfaces "
        "interact through the slab (a thin film, not γ of a surface); give a larger --thickness",
        d0 * jrep, 2.0 * body.potential->cutoff());
  // Cut in the middle of the widest gap between atomic heights (cyclic along a3).
  std::vector<double> hs;
  hs.reserve(u.size());
  for (const auto& uk : u) hs.push_back(uk[2] - std::floor(uk[2]));
  std::sort(hs.begin(), hs.end());
  const double height = n.dot(Hs.col(2));
  double best_gap = -1.0, cut = 0.0;
  int layers = 0;
  const double tol = 1e-6 / height;  // same layer: heights within 1e-6 length units
  for (std::size_t q = 0; q < hs.size(); ++q) {
    const double next = q + 1 < hs.size() ? hs[q + 1] : hs[0] + 1.0;
    const double gap = next - hs[q];
    if (gap > tol) ++layers;
    if (gap > best_gap + tol) {
      best_gap = gap;
      cut = hs[q] + 0.5 * gap;
    }
  }
  cut -= std::floor(cut);
  for (auto& uk : u) {
    uk[2] -= cut;
    uk[2] -= std::floor(uk[2]);
  }

  // Rotate: Hs = Q R with R upper triangular, positive diagonal (LAMMPS's box form).
  Eigen::HouseholderQR<Eigen::Matrix3d> qr(Hs);
  Eigen::Matrix3d Q = qr.householderQ();
  Eigen::Matrix3d R = qr.matrixQR().triangularView<Eigen::Upper>();
  for (int c = 0; c < 3; ++c)
    if (R(c, c) < 0.0) {
      R.row(c) *= -1.0;
      Q.col(c) *= -1.0;
    }
  for (int r = 1; r < 3; ++r)
    for (int c = 0; c < r; ++c) R(r, c) = 0.0;

  atomistic::Atoms atoms;
  atoms.box.lo = Eigen::Vector3d::Zero();
  atoms.box.hi = Eigen::Vector3d(R(0, 0), R(1, 1), R(2, 2));
  atoms.box.xy = R(0, 1);
  atoms.box.xz = R(0, 2);
  atoms.box.yz = R(1, 2);
  atoms.box.periodic = {true, true, true};
  atoms.ntypes = body.potential->ntypes();
  const std::size_t N = u.size();
  atoms.id.resize(N);
  atoms.type.resize(N);
  atoms.mass.resize(N);
  atoms.x.resize(3 * N);
  for (std::size_t q = 0; q < N; ++q) {
    const Eigen::Vector3d xq = R * u[q];
    atoms.id[q] = static_cast<std::int64_t>(q + 1);
    atoms.type[q] = body.type[src[q]];
    atoms.mass[q] = body.mass[src[q]];
    for (int c = 0; c < 3; ++c) atoms.x[3 * q + static_cast<std::size_t>(c)] = xq[c];
  }
  DeltaBodyOptions dopt;
  dopt.cutoff = body.base_horizon;
  dopt.source = "slab cell of " +
                (body.provenance.empty() ? std::string("the body") : body.provenance.front());
  Slab out{make_delta_body(atoms, body.base_potential, body.potential_spec, dopt),
           Body{},
           M,
           Q,
           n,
           area,
           height,
           d0,
           layers,
           best_gap * height};
  atoms.box.periodic[2] = false;
  out.slab = make_delta_body(atoms, body.base_potential, body.potential_spec, dopt);
  const std::string what = fmt::format(
      "slab cell for the plane normal ({:.6g}, {:.6g}, {:.6g}): M = [{} {} {}; {} {} {}; {} {} "
      "{}], area {:.10g}, height {:.10g} ({} layers)",
      n[0], n[1], n[2], M(0, 0), M(0, 1), M(0, 2), M(1, 0), M(1, 1), M(1, 2), M(2, 0), M(2, 1),
      M(2, 2), area, height, layers);
  out.bulk.provenance = body.provenance;
  out.bulk.provenance.push_back(what + ", periodic");
  out.slab.provenance = body.provenance;
  out.slab.provenance.push_back(what + ", free along the normal");
  return out;
}

SurfaceEnergy surface_energy(const Slab& s, const std::optional<StaticsOptions>& statics) {
  SurfaceEnergy r;
  r.area = s.area;
  {
    Evaluator eb(s.bulk), es(s.slab);
    r.e_bulk = eb.reference().energy;
    r.e_slab = es.reference().energy;
  }
  r.gamma = (r.e_slab - r.e_bulk) / (2.0 * s.area);
  if (!statics) return r;
  auto run = [&](const Body& b, const char* what) {
    std::vector<double> y = b.x;
    StaticsResult st = relax(b, y, *statics);
    if (!st.converged)
      throw NumericalError(fmt::format(
          "molecular statics of the {} did not converge: |f| = {:.3g} > {:.3g} after {} "
          "iterations ({}); raise the iteration limit or the force tolerance",
          what, st.force_norm, statics->force_tolerance, st.iterations, st.stop));
    log::info("statics ({}): {} iterations, {} evaluations, {} family rebuilds, |f| = {:.3g}", what,
              st.iterations, st.evaluations, st.rebuilds, st.force_norm);
    return st;
  };
  r.bulk_statics = run(s.bulk, "bulk");
  r.slab_statics = run(s.slab, "slab");
  r.e_bulk_relaxed = r.bulk_statics->energy;
  r.e_slab_relaxed = r.slab_statics->energy;
  r.gamma_relaxed = (*r.e_slab_relaxed - *r.e_bulk_relaxed) / (2.0 * s.area);
  return r;
}

}  // namespace pdcg::body
