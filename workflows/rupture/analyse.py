#!/usr/bin/python3
"""Rubber-sheet rupture study (docs/validation.md §3): tables and plots from the runs of run.sh.

usage: analyse.py OUT IMGDIR
  OUT/edge       edge pre-crack c = 0.3 (the main case)
  OUT/centre     centre pre-crack 2c = 1/3
  OUT/edge_cNNN  edge pre-crack of length NNN/1000 (Rivlin-Thomas study)
Writes OUT/summary.txt, IMGDIR/rupture_load_displacement.png, IMGDIR/rupture_damage.png,
IMGDIR/rupture_rivlin_thomas.png.
"""
import glob
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rupture_lib as L  # noqa: E402

OUT, IMG = sys.argv[1], sys.argv[2]
os.makedirs(IMG, exist_ok=True)
def grip_u_of(run_dir):
    """u_y(t) of the top grip, read from the run's scene.resolved.yaml (0 at t = 0: the
    unloaded state of row 0 of reactions.csv)."""
    expr = None
    for line in open(os.path.join(run_dir, "scene.resolved.yaml")):
        m = re.search(r"name: top,.*displacement: \{y: \"?([^}\"]*)\"?\}", line)
        if m:
            expr = m.group(1).replace("^", "**")
    return lambda t: np.where(t > 0, eval(expr, {"t": np.asarray(t, float), "sqrt": np.sqrt,
                                                 "pi": np.pi}), 0.0)


lines = []


def say(s=""):
    print(s)
    lines.append(s)


def grip_length(h):
    return 1.0 - h  # distance between the rows of cell centres of the two grips


runs = {}
if os.path.isdir(os.path.join(OUT, "edge")):
    runs["edge"] = L.analyse(os.path.join(OUT, "edge"), tip=(0.3, 0.5), y_line=0.5,
                             grip_length=None)
if os.path.isdir(os.path.join(OUT, "edge_path2")):
    runs["edge_path2"] = L.analyse(os.path.join(OUT, "edge_path2"), tip=(0.3, 0.5), y_line=0.5,
                                   grip_length=None)
if os.path.isdir(os.path.join(OUT, "centre")):
    runs["centre"] = L.analyse(os.path.join(OUT, "centre"), tip=(2.0 / 3.0, 0.5), y_line=0.5,
                               grip_length=None, tip2=(1.0 / 3.0, 0.5))

say("# Rubber sheet rupture (plane stress Neo-Hookean mu = 1, K = 100, bond_stretch 2.0)")
for name, r in runs.items():
    h = r["h"]
    lam = 1 + grip_u_of(r["dir"])(r["t"]) / grip_length(h)
    say(f"\n## {name}: {os.path.abspath(r['dir'])}")
    say(f"spacing h = {h:.4g}, horizon delta = {3.015 * h:.4g}, steps written = {len(r['t']) - 1}, "
        f"last load factor = {r['t'][-1]:.4g} (stretch {lam[-1]:.4f})")
    if r["first_break_step"] is not None:
        k = r["first_break_step"]
        say(f"first broken bonds at step {k}: stretch in ({lam[k - 1]:.4f}, {lam[k]:.4f}]; "
            f"{r.get('first_damage_points', 0)} damaged points, distance from the tip "
            f"min {r.get('first_damage_min_dist', float('nan')):.4f} max "
            f"{r.get('first_damage_max_dist', float('nan')):.4f} (delta = {3.015 * h:.4f})")
    else:
        say("no bond broke")
    say(f"peak load {r['peak_force']:.5g} at step {r['peak_step']} (stretch {lam[r['peak_step']]:.4f}); "
        f"last load {r['final_force']:.5g}: drop {100 * r['drop']:.1f}% of the peak")
    say(f"crack path (columns with damage >= {L.DAMAGE_ON_CRACK}): cracked length "
        f"{r['cracked_length']:.4f}, mean |y_c - 0.5| = {r['path_mean_dev']:.2e}, "
        f"max {r['path_max_dev']:.2e} (h = {h:.4g})")
    say(f"mirror asymmetry of the damage about y = 0.5: max |D(x,y) - D(x,1-y)| = "
        f"{r['mirror_asymmetry']:.3f}")

# ---- load-displacement -------------------------------------------------------------------
if runs:
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for name, r in runs.items():
        lam = 1 + grip_u_of(r["dir"])(r["t"]) / grip_length(r["h"])
        ax.plot(lam, r["force"], "o-", ms=3, label=f"{name} pre-crack")
        if r["first_break_step"] is not None:
            k = r["first_break_step"]
            ax.axvline(lam[k], color=ax.lines[-1].get_color(), lw=0.6, ls=":")
    for d in [d for d in sorted(glob.glob(os.path.join(OUT, "edge_c*"))) if os.path.isdir(d)]:
        R = L.read_reactions(d)
        h = L.spacing(L.read_step(L.result_files(d)[0])["X"])
        ax.plot(1 + grip_u_of(d)(R["t"]) / grip_length(h), R["top_fy"], "-", lw=0.8,
                label=f"edge c = {int(d[-3:]) / 1000:.2f}")
    ax.set_xlabel("grip stretch  1 + u_top / L")
    ax.set_ylabel("top grip force (per unit thickness)")
    ax.set_title("Rubber sheet, bond stretch 2.0: load vs. grip stretch")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, "rupture_load_displacement.png"), dpi=120)

