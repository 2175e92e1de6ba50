#!/usr/bin/env python3
"""Coarse-graining accuracy against cost: rescaled models of an LJ lattice vs LAMMPS MD (docs/accuracy-cost.md §2).

usage: PDCG=/path/to/pdcg [LATTICE=chain|fcc] coarse_graining.py OUT_DIR

LATTICE=fcc: the same with a long FCC bar (ρ* = 1, a = 4^(1/3)σ, N planes normal to x at spacing
a/2, cross-section CROSS×CROSS cells, periodic in x, y, z), the packet longitudinal along [100],
Δt = 0.005, atoms2pd in 3D; coarse atom at ε x is compared with the MD atom at ε x (y, z folded
into the MD box: the field is uniform across); the closed form is the lattice sum
ω²(κ) = Σ_R K_xx(R)(1 − cos κR_x)/M. No homogenised column.

Problem. A periodic 1D Lennard-Jones chain (lj/cut 2.5σ shifted, M = 1, LJ units), N atoms at
x_i = i·h, h = 2^(1/6)σ (the nearest-neighbour minimum), box [−h/2, Nh − h/2), motion along x
only (atoms on a line: the y, z forces vanish exactly). Initial condition: a Gaussian wave
packet of carrier wavenumber κ₀ = 2π/(LAM·h) and envelope width W·LAM·h centred in the box,

    u(x, 0) = A exp(−(x − x_c)²/(2 w²)) cos(κ₀ (x − x_c)),   v(x, 0) = 0,

with strain amplitude A κ₀ = STRAIN (linear regime). It splits into two packets travelling at
the group velocity; the run lasts T = TRAVEL · L / c (c the long-wave sound speed).

Reference: LAMMPS MD (`lmp`, fix nve, Δt = DT) of the N atoms.
Coarse models, ε ∈ EPS: a chain of N/ε atoms at the same spacing h carrying the initial field
scaled by 1/ε, positions h j + u(ε h j)/ε; `pdcg atoms2pd` (delta body) then `pdcg rescale
--factor ε` → N/ε points at ε h j + u(ε h j), masses ε M, bonds ε ξ (the body of length L with
N/ε points); `pdcg md` with Δt_ε = ε Δt (the stable limit scales with ε; Verlet's relative
frequency error (ωΔt)²/24 at κ₀ is ≤ 1.4e-4, under 1 % of the dispersion error for every ε ≥ 2).
ε = 1 is the delta body: fixed-family MD.

Errors (coarse point j and atom i = ε j are the same material point: no interpolation):
  displacement   e(t) = ‖u_ε(t) − u_MD(t)‖₂ / ‖u_MD(t)‖₂ over the coarse points, at every frame;
                 e_T at the final time, e_rms over all frames (sums over frames and points);
  dispersion     |ω_ε(κ₀) − ω(κ₀)| / ω(κ₀) from `pdcg dispersion` of the rescaled perfect chain
                 and of the atomic one; also checked against the closed form
                 ω²(κ) = (2/M) Σ_n φ''(nh)(1 − cos nκh), ω_ε(κ) = ω(εκ)/ε (written here);
  linear theory  the same e_T for the two linearised chains solved by normal modes (FFT of the
                 initial field, cos ω t) — the error the dispersion alone explains.
Also the dispersion of the homogenised (Wendland C2, support 2h, grid = lattice) + rescaled chain.

Time: best of REPEAT runs, one thread: LAMMPS "Loop time" and process wall time; `pdcg md` loop
time (its log line) and process wall time (reading the body, stable step bound, dumps included).
Both runs write FRAMES + 1 dump frames. Pareto front: over (loop time, displacement error at T) of
the pdcg runs and the LAMMPS run (error 0: the reference).
Writes coarse_graining.csv, coarse_graining_time.csv, coarse_graining.json and coarse_graining.png.
"""
import json
import math
import os
import re
import subprocess
import sys
import time

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import matplotlib.ticker

