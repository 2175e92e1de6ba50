// Private to the solver module: the AVX2 + FMA residual sweep and the batched Neo-Hookean
// stress (docs/performance.md "BA kernels against the roofline"). Compiled on
// x86-64 with GCC/Clang as functions with target("avx2,fma") and picked at run time when the
// CPU has both (the portable build stays portable: other CPUs take the scalar code).
#pragma once

#include <atomic>
#include <cstddef>

#include "pdcg/solver/discretization.hpp"
#include "pdcg/solver/material.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PDCG_SOLVER_AVX2 1
#endif

namespace pdcg::solver::detail {

/// False after set_vector_kernels(false) (material.hpp).
extern std::atomic<bool> vector_kernels_allowed;

#ifdef PDCG_SOLVER_AVX2
/// True when the CPU has AVX2 and FMA and the vector kernels are allowed
/// (set_vector_kernels: a switch to compare the two paths on the same machine).
bool cpu_has_avx2_fma();

/// The fused residual sweep over stencils [s0, s1) of dimension d (2 or 3): gather F_S, P(F_S)
/// (four stencils at a time, Material::stress4), scatter f_m += w_S P_S G_S^m into f.
/// Returns false if some F_S is inadmissible (its stencil adds nothing). 2D: f holds 2 doubles
/// per point; 3D: f is padded to 4 doubles per point (the 4th is not used) and 32-byte
/// aligned.
bool stencil_sweep_avx2(int d, const Stencils& S, std::size_t s0, std::size_t s1, const double* u,
                        double* f, const Material& material);

/// Neo-Hookean stress of four deformation gradients (layout of Material::stress4), d = 2
/// (plane strain, F₃₃ = 1) or 3. Returns the admissibility mask, or kNotHandled when some J
/// is outside [1e-290, 1e290] (the caller then takes the scalar path).
constexpr unsigned kNotHandled = 0x80000000u;
unsigned neo_hookean_stress4_avx2(int d, double mu, double K, const double* F, double* P);
#endif

}  // namespace pdcg::solver::detail
