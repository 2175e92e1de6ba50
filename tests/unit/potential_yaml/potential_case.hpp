// The data-driven potential-style tests (tests/potentials/*.yaml, docs/testing.md "Potential
// styles against LAMMPS"): a case file holds the LAMMPS commands a user writes, the atoms LAMMPS
// made, and LAMMPS's `run 0` reference (tests/potentials/generate.py wrote it with LAMMPS;
// nothing of pdcg made it). This header reads a case, computes it the way `pdcg atoms2pd` +
// `pdcg forces` + `pdcg energy --stress` do (data file and commands file through the public
// readers, body::build_body, the body file written and read back, body::Evaluator), and
// compares the two within the case's epsilon.
#pragma once

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "pdcg/atomistic/configurations.hpp"
#include "pdcg/atomistic/lammps_engine.hpp"
#include "pdcg/atomistic/potential_file.hpp"
#include "pdcg/atomistic/potentials.hpp"
#include "pdcg/body/body.hpp"
#include "pdcg/body/build.hpp"
#include "pdcg/body/model_file.hpp"

namespace pdcg::test::potential_case {

/// LAMMPS's `run 0`, as the case file stores it (sorted by atom id).
struct Reference {
  double energy = 0.0;                  ///< total potential energy
  std::array<double, 6> virial{};       ///< W = Σ r_i f_j: xx yy zz xy xz yz (energy units)
  std::vector<std::int64_t> ids;        ///< atom ids of `forces`, ascending
  std::vector<double> forces;           ///< 3 per id
  std::vector<std::int64_t> pe_ids;     ///< atom ids of `per_atom_energy`
  std::vector<double> per_atom_energy;  ///< compute pe/atom
};

/// One case file.
struct Case {
  std::string path;  ///< the file
  std::string name;  ///< its file name, e.g. "sw.yaml" (named in every message)
  std::string style, description, engine, epsilon_reason, commands, data;
  double epsilon = 0.0;  ///< relative tolerance of every check
  Reference reference;
};

/// pdcg's numbers for a case, sorted by atom id.
struct Computed {
  double energy = 0.0;
  std::array<double, 6> virial{};  ///< −sym(P)·V at F = I (P = ∂W/∂F): xx yy zz xy xz yz
  std::vector<std::int64_t> ids;
  std::vector<double> forces;           ///< 3 per id
  std::vector<double> per_atom_energy;  ///< ψ_k
};

/// The worst entry of one quantity.
struct Worst {
  std::string quantity;   ///< "force", "per-atom energy", "energy", "virial"
  double relative = 0.0;  ///< |pdcg − LAMMPS| / scale
  double scale = 0.0;     ///< the largest |reference entry| of the quantity
  std::string where;      ///< e.g. "atom 17 force y", "virial xz", "" for the energy
  double got = 0.0, expected = 0.0;
  int beyond = 0;  ///< entries of this quantity beyond epsilon
};

struct Comparison {
  std::vector<Worst> worst;           ///< one per quantity
  std::vector<std::string> failures;  ///< one message per failing quantity (or a mismatch)
  bool ok() const { return failures.empty(); }
};

namespace detail {

inline std::runtime_error bad(const std::string& path, const std::string& key,
                              const std::string& what) {
  return std::runtime_error(fmt::format(
      "{}: key `{}`: {} (case files are described in tests/potentials/README.md; `data` and "
      "`reference` are written by tests/potentials/generate.py)",
      path, key, what));
}

inline YAML::Node need(const YAML::Node& node, const std::string& key, const std::string& path) {
  if (!node[key]) throw bad(path, key, "missing");
  return node[key];
}

/// node as T; a malformed value names the file and the key.
template <class T>
T as(const YAML::Node& node, const std::string& key, const std::string& path) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception& e) {
    const char* kind = std::is_floating_point_v<T> ? "a number"
                       : std::is_integral_v<T>     ? "an integer"
                                                   : "a string";
    throw bad(path, key, fmt::format("expected {}: {}", kind, e.what()));
  }
}

}  // namespace detail

