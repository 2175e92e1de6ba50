#!/usr/bin/env python3
"""Checks the dispersion workflow's CSVs against the closed forms and draws dispersion.png.

usage: check_and_plot.py OUT_DIR

Closed forms (written here, independent of pdcg): chain with springs μ₁ = 1, μ₂, M = h = 1,
    ω(κ) = sqrt(2[(1 − cos κ) + μ₂(1 − cos 2κ)]),   rescaled by ε: ω_ε(κ) = ω(εκ)/ε.
Tolerances (each with its reason):
    model vs closed form        1e-12 absolute (the same formula up to round-off)
    measured ridge vs closed    1 frequency bin Δω = 2π/(T Δt) (the transform's resolution)
    FCC LJ vs LAMMPS LD         1e-5 · ω_max (central differences of LAMMPS forces, step 1e-4σ)
    FCC LJ ε = 16 vs delta      ω₁₆(κ/16)·16 = ω(κ) to 1e-12 relative, ω² finite and ≥ 0
Writes OUT_DIR/errors.csv, OUT_DIR/acceptance.json, OUT_DIR/dispersion.png; exits 1 on a miss.
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

KERNELS = ["top-hat", "gaussian", "cubic-bspline", "wendland-c2"]


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith("#")))  # `#`: units line
    return {c: [float(r[c]) for r in rows] for c in rows[0]}


def chain_omega(k, mu2):
    return math.sqrt(2 * (1 - math.cos(k)) + 2 * mu2 * (1 - math.cos(2 * k)))


def main(out):
    results = []  # (case, reference, worst, tolerance, unit)
    fig, axes = plt.subplots(1, 3, figsize=(16, 5.8))
    for ax, mu2 in zip(axes[:2], (0.0, 0.25)):
        d = os.path.join(out, f"chain_mu2_{mu2:g}")
        tag = f"chain μ₂={mu2:g}"
        models = [("delta", "model_delta.csv", 1)] + [(f"homogenised {k}", f"model_hom_{k}.csv", 1) for k in KERNELS]
        models += [("rescaled ε=2", "model_res_2.csv", 2), ("rescaled ε=4", "model_res_4.csv", 4),
                   ("homogenised wendland-c2, rescaled ε=4", "model_hom_res_4.csv", 4)]
        curves = {}
        for name, f, eps in models:
            c = read(os.path.join(d, f))
            # longitudinal branch = the largest; the transverse ones are zero (no tension)
            w = c["omega_3"]
            worst = max(abs(wi - chain_omega(eps * k, mu2) / eps) for k, wi in zip(c["kappa"], w))
            worst_t = max(max(abs(x) for x in c["omega_1"]), max(abs(x) for x in c["omega_2"]))
            results.append((f"{tag}: {name}", "closed form ω(εκ)/ε" if eps > 1 else "closed form ω(κ)",
                            max(worst, worst_t), 1e-12, "abs"))
            curves[name] = (c["kappa"], w)
        # reference values of the closed forms
        k, w = curves["delta"]
        at_pi = w[k.index(max(k))]
        k2, w2 = curves["rescaled ε=2"]
        i2 = min(range(len(k2)), key=lambda i: abs(k2[i] - math.pi / 2))
        results.append((f"{tag}: delta ω(π)", f"{chain_omega(math.pi, mu2):.6f}", abs(at_pi - chain_omega(math.pi, mu2)), 1e-12, "abs"))
        results.append((f"{tag}: ε=2 ω(π/2)", f"{chain_omega(math.pi, mu2) / 2:.6f}", abs(w2[i2] - chain_omega(math.pi, mu2) / 2), 1e-12, "abs"))
        # measured ridges, in frequency bins
        meas = {}
        for name, f, eps in (("LAMMPS MD", "measured_lammps.csv", 1), ("pdcg md, ε=2 body", "measured_md_res_2.csv", 2)):
            c = read(os.path.join(d, f))
            bins = max(abs(w - chain_omega(eps * k, mu2) / eps) / r for k, w, r in zip(c["kappa"], c["omega"], c["resolution"]))
            results.append((f"{tag}: measured ridge, {name} ({len(c['kappa'])} κ)", "closed form", bins, 1.0, "bins"))
            meas[name] = c

        kk = [math.pi * i / 400 for i in range(401)]
        ax.plot(kk, [chain_omega(k, mu2) for k in kk], color="0.6", lw=5, alpha=0.5, label="closed form ω(κ), ω(εκ)/ε")
        for eps in (2, 4):
            ax.plot(kk, [chain_omega(eps * k, mu2) / eps for k in kk], color="0.6", lw=5, alpha=0.5)
        ax.plot(*curves["delta"], "-", color="C0", lw=1.5, label="atomistic (delta body)")
        for i, (kname, m) in enumerate(zip(KERNELS, "os^D")):
            k, w = curves[f"homogenised {kname}"]
            ax.plot(k[i::4], w[i::4], m, ms=4, mfc="none", color=f"C{i + 1}", label=f"homogenised, {kname}")
        ax.plot(*curves["rescaled ε=2"], "--", color="C5", lw=1.5, label="rescaled ε = 2")
        ax.plot(*curves["rescaled ε=4"], "-.", color="C6", lw=1.5, label="rescaled ε = 4")
        k, w = curves["homogenised wendland-c2, rescaled ε=4"]
        ax.plot(k[2::4], w[2::4], "x", ms=4, color="C6", label="homogenised + rescaled ε = 4")
        c = meas["LAMMPS MD"]
        ax.errorbar(c["kappa"], c["omega"], yerr=c["resolution"], fmt="o", ms=5, color="k", mfc="none",
                    capsize=2, label="measured, LAMMPS MD (±1 bin)")
        c = meas["pdcg md, ε=2 body"]
        ax.errorbar(c["kappa"], c["omega"], yerr=c["resolution"], fmt="v", ms=5, color="C5", mfc="none",
                    capsize=2, label="measured, pdcg md of ε = 2 (±1 bin)")
        for eps in (2, 4):
            ax.axvline(math.pi / eps, color="0.8", ls=":", lw=1)
        ax.set_xlim(0, math.pi)
        ax.set_xlabel("κ (1/h)")
        ax.set_ylabel("ω (√(μ/M))")
        ax.set_title(f"1D chain μ₁ = 1, μ₂ = {mu2:g} (zone edges π/ε dotted)")
        ax.grid(alpha=0.3)

    # FCC LJ
    d = os.path.join(out, "fcc_lj")
    m, ld, r16 = (read(os.path.join(d, f)) for f in ("model_delta.csv", "lammps_ld.csv", "model_res_16.csv"))
    wmax = max(max(ld[f"omega_{b}"]) for b in (1, 2, 3))
    worst = max(abs(m[f"omega_{b}"][i] - ld[f"omega_{b}"][i]) for b in (1, 2, 3) for i in range(len(m["kappa"])))
    results.append(("FCC LJ delta body, G-X-W-L-G-K (3 branches)", "LAMMPS lattice dynamics", worst / wmax, 1e-5, "rel. to ω_max"))
    w16 = [16 * r16[f"omega_{b}"][i] for b in (1, 2, 3) for i in range(len(m["kappa"]))]
    w1 = [m[f"omega_{b}"][i] for b in (1, 2, 3) for i in range(len(m["kappa"]))]
    finite = all(math.isfinite(x) and x >= 0 for x in w16)
    results.append(("FCC LJ rescaled ε=16: 16·ω₁₆(κ/16), path incl. zone edges X, W, L, K", "delta body ω(κ)",
                    max(abs(a - b) for a, b in zip(w16, w1)) / wmax if finite else float("inf"), 1e-12, "rel. to ω_max"))
    ax = axes[2]
    labels = ["Γ", "X", "W", "L", "Γ", "K"]
    ticks = [m["kappa"][20 * i] for i in range(6)]
    for b in (1, 2, 3):
        ax.plot(m["kappa"], m[f"omega_{b}"], "-", color="C0", lw=1.5, label="pdcg delta body" if b == 1 else None)
        ax.plot(ld["kappa"], ld[f"omega_{b}"], "o", ms=3.5, mfc="none", color="k",
                label="LAMMPS lattice dynamics (FD forces)" if b == 1 else None)
        ax.plot(m["kappa"], w16[(b - 1) * len(m["kappa"]):b * len(m["kappa"])], ":", color="C3", lw=1.5,
                label="16·ω of the ε = 16 body at κ/16" if b == 1 else None)
    for t in ticks:
        ax.axvline(t, color="0.8", lw=0.8)
    ax.set_xticks(ticks, labels)
    ax.set_xlim(ticks[0], ticks[-1])
    ax.set_ylabel("ω (LJ units)")
    ax.set_title("FCC Lennard-Jones (lj/cut 2.5σ, ρ* = 1)")
    ax.grid(alpha=0.3, axis="y")
    h0, l0 = axes[0].get_legend_handles_labels()
    h2, l2 = ax.get_legend_handles_labels()
    fig.legend(h0 + h2, l0 + ["FCC: " + t for t in l2], loc="lower center", ncol=5, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.17, 1, 1))
    fig.savefig(os.path.join(out, "dispersion.png"), dpi=110)

    ok = True
    with open(os.path.join(out, "errors.csv"), "w") as f:
        f.write("case,reference,worst_error,tolerance,unit,pass\n")
        for case, ref, worst, tol, unit in results:
            p = math.isfinite(worst) and worst <= tol
            ok &= p
            f.write(f'"{case}","{ref}",{worst:.3e},{tol:g},{unit},{int(p)}\n')
            print(f"  {'ok  ' if p else 'FAIL'} {case}: {worst:.3e} {unit} (tolerance {tol:g}) vs {ref}")
    json.dump([dict(case=c, reference=r, worst=w, tolerance=t, unit=u) for c, r, w, t, u in results],
              open(os.path.join(out, "acceptance.json"), "w"), indent=1)
    print(f"  -> {out}/dispersion.png, errors.csv, acceptance.json")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
