#!/usr/bin/python3
"""Analysis of one brittle_md fracture run (in.fracture): stress-strain, peak stress, critical
strain, crack initiation, crack-tip position vs time -> crack speed, crack path, snapshots.

Usage: analyze.py RUN_DIR [--gamma G] [--png]
  RUN_DIR  holds meta.txt, series.txt, frames.dump (written by in.fracture); its parent
           holds potential.mod and a0.txt (make_decks.py)
Writes RUN_DIR/analysis.json, and with --png RUN_DIR/curves.png and RUN_DIR/snapshots.png.

Definitions (docs/fracture.md, 'A brittle reference system'):
  stress     nominal: force on the top grip / initial width W (energy/length^2, 2D)
  peak       maximum of the 5-sample (2.5 tau at nprint 100, dt 0.005) running mean of the stress;
             critical strain = strain at the peak
  tip        largest x of an interior atom with fewer than 6 neighbours within rb (in.fracture)
  initiation first sample with the tip 2 a0 past the notch tip a
  speed      least-squares slope of tip(t) while the tip runs from a + 0.2 (W - a) to a + 0.7 (W - a)
  on_plane   of the interior atoms with coordination < 6 right of the notch in the last
             frame (crack faces, dislocation cores, voids), the fraction in the two rows next to
             the notch plane (1: the only defect is a cleaved plane)
  path       in each lattice column right of the notch, the row where the widest gap between
             vertically adjacent atoms exceeds rb (the crack), as an offset in rows from the notch
             plane; path_on_plane = the fraction of cut columns with offset 0 in the running window
             of the speed (path_on_plane_all: up to 4 sigma from the right edge)
  Griffith   sigma_G = sqrt(E G_c / (pi a)) / F(a/W), G_c = 2 gamma (relaxed edge energy of the
             close-packed row, gamma.txt), E the 2D Young modulus of the lattice (Cauchy-Born, from
             the pair potential), F the edge-crack factor of Tada's handbook (single edge notch,
             tension, 1.12 at a/W -> 0; pin-loaded ends: an approximation for these grips);
  sigma_G_statics  the Griffith load of this very sheet from LAMMPS statics (griffith.py,
             SYSDIR/griffith_W<nx>.json), no geometry factor assumed
"""
import argparse
import json
import math
import os
import re
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from dumpio import frames  # noqa: E402


def read_meta(path):
    w = open(path).read().split()
    meta = {}
    for k, v in zip(w[0::2], w[1::2]):
        try:
            meta[k] = float(v)
        except ValueError:
            meta[k] = v
    return meta


def pair_energy(pot_path):
    """phi(r) of the potential.mod written by make_decks.py (lj/cut or morse, energy shifted)."""
    text = open(pot_path).read()
    style = re.search(r"pair_style\s+(\S+)\s+(\S+)", text)
    coeff = re.search(r"pair_coeff\s+\*\s+\*\s+(.+)", text).group(1).split()
    shift = re.search(r"pair_modify\s+shift\s+yes", text) is not None
    name, rc = style.group(1), float(style.group(2))
    c = [float(x) for x in coeff]
    if name == "lj/cut":
        eps, sig = c[0], c[1]
        rc = c[2] if len(c) > 2 else rc

        def phi0(r):
            return 4 * eps * ((sig / r) ** 12 - (sig / r) ** 6)
    elif name == "morse":
        d0, al, r0 = c[0], c[1], c[2]
        rc = c[3] if len(c) > 3 else rc

        def phi0(r):
            e = np.exp(-al * (r - r0))
            return d0 * (e * e - 2 * e)
    else:
        raise SystemExit(f"analyze.py: {pot_path}: pair style {name} not handled (lj/cut, morse)")
    s = phi0(rc) if shift else 0.0
    return (lambda r: np.where(r < rc, phi0(r) - s, 0.0)), rc


