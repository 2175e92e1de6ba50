/// \file
/// Statistical bodies (docs/theory.md §2, docs/bodies.md): each atom k has a position density P_k;
///   ρ(x) = Σ_k M_k P_k(x),
///   W(Y, x) = Σ_k P_k(x) ∫…∫ ψ_k(Y⟨ξ_1⟩, …) Π_j P_j(ξ_j + x) dξ_j,
/// so the total energy is the expected energy of independent atoms. Forms:
///  - Gaussian P_k = N(x̄_k, Σ_k): mean and covariance fitted per atom from frames, or an
///    isotropic width σ (Σ_k = σ² I_d). Pair terms: the relative displacement of a bond is
///    Gaussian with covariance Σ_j + Σ_k, so E[φ] is a d-dimensional integral, done by
///    tensor-product Gauss–Hermite cubature of selectable order. Many-body terms: sampling
///    (joint draws of all atom positions, fixed seed).
///  - empirical: the average over the frames themselves.
/// Under a homogeneous deformation the densities are carried along (conforming deformation,
/// p_k(y) dV_y = P_k(x) dV_x): fluctuations are mapped by F.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "pdcg/atomistic/atoms.hpp"
#include "pdcg/body/body.hpp"

namespace pdcg::body {

/// Gauss–Hermite rule for the standard normal density: Σ_i w_i f(z_i) = E[f(Z)], Z ~ N(0,1),
/// exact for polynomials of degree ≤ 2n − 1 (Golub–Welsch). n in 1..64, else InputError.
void gauss_hermite(int n, std::vector<double>& nodes, std::vector<double>& weights);

/// Gaussian statistics with Σ_k = σ² I_d for every atom (first d directions).
Statistics isotropic_gaussian(const Body& body, double width);

/// Mean and covariance per atom from S > d frames with the body's ids (unwrapped positions;
/// periodic jumps are undone by minimum image against the first frame). The body's reference
/// positions become the means. Throws InputError for ids or types that differ from the body's,
/// for a periodic edge of the box that differs from the reference frame's (NPT trajectories),
/// and for S ≤ d (the covariance of S frames has rank ≤ S − 1: singular).
Statistics gaussian_from_frames(Body& body, std::span<const atomistic::Atoms> frames);

/// Gaussian statistics of a temperature from a local-harmonic (Einstein) estimate
/// (docs/temperature.md): each atom in the well of its neighbours held at their reference
/// positions, H_k = ∂²U/∂x_k² (force_state_tangent: Σ_bc K_bc of its own family plus K_bb of
/// every family it belongs to), and the classical equipartition width
///   Σ_k = k_B T H_k⁻¹   (first d directions),
/// k_B the Boltzmann constant of the body's unit style (LAMMPS's force->boltz; 1 in lj).
/// The neighbours' own motion is left out, so the widths are smaller than those of a
/// crystal whose atoms all move (by about 30 % in variance for fcc LJ; docs/temperature.md).
/// Throws InputError for T < 0 or not finite; for an atom whose H_k is not positive
/// definite (the reference is not a minimum: relax it first); and when the rms displacement
/// exceeds 0.15 of the nearest-neighbour distance (Lindemann's melting criterion: no crystal
/// is left to describe; the usual cause is a temperature in kelvin given in lj units). Above
/// 0.10 a warning says the harmonic estimate is poor near melting. `where` names the option
/// in messages ("--temperature", "temperature").
Statistics einstein_statistics(const Body& body, double temperature,
                               std::string_view where = "temperature");

/// Empirical statistics: the frames themselves (reference positions become their mean).
Statistics empirical_from_frames(Body& body, std::span<const atomistic::Atoms> frames);

/// Turns a delta body into a statistical one (kind = statistical). Checks the statistics
/// against the body (sizes, order ≥ 1, samples ≥ 1; cubature needs a pair potential).
void make_statistical(Body& body, Statistics statistics);

}  // namespace pdcg::body