PDCG = os.environ["PDCG"]
LATTICE = os.environ.get("LATTICE", "chain")  # chain | fcc
FCC = LATTICE == "fcc"
assert LATTICE in ("chain", "fcc"), LATTICE
N = int(os.environ.get("N", "512" if FCC else "2048"))  # lattice planes normal to x (chain: atoms)
CROSS = int(os.environ.get("CROSS", "1"))  # fcc: cross-section CROSS×CROSS cubic cells, periodic
EPS = [int(x) for x in os.environ.get("EPS", "1 2 4 8").split()]
LAM = float(os.environ.get("LAM", "32" if FCC else "64"))  # carrier wavelength in plane spacings
W = float(os.environ.get("W", "1.5"))  # envelope width in carrier wavelengths
STRAIN = float(os.environ.get("STRAIN", "1e-3"))
TRAVEL = float(os.environ.get("TRAVEL", "0.25"))  # distance travelled by the packets, in box lengths
DT = float(os.environ.get("DT", "0.005" if FCC else "0.01"))
FRAMES = int(os.environ.get("FRAMES", "16"))
REPEAT = int(os.environ.get("REPEAT", "3"))
RC, SKIN = 2.5, 2.8  # LJ cutoff; family radius (pairs within 2.5 stay within it: strains ~1e-3)
A_FCC = 4.0 ** (1.0 / 3.0)  # fcc at ρ* = 1 (LAMMPS `lattice fcc 1.0`)
H = A_FCC / 2 if FCC else 2.0 ** (1.0 / 6.0)  # spacing of the planes normal to x
ENV = dict(os.environ, OMP_NUM_THREADS="1")


def phi2(r):
    """φ''(r) of LJ (ε = σ = 1); the shift does not change derivatives."""
    return 4.0 * (156.0 * r ** -14 - 42.0 * r ** -8)


def phi1(r):
    return 4.0 * (-12.0 * r ** -13 + 6.0 * r ** -7)


def force_constants():
    """(R_x, K_xx(R)) of every lattice vector R ≠ 0 within r_c; K_xx = φ''(r) e_x² + φ'(r)/r (1 − e_x²)
    (pair potential; for a plane wave along x the x-x block is all that couples)."""
    m = int(RC / H) + 1
    out = []
    rng = range(-m, m + 1)
    for i in rng:
        for j in (rng if FCC else [0]):
            for k in (rng if FCC else [0]):
                if (i, j, k) == (0, 0, 0) or (FCC and (i + j + k) % 2):
                    continue
                R = H * np.array([i, j, k], dtype=float)
                r = float(np.linalg.norm(R))
                if r < RC:
                    ex2 = (R[0] / r) ** 2
                    out.append((R[0], phi2(r) * ex2 + phi1(r) / r * (1 - ex2)))
    return out


FC = force_constants()


def omega(k):
    """Closed form of the longitudinal branch along x (M = 1): ω² = Σ_R K_xx(R)(1 − cos κR_x)
    (Born & Huang; for the chain ω² = 2 Σ_n φ''(nh)(1 − cos nκh))."""
    k = np.asarray(k, dtype=float)
    return np.sqrt(np.maximum(0.0, sum(K * (1.0 - np.cos(k * Rx)) for Rx, K in FC)))


C_SOUND = math.sqrt(sum(K * Rx ** 2 for Rx, K in FC) / 2)
L = N * H
K0 = 2 * math.pi / (LAM * H)
WIDTH = W * LAM * H
AMP = STRAIN / K0
XC = 0.5 * L
T_END = TRAVEL * L / C_SOUND
step_unit = FRAMES * max(EPS)
STEPS = max(step_unit, int(round(T_END / DT / step_unit)) * step_unit)
T_END = STEPS * DT


def u0(x):
    return AMP * np.exp(-((x - XC) ** 2) / (2 * WIDTH ** 2)) * np.cos(K0 * (x - XC))