def lattice_moduli(phi, rc, a0):
    """2D Cauchy-Born moduli of the triangular lattice: W(eps) by a lattice sum, C by central
    differences; returns C11, C12, C66, E (2D Young modulus), nu, c_s, c_R (unit mass)."""
    n = int(math.ceil(rc / a0)) + 2
    a1, a2 = np.array([a0, 0.0]), np.array([0.5 * a0, math.sqrt(3) / 2 * a0])
    xi = np.array([i * a1 + j * a2 for i in range(-n, n + 1) for j in range(-n, n + 1) if i or j])
    xi = xi[np.linalg.norm(xi, axis=1) < rc * 1.3]
    omega = math.sqrt(3) / 2 * a0 * a0

    def W(e):
        F = np.eye(2) + e
        r = np.linalg.norm(xi @ F.T, axis=1)
        return 0.5 * phi(r).sum() / omega

    h = 1e-4

    def d2(i, j, k, l):
        def E(s, t):
            e = np.zeros((2, 2))
            e[i, j] += s
            e[k, l] += t
            return W(e)
        return (E(h, h) - E(h, -h) - E(-h, h) + E(-h, -h)) / (4 * h * h)

    c11, c12, c66 = d2(0, 0, 0, 0), d2(0, 0, 1, 1), d2(0, 1, 0, 1)
    E = (c11 * c11 - c12 * c12) / c11
    nu = c12 / c11
    rho = 1.0 / omega
    cs = math.sqrt(c66 / rho)
    cl = math.sqrt(c11 / rho)
    # Rayleigh speed: root of (2 - x)^2 = 4 sqrt(1 - x) sqrt(1 - x (cs/cl)^2), x = (c/cs)^2
    f = lambda x: (2 - x) ** 2 - 4 * math.sqrt(1 - x) * math.sqrt(1 - x * (cs / cl) ** 2)
    lo, hi = 0.5, 0.999999
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if f(lo) * f(mid) <= 0:
            hi = mid
        else:
            lo = mid
    return dict(C11=c11, C12=c12, C66=c66, E=E, nu=nu, c_s=cs, c_l=cl, c_R=cs * math.sqrt(lo))


