/// \file
/// Model dispersion of a pdcg body (delta, homogenised or rescaled) — see model.hpp for the
/// equations. A point of the body is either one atom (delta, rescaled) or one homogenised
/// point with its weighted atoms; `cell` mode treats all atoms of a periodic body as the
/// basis of its cell (3N folded branches).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <string_view>

#include "pdcg/body/body.hpp"
#include "pdcg/dispersion/grid.hpp"
#include "pdcg/dispersion/model.hpp"

namespace pdcg::dispersion {

/// The Bravais lattice a body's point sits on, told from its nearest-neighbour shell:
/// 2 neighbours on a line → chain (a = d_nn); 6 in a plane → hex (a = d_nn); 6 → sc (a = d_nn);
/// 8 → bcc (a = 2d_nn/√3); 12 → fcc (a = √2·d_nn). Throws InputError otherwise (pass
/// --lattice and --a).
struct LatticeGuess {
  std::string lattice;
  double a = 0.0;
  double nearest = 0.0;
  int coordination = 0;
};
LatticeGuess detect_lattice(const body::Body& body, std::size_t atom);

/// The atom BodyDispersion(body, point, false).representative_atom() will use, without
/// linearising anything (cheap: for checks before the model is built).
std::size_t representative_atom(const body::Body& body, std::optional<std::size_t> point);

/// Zone edge along the unit vector `direction` at atom `atom`: π over the shortest non-zero
/// projection onto `direction` of its nearest-neighbour bonds (chain: π/h; fcc [100]: 2π/a;
/// fcc [111]: √3π/a). Throws InputError naming `option` when no nearest-neighbour bond has a
/// component along the direction (then give κ_max explicitly); `given` is the direction as the
/// user wrote it, for the message (empty: the components of `direction`).
double zone_edge(const body::Body& body, std::size_t atom, const Eigen::Vector3d& direction,
                 std::string_view option = "--direction", std::string_view given = {});

class BodyDispersion {
 public:
  /// point: atom index (delta/rescaled) or homogenised point index; nullopt = the point nearest
  /// the centre of the box. cell: all atoms as the basis of a periodic cell.
  BodyDispersion(const body::Body& body, std::optional<std::size_t> point, bool cell);
  /// Frequencies at κ, ascending (3 for a point, 3N in cell mode).
  Eigen::VectorXd omega(const Eigen::Vector3d& kappa) const;
  /// ω on every κ commensurate with the periodic box at once (grid.hpp; one FFT). Not in
  /// cell mode (InputError).
  KappaGrid grid() const;
  /// An atom of the chosen point (for detect_lattice).
  std::size_t representative_atom() const { return representative_; }
  std::string description() const { return description_; }

 private:
  const body::Body& body_;
  bool cell_;
  std::vector<std::pair<std::int32_t, double>> site_;
  std::unique_ptr<LinearisedFamilies> lin_;
  std::size_t representative_ = 0;
  std::string description_;
};

}  // namespace pdcg::dispersion
