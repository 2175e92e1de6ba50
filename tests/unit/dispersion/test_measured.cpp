#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "pdcg/core/error.hpp"
#include "pdcg/dispersion/closed_form.hpp"
#include "pdcg/dispersion/measured.hpp"
#include "pdcg/dispersion/trajectory.hpp"

#if PDCG_WITH_LAMMPS
#include <library.h>
#include <omp.h>
#endif

using namespace pdcg::dispersion;

namespace {
const double kPi = std::numbers::pi;
}

// A field made of travelling waves at known (κ, ω) pairs: the ridge must find each ω within
// one frequency bin (the transform's resolution; Hann keeps the peak at the nearest bin).
TEST(Measured, SyntheticWavesAreFoundWithinOneBin) {
  const std::size_t N = 32, T = 512;
  const double h = 1.0, dt = 0.2;
  std::vector<double> u(T * N, 0.0);
  auto omega_of = [](double k) { return 1.3 * std::abs(std::sin(0.5 * k)) + 0.05; };
  for (std::size_t m = 1; m <= N / 2; ++m) {
    const double k = 2 * kPi * static_cast<double>(m) / (static_cast<double>(N) * h);
    const double w = omega_of(k);
    const double dir = (m % 2) ? 1.0 : -1.0;  // waves in both directions
    for (std::size_t t = 0; t < T; ++t)
      for (std::size_t n = 0; n < N; ++n)
        u[t * N + n] += std::cos(k * static_cast<double>(n) * h -
                                 dir * w * static_cast<double>(t) * dt + 0.3 * m);
  }
  const Spectrum s = space_time_spectrum(u, T, N, h, dt);
  EXPECT_NEAR(s.resolution, 2 * kPi / (T * dt), 1e-15);
  const auto r = ridge(s);
  ASSERT_EQ(r.size(), N / 2);
  for (const auto& p : r)
    EXPECT_LE(std::abs(p.omega - omega_of(p.kappa)), p.resolution) << "κ = " << p.kappa;
}

TEST(Measured, BadInputIsExplained) {
  std::vector<double> u(3 * 8, 0.0);
  EXPECT_THROW(space_time_spectrum(u, 3, 8, 1.0, 0.1), pdcg::InputError);  // too few frames
  std::vector<double> v(64 * 8, 0.0);
  try {
    space_time_spectrum(v, 64, 8, 1.0, 0.1, Window::hann, 0.01);  // needs 2π/(0.01·0.1) frames
    FAIL();
  } catch (const pdcg::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 6284 frames"), std::string::npos) << e.what();
  }
}

#if PDCG_WITH_LAMMPS
namespace {
/// Runs LAMMPS MD of a periodic 1D chain (bond_style harmonic to the nearest and, when
/// mu2 > 0, next-nearest neighbours; motion only along x) and returns the displacement
/// samples (frames × sites).
std::vector<double> lammps_chain(std::size_t N, double mu1, double mu2, double dt, int every,
                                 std::size_t frames) {
  const int threads = omp_get_max_threads();
  const char* args[] = {"test", "-log", "none", "-screen", "none", "-nocite"};
  void* lmp = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
  omp_set_num_threads(threads);
  const std::string n = std::to_string(N);
  // LAMMPS bond harmonic: E = K (r − r0)², so K = μ/2 for a spring of stiffness μ.
  const std::string script =
      "units lj\natom_style bond\nboundary p f f\nlattice sc 1.0\n"
      "region box block 0 " +
      n +
      " -0.5 0.5 -0.5 0.5\n"
      "create_box 1 box bond/types 2 extra/bond/per/atom 4 extra/special/per/atom 8\n"
      "create_atoms 1 box\nmass 1 1.0\n"
      "pair_style zero 2.5\npair_coeff * *\n"
      "bond_style harmonic\n"
      "bond_coeff 1 " +
      std::to_string(mu1 / 2) +
      " 1.0\n"
      "bond_coeff 2 " +
      std::to_string(mu2 / 2) +
      " 2.0\n"
      "special_bonds lj/coul 0.0 1.0 1.0\n"
      "create_bonds many all all 1 0.9 1.1\n" +
      std::string(mu2 > 0 ? "create_bonds many all all 2 1.9 2.1\n" : "") +
      "velocity all create 0.01 4928459 dist gaussian\n"
      "velocity all set NULL 0.0 0.0\nvelocity all zero linear\n"
      "fix 1 all nve\nfix 2 all setforce NULL 0.0 0.0\n"
      "timestep " +
      std::to_string(dt) + "\nthermo 0\nrun 0\n";
  lammps_commands_string(lmp, script.c_str());
  std::vector<double> x0(3 * N), x(3 * N), u(frames * N);
  lammps_gather_atoms(lmp, const_cast<char*>("x"), 1, 3, x0.data());
  const std::string run = "run " + std::to_string(every) + " pre no post no";
  const double L = static_cast<double>(N);
  for (std::size_t t = 0; t < frames; ++t) {
    lammps_command(lmp, run.c_str());
    lammps_gather_atoms(lmp, const_cast<char*>("x"), 1, 3, x.data());
    for (std::size_t i = 0; i < N; ++i) {
      double d = x[3 * i] - x0[3 * i];
      d -= L * std::round(d / L);  // minimum image along the periodic x
      u[t * N + i] = d;
    }
  }
  lammps_close(lmp);
  return u;
}
}  // namespace