def tada_sent(r):
    """Single edge notch in tension, K = sigma sqrt(pi a) F(a/W) (Tada, Paris & Irwin; 0.5 % for
    a/W <= 0.6)."""
    return 1.12 - 0.231 * r + 10.55 * r**2 - 21.72 * r**3 + 30.39 * r**4


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("run")
    ap.add_argument("--png", action="store_true")
    o = ap.parse_args()
    run = o.run
    sysdir = os.path.dirname(os.path.abspath(run))
    meta = read_meta(os.path.join(run, "meta.txt"))
    a0, W, a, h, yc = meta["a0"], meta["W"], meta["a"], meta["h"], meta["yc"]
    dt, rate, natoms = meta["dt"], meta["rate"], int(meta["atoms"])
    s = np.loadtxt(os.path.join(run, "series.txt"), ndmin=2)
    # a sample taken at the setup of a new run (after a halt) can carry stale coordinations:
    # drop samples whose defect count is a sizeable part of the sheet
    s = s[s[:, 4] < 0.2 * natoms]
    step, strain, stress, tip, ndef = s[:, 0], s[:, 1], s[:, 2], s[:, 3].copy(), s[:, 4]
    # tip: median of 3 consecutive samples (a lone sample can pick up an atom at an edge)
    if len(tip) >= 3:
        tip[1:-1] = np.median(np.stack([s[:-2, 3], s[1:-1, 3], s[2:, 3]]), axis=0)
    t = step * dt
    k = 5
    smooth = np.convolve(stress, np.ones(k) / k, mode="same")
    smooth[: k // 2] = stress[: k // 2]
    ip = int(np.argmax(smooth))
    res = dict(run=os.path.abspath(run), atoms=natoms, W=W, a=a, a_over_W=a / W, rate=rate,
               T=meta["T"], peak_stress=float(smooth[ip]), critical_strain=float(strain[ip]),
               peak_stress_raw=float(stress.max()))
    adv = np.nonzero(tip > a + 2 * a0)[0]
    if len(adv):
        i0 = adv[0]
        res.update(init_strain=float(strain[i0]), init_stress=float(smooth[i0]), init_time=float(t[i0]))
    x1, x2 = a + 0.2 * (W - a), a + 0.7 * (W - a)
    sel = np.nonzero((tip >= x1) & (tip <= x2))[0]
    if len(sel) >= 3 and len(adv):
        # the first passage: samples from the first above x1 to the first above x2
        j1 = sel[0]
        later = np.nonzero(tip > x2)[0]
        j2 = later[0] if len(later) else sel[-1]
        if j2 - j1 >= 2:
            v = np.polyfit(t[j1:j2 + 1], tip[j1:j2 + 1], 1)[0]
            res["speed"] = float(v)
            res["speed_window"] = [float(t[j1]), float(t[j2])]
    res["defects_end"] = int(ndef[-1])
    # while the crack runs: the count when the tip first passes a + 0.7 (W - a) (at the end it
    # also holds the edges of the separated halves as they spring back)
    past = np.nonzero(tip > x2)[0]
    if len(past):
        res["defects_running"] = int(ndef[past[0]])
    res["defects_max"] = int(ndef.max())

    phi, rc = pair_energy(os.path.join(sysdir, "potential.mod"))
    mod = lattice_moduli(phi, rc, a0)
    res["moduli"] = mod
    if "speed" in res:
        res["speed_over_cR"] = res["speed"] / mod["c_R"]
    gpath = os.path.join(sysdir, "gamma.txt")
    if os.path.exists(gpath):
        g = dict(line.split()[:2] for line in open(gpath) if line.startswith("gamma"))
        gamma = float(g["gamma_relaxed"])
        Gc = 2 * gamma
        F = tada_sent(a / W)
        sG = math.sqrt(mod["E"] * Gc / (math.pi * a)) / F
        res.update(gamma=gamma, G_c=Gc, F_tada=F, sigma_griffith=sG,
                   peak_over_griffith=res["peak_stress"] / sG,
                   sigma_sqrt_a=res["peak_stress"] * math.sqrt(a))

    # Griffith load of this very sheet by molecular statics (griffith.py), if computed
    gj = os.path.join(sysdir, f"griffith_W{int(meta['nx'])}.json")
    if os.path.exists(gj):
        gr = json.load(open(gj)).get(str(int(meta["notch"])))
        if gr:
            res.update(sigma_G_statics=gr["sigma_G"], eps_G_statics=gr["eps_G"],
                       peak_over_G_statics=res["peak_stress"] / gr["sigma_G"],
                       strain_over_G_statics=res["critical_strain"] / gr["eps_G"])

    # crack path from the dumps: rows of the reference lattice (first frame of sparse.dump)
    f0 = next(frames(os.path.join(run, "frames.dump")))[1]
    row = np.rint(f0[:, 3] / h).astype(int)
    row_lo = int(np.rint((yc - 0.5 * h) / h))  # the row just below the notch plane
    fr = [(st, d) for st, d in frames(os.path.join(run, "frames.dump"))
          if np.count_nonzero(d[:, 4] < 6) < 0.2 * natoms]
    if fr:
        st, d = fr[-1]
        x, y, c = d[:, 2], d[:, 3], d[:, 4]
        inner = (x > x.min() + 2) & (x < x.max() - 2) & (y > y.min() + 2) & (y < y.max() - 2)
        face = inner & (c < 6) & (f0[:, 2] > a)
        off = np.where(row[face] <= row_lo, row_lo - row[face], row[face] - (row_lo + 1))
        res["path_step"] = int(st)
        res["face_atoms"] = int(face.sum())
        res["on_plane"] = float(np.mean(off == 0)) if face.any() else None
        # path: in each column of width a0 right of the notch, the widest gap between atoms
        # adjacent in y; where it exceeds rb the crack crosses the column there, and its row
        # offset from the notch plane is the row of the atom below the gap minus row_lo
        path = []
        xs = f0[:, 2]
        for xb in np.arange(a + a0, W - 4.0, a0):
            m = np.nonzero((xs >= xb) & (xs < xb + a0))[0]
            o_ = m[np.argsort(y[m])]
            gaps = np.diff(y[o_])
            j = int(np.argmax(gaps))
            if gaps[j] > meta["rb"]:
                path.append((float(xb), int(row[o_[j]] - row_lo)))
        res["path"] = path
        # over the running window of the speed (a -> a + 0.7 (W - a)); the last ligament bends
        run_path = [p_ for p_ in path if p_[0] < x2]
        if run_path:
            offs = np.array([p_[1] for p_ in run_path])
            res["path_on_plane"] = float(np.mean(offs == 0))
            res["path_max_offset_rows"] = int(np.abs(offs).max())
            res["path_columns_cut"] = len(run_path)
        if path:
            offs = np.array([p_[1] for p_ in path])
            res["path_on_plane_all"] = float(np.mean(offs == 0))
    json.dump(res, open(os.path.join(run, "analysis.json"), "w"), indent=1)
    keys = ["atoms", "a", "rate", "peak_stress", "critical_strain", "init_strain", "speed",
            "speed_over_cR", "on_plane", "path_on_plane", "path_max_offset_rows", "path_on_plane_all", "defects_running", "defects_end", "sigma_griffith",
            "peak_over_griffith", "sigma_G_statics", "peak_over_G_statics", "strain_over_G_statics",
            "sigma_sqrt_a"]
    print(" ".join(f"{kk}={res[kk]:.4g}" if isinstance(res.get(kk), float) else f"{kk}={res.get(kk)}"
                   for kk in keys))

    if o.png:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(1, 2, figsize=(10, 3.6))
        ax[0].plot(strain, stress, lw=0.5, color="0.6")
        ax[0].plot(strain, smooth, lw=1.2)
        ax[0].plot(strain[ip], smooth[ip], "ro")
        ax[0].set_xlabel("strain")
        ax[0].set_ylabel("nominal stress (ε/σ²)")
        ax[1].plot(t, tip, lw=1)
        ax[1].axhline(a, ls=":", color="k")
        if "speed" in res:
            ax[1].set_title(f"v = {res['speed']:.2f} σ/τ = {res['speed_over_cR']:.2f} c_R")
        ax[1].set_xlabel("time (τ)")
        ax[1].set_ylabel("crack tip x (σ)")
        fig.suptitle(os.path.basename(os.path.abspath(run)))
        fig.tight_layout()
        fig.savefig(os.path.join(run, "curves.png"), dpi=80)
        if fr:
            tips = {int(st): None for st, _ in fr}
            tipof = dict(zip(step.astype(int), tip))
            want = [a + q * (W - a) for q in (0.1, 0.4, 0.7)]
            pick = []
            for w in want:
                cand = [i for i, (st, _) in enumerate(fr) if tipof.get(int(st), -1) >= w]
                if cand and cand[0] not in pick:
                    pick.append(cand[0])
            if len(fr) - 1 not in pick:
                pick.append(len(fr) - 1)
            fig, axs = plt.subplots(1, len(pick), figsize=(4 * len(pick), 4.3))
            axs = np.atleast_1d(axs)
            for axx, i in zip(axs, pick):
                st, d = fr[i]
                c = d[:, 4]
                col = np.where(c < 6, "r", np.where(c > 6, "b", "0.8"))
                axx.scatter(d[:, 2], d[:, 3], s=min(4.0, 60000.0 / natoms), c=col, lw=0, rasterized=True)
                axx.set_aspect("equal")
                axx.set_title(f"t = {st * dt:.0f} τ, strain {st * dt * rate:.4f}")
                axx.set_xticks([])
                axx.set_yticks([])
            fig.suptitle(f"{natoms} atoms, a = {a / a0:.0f} a0, rate {rate:g}/τ: "
                         "red = fewer than 6 neighbours, blue = more")
            fig.tight_layout()
            fig.savefig(os.path.join(run, "snapshots.png"), dpi=70)


if __name__ == "__main__":
    main()
