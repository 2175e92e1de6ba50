"""Post-processing of pdcg rupture runs (docs/validation.md "Rubber sheet rupture").

Reads only what `pdcg run` writes (reactions.csv, results_NNNN.h5) and measures:
  * the load-displacement curve of the top grip, its peak and the drop after it;
  * where damage first appears (distance of the first damaged points from the pre-crack tip);
  * the crack path: per column of points past the tip, the damage-weighted centre line
    y_c(x) of the points whose damage exceeds a threshold, and the mean |y_c - y_crack|;
  * the mirror symmetry of the damage about the crack line (centre crack).
Independent of the solver: the Neo-Hookean energy of the uniaxial far field (plane stress,
lateral and thickness stretches from the traction-free conditions), for Rivlin-Thomas.
"""
import csv
import glob
import math
import os
import re

import h5py
import numpy as np

# A point is "on the crack" when at least this fraction of its family is broken: a point next to
# a straight crack through its family loses about half of its bonds, its neighbour one spacing
# further away a quarter or less (m = 3), so 0.25 keeps the two rows that flank the crack faces.
DAMAGE_ON_CRACK = 0.25


def read_reactions(run_dir):
    with open(os.path.join(run_dir, "reactions.csv")) as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith("#")))  # units line
    out = {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}
    return out


def result_files(run_dir):
    files = glob.glob(os.path.join(run_dir, "results_*.h5"))
    return sorted(files, key=lambda p: int(re.findall(r"(\d+)\.h5$", p)[0]))


def read_step(path):
    with h5py.File(path, "r") as h5:
        X = h5["points/reference"][:, :2]
        D = h5["fields/damage"][:] if "fields/damage" in h5 else np.zeros(len(X))
        t = float(h5.attrs["load_factor"])
        step = int(h5.attrs["step"])
    return {"X": X, "D": D, "t": t, "step": step}


def spacing(X):
    xs = np.unique(np.round(X[:, 0], 12))
    return float(np.min(np.diff(xs)))


def crack_path(X, D, h, y_line, x_from=None, x_to=None):
    """Per column x: damage-weighted y of the points with D >= DAMAGE_ON_CRACK.
    Returns arrays (x, y_c, n_points) over the columns that hold such points."""
    on = D >= DAMAGE_ON_CRACK
    cols = np.unique(np.round(X[on, 0] / h).astype(int))
    xs, ys, ns = [], [], []
    for c in cols:
        sel = on & (np.round(X[:, 0] / h).astype(int) == c)
        x = c * h
        if x_from is not None and x < x_from:
            continue
        if x_to is not None and x > x_to:
            continue
        w = D[sel]
        xs.append(float(np.mean(X[sel, 0])))
        ys.append(float(np.sum(w * X[sel, 1]) / np.sum(w)))
        ns.append(int(np.sum(sel)))
    return np.array(xs), np.array(ys), np.array(ns)


def mirror_asymmetry(X, D, y_line, h):
    """max |D(x, y) - D(x, 2 y_line - y)| over the points whose mirror image is a point."""
    key = {(int(round(x / h * 2)), int(round(y / h * 2))): i for i, (x, y) in enumerate(X)}
    worst = 0.0
    for i, (x, y) in enumerate(X):
        j = key.get((int(round(x / h * 2)), int(round((2 * y_line - y) / h * 2))))
        if j is not None:
            worst = max(worst, abs(D[i] - D[j]))
    return worst