// Acceptance: an MD trajectory of a 1D chain produced by LAMMPS gives ridge
// frequencies within one frequency-resolution bin of the closed form for every κ.
TEST(MeasuredLammps, NearestNeighbourChainRidgeMatchesClosedForm) {
  const std::size_t N = 32, T = 1024;
  const double dt = 0.01;
  const int every = 10;
  const auto u = lammps_chain(N, 1.0, 0.0, dt, every, T);
  const auto r = ridge(space_time_spectrum(u, T, N, 1.0, dt * every));
  const std::vector<double> mu{1.0};
  for (const auto& p : r)
    EXPECT_LE(std::abs(p.omega - chain_omega(p.kappa, 1.0, 1.0, mu)), p.resolution)
        << "κ = " << p.kappa;
}

TEST(MeasuredLammps, NextNearestChainRidgeMatchesClosedForm) {
  const std::size_t N = 32, T = 1024;
  const double dt = 0.01;
  const int every = 10;
  const auto u = lammps_chain(N, 1.0, 0.25, dt, every, T);
  const auto r = ridge(space_time_spectrum(u, T, N, 1.0, dt * every));
  const std::vector<double> mu{1.0, 0.25};
  for (const auto& p : r)
    EXPECT_LE(std::abs(p.omega - chain_omega(p.kappa, 1.0, 1.0, mu)), p.resolution)
        << "κ = " << p.kappa;
}

namespace {
/// Harmonic lattice dynamics of fcc with the pair potential 4(r⁻¹² − r⁻⁶), cut at 2.5, for a
/// wave along [100] (Born & Huang 1954, ch. V): ω²_αα(κ) = (1/m) Σ_R Φ_αα(R) (1 − cos κR_x),
/// Φ_αβ(R) = φ''(r) e_α e_β + φ'(r)/r (δ_αβ − e_α e_β), over the lattice vectors R, r = |R| < 2.5.
/// α = 0: the longitudinal branch, α = 1: the (doubly degenerate) transverse one. Mass 1.
double fcc_lj_omega(double a, double kappa, int alpha) {
  double d = 0.0;
  const int n = static_cast<int>(std::ceil(2.5 / a)) + 1;
  for (int i = -2 * n; i <= 2 * n; ++i)
    for (int j = -2 * n; j <= 2 * n; ++j)
      for (int k = -2 * n; k <= 2 * n; ++k) {
        if ((i + j + k) % 2 != 0 || (i == 0 && j == 0 && k == 0))
          continue;  // fcc: a/2 (i,j,k), even sum
        const std::array<double, 3> R{0.5 * a * i, 0.5 * a * j, 0.5 * a * k};
        const double r = std::sqrt(R[0] * R[0] + R[1] * R[1] + R[2] * R[2]);
        if (r >= 2.5) continue;
        const double dphi = 4.0 * (-12.0 * std::pow(r, -13) + 6.0 * std::pow(r, -7));
        const double d2phi = 4.0 * (156.0 * std::pow(r, -14) - 42.0 * std::pow(r, -8));
        const double e = R[static_cast<std::size_t>(alpha)] / r;
        d += (d2phi * e * e + dphi / r * (1.0 - e * e)) * (1.0 - std::cos(kappa * R[0]));
      }
  return std::sqrt(d);
}
}  // namespace

