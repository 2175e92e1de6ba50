#!/usr/bin/env python3
"""Phonons at a temperature: measured dispersion of MD against the static and quasi-harmonic
models (docs/temperature.md §3.2).

    dispersion.py OUT [lj|cu ...]      (run.sh with DISPERSION=1; ~10 min CPU)
    env: PDCG, REUSE=1 (keep OUT/<sys>_<T>_<ens>/traj.dump of an earlier run)

For each system (fcc LJ, lj/cut 2.5 shifted, T* = 0.05 0.2 0.4; Cu EAM Cu_u3.eam, 300 600
900 K), temperature and ensemble (fixed: the T = 0 volume of md.in; p0: the zero-pressure
volume at T from NPT), md_disp.in runs 8×4×4 fcc cells (512 atoms; 16 (100) planes along x,
so κ_m = m/8 of Γ–X, m = 1…8): NVT, then an NVE trajectory. Measured:
  ridge     `pdcg dispersion --trajectory traj.dump --axis x --component x|y` (L|T): the
            frequency bin of peak power S(κ, ω) (bin Δω = 2π/(frames·Δt));
  fit       a Lorentzian A/((ω − ω₀)² + Γ²/4) + B fitted to S(κ_m, ω) around the peak (the same
            transform as pdcg's, in numpy: plane-averaged displacement, Hann window, |Û(ω)|² +
            |Û(−ω)|²; T: the y and z spectra summed), ω₀ with the error |ω₀(1st half) −
            ω₀(2nd half)|/2 of the trajectory's halves, and the line width Γ.
Models (`pdcg dispersion BODY --direction 1,0,0 --nk 64`, delta bodies of the perfect lattice):
  static    the T = 0 lattice a₀ (the harmonic frequencies, what every static body has);
  qha       the quasi-harmonic frequencies at T: those of the lattice at the volume where the
            quasi-harmonic free energy's pressure vanishes, p(a, T) = 0 (`pdcg energy
            --quasi-harmonic T --stress`, same 512-atom cell); at fixed volume the quasi-harmonic
            frequencies are the static ones (ω depends on the volume only);
  harm(a_MD) the harmonic frequencies of the lattice at MD's mean lattice constant (separates
            the error of the quasi-harmonic volume from what is anharmonic at fixed volume).
Writes OUT/dispersion.csv (every κ), OUT/dispersion.md (summary), OUT/dispersion.png.
"""
import csv
import json
import os
import subprocess
import sys

import numpy as np
from scipy.optimize import brentq, curve_fit

HERE = os.path.dirname(os.path.abspath(__file__))
PDCG = os.environ.get("PDCG", "pdcg")
CX, CY = 8, 4  # cells along the wave axis x, and along y and z
PLANES = 2 * CX  # (100) planes of fcc along x
SYSTEMS = {
    "lj": dict(temps=["0.05", "0.2", "0.4"], equil=5000, nve=20000, every=10,
               potential="units lj\natom_style atomic\nmass 1 1.0\npair_style lj/cut 2.5\n"
                         "pair_coeff 1 1 1.0 1.0 2.5\npair_modify shift yes\n",
               unit="τ⁻¹", tunit=""),
    "cu": dict(temps=["300", "600", "900"], equil=5000, nve=20000, every=20,
               potential="units metal\natom_style atomic\nmass 1 63.55\npair_style eam\n"
                         "pair_coeff 1 1 Cu_u3.eam\n",
               unit="rad/ps", tunit=" K"),
}


def run(*args, **kw):
    return subprocess.run(list(args), check=True, **kw)


def md(sys_, T, ens, d):
    s = SYSTEMS[sys_]
    os.makedirs(d, exist_ok=True)
    if not (os.environ.get("REUSE") == "1" and os.path.exists(os.path.join(d, "traj.dump"))):
        run("nice", "-n", "10", "lmp", "-in", os.path.join(HERE, "md_disp.in"), "-var", "sys",
            sys_, "-var", "T", T, "-var", "ens", ens, "-var", "seed", "4711", "-var", "cx",
            str(CX), "-var", "cy", str(CY), "-var", "equil", str(s["equil"]), "-var", "nve",
            str(s["nve"]), "-var", "every", str(s["every"]), "-var", "out", d, "-log",
            os.path.join(d, "log.lammps"), "-screen", "none", cwd="/usr/share/lammps/potentials")
    # CPU time of the MD from its log: Σ loop time × CPU use of the runs and the minimisation
    cpu, loop = 0.0, None
    for line in open(os.path.join(d, "log.lammps")):
        if line.startswith("Loop time of"):
            loop = float(line.split()[3])
        elif loop is not None and "% CPU use" in line:
            cpu += loop * float(line.split("%")[0]) / 100
            loop = None
    return cpu


