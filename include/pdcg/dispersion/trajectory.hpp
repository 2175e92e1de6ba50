/// \file
/// Measured dispersion from a LAMMPS dump (or any trajectory of Atoms frames).
///
/// Atoms are grouped into lattice planes normal to the chosen axis by their time-averaged
/// coordinate along it (a 1D chain is the case of one atom per plane); the displacement
/// component of each plane, averaged over its atoms, is the field u_n(t) on a periodic 1D
/// lattice of planes with spacing h = L/N_planes, which space_time_spectrum transforms.
/// For a crystal along [100] with component x this measures the longitudinal branch, with a
/// transverse component the transverse branch.
#pragma once

#include <string>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/dispersion/measured.hpp"

namespace pdcg::dispersion {

struct TrajectoryOptions {
  int axis = 0;                 ///< 0, 1, 2 = x, y, z: the wave direction
  int component = 0;            ///< displacement component (= axis: longitudinal)
  double frame_interval = 0.0;  ///< Δt between frames (time units of the trajectory)
  Window window = Window::hann;
  double min_resolution = 0.0;  ///< refuse trajectories with a coarser Δω (0: no check)
  std::string source;           ///< file name for messages
};

struct LatticePlanes {
  std::vector<int> plane_of_atom;  ///< per atom (in id order)
  std::size_t planes = 0;
  double spacing = 0.0;
};

/// Planes from reference positions (3N) in a box periodic along `axis`. Throws InputError
/// if the box is not periodic along the axis, all atoms lie in one plane (the axis is not
/// the wave's lattice direction), or the planes are not evenly spaced.
LatticePlanes find_planes(const std::vector<double>& reference, const atomistic::Box& box, int axis,
                          const std::string& source);

/// S(κ, ω) of the frames. Every frame must hold the same atom ids. Throws InputError naming
/// the atom id and frame index when an atom moves more than half a plane spacing from its
/// mean position along the axis (it left its plane: diffusion, melting, a wrong axis), or more
/// than half the transverse lattice spacing across it (it left the axis / its site sideways;
/// transverse spacing = (plane area per atom over the periodic transverse directions)^(1/p),
/// the plane spacing when no transverse direction is periodic, as for a chain).
Spectrum measure(const std::vector<atomistic::Atoms>& frames, const TrajectoryOptions& options);

}  // namespace pdcg::dispersion