/// Reads a case file; std::runtime_error naming the file and the key for anything missing or
/// malformed.
inline Case load_case(const std::string& path) {
  using detail::as;
  using detail::bad;
  using detail::need;
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("{}: not a YAML file: {}", path, e.what()));
  }
  Case c;
  c.path = path;
  c.name = std::filesystem::path(path).filename().string();
  c.style = as<std::string>(need(root, "style", path), "style", path);
  if (root["description"]) c.description = root["description"].as<std::string>();
  if (root["engine"]) c.engine = root["engine"].as<std::string>();
  c.epsilon = as<double>(need(root, "epsilon", path), "epsilon", path);
  if (!(c.epsilon > 0.0) || !std::isfinite(c.epsilon))
    throw bad(path, "epsilon", fmt::format("got {}, expected a positive number", c.epsilon));
  c.epsilon_reason = as<std::string>(need(root, "epsilon_reason", path), "epsilon_reason", path);
  c.commands = as<std::string>(need(root, "commands", path), "commands", path);
  c.data = as<std::string>(need(root, "data", path), "data", path);
  const YAML::Node ref = need(root, "reference", path);
  Reference& r = c.reference;
  r.energy = as<double>(need(ref, "energy", path), "reference.energy", path);
  const YAML::Node vir = need(ref, "virial", path);
  if (!vir.IsSequence() || vir.size() != 6)
    throw bad(path, "reference.virial", "expected 6 numbers: xx yy zz xy xz yz");
  for (std::size_t i = 0; i < 6; ++i) r.virial[i] = as<double>(vir[i], "reference.virial", path);
  const auto natoms = as<std::int64_t>(need(ref, "natoms", path), "reference.natoms", path);
  const YAML::Node f = need(ref, "forces", path);
  const YAML::Node pe = need(ref, "per_atom_energy", path);
  if (!f.IsSequence() || static_cast<std::int64_t>(f.size()) != natoms)
    throw bad(path, "reference.forces", fmt::format("expected {} rows (natoms)", natoms));
  if (!pe.IsSequence() || static_cast<std::int64_t>(pe.size()) != natoms)
    throw bad(path, "reference.per_atom_energy", fmt::format("expected {} rows (natoms)", natoms));
  for (const auto& row : f) {
    if (!row.IsSequence() || row.size() != 4)
      throw bad(path, "reference.forces", "expected rows [id, fx, fy, fz]");
    r.ids.push_back(as<std::int64_t>(row[0], "reference.forces", path));
    for (std::size_t d = 1; d < 4; ++d)
      r.forces.push_back(as<double>(row[d], "reference.forces", path));
  }
  for (const auto& row : pe) {
    if (!row.IsSequence() || row.size() != 2)
      throw bad(path, "reference.per_atom_energy", "expected rows [id, pe]");
    r.pe_ids.push_back(as<std::int64_t>(row[0], "reference.per_atom_energy", path));
    r.per_atom_energy.push_back(as<double>(row[1], "reference.per_atom_energy", path));
  }
  if (!std::is_sorted(r.ids.begin(), r.ids.end()) || r.pe_ids != r.ids)
    throw bad(path, "reference",
              "forces and per_atom_energy must list the same atom ids in ascending order");
  return c;
}

/// True for cases that pdcg evaluates natively (no `engine: embedded-lammps`).
inline bool native(const Case& c) { return c.engine.empty() || c.engine == "native"; }

/// The case computed the way `pdcg atoms2pd --input atoms.data --potential commands.in`,
/// `pdcg forces body.h5` and `pdcg energy body.h5 --F I --stress` compute it: the data and the
/// commands written as files into `scratch` and read by the public readers, the periodicity of
/// the commands' `boundary` (else LAMMPS's default p p p, checked for overlapping images),
/// the body built, written and read back.
inline Computed compute_with_pdcg(const Case& c, const std::filesystem::path& scratch) {
  const std::string data_path = (scratch / "atoms.data").string();
  const std::string commands_path = (scratch / "commands.in").string();
  std::ofstream(data_path) << c.data;
  std::ofstream(commands_path) << c.commands;
  atomistic::FrameNeeds needs;
  needs.type = true;
  needs.operation = "potential-style test";
  std::vector<atomistic::Atoms> frames =
      atomistic::read_configurations(data_path, std::nullopt, "", nullptr, needs);
  atomistic::PotentialSpec spec =
      atomistic::read_potential_commands(commands_path, frames.front().ntypes);
  const bool assumed = !spec.periodic.has_value();  // a data file states no periodicity
  if (spec.periodic)
    for (auto& f : frames) f.box.periodic = *spec.periodic;
  atomistic::take_type_charges(spec, frames.front());
  std::shared_ptr<const atomistic::Potential> pot = atomistic::make_potential(spec);
  body::BodyRequest request;
  request.delta.source = data_path;
  request.delta.periodicity_assumed = assumed;
  const std::filesystem::path body_path = scratch / "body.h5";
  body::write_body(body::build_body(frames, pot, spec, request), body_path);
  const body::Body b = body::read_body(body_path);
  body::Evaluator ev(b);
  Computed out;
  {
    const body::Evaluation e = ev.reference();
    out.energy = e.energy;
    out.ids = b.id;
    out.forces.assign(e.forces.begin(), e.forces.end());
    out.per_atom_energy.assign(e.psi.begin(), e.psi.end());
  }
  const Eigen::Matrix3d P = ev.stress(Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d W = -0.5 * (P + P.transpose()) * b.reference_volume();
  out.virial = {W(0, 0), W(1, 1), W(2, 2), W(0, 1), W(0, 2), W(1, 2)};
  // sort by id (a body keeps the order of the data file's Atoms section)
  std::vector<std::size_t> order(out.ids.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b2) { return out.ids[a] < out.ids[b2]; });
  Computed sorted = out;
  for (std::size_t i = 0; i < order.size(); ++i) {
    sorted.ids[i] = out.ids[order[i]];
    sorted.per_atom_energy[i] = out.per_atom_energy[order[i]];
    for (int d = 0; d < 3; ++d) sorted.forces[3 * i + d] = out.forces[3 * order[i] + d];
  }
  return sorted;
}