def log_values(d):
    v = {}
    for line in open(os.path.join(d, "log.lammps")):
        w = line.split()
        if line.startswith("LATTICE a0 ="):
            v["a0"] = float(w[3])
        elif line.startswith("BOX a ="):
            v["a"] = float(w[3])
        elif line.startswith("NVE mean T ="):
            v["T"], v["pe"], v["p"] = float(w[4]), float(w[7]), float(w[10])
    return v


def read_traj(path):
    """Times, positions (frames × atoms × 3, id order) and box lengths of an `id xu yu zu` dump."""
    times, frames, box = [], [], None
    with open(path) as f:
        while True:
            line = f.readline()
            if not line:
                break
            assert line.startswith("ITEM: TIME"), line
            times.append(float(f.readline()))
            f.readline(), f.readline(), f.readline()
            n = int(f.readline())
            f.readline()
            box = [list(map(float, f.readline().split())) for _ in range(3)]
            f.readline()
            a = np.array([f.readline().split() for _ in range(n)], dtype=float)
            frames.append(a[np.argsort(a[:, 0]), 1:4])
    box = np.array(box)
    return np.array(times), np.array(frames), box[:, 1] - box[:, 0]


def lorentz(w, A, w0, g, B):
    return A / ((w - w0) ** 2 + g ** 2 / 4) + B


