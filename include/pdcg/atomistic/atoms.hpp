/// \file
/// One configuration of atoms: a frame of a dump or the content of a data
/// file. Structure of arrays; vectors per atom are interleaved xyz (3N
/// doubles, row-major N×3), so Eigen::Map<Matrix3Xd>(x.data(), 3, N) views them.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "pdcg/atomistic/box.hpp"

namespace pdcg::atomistic {

/// A molecular bond (data file "Bonds" section).
struct Bond {
  int type = 0;            ///< bond type, 1-based
  std::int64_t atom1 = 0;  ///< atom ids (not indices)
  std::int64_t atom2 = 0;
};

struct Atoms {
  std::int64_t timestep = 0;
  Box box;
  std::vector<std::int64_t> id;  ///< atom ids (sorted ascending after sort_by_id())
  std::vector<int> type;         ///< 1-based LAMMPS types; empty if unknown
  std::vector<double> x;         ///< positions, 3N, unwrapped if image flags were given
  std::vector<int> image;        ///< image flags, 3N; empty if none were given
  std::vector<double> v;         ///< velocities, 3N; empty if absent
  std::vector<double> f;         ///< forces, 3N; empty if absent
  std::vector<std::int64_t> molecule;  ///< molecule ids; empty if absent
  std::vector<double> charge;    ///< charges; empty if absent
  /// Mass per type: type_mass[t] for t = 1..ntypes (index 0 unused); NaN if unknown.
  std::vector<double> type_mass;
  /// Per-atom masses (dump column `mass`, atom style with per-atom mass); empty if absent.
  std::vector<double> mass;
  std::vector<Bond> bonds;
  /// Any other per-atom column, by the name the file gave it (e.g. "c_pe", "q").
  std::map<std::string, std::vector<double>> extra;
  /// Number of atom types declared by the source (data file header); 0 if unknown.
  int ntypes = 0;

  std::size_t size() const { return id.size(); }
  Eigen::Map<const Eigen::Matrix3Xd> positions() const {
    return {x.data(), 3, static_cast<Eigen::Index>(id.size())};
  }
  Eigen::Map<Eigen::Matrix3Xd> positions() { return {x.data(), 3, static_cast<Eigen::Index>(id.size())}; }
  /// Mass of atom i (per-atom mass if present, else by type); NaN if unknown.
  double mass_of(std::size_t i) const;
};

/// Sorts every per-atom array by atom id. Throws InputError on duplicate ids
/// (naming `source` and the id).
void sort_by_id(Atoms& atoms, std::string_view source = {});

}  // namespace pdcg::atomistic