// Acceptance: LAMMPS NVE MD of a 3D fcc LJ crystal (8 × 2 × 2 cells, 128 atoms, 16 (100)
// planes along x, T* ≈ 0.001: harmonic), measured through the plane averages of `measure`, has
// its longitudinal (component x) and transverse (component y) ridges within one frequency bin
// of the harmonic lattice dynamics written above, at all 8 κ of Γ–X. (At T* ≈ 0.005 the
// longitudinal line at 3/4 X of this small cell is already split by anharmonic coupling, 2 bins
// below the harmonic frequency: the temperature is part of what makes the reference harmonic.)
TEST(MeasuredLammps, FccLennardJonesPlanesMatchLatticeDynamics) {
  const std::size_t frames = 1024;
  const int every = 10;
  const double dt = 0.005;
  const int threads = omp_get_max_threads();
  const char* args[] = {"test", "-log", "none", "-screen", "none", "-nocite"};
  void* lmp = lammps_open_no_mpi(6, const_cast<char**>(args), nullptr);
  omp_set_num_threads(threads);
  lammps_commands_string(lmp,
                         "units lj\natom_style atomic\nboundary p p p\nlattice fcc 1.0733\n"
                         "region box block 0 8 0 2 0 2\ncreate_box 1 box\ncreate_atoms 1 box\n"
                         "mass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0 2.5\n"
                         "pair_modify shift yes\n"
                         "velocity all create 0.002 4711 mom yes rot no dist gaussian\n"
                         "timestep 0.005\nfix 1 all nve\nthermo 0\nrun 0\n");
  const auto n = static_cast<std::size_t>(lammps_get_natoms(lmp));
  ASSERT_EQ(n, 128u);
  pdcg::atomistic::Atoms frame;
  const auto* lo = static_cast<double*>(lammps_extract_global(lmp, "boxlo"));
  const auto* hi = static_cast<double*>(lammps_extract_global(lmp, "boxhi"));
  frame.box.lo = {lo[0], lo[1], lo[2]};
  frame.box.hi = {hi[0], hi[1], hi[2]};
  frame.box.periodic = {true, true, true};
  const double a = (hi[0] - lo[0]) / 8.0;
  for (std::size_t i = 0; i < n; ++i) frame.id.push_back(static_cast<std::int64_t>(i + 1));
  frame.x.resize(3 * n);
  std::vector<pdcg::atomistic::Atoms> traj;
  const std::string run = "run " + std::to_string(every) + " pre no post no";
  for (std::size_t t = 0; t < frames; ++t) {
    lammps_command(lmp, run.c_str());
    lammps_gather_atoms(lmp, const_cast<char*>("x"), 1, 3, frame.x.data());  // in id order
    traj.push_back(frame);
  }
  lammps_close(lmp);
  for (int alpha : {0, 1}) {
    TrajectoryOptions o;
    o.axis = 0;
    o.component = alpha;
    o.frame_interval = dt * every;
    o.source = "fcc.dump";
    const auto r = ridge(measure(traj, o));
    ASSERT_EQ(r.size(), 8u);  // 16 planes: κ_m = 2πm/(8a), m = 1…8 (X)
    for (const auto& p : r) {
      EXPECT_LE(std::abs(p.omega - fcc_lj_omega(a, p.kappa, alpha)), p.resolution)
          << (alpha ? "T" : "L") << ", κ = " << p.kappa << ", ω " << p.omega << " vs "
          << fcc_lj_omega(a, p.kappa, alpha);
    }
  }
}
#endif

