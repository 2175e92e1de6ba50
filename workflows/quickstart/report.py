#!/usr/bin/env python3
"""Write results/quickstart/report.md from the files the pipeline produced."""
import csv
import json
import os
import platform
import sys

out, elapsed = sys.argv[1], sys.argv[2]

os.chdir(out)
fc = json.load(open("forces_check.json"))
ins = json.load(open("inspect.json"))
e = {k: json.load(open(f"energy_{k}.json")) for k in ("delta", "hom", "res")}


def curves(path):
    rows = list(csv.DictReader(l for l in open(path) if not l.startswith("#")))  # `#`: units line
    return [(float(r["kappa"]), max(float(v) for c, v in r.items() if c.startswith("omega_"))) for r in rows]


def sheet_section(summary):
    """Flagship: the notched triangular LJ sheet (docs/flagship.md). Fills `summary` (stdout)."""
    import h5py
    import matplotlib
    import numpy as np

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fc2 = json.load(open("sheet/forces_check.json"))
    info = json.load(open("sheet/scene_info.json"))
    md = json.load(open("sheet/md_fracture.json"))
    tpd, tmd = json.load(open("sheet/pd_time.json")), json.load(open("sheet/md_time.json"))
    pd_wall, md_wall, pd_cpu, md_cpu = tpd["wall"], tmd["wall"], tpd["cpu"], tmd["cpu"]
    el = {k: json.load(open(f"sheet/elastic_{k}.json")) for k in ("perfect", "hom", "res")}
    C = el["perfect"]["C_voigt"]
    dC = max(abs(el[k]["C_voigt"][i][j] - C[i][j]) for k in ("hom", "res") for i in range(6) for j in range(6)) / C[0][0]

    # dispersion: in-plane branches (omega_2 = transverse, omega_3 = longitudinal; omega_1 is the
    # out-of-plane mode, zero for an in-plane 2D body)
    def disp(path):
        rows = list(csv.DictReader(l for l in open(path) if not l.startswith("#")))  # `#`: units
        return np.array([[float(r["kappa"]), float(r["omega_2"]), float(r["omega_3"])] for r in rows])

    D = {k: disp(f"sheet/dispersion_{k}.csv") for k in ("atoms", "eps2", "eps4", "res")}
    labels = {"atoms": "atoms (delta body)", "eps2": "rescaled ε = 2", "eps4": "rescaled ε = 4",
              "res": "homogenised + rescaled ε = 2 (solver model)"}
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for k, st in (("atoms", "k-"), ("eps2", "C0--"), ("eps4", "C1-."), ("res", "C2:")):
        ax.plot(D[k][:, 0], D[k][:, 2], st, label=labels[k])
        ax.plot(D[k][:, 0], D[k][:, 1], st)
    a0 = info["a0"]
    ax.set_xlabel("κ (1/σ), along x (Γ → K)")
    ax.set_ylabel("ω (1/τ)")
    ax.set_title("Triangular LJ sheet: LA (upper) and TA branches")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig("sheet_dispersion.png", dpi=110)
    plt.close(fig)

    # PD stress–strain from the reactions of the pulled grip
    rows = list(csv.DictReader(l for l in open("sheet/pd/reactions.csv") if not l.startswith("#")))
    t = np.array([float(r["t"]) for r in rows])
    fy = np.array([float(r["top_fy"]) for r in rows])
    broken = np.array([float(r["broken_bonds"]) for r in rows])
    pd_strain = t * info["strain_max"]
    pd_stress = fy / info["width"]
    ip = int(np.argmax(pd_stress))
    pd_peak, pd_crit = float(pd_stress[ip]), float(pd_strain[ip])
    mdd = np.loadtxt("sheet/md_stress_strain.txt")
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    ax.plot(mdd[:, 0], mdd[:, 1], "k-", lw=0.8, label=f"MD (LAMMPS), {md['atoms']} atoms")
    ax.plot(pd_strain, pd_stress, "C3o-", ms=3, label=f"PD (BA, Cauchy–Born), {info['points']} points")
    ax.set_xlabel("nominal strain Δ/L₀")
    ax.set_ylabel("nominal stress F/W (ε/σ²)")
    ax.set_title("Notched LJ sheet in tension")
    ax.legend()
    fig.tight_layout()
    fig.savefig("sheet_stress_strain.png", dpi=110)
    plt.close(fig)

    # damage field of the last PD step (deformed positions)
    last = sorted(f for f in os.listdir("sheet/pd") if f.startswith("results_") and f.endswith(".h5"))[-1]
    with h5py.File(os.path.join("sheet/pd", last), "r") as h:
        Y = h["fields/deformed_position"][:]
        dmg = h["fields/damage"][:]
    fig, ax = plt.subplots(figsize=(5.2, 4.6))
    sc = ax.scatter(Y[:, 0], Y[:, 1], c=dmg, s=18, cmap="inferno_r", vmin=0, vmax=1)
    fig.colorbar(sc, label="damage (broken fraction of the family)")
    ax.set_aspect("equal")
    ax.set_title(f"PD damage, strain {pd_strain[-1]:.3f} (deformed)")
    fig.tight_layout()
    fig.savefig("sheet_damage.png", dpi=110)
    plt.close(fig)

    # dispersion error of the coarse models per κ (LA branch, relative to the atoms)
    err_rows = []
    for i in range(6, len(D["atoms"]), 6):
        k, w = D["atoms"][i, 0], D["atoms"][i, 2]
        err_rows.append((k, w, *[D[m][i, 2] / w - 1 for m in ("eps2", "eps4", "res")]))
    t_phys = md["simulated_time"]
    # PD is quasi-static: it has no time of its own; it follows the same loading path
    # (strain 0 … strain_max) that MD covers in t_phys at its strain rate
    pd_t_phys = info["strain_max"] / md["strain_rate"]
    speed = (md_wall / t_phys) / (pd_wall / pd_t_phys)
    speed_cpu = (md_cpu / t_phys) / (pd_cpu / pd_t_phys)
    L = [
        "## 5. Flagship: a notched Lennard-Jones sheet from atoms to rupture",
        "2D triangular Lennard-Jones sheet (`atomistics/lj_sheet`, LAMMPS `dimension 2`, `lj/cut` 2.5σ, shifted);",
        f"zero-stress nearest-neighbour distance a0 = {a0:.6f}σ (LAMMPS `fix box/relax`). See docs/flagship.md.",
        "",
        "| check | value |",
        "|---|---|",
        f"| delta body forces vs LAMMPS, max \\|Δf\\| / max \\|f\\| ({fc2['atoms']} atoms, perturbed 0.03σ) | {fc2['max_norm_relative_error']:.2e} |",
        f"| Cauchy–Born C11, C12, C66 (ε/σ²) | {C[0][0]:.6g}, {C[0][1]:.6g}, {C[5][5]:.6g} |",
        f"| homogenised / rescaled (ε = 2) models: max \\|ΔC\\| / C11 | {dC:.1e} |",
        f"| critical bond stretch λ_c = r_infl / a0 (LJ inflection) | {info['critical_stretch']:.6f} |",
        "",
        "### Dispersion (upper in-plane branch along x): error of the coarse models against the atoms",
        "",
        "| κ (1/σ) | ω atoms | ε = 2 | ε = 4 | homogenised + ε = 2 |",
        "|---|---|---|---|---|",
    ]
    for k, w, e2, e4, er in err_rows:
        L.append(f"| {k:.3f} | {w:.5f} | {e2:+.2%} | {e4:+.2%} | {er:+.2%} |")
    L += [
        "",
        "![sheet dispersion](sheet_dispersion.png)",
        "",
        "### Fracture: BA solver with the Cauchy–Born material vs LAMMPS MD",
        "",
        "| | PD (quasi-static) | MD | PD / MD |",
        "|---|---|---|---|",
        f"| size | {info['points']} points (grid Δ = {info['spacing']:.4f}σ = {info['spacing'] / a0:.2f} a0) | {md['atoms']} atoms | |",
        f"| peak nominal stress (ε/σ²) | {pd_peak:.4f} | {md['peak_stress']:.4f} | {pd_peak / md['peak_stress']:.3f} |",
        f"| critical strain (at the peak) | {pd_crit:.4f} | {md['critical_strain']:.4f} | {pd_crit / md['critical_strain']:.3f} |",
        f"| broken PD bonds at the end | {int(broken[-1])} | | |",
        f"| wall time (s) | {pd_wall:.1f} | {md_wall:.1f} | {pd_wall / md_wall:.2f} |",
        f"| CPU time (s; PD on 2 threads, MD on 1 core) | {pd_cpu:.1f} | {md_cpu:.1f} | {pd_cpu / md_cpu:.2f} |",
        f"| simulated physical time (τ) | none (quasi-static; same path as MD: {pd_t_phys:.0f}) | {t_phys:.0f} ({md['steps']} steps of {md['timestep']}τ, strain rate {md['strain_rate']:g}/τ) | |",
        f"| speed-up of PD per unit simulated time, wall (CPU) | {speed:.2f}× ({speed_cpu:.2f}×) | | |",
        "",
        "![stress-strain](sheet_stress_strain.png)",
        "",
        "![damage](sheet_damage.png)",
        "",
        "![MD snapshots](sheet/md_fracture.png)",
        "",
        "Results: `sheet/pd/results.xdmf` (+ `results_NNNN.h5`, damage field), `sheet/pd/reactions.csv`,",
        "`sheet/md_stress_strain.txt`, `sheet/md_fracture.dump`. Interpretation: docs/flagship.md.",
        "",
    ]
    summary += [
        "",
        "================ pdcg flagship: notched LJ sheet, atoms → PD → rupture ================",
        f" forces, delta body vs LAMMPS:     max|Δf|/max|f| = {fc2['max_norm_relative_error']:.1e} ({fc2['atoms']} atoms)",
        " dispersion error (upper branch along x), coarse model (homogenised + rescaled ε = 2) per κ:",
        "   " + "  ".join(f"κ={k:.2f}: {er:+.1%}" for k, _, _, _, er in err_rows),
        "   rescaled ε = 4:  " + "  ".join(f"{e4:+.1%}" for _, _, _, e4, _ in err_rows),
        f" peak stress      PD {pd_peak:.3f}  MD {md['peak_stress']:.3f}  ratio PD/MD {pd_peak / md['peak_stress']:.2f}",
        f" critical strain  PD {pd_crit:.4f} MD {md['critical_strain']:.4f} ratio PD/MD {pd_crit / md['critical_strain']:.2f}",
        f" run time         PD {pd_wall:.1f} s wall / {pd_cpu:.1f} s CPU ({info['points']} points, quasi-static)",
        f"                  MD {md_wall:.1f} s wall / {md_cpu:.1f} s CPU ({md['atoms']} atoms, {md['steps']} steps, {md['simulated_time']:.0f} τ)",
        " per unit simulated time (same loading path at the MD strain rate "
        + f"{md['strain_rate']:g}/τ): PD is "
        + (f"{speed:.1f}× FASTER" if speed >= 1 else f"{1 / speed:.1f}× SLOWER")
        + " than MD in wall time, "
        + (f"{speed_cpu:.1f}× faster" if speed_cpu >= 1 else f"{1 / speed_cpu:.1f}× slower")
        + " in CPU time",
        "   why: at this size MD is cheap (1820 atoms, ~0.1 µs per atom-step) while every PD point costs",
        "   ~28 Cauchy–Born family evaluations with tangents per Newton iteration, a sparse direct solve,",
        "   and the crack needs ~60 staggered re-equilibrations. Quasi-static PD has no time scale: its",
        "   result holds for any slower loading, where MD cost grows ∝ 1/rate (docs/flagship.md).",
        "=======================================================================================",
    ]
    return L