/// Compares pdcg's numbers with the case's reference. Per quantity, the error is the max norm
/// relative to the largest reference entry of that quantity (forces: over all components;
/// per-atom energies; the virial over its six components; the energy relative to |E|); it must
/// be ≤ epsilon. A failing quantity gives one message naming the file, the worst atom (or
/// component), pdcg's and LAMMPS's values, and how many entries are beyond epsilon. A scale of
/// zero (every reference entry 0) compares absolutely.
inline Comparison compare(const Case& c, const Computed& got) {
  Comparison out;
  const Reference& r = c.reference;
  if (got.ids != r.ids) {
    std::string detail = fmt::format("pdcg has {} atoms, LAMMPS {}", got.ids.size(), r.ids.size());
    for (std::size_t i = 0; i < std::min(got.ids.size(), r.ids.size()); ++i)
      if (got.ids[i] != r.ids[i]) {
        detail += fmt::format("; first differing id: pdcg {}, LAMMPS {}", got.ids[i], r.ids[i]);
        break;
      }
    out.failures.push_back(
        fmt::format("{}: the atoms differ from the reference: {}", c.name, detail));
    return out;
  }
  const double eps = c.epsilon;
  // entries: pdcg values, reference values, a label per entry
  auto check = [&](const std::string& quantity, const std::vector<double>& g,
                   const std::vector<double>& e, auto&& label) {
    double scale = 0.0;
    for (double v : e) scale = std::max(scale, std::abs(v));
    const double denom = scale > 0.0 ? scale : 1.0;
    Worst w;
    w.quantity = quantity;
    w.scale = scale;
    w.relative = -1.0;
    for (std::size_t i = 0; i < e.size(); ++i) {
      const double d = std::abs(g[i] - e[i]) / denom;
      const double rel = std::isnan(d) ? INFINITY : d;  // a NaN from pdcg fails
      if (rel > eps) ++w.beyond;
      if (rel > w.relative) {
        w.relative = rel;
        w.where = label(i);
        w.got = g[i];
        w.expected = e[i];
      }
    }
    if (w.beyond > 0)
      out.failures.push_back(fmt::format(
          "{}: {}{}: pdcg {:.17g}, LAMMPS {:.17g}: |difference| / {} = {:.3e} > epsilon {:g} "
          "({} of {} entries beyond epsilon)",
          c.name, quantity, w.where.empty() ? "" : " at " + w.where, w.got, w.expected,
          scale > 0.0 ? fmt::format("{:.6g} (largest |LAMMPS| entry)", scale)
                      : std::string("1 (every LAMMPS entry is 0)"),
          w.relative, eps, w.beyond, e.size()));
    out.worst.push_back(w);
  };
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  check("force", got.forces, r.forces,
        [&](std::size_t i) { return fmt::format("atom {} f{}", r.ids[i / 3], kAxis[i % 3]); });
  check("per-atom energy", got.per_atom_energy, r.per_atom_energy,
        [&](std::size_t i) { return fmt::format("atom {}", r.ids[i]); });
  check("energy", {got.energy}, {r.energy}, [](std::size_t) { return std::string(); });
  static constexpr const char* kVoigt[6] = {"xx", "yy", "zz", "xy", "xz", "yz"};
  check("virial", std::vector<double>(got.virial.begin(), got.virial.end()),
        std::vector<double>(r.virial.begin(), r.virial.end()),
        [](std::size_t i) { return std::string(kVoigt[i]); });
  return out;
}

/// The case files of a directory, sorted by name.
inline std::vector<std::string> case_files(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".yaml") out.push_back(entry.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace pdcg::test::potential_case