def sites(n):
    """Integer site coordinates (units H) of a lattice of n planes normal to x, in id order."""
    if not FCC:
        return np.array([[p, 0, 0] for p in range(n)])
    basis = [(0, 0, 0), (0, 1, 1), (1, 0, 1), (1, 1, 0)]
    return np.array([[2 * i + b[0], 2 * jy + b[1], 2 * jz + b[2]] for i in range(n // 2) for jy in range(CROSS)
                     for jz in range(CROSS) for b in basis])


def write_data(path, n, eps, displaced=True):
    """Lattice of n planes at spacing H carrying u(ε x)/ε along x (the coarse lattice before rescaling)."""
    g = sites(n)
    x = H * g.astype(float)
    if displaced:
        x[:, 0] += u0(eps * x[:, 0]) / eps
    yz = (-0.5 * H, (2 * CROSS - 0.5) * H) if FCC else (-0.5, 0.5)
    with open(path, "w") as f:
        f.write(f"LJ {LATTICE}, {len(g)} atoms, eps {eps}\n\n{len(g)} atoms\n1 atom types\n\n")
        f.write(f"{-0.5 * H:.17g} {n * H - 0.5 * H:.17g} xlo xhi\n{yz[0]:.17g} {yz[1]:.17g} ylo yhi\n"
                f"{yz[0]:.17g} {yz[1]:.17g} zlo zhi\n\n")
        f.write("Masses\n\n1 1.0\n\nAtoms # atomic\n\n")
        for j, p in enumerate(x):
            f.write(f"{j + 1} 1 {p[0]:.17g} {p[1]:.17g} {p[2]:.17g}\n")
    return g


def pdcg(*args, capture=False):
    r = subprocess.run([PDCG, *args], check=True, env=ENV, capture_output=True, text=True)
    return r.stderr if capture else None


def read_dump(path, box_len=None):
    """LAMMPS text dump -> (timesteps, x[frame, atom] unwrapped, sorted by id)."""
    steps, frames = [], []
    with open(path) as f:
        lines = f.read().splitlines()
    i = 0
    while i < len(lines):
        assert lines[i].startswith("ITEM: TIMESTEP"), lines[i]
        steps.append(int(lines[i + 1]))
        n = int(lines[i + 3])
        cols = lines[i + 8].split()[2:]
        lo, hi = (float(v) for v in lines[i + 5].split()[:2])
        data = np.array([[float(v) for v in l.split()] for l in lines[i + 9:i + 9 + n]])
        data = data[np.argsort(data[:, cols.index("id")])]
        if "xu" in cols:
            x = data[:, cols.index("xu")]
        else:
            x = data[:, cols.index("x")] + data[:, cols.index("ix")] * (hi - lo)
        frames.append(x)
        i += 9 + n
    return np.array(steps), np.array(frames)


def lammps_run(d):
    deck = f"""units lj
atom_style atomic
boundary {"p p p" if FCC else "p f f"}
read_data {d}/atoms.data
pair_style lj/cut {RC}
pair_coeff 1 1 1.0 1.0 {RC}
pair_modify shift yes
neighbor 0.3 bin
neigh_modify every 1 delay 0 check yes
timestep {DT:.17g}
fix 1 all nve
thermo 0
dump d all custom {STEPS // FRAMES} {d}/md.dump id xu
dump_modify d format float %.17g sort id
run {STEPS}
"""
    open(f"{d}/in.md", "w").write(deck)
    best = (math.inf, math.inf)
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        r = subprocess.run(["lmp", "-in", f"{d}/in.md", "-log", "none"], check=True, env=ENV,
                           capture_output=True, text=True, cwd=d)
        wall = time.perf_counter() - t0
        loop = float(re.search(r"Loop time of ([0-9.eE+-]+)", r.stdout).group(1))
        best = (min(best[0], loop), min(best[1], wall))
    return best


def pdcg_md(body, steps, dt, dump, every):
    best = (math.inf, math.inf)
    for _ in range(REPEAT):
        t0 = time.perf_counter()
        log = pdcg("md", body, "--steps", str(steps), "--dt", f"{dt:.17g}", "--dump", dump, "--every", str(every),
                   capture=True)
        wall = time.perf_counter() - t0
        loop = float(re.search(r"steps in ([0-9.eE+-]+) s", log).group(1))
        best = (min(best[0], loop), min(best[1], wall))
    return best


def model_omega(body):
    """Largest branch at κ₀ from `pdcg dispersion` (rows κ = 0 and κ₀)."""
    csv = body.replace(".h5", "_disp.csv")
    pdcg("dispersion", body, "--direction", "1,0,0", "--kmax", f"{K0:.17g}", "--nk", "1", "-o", csv)
    rows = np.genfromtxt([l for l in open(csv) if not l.startswith("#")], delimiter=",", names=True)  # `#`: units line
    row = rows[np.argmin(abs(rows["kappa"] - K0))]
    assert abs(row["kappa"] - K0) <= 1e-12 * K0, row
    return max(row["omega_1"], row["omega_2"], row["omega_3"])


def linear_solution(n, eps, t):
    """Normal-mode solution of the linearised chain of n points at spacing εh (ω_ε(κ) = ω(εκ)/ε)."""
    x = eps * H * np.arange(n)
    k = 2 * np.pi * np.fft.fftfreq(n, d=eps * H)
    w = omega(eps * k) / eps
    return np.real(np.fft.ifft(np.fft.fft(u0(x)) * np.cos(w * t)))


def main(out):
    pot = f"{out}/potential.lj"
    open(pot, "w").write(f"units lj\natom_style atomic\nmass 1 1.0\npair_style lj/cut {RC}\n"
                         f"pair_coeff 1 1 1.0 1.0 {RC}\npair_modify shift yes\n")
    assert all(N % e == 0 for e in EPS), "N must be divisible by every ε"
    assert max(EPS) * K0 * H < math.pi, "κ₀ must lie inside the coarsest model's zone"
    print(f"LJ {LATTICE} N = {N} planes, h = {H:.6f}, L = {L:.3f}, κ₀h = {K0 * H:.4f} (λ₀ = {LAM:g}h), width {WIDTH:.2f}, "
          f"A = {AMP:.4g}, c = {C_SOUND:.5f}, T = {T_END:g} ({STEPS} steps of {DT:g}), {REPEAT} repeats")

    # reference: LAMMPS MD of the N atoms
    d = f"{out}/md"
    os.makedirs(d, exist_ok=True)
    g_md = write_data(f"{d}/atoms.data", N, 1)
    key_md = {tuple(k): i for i, k in enumerate(g_md)}
    lmp_loop, lmp_wall = lammps_run(d)
    steps_md, x_md = read_dump(f"{d}/md.dump")
    u_md = x_md - H * g_md[:, 0]
    t_frames = steps_md * DT
    print(f"LAMMPS: {STEPS} steps, loop {lmp_loop:.3f} s, wall {lmp_wall:.3f} s")
    w_atoms_closed = float(omega(K0))

    rows, curves = [], {}
    for eps in EPS:
        n = N // eps
        d = f"{out}/eps{eps}"
        os.makedirs(d, exist_ok=True)
        g = write_data(f"{d}/atoms.data", n, eps)
        write_data(f"{d}/perfect.data", n, eps, displaced=False)
        # the MD atom at the coarse point's reference position ε x (y, z folded into the MD box)
        ny = 2 * CROSS if FCC else 1
        match = np.array([key_md[(eps * a, (eps * b) % ny, (eps * c) % ny)] for a, b, c in g])
        common = ["--potential", pot, "--family-cutoff", str(SKIN)]
        common += ["--boundary", "p p p"] if FCC else ["--dimension", "1", "--boundary", "p f f"]
        t0 = time.perf_counter()
        pdcg("atoms2pd", "--input", f"{d}/atoms.data", *common, "-o", f"{d}/delta.h5")
        body = f"{d}/delta.h5"
        if eps > 1:
            pdcg("rescale", body, "--factor", str(eps), "-o", f"{d}/coarse.h5")
            body = f"{d}/coarse.h5"
        t_build = time.perf_counter() - t0
        # dispersion at κ₀: rescaled perfect chain, and homogenised + rescaled
        pdcg("atoms2pd", "--input", f"{d}/perfect.data", *common, "-o", f"{d}/perfect.h5")
        perf, hom = f"{d}/perfect.h5", f"{d}/perfect_hom.h5"
        if not FCC:  # homogenised chain (fcc: not in this workflow)
            pdcg("homogenize", perf, "--kernel", "wendland-c2", "--width", f"{2 * H:.17g}", "--spacing",
                 f"{H:.17g}", "--shift", "0.5 0 0", "-o", hom)
        if eps > 1:
            pdcg("rescale", perf, "--factor", str(eps), "-o", f"{d}/perfect_res.h5")
            if not FCC:
                pdcg("rescale", hom, "--factor", str(eps), "-o", f"{d}/perfect_hom_res.h5")
            perf, hom = f"{d}/perfect_res.h5", f"{d}/perfect_hom_res.h5"
        w_model = model_omega(perf)
        w_hom = math.nan if FCC else model_omega(hom)
        if eps == 1:
            w_atoms = w_model
        # dynamics
        steps = STEPS // eps
        every = steps // FRAMES
        md_loop, md_wall = pdcg_md(body, steps, DT * eps, f"{d}/cg.dump", every)
        steps_cg, x_cg = read_dump(f"{d}/cg.dump")
        assert np.allclose(steps_cg * DT * eps, t_frames, rtol=0, atol=1e-9), "frames at different times"
        u_cg = x_cg - eps * H * g[:, 0]
        u_ref = u_md[:, match]  # the same material points
        diff = u_cg - u_ref
        e_t = np.linalg.norm(diff, axis=1) / np.linalg.norm(u_ref, axis=1)
        e_rms = float(np.sqrt((diff ** 2).sum() / (u_ref ** 2).sum()))
        # linear theory: the same error for the linearised chains (normal modes)
        lin = []
        for t in t_frames:
            ref = linear_solution(N, 1, t)[eps * g[:, 0]]
            lin.append(np.linalg.norm(linear_solution(n, eps, t)[g[:, 0]] - ref) / np.linalg.norm(ref))
        lin_md = float(np.linalg.norm(linear_solution(N, 1, T_END)[g_md[:, 0]] - u_md[-1]) / np.linalg.norm(u_md[-1]))
        curves[eps] = (t_frames, e_t, np.array(lin))
        w_closed = float(omega(eps * K0) / eps)
        rows.append(dict(eps=eps, points=len(g), dt=DT * eps, steps=steps, omega_model=w_model, omega_hom=w_hom,
                         omega_closed=w_closed, omega_atoms=w_atoms, omega_atoms_closed=w_atoms_closed,
                         dispersion_error=abs(w_model - w_atoms) / w_atoms,
                         dispersion_closed_dev=abs(w_model - w_closed) / w_closed,
                         hom_dev=abs(w_hom - w_model) / w_model,
                         error_final=float(e_t[-1]), error_rms=e_rms, error_max=float(e_t.max()),
                         error_linear_final=float(lin[-1]), md_vs_linear=lin_md,
                         pdcg_loop=md_loop, pdcg_wall=md_wall, build_wall=t_build,
                         lammps_loop=lmp_loop, lammps_wall=lmp_wall))
        r = rows[-1]
        print(f"ε = {eps}: {len(g)} points, ω(κ₀) {w_model:.10f} (atoms {w_atoms:.10f}, closed ω(εκ₀)/ε {w_closed:.10f}), "
              f"dispersion error {r['dispersion_error']:.3e}; displacement error final {r['error_final']:.3e} "
              f"(linear theory {r['error_linear_final']:.3e}), rms {e_rms:.3e}; pdcg md loop {md_loop:.3f} s, "
              f"wall {md_wall:.3f} s")
        for f in ("delta.h5", "coarse.h5", "cg.dump"):
            if os.path.exists(f"{d}/{f}"):
                os.remove(f"{d}/{f}")
    os.remove(f"{out}/md/md.dump")

    # Pareto front over (loop time, final displacement error) of the pdcg runs and LAMMPS MD (error 0
    # by construction: it is the reference). Loop times exclude process start-up (≈ 0.8 s for lmp).
    pts = [(r["pdcg_loop"], r["error_final"]) for r in rows] + [(lmp_loop, 0.0)]
    for r, (t, e) in zip(rows, pts):
        r["pareto"] = not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for t2, e2 in pts)

    keys = list(rows[0].keys())
    with open(f"{out}/coarse_graining.csv", "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(f"{r[k]:.10g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + "\n")
    with open(f"{out}/coarse_graining_time.csv", "w") as f:
        f.write("time," + ",".join(f"error_eps{e},linear_eps{e}" for e in EPS) + "\n")
        for i, t in enumerate(t_frames):
            f.write(f"{t:.10g}," + ",".join(f"{curves[e][1][i]:.10g},{curves[e][2][i]:.10g}" for e in EPS) + "\n")
    meta = dict(lattice=LATTICE, cross=CROSS, atoms=len(g_md), N=N, h=H, L=L, kappa0=K0, kappa0_h=K0 * H, lam_h=LAM, width=WIDTH, amplitude=AMP, strain=STRAIN,
                c=C_SOUND, t_end=T_END, steps=STEPS, dt=DT, frames=FRAMES, repeat=REPEAT, rows=rows)
    json.dump(meta, open(f"{out}/coarse_graining.json", "w"), indent=1)

    fig, ax = plt.subplots(1, 3, figsize=(16, 4.6))
    co = [r for r in rows if r["eps"] > 1]  # ε = 1: dispersion and linear-theory errors are exactly 0
    ec = [r["eps"] for r in co]
    ax[0].loglog([r["eps"] for r in rows], [r["error_final"] for r in rows], "o-",
                 label="displacement vs MD at t = T (ε = 1: round-off)")
    ax[0].loglog(ec, [r["error_linear_final"] for r in co], "x--", label="same, linear theory (dispersion only)")
    ax[0].loglog(ec, [r["dispersion_error"] for r in co], "s-", label="dispersion |ω_ε(κ₀) − ω(κ₀)|/ω(κ₀)")
    ax[0].set_xlabel("ε")
    ax[0].set_ylabel("relative error")
    ax[0].xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
    ax[0].set_xticks(EPS, [str(x) for x in EPS])
    ax[0].legend(fontsize=8)
    ax[0].set_title(f"LJ {LATTICE}, {len(g_md)} atoms, κ₀h = {K0 * H:.3f}, travel {C_SOUND * T_END / (LAM * H):.1f} λ₀")
    for eps in EPS:
        t, et, lt = curves[eps]
        ln, = ax[1].semilogy(t[1:], et[1:], "o-", ms=3, label=f"ε = {eps}")
        if eps > 1:
            ax[1].semilogy(t[1:], lt[1:], "--", color=ln.get_color(), lw=0.8)
    ax[1].set_xlabel("time (LJ units)")
    ax[1].set_ylabel("‖u_ε − u_MD‖/‖u_MD‖")
    ax[1].set_title("error vs simulated time (dashed: linear theory)")
    ax[1].legend(fontsize=8)
    for r in rows:
        ax[2].loglog(r["pdcg_loop"], r["error_final"], "o", ms=7 if r["pareto"] else 4,
                     label=f"pdcg md ε = {r['eps']}" + (" (Pareto)" if r["pareto"] else ""))
    ax[2].axvline(lmp_loop, color="k", ls=":", label=f"LAMMPS MD (reference, error 0) {lmp_loop:.2f} s")
    ax[2].set_xlabel("loop time (s), one thread, same simulated time")
    ax[2].set_ylabel("displacement error at T")
    ax[2].set_title("accuracy against cost")
    ax[2].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{out}/coarse_graining.png", dpi=110)
    print(f"wrote {out}/coarse_graining.csv, coarse_graining_time.csv, coarse_graining.json, coarse_graining.png")


if __name__ == "__main__":
    main(os.path.abspath(sys.argv[1]))