def analyse(run_dir, tip, y_line, grip_length, grip="top", direction=+1, tip2=None):
    """Measures one run. tip: (x, y) of the pre-crack tip that grows in `direction` (+1: +x);
    tip2: the second tip of a centre crack (grows in -x). grip_length: reference distance
    between the grip rows (far-field stretch = 1 + u_top / grip_length)."""
    R = read_reactions(run_dir)
    files = result_files(run_dir)
    last = read_step(files[-1])
    X = last["X"]
    h = spacing(X)
    # load-displacement (grip displacement from the step's load factor via the scene)
    u = R["t"] * R["_grip_amplitude"] if "_grip_amplitude" in R else None
    F = R[f"{grip}_fy"]
    broken = R["broken_bonds"]
    ipk = int(np.argmax(F))
    res = {"dir": run_dir, "h": h, "t": R["t"], "force": F, "broken": broken,
           "peak_step": ipk, "peak_force": float(F[ipk]), "final_force": float(F[-1])}
    res["drop"] = 1.0 - float(F[-1]) / float(F[ipk]) if F[ipk] > 0 else float("nan")
    # first step with broken bonds
    first = next((k for k in range(len(broken)) if broken[k] > 0), None)
    res["first_break_step"] = first
    res["t_before_break"] = float(R["t"][first - 1]) if first else float("nan")
    res["t_first_break"] = float(R["t"][first]) if first is not None else float("nan")
    # damage of the first damaged output
    if first is not None:
        f1 = [p for p in files if read_step(p)["step"] == int(R["step"][first])]
        s1 = read_step(f1[0]) if f1 else None
        if s1 is not None:
            dm = s1["D"] > 0
            tips = [tip] + ([tip2] if tip2 is not None else [])
            dist = np.min([np.hypot(s1["X"][dm, 0] - tx, s1["X"][dm, 1] - ty) for tx, ty in tips],
                          axis=0)
            res["first_damage_points"] = int(np.sum(dm))
            res["first_damage_min_dist"] = float(np.min(dist))
            res["first_damage_max_dist"] = float(np.max(dist))
            res["first_damage_mean_dist"] = float(np.mean(dist))
    # crack path in the final state
    D = last["D"]
    if tip2 is None:
        xs, ys, ns = crack_path(X, D, h, y_line, x_from=tip[0])
    else:
        xs, ys, ns = crack_path(X, D, h, y_line)
        keep = (xs > tip[0]) | (xs < tip2[0])
        xs, ys, ns = xs[keep], ys[keep], ns[keep]
    res["path_x"], res["path_y"] = xs, ys
    if len(xs):
        dev = np.abs(ys - y_line)
        res["path_mean_dev"] = float(np.mean(dev))
        res["path_max_dev"] = float(np.max(dev))
        if tip2 is None:
            res["cracked_length"] = float(np.max(xs) - tip[0])
        else:
            res["cracked_length"] = float(max(np.max(xs) - tip[0], 0) + max(tip2[0] - np.min(xs), 0))
    else:
        res["path_mean_dev"] = res["path_max_dev"] = float("nan")
        res["cracked_length"] = 0.0
    res["mirror_asymmetry"] = mirror_asymmetry(X, D, y_line, h)
    res["X"], res["D"] = X, D
    return res


# ---- independent reference: Neo-Hookean plane-stress uniaxial tension ----------------------
def psi(l1, l2, l3, mu, K):
    """Psi = mu/2 (J^(-2/3) tr C - 3) + K/8 (J - 1/J)^2 (docs/theory.md §8)."""
    J = l1 * l2 * l3
    return 0.5 * mu * (J ** (-2.0 / 3.0) * (l1 * l1 + l2 * l2 + l3 * l3) - 3.0) + \
        K / 8.0 * (J - 1.0 / J) ** 2


def uniaxial(lam, mu=1.0, K=100.0):
    """Far field of a sheet in uniaxial tension: lateral = thickness stretch f from
    dPsi/df = 0 (both free, equal by isotropy), by bisection on a central difference.
    Returns (f, W, nominal stress dW/dlam)."""
    def dpsi_df(f, e=1e-7):
        return (psi(lam, f + e, f + e, mu, K) - psi(lam, f - e, f - e, mu, K)) / (2 * e)
    lo, hi = 0.2, 1.2
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if dpsi_df(mid) > 0:
            hi = mid
        else:
            lo = mid
    f = 0.5 * (lo + hi)
    W = psi(lam, f, f, mu, K)
    e = 1e-6
    def Wof(l):
        return uniaxial_W_only(l, mu, K)
    return f, W, (Wof(lam + e) - Wof(lam - e)) / (2 * e)


def uniaxial_W_only(lam, mu, K):
    def dpsi_df(f, e=1e-7):
        return (psi(lam, f + e, f + e, mu, K) - psi(lam, f - e, f - e, mu, K)) / (2 * e)
    lo, hi = 0.2, 1.2
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if dpsi_df(mid) > 0:
            hi = mid
        else:
            lo = mid
    f = 0.5 * (lo + hi)
    return psi(lam, f, f, mu, K)


def rivlin_thomas_T(lam, c, mu=1.0, K=100.0):
    """Tearing energy of an edge crack of length c at far-field stretch lam:
    T = 2 k(lam) W(lam) c, k = pi / sqrt(lam) (Rivlin & Thomas 1953; Greensmith 1963)."""
    return 2.0 * math.pi / math.sqrt(lam) * uniaxial_W_only(lam, mu, K) * c