atoms = curves("dispersion_atoms_100.csv")
lines = [
    "# pdcg quickstart report",
    "",
    f"Machine: {platform.machine()}, {os.cpu_count()} cores; pdcg stages took {elapsed} s.",
    "",
    "## 1. Atoms → delta PD body, checked against LAMMPS",
    f"FCC Lennard-Jones crystal, {ins['natoms']} atoms, periodic box "
    f"{ins['box']['hi'][0] - ins['box']['lo'][0]:.4f}σ, positions perturbed by up to 0.03σ "
    "(`atomistics/lj_fcc`, `lj/cut` 2.5σ with `pair_modify shift yes`).",
    "",
    "| check | value |",
    "|---|---|",
    f"| max \\|f_PD − f_LAMMPS\\| / max \\|f_LAMMPS\\| | {fc['max_norm_relative_error']:.2e} |",
    f"| largest MD force | {fc['max_force']:.4f} |",
    f"| \\|Σ_k f_k\\| (momentum balance) | {fc['net_force']:.1e} |",
    "",
    "The PD internal force f_k = Σ_j (t_kj − t_jk) with t_kj = ∂ψ_k/∂Y⟨ξ_kj⟩ equals the MD force to",
    "round-off (docs/theory.md §1).",
    "",
    "## 2. Homogenise and rescale: energy is conserved",
    f"Under F = [[1.02, 0.01, 0], [0, 0.99, 0], [0, 0, 1.01]]:",
    "",
    "| body | energy density | relative difference to atoms |",
    "|---|---|---|",
]
for k, name in (("delta", "atoms (delta body)"), ("hom", "homogenised (Wendland C2, width 2σ, grid 0.8σ)"),
                ("res", "homogenised + rescaled (ε = 4)")):
    rel = abs(e[k]["energy_density"] / e["delta"]["energy_density"] - 1)
    lines.append(f"| {name} | {e[k]['energy_density']:.12g} | {rel:.1e} |")