def fit_lines(X, dt, Lx, comps):
    """ω₀ and Γ of a Lorentzian fitted at each κ_m (m = 1…PLANES/2) to S(κ_m, ω) summed over
    the displacement components `comps` (the transform of measured.cpp)."""
    T = X.shape[0]
    mean = X.mean(axis=0)
    plane = np.round((mean[:, 0] - mean[:, 0].min()) / (Lx / PLANES)).astype(int) % PLANES
    hann = 0.5 * (1 - np.cos(2 * np.pi * np.arange(T) / (T - 1)))
    dw = 2 * np.pi / (T * dt)
    om = np.arange(T // 2 + 1) * dw
    P = 0.0
    for c in comps:
        u = np.stack([(X[:, plane == n, c] - mean[plane == n, c]).mean(axis=1)
                      for n in range(PLANES)], axis=1)
        u -= u.mean(axis=0)
        Q = np.abs(np.fft.fft2(u * hann[:, None])) ** 2
        P = P + Q + Q[(-np.arange(T)) % T]
    out = []
    for m in range(1, PLANES // 2 + 1):
        # a single trajectory's periodogram scatters by its own size from bin to bin
        # (exponential statistics): smooth over 5 bins (the centre of a symmetric line stays)
        s = np.convolve(P[:T // 2 + 1, m], np.ones(5) / 5, mode="same")
        l = int(np.argmax(s[3:])) + 3
        half = np.nonzero(s < s[l] / 2)[0]
        lo, hi = half[half < l], half[half > l]
        g0 = max(2 * dw, ((hi[0] if len(hi) else l + 2) - (lo[-1] if len(lo) else l - 2)) * dw)
        n = max(8, int(3 * g0 / dw))  # fit ±3 half-power widths (at least ±8 bins)
        sel = slice(max(3, l - n), min(len(s) - 2, l + n + 1))
        try:
            p, _ = curve_fit(lorentz, om[sel], s[sel], p0=[s[l] * g0 ** 2 / 4, om[l], g0, 0.0],
                             bounds=([0, om[sel][0], dw, 0], [np.inf, om[sel][-1], 50 * g0,
                                                              s[l]]), maxfev=20000)
            out.append((p[1], p[2]))
        except RuntimeError:
            out.append((np.nan, np.nan))
    return out


def measured(d):
    """pdcg's ridge (L: component x, T: y) and the Lorentzian fits, with half-split errors."""
    res = {}
    for br, comp in (("L", "x"), ("T", "y")):
        csvp = os.path.join(d, f"measured_{br}.csv")
        run(PDCG, "-q", "dispersion", "--trajectory", os.path.join(d, "traj.dump"), "--axis", "x",
            "--component", comp, "-o", csvp, "--compare", os.path.join(d, "model_static.csv"),
            stdout=subprocess.DEVNULL)
        rows = list(csv.DictReader(l for l in open(csvp) if not l.startswith("#")))
        res[br + "_ridge"] = [float(r["omega"]) for r in rows]
        res["kappa"] = [float(r["kappa"]) for r in rows]
        res["bin"] = float(rows[0]["resolution"])
    t, X, L = read_traj(os.path.join(d, "traj.dump"))
    dt = t[1] - t[0]
    h = X.shape[0] // 2
    for br, comps in (("L", (0,)), ("T", (1, 2))):
        full = fit_lines(X, dt, L[0], comps)
        a = fit_lines(X[:h], dt, L[0], comps)
        b = fit_lines(X[h:2 * h], dt, L[0], comps)
        res[br + "_fit"] = [f[0] for f in full]
        res[br + "_width"] = [f[1] for f in full]
        res[br + "_err"] = [abs(x[0] - y[0]) / 2 for x, y in zip(a, b)]
    return res


def body_at(sys_, d, a, name):
    """Delta body of the perfect lattice of lattice.dump scaled to lattice constant a."""
    src = os.path.join(d, "lattice.dump")
    lines = open(src).read().splitlines()
    a0 = log_values(d)["a0"]
    s = a / a0
    out = []
    for i, line in enumerate(lines):
        if 5 <= i <= 7:  # box bounds
            lo, hi = map(float, line.split())
            out.append(f"{lo * s:.17g} {hi * s:.17g}")
        elif i >= 9:
            w = line.split()
            out.append(" ".join(w[:2] + [f"{float(x) * s:.17g}" for x in w[2:5]]))
        else:
            out.append(line)
    dump = os.path.join(d, f"{name}.dump")
    open(dump, "w").write("\n".join(out) + "\n")
    pot = os.path.join(d, "potential.in")
    open(pot, "w").write(SYSTEMS[sys_]["potential"])
    body = os.path.join(d, f"{name}.h5")
    run(PDCG, "-q", "atoms2pd", "--input", dump, "--potential", pot, "--density", "delta",
        "-o", body, stdout=subprocess.DEVNULL,
        cwd="/usr/share/lammps/potentials")
    return body


def model(body, out):
    run(PDCG, "-q", "dispersion", body, "--direction", "1,0,0", "--nk", "64", "-o", out,
        stdout=subprocess.DEVNULL)
    rows = np.array([[float(x) for x in l.split(",")] for l in open(out)
                     if l[0].isdigit() or l[0] == "-"])
    k, w = rows[:, 0], np.sort(rows[:, 1:4], axis=1)
    return k[8::8], w[8::8, 2], w[8::8, 0]  # κ_m, L, T (T1 = T2 along [100])


def qha_pressure(body, s, T):
    j = json.loads(run(PDCG, "-q", "energy", body, "--F", f"{s} 0 0 0 {s} 0 0 0 {s}",
                       "--quasi-harmonic", T, "--stress", "--json", capture_output=True,
                       text=True).stdout)
    P = np.array(j["free_energy_stress"]).reshape(3, 3)
    return -np.trace(P) / (3 * s * s)  # p = −tr σ/3, σ = P Fᵀ/J = P/s² at F = sI


def main():
    out = os.path.abspath(sys.argv[1])
    systems = sys.argv[2:] or ["lj", "cu"]
    rows, summary = [], []
    for sys_ in systems:
        S = SYSTEMS[sys_]
        for T in S["temps"]:
            for ens in ("fixed", "p0"):
                d = os.path.join(out, f"{sys_}_{T}_{ens}")
                cpu_md = md(sys_, T, ens, d)
                v = log_values(d)
                c0 = os.times().children_user + os.times().children_system
                static = body_at(sys_, d, v["a0"], "body_static")
                ks, Ls, Ts = model(static, os.path.join(d, "model_static.csv"))
                if ens == "fixed":
                    a_qha = v["a0"]
                    Lq, Tq = Ls, Ts
                    Lh, Th = Ls, Ts
                else:
                    # quasi-harmonic volume: p(a, T) = 0 of the free energy of the same cell
                    f = lambda s: qha_pressure(static, s, T)
                    s_md = v["a"] / v["a0"]
                    s_q = brentq(f, 1.0, 1.0 + 2.0 * (s_md - 1.0), xtol=1e-7)
                    a_qha = s_q * v["a0"]
                    _, Lq, Tq = model(body_at(sys_, d, a_qha, "body_qha"),
                                      os.path.join(d, "model_qha.csv"))
                    _, Lh, Th = model(body_at(sys_, d, v["a"], "body_amd"),
                                      os.path.join(d, "model_amd.csv"))
                m = measured(d)
                cpu_pdcg = os.times().children_user + os.times().children_system - c0
                for i in range(PLANES // 2):
                    rows.append(dict(system=sys_, T=T, ensemble=ens, a0=v["a0"], a_md=v["a"],
                                     a_qha=a_qha, T_nve=v["T"], p_nve=v["p"], m=i + 1,
                                     kappa=m["kappa"][i], bin=m["bin"],
                                     L_ridge=m["L_ridge"][i], L_fit=m["L_fit"][i],
                                     L_err=m["L_err"][i], L_width=m["L_width"][i],
                                     L_static=Ls[i], L_qha=Lq[i], L_harm_amd=Lh[i],
                                     T_ridge=m["T_ridge"][i], T_fit=m["T_fit"][i],
                                     T_err=m["T_err"][i], T_width=m["T_width"][i],
                                     T_static=Ts[i], T_qha=Tq[i], T_harm_amd=Th[i]))
                summary.append((sys_, T, ens, v, a_qha, cpu_md, cpu_pdcg))
                print(f"{sys_} T={T} {ens}: a/a0 MD {v['a'] / v['a0']:.5f} QHA "
                      f"{a_qha / v['a0']:.5f}; X: L {m['L_fit'][-1]:.3f} (static {Ls[-1]:.3f}, "
                      f"qha {Lq[-1]:.3f}), T {m['T_fit'][-1]:.3f} (static {Ts[-1]:.3f}, qha "
                      f"{Tq[-1]:.3f}); CPU MD {cpu_md:.1f} s, pdcg {cpu_pdcg:.1f} s", flush=True)
    with open(os.path.join(out, "dispersion.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    plot(rows, os.path.join(out, "dispersion.png"))
    tab = ["| system | T | volume | a/a₀ MD | a/a₀ QHA | branch | κ | MD (fit) | MD (ridge) | static | "
          "QHA | harmonic at a_MD | MD/static − 1 | MD/QHA − 1 |",
          "|---|---:|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        if r["m"] not in (1, 4, 8):
            continue
        for br in ("L", "T"):
            tab.append(f"| {r['system']} | {r['T']} | {r['ensemble']} | {r['a_md'] / r['a0']:.5f} | "
                      f"{r['a_qha'] / r['a0']:.5f} | {br} | {r['m']}/8 X | "
                      f"{r[br + '_fit']:.3f} ± {r[br + '_err']:.3f} | {r[br + '_ridge']:.3f} ± "
                      f"{r['bin'] / 2:.3f} | {r[br + '_static']:.3f} | {r[br + '_qha']:.3f} | "
                      f"{r[br + '_harm_amd']:.3f} | {100 * (r[br + '_fit'] / r[br + '_static'] - 1):+.1f} % | "
                      f"{100 * (r[br + '_fit'] / r[br + '_qha'] - 1):+.1f} % |")
    tab += ["", "| system | T | volume | NVE ⟨T⟩ | NVE ⟨p⟩ | CPU MD (s) | CPU pdcg (s) |",
           "|---|---:|---|---:|---:|---:|---:|"]
    for sys_, T, ens, v, a_qha, cpu_md, cpu_pdcg in summary:
        tab.append(f"| {sys_} | {T} | {ens} | {v['T']:.4g} | {v['p']:.4g} | {cpu_md:.1f} | "
                  f"{cpu_pdcg:.1f} |")
    with open(os.path.join(out, "dispersion.md"), "w") as f:
        f.write("\n".join(tab) + "\n")
    print("\n".join(tab))


def plot(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    systems = sorted({r["system"] for r in rows}, key=["lj", "cu"].index)
    fig, axes = plt.subplots(1, len(systems), figsize=(5.2 * len(systems), 4.2), squeeze=False)
    colors = ["tab:blue", "tab:orange", "tab:red"]
    for ax, sys_ in zip(axes[0], systems):
        S = SYSTEMS[sys_]
        R = [r for r in rows if r["system"] == sys_ and r["ensemble"] == "p0"]
        first = [r for r in R if r["T"] == S["temps"][0]]
        kx = 2 * np.pi / first[0]["a0"]
        k = [0] + [r["m"] / 8 for r in first]
        for br, ls in (("L", "-"), ("T", "-")):
            ax.plot(k, [0] + [r[br + "_static"] for r in first], "k" + ls, lw=1,
                    label="static lattice (T = 0)" if br == "L" else None)
        for c, T in zip(colors, S["temps"]):
            RT = [r for r in R if r["T"] == T]
            for br in ("L", "T"):
                ax.plot(k, [0] + [r[br + "_qha"] for r in RT], "--", color=c, lw=1,
                        label=f"quasi-harmonic, {T}{S['tunit']}" if br == "L" else None)
                ax.errorbar([r["m"] / 8 for r in RT], [r[br + "_fit"] for r in RT],
                            yerr=[max(r[br + "_err"], 1e-9) for r in RT], fmt="o", ms=3.5,
                            color=c, label=f"MD (p = 0), {T}{S['tunit']}" if br == "L" else None)
        ax.set_xlabel("κ / κ_X along [100] (κ_X = 2π/a)")
        ax.set_ylabel(f"ω ({S['unit']})")
        ax.set_title({"lj": "fcc LJ (lj/cut 2.5), zero pressure",
                      "cu": "fcc Cu (EAM Cu_u3), zero pressure"}[sys_])
        ax.set_xlim(0, 1.02)
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=90)


if __name__ == "__main__":
    main()