// Bad trajectories: atoms that leave the axis or their plane, and a wrong axis.
namespace {
/// Frames of a periodic 16-atom chain along x (spacing 1) vibrating along x by 0.05 and along
/// y by `side`; atom id 5 gets `kick` (x, y, z) added in the last frame.
std::vector<pdcg::atomistic::Atoms> chain_frames(double side, std::array<double, 3> kick,
                                                 bool periodic_yz = false) {
  std::vector<pdcg::atomistic::Atoms> frames(16);
  for (std::size_t t = 0; t < frames.size(); ++t) {
    auto& a = frames[t];
    a.box.lo = {0, -1, -1};
    a.box.hi = {16, 1, 1};
    a.box.periodic = {true, periodic_yz, periodic_yz};
    for (std::size_t i = 0; i < 16; ++i) {
      const double ph = 0.7 * static_cast<double>(t) + 0.4 * static_cast<double>(i);
      a.id.push_back(static_cast<std::int64_t>(i + 1));
      a.x.insert(a.x.end(),
                 {static_cast<double>(i) + 0.05 * std::sin(ph), side * std::cos(ph), 0.0});
    }
  }
  for (int k = 0; k < 3; ++k)
    frames.back().x[3 * 4 + static_cast<std::size_t>(k)] += kick[static_cast<std::size_t>(k)];
  return frames;
}
std::string measure_error(const std::vector<pdcg::atomistic::Atoms>& frames, int axis = 0) {
  TrajectoryOptions o;
  o.axis = o.component = axis;
  o.frame_interval = 0.1;
  o.source = "chain.dump";
  try {
    measure(frames, o);
  } catch (const pdcg::InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Measured, AtomsThatLeaveTheAxisOrTheirPlaneAreRefused) {
  // transverse vibration of 0.1 spacing is a chain's thermal motion: accepted
  EXPECT_EQ(measure_error(chain_frames(0.1, {0, 0, 0})), "");
  // sideways by 0.6 (> half the spacing 1): left the axis; the message names file, atom, frame
  const std::string side = measure_error(chain_frames(0.0, {0, 0.6, 0}));
  EXPECT_NE(side.find("chain.dump"), std::string::npos) << side;
  EXPECT_NE(side.find("left the wave axis"), std::string::npos) << side;
  EXPECT_NE(side.find("atom id 5 in frame 15"), std::string::npos) << side;
  EXPECT_NE(side.find("less than half the transverse lattice spacing 0.5"), std::string::npos)
      << side;
  EXPECT_NE(measure_error(chain_frames(0.0, {0, 0, -0.6})).find("left the wave axis"),
            std::string::npos);
  // along the axis by 0.7: left its plane
  const std::string along = measure_error(chain_frames(0.0, {0.7, 0, 0}));
  EXPECT_NE(along.find("left its lattice plane"), std::string::npos) << along;
  EXPECT_NE(along.find("atom id 5 in frame 15"), std::string::npos) << along;
  // wrong axis in a fully periodic box: every atom in the plane y ≈ 0
  const std::string wrong = measure_error(chain_frames(0.0, {0, 0, 0}, true), 1);
  EXPECT_NE(wrong.find("all atoms lie in one lattice plane"), std::string::npos) << wrong;
  EXPECT_NE(wrong.find("--axis"), std::string::npos) << wrong;
}

// The time-averaged positions of a thermal crystal scatter within a plane: measured, the 32
// atoms of a (100) plane of fcc LJ at T* = 0.4 over 2000 frames spread over 0.0058 (spacing
// 0.79). Such a set — four offsets ±0.0012, ±0.0036, 0.0024 apart, the first plane straddling
// the periodic boundary — is 16 planes (a gap tolerance of 1e-3 L/∛n = 0.0016 split each
// plane and refused the trajectory as unevenly spaced).
TEST(Measured, ThermalScatterWithinPlanesKeepsThePlanes) {
  const std::size_t planes = 16, per = 32;
  const double h = 0.79354;
  pdcg::atomistic::Box box;
  box.lo = {-0.15, 0, 0};
  box.hi = {-0.15 + planes * h, 3.17, 3.17};
  box.periodic = {true, true, true};
  std::vector<double> ref;
  for (std::size_t p = 0; p < planes; ++p)
    for (std::size_t k = 0; k < per; ++k) {
      const double d = 0.0012 * (2.0 * static_cast<double>((k + p) % 4) - 3.0);
      ref.insert(ref.end(), {box.lo[0] + 0.001 + static_cast<double>(p) * h + d,
                             0.1 * static_cast<double>(k % 8), 0.4 * static_cast<double>(k / 8)});
    }
  const LatticePlanes lp = find_planes(ref, box, 0, "thermal.dump");
  ASSERT_EQ(lp.planes, planes);
  EXPECT_NEAR(lp.spacing, h, 1e-12);
  // the atoms of one plane share an index, consecutive planes consecutive indices (mod 16)
  const int first = lp.plane_of_atom[0];
  for (std::size_t p = 0; p < planes; ++p)
    for (std::size_t k = 0; k < per; ++k)
      EXPECT_EQ(lp.plane_of_atom[p * per + k], static_cast<int>((first + static_cast<int>(p)) % 16))
          << "plane " << p << " atom " << k;
}