lines += [
    "",
    "## 3. Dispersion: what rescaling costs",
    "Along [100] (longitudinal branch): ω_ε(κ) = ω(εκ)/ε — long waves unchanged, short waves",
    "more dispersive. Error of the rescaled model against the atoms at each κ:",
    "",
    "| κa/2π | ω atoms | ω (ε = 2) | error (ε = 2) | ω (ε = 4) | error (ε = 4) |",
    "|---|---|---|---|---|---|",
]
r2, r4 = curves("dispersion_eps2.csv"), curves("dispersion_eps4.csv")
a = 1.5874010519681994
for i in range(0, len(atoms), 6):
    k, w = atoms[i]
    if w == 0:
        continue
    lines.append(f"| {k * a / (2 * 3.141592653589793):.3f} | {w:.5f} | {r2[i][1]:.5f} | {r2[i][1] / w - 1:+.2%} | "
                 f"{r4[i][1]:.5f} | {r4[i][1] / w - 1:+.2%} |")
lines += [
    "",
    "![dispersion](dispersion.png)",
    "",
    "![dispersion along a path](dispersion_path.png)",
    "",
]
if os.path.exists("plate/reactions.csv"):
    rows = list(csv.DictReader(l for l in open("plate/reactions.csv") if not l.startswith("#")))
    last = rows[-1]
    lines += ["## 4. Continuum: BA correspondence solver",
              f"Plate with a hole (plane strain Neo-Hookean), {len(rows)} load steps; final reactions: " +
              ", ".join(f"{k} = {float(v):.5g}" for k, v in last.items() if k not in ("step", "t")), ""]
summary = []
if os.path.exists("sheet/md_fracture.json") and os.path.exists("sheet/pd/reactions.csv"):
    lines += sheet_section(summary)
lines += ["## What is not in this run",
          "See docs/flagship.md (what is not done) and docs/status.md."]
open("report.md.tmp", "w").write("\n".join(lines) + "\n")
os.replace("report.md.tmp", "report.md")
if summary:
    print("\n".join(summary))