# ---- damage maps -------------------------------------------------------------------------
if runs:
    fig, axes = plt.subplots(len(runs), 3, figsize=(10, 3.3 * len(runs)), squeeze=False)
    for row, (name, r) in enumerate(runs.items()):
        files = L.result_files(r["dir"])
        steps = [L.read_step(f) for f in files]
        k1 = r["first_break_step"] if r["first_break_step"] is not None else steps[-1]["step"]
        picks = [s for s in steps if s["step"] == k1][:1] + \
            [steps[len(steps) // 2 + (len(steps) - 1) // 4]] + [steps[-1]]
        picks = [s for s in steps if s["step"] >= k1]
        sel = [picks[0], picks[len(picks) // 2], picks[-1]] if picks else [steps[-1]] * 3
        for col, s in enumerate(sel):
            ax = axes[row][col]
            sc = ax.scatter(s["X"][:, 0], s["X"][:, 1], c=s["D"], s=9, cmap="inferno_r", vmin=0,
                            vmax=0.6, marker="s")
            ax.set_aspect("equal")
            ax.set_title(f"{name}: step {s['step']}, t = {s['t']:.3g}", fontsize=9)
            ax.set_xticks([0, 0.5, 1])
            ax.set_yticks([0, 0.5, 1])
        fig.colorbar(sc, ax=axes[row].tolist(), shrink=0.8, label="damage")
    fig.savefig(os.path.join(IMG, "rupture_damage.png"), dpi=120)

# ---- Rivlin-Thomas -----------------------------------------------------------------------
rt = []
for d in [d for d in sorted(glob.glob(os.path.join(OUT, "edge_c*"))) if os.path.isdir(d)]:
    c = int(d[-3:]) / 1000.0
    R = L.read_reactions(d)
    h = L.spacing(L.read_step(L.result_files(d)[0])["X"])
    k = next((i for i in range(len(R["t"])) if R["broken_bonds"][i] > 0), None)
    if k is None:
        say(f"\nedge c = {c}: no bond broke up to t = {R['t'][-1]}")
        continue
    lam_lo = 1 + grip_u_of(d)(R["t"][k - 1]) / grip_length(h)
    lam_hi = 1 + grip_u_of(d)(R["t"][k]) / grip_length(h)
    # the peak load marks the onset of running growth (the first bonds break stably)
    kp = int(np.argmax(R["top_fy"]))
    lam_pk = 1 + grip_u_of(d)(R["t"][kp]) / grip_length(h)
    lam_c = 0.5 * (lam_lo + lam_hi)
    rt.append((c, lam_lo, lam_hi, lam_c, L.rivlin_thomas_T(lam_c, c), lam_pk,
               L.rivlin_thomas_T(lam_pk, c), kp == len(R["t"]) - 1))
if rt:
    say("\n## Rivlin-Thomas: T = 2 k(lam) W(lam) c, k = pi/sqrt(lam), W of the uniaxial far field")
    say("| c | initiation stretch | T at initiation | stretch at peak load | T at peak |")
    say("|---|---|---|---|---|")
    for c, lo, hi, lc, T, lp, Tp, last in rt:
        say(f"| {c:.2f} | {lo:.4f} … {hi:.4f} | {T:.4f} | {lp:.4f}{' (last step)' if last else ''} "
            f"| {Tp:.4f} |")
    Ts = np.array([x[4] for x in rt])
    Tp = np.array([x[6] for x in rt])
    say(f"T at initiation: mean {Ts.mean():.4f}, spread (max-min)/mean {np.ptp(Ts) / Ts.mean():.2%}")
    say(f"T at peak load:  mean {Tp.mean():.4f}, spread (max-min)/mean {np.ptp(Tp) / Tp.mean():.2%}")
    fig, ax = plt.subplots(figsize=(5, 3.6))
    cs = np.array([x[0] for x in rt])
    ax.errorbar(cs, [x[3] for x in rt], yerr=[[x[3] - x[1] for x in rt], [x[2] - x[3] for x in rt]],
                fmt="o", label="initiation (pdcg)")
    ax.plot(cs, [x[5] for x in rt], "s", label="peak load (pdcg)")
    cc = np.linspace(cs.min() * 0.8, cs.max() * 1.2, 50)
    T0 = Ts.mean()
    lam_pred = []
    for c in cc:  # stretch at which 2kWc = T0 (bisection; T grows with lam)
        lo, hi = 1.0 + 1e-9, 4.0
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if L.rivlin_thomas_T(mid, c) < T0 else (lo, mid)
        lam_pred.append(0.5 * (lo + hi))
    ax.plot(cc, lam_pred, "-", lw=0.8, label=f"Rivlin-Thomas, T = {T0:.3f}")
    ax.set_xlabel("edge crack length c")
    ax.set_ylabel("critical grip stretch")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(IMG, "rupture_rivlin_thomas.png"), dpi=120)

with open(os.path.join(OUT, "summary.txt"), "w") as f:
    f.write("\n".join(lines) + "\n")
