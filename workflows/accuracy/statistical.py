#!/usr/bin/env python3
"""Energy error of statistical densities versus cubature order / sample count, with time.

usage: PDCG=/path/to/pdcg statistical.py OUT_DIR   (OUT_DIR holds fcc256.data)

Two cases (CASES): the quickstart potential, whose cutoff sits on the 5th fcc shell (the shifted
energy is continuous but its derivative jumps at r_c inside the atoms' Gaussians), and a cutoff
placed mid-gap between shells with narrower Gaussians (the kink lies 4.6 standard deviations out). For
each Gauss–Hermite order n (ORDERS) and sample count S (SAMPLES, SEEDS seeds each, the seed set
in the body file's statistics/seed attribute) it builds the statistical body with
`pdcg atoms2pd --density statistical --width σ` and evaluates `pdcg energy --F I --json`;
error = |E/N − E_ref/N| with E_ref from a high order (24 resp. 16; the reference's own error is
estimated by fitting C(n^−p − n_ref^−p) to the four highest orders). Time = best of 3 wall times of
`pdcg energy` (one thread), which includes process start and reading the body; the delta body's
time is given as that floor. The reference is checked against a NumPy Monte-Carlo estimate
(MC_SAMPLES joint draws; independent of pdcg) within 4 standard errors, and against order 12.
Writes statistical.csv, statistical.json and statistical.png into OUT_DIR.
"""
import json
import math
import os
import subprocess
import sys
import time

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt

PDCG = os.environ["PDCG"]
ORDERS = [int(x) for x in os.environ.get("ORDERS", "1 2 3 4 5 6 8 10 12").split()]
SAMPLES = [int(x) for x in os.environ.get("SAMPLES", "16 64 256 1024 4096").split()]
SEEDS = int(os.environ.get("SEEDS", "4"))
MC_SAMPLES = int(os.environ.get("MC_SAMPLES", "4000"))
SKIN = 3.0  # family radius: pairs just outside r_c = 2.5 (5th shell at 2.51) that fluctuate inside count
ENV = dict(os.environ, OMP_NUM_THREADS="1")
IDENTITY = "1 0 0 0 1 0 0 0 1"


def run(args):
    subprocess.run([PDCG, "-q", *args], check=True, env=ENV, stdout=subprocess.DEVNULL)


def build(d, data, pot, name, extra):
    path = os.path.join(d, name)
    run(["atoms2pd", "--input", data, "--potential", pot, "--family-cutoff", str(SKIN), "-o", path, *extra])
    return path


def energy(body, repeat=3):
    best, e = math.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = subprocess.run([PDCG, "-q", "energy", body, "--F", IDENTITY, "--json"], check=True, env=ENV,
                           capture_output=True, text=True)
        best = min(best, time.perf_counter() - t0)
        e = json.loads(r.stdout)["energy"]
    return e, best


def numpy_reference(data, samples, sigma, rc=2.5, seed=2024):
    """E[U]/N by plain Monte Carlo: U = Σ_{i<j} φ(|x_j − x_i|) (minimum image), φ = LJ − LJ(r_c)."""
    lines = open(data).read().splitlines()
    lo_hi = [l.split() for l in lines if l.endswith("xlo xhi")][0]
    L = float(lo_hi[1]) - float(lo_hi[0])
    i = lines.index("Atoms # atomic")
    x0 = []
    for l in lines[i + 2:]:
        f = l.split()
        if len(f) < 5:
            break
        x0.append([float(f[2]), float(f[3]), float(f[4])])
    x0 = np.array(x0)
    n = len(x0)
    assert L > 2 * rc, "minimum image needs a box larger than 2 r_c"
    phic = 4 * (rc ** -12 - rc ** -6)
    rng = np.random.default_rng(seed)
    vals = []
    iu = np.triu_indices(n, 1)
    for start in range(0, samples, 20):
        m = min(20, samples - start)
        x = x0[None] + sigma * rng.standard_normal((m, n, 3))
        d = x[:, iu[1], :] - x[:, iu[0], :]  # m, pairs, 3
        d -= L * np.round(d / L)
        r2 = np.einsum("...k,...k->...", d, d)
        inside = r2 < rc * rc
        inv6 = np.where(inside, 1.0 / np.where(inside, r2, 1.0) ** 3, 0.0)
        phi = np.where(inside, 4 * (inv6 * inv6 - inv6) - phic, 0.0)
        vals.append(phi.sum(axis=1) / n)
    v = np.concatenate(vals)
    return v.mean(), v.std(ddof=1) / math.sqrt(len(v)), n


CASES = [
    # name, cutoff r_c, σ, reference order
    ("kink", "lj/cut 2.5σ shifted (atomistics/lj_fcc), σ = 0.06σ: 5th shell (2.51σ) on r_c", 2.5, 0.06, 24),
    ("smooth", "lj/cut 2.38σ shifted, σ = 0.02σ: r_c mid-gap, 4.6 σ_rel from the shells", 2.38, 0.02, 16),
]


def fit_reference_error(rows, ref_order):
    """e(n) = |E(n) − E(ref)| = C (n^−p − ref^−p) over the four highest orders -> C ref^−p."""
    from scipy.optimize import curve_fit

    r = [x for x in rows if x["method"] == "cubature"][-4:]
    n = np.array([x["parameter"] for x in r], float)
    e = np.array([x["error"] for x in r])
    try:
        (C, p), _ = curve_fit(lambda n, C, p: C * (n ** -p - ref_order ** -p), n, e, p0=(e[0] * n[0] ** 2, 2.0), maxfev=20000)
        return float(C * ref_order ** -p), float(p)
    except Exception:
        return float("nan"), float("nan")


def run_case(out, key, title, rc, sigma, ref_order):
    d = os.path.join(out, key)
    os.makedirs(d, exist_ok=True)
    pot = os.path.join(d, "potential.lj")
    with open(pot, "w") as f:
        f.write(f"pair_style lj/cut {rc}\npair_coeff 1 1 1.0 1.0 {rc}\npair_modify shift yes\n")
    data = os.path.join(out, "fcc256.data")
    n = 256
    rows = []
    stat = ["--density", "statistical", "--width", str(sigma)]
    e_delta, t_delta = energy(build(d, data, pot, "delta.h5", []))
    e_ref, t_ref = energy(build(d, data, pot, f"order{ref_order}.h5", [*stat, "--order", str(ref_order)]), repeat=1)
    e_ref /= n
    print(f"== {title}: reference order {ref_order}: E/N = {e_ref:.12f} ({t_ref:.2f} s)")
    for order in ORDERS:
        e, t = energy(build(d, data, pot, f"order{order}.h5", [*stat, "--order", str(order)]))
        rows.append(dict(case=key, method="cubature", parameter=order, evaluations=order ** 3, seeds=1,
                         energy_per_atom=e / n, error=abs(e / n - e_ref), time_s=t))
        print(f"  cubature order {order:2d}: E/N = {e / n:.12f}, error {rows[-1]['error']:.2e}, {t:.3f} s")
    for s_ in SAMPLES:
        b = build(d, data, pot, f"samples{s_}.h5", [*stat, "--samples", str(s_)])
        errs, times, es = [], [], []
        for seed in range(SEEDS):
            with h5py.File(b, "r+") as f:
                f["statistics"].attrs["seed"] = np.uint64(1000 + 7919 * seed)
            e, t = energy(b, repeat=1)
            es.append(e / n)
            errs.append(e / n - e_ref)
            times.append(t)
        rms = math.sqrt(sum(x * x for x in errs) / len(errs))
        rows.append(dict(case=key, method="sampling", parameter=s_, evaluations=s_, seeds=SEEDS,
                         energy_per_atom=float(np.mean(es)), error=rms, time_s=float(np.median(times))))
        print(f"  sampling S = {s_:5d}: rms error over {SEEDS} seeds {rms:.2e}, rms·√S = {rms * math.sqrt(s_):.2f}, "
              f"{np.median(times):.3f} s")
    for f in os.listdir(d):
        if f.endswith(".h5"):
            os.remove(os.path.join(d, f))
    mc, mc_se, _ = numpy_reference(data, MC_SAMPLES, sigma, rc)
    ref_err, p = fit_reference_error(rows, ref_order)
    check = dict(case=key, title=title, cutoff=rc, sigma=sigma, reference_order=ref_order,
                 reference_energy_per_atom=e_ref, reference_time_s=t_ref, reference_error_estimate=ref_err,
                 cubature_rate=p, delta_energy_per_atom=e_delta / n, delta_time_s=t_delta,
                 numpy_mc_energy_per_atom=mc, numpy_mc_standard_error=mc_se, numpy_mc_samples=MC_SAMPLES,
                 numpy_mc_deviation_in_se=abs(mc - e_ref) / mc_se)
    print(f"  NumPy MC ({MC_SAMPLES} samples) {mc:.6f} ± {mc_se:.1e}: {check['numpy_mc_deviation_in_se']:.2f} "
          f"standard errors from the reference; fitted cubature rate n^-{p:.2f}, reference error ≈ {ref_err:.1e}; "
          f"delta body {t_delta:.3f} s")
    best = math.inf
    for r in sorted(rows, key=lambda r: (r["time_s"], r["error"])):
        r["pareto"] = int(r["error"] < best)
        best = min(best, r["error"])
    return rows, check


def main(out):
    allrows, checks = [], []
    fig, axes = plt.subplots(2, 2, figsize=(12, 9))
    for (key, title, rc, sigma, ref_order), (a1, a2) in zip(CASES, axes):
        rows, check = run_case(out, key, title, rc, sigma, ref_order)
        allrows += rows
        checks.append(check)
        cub = [r for r in rows if r["method"] == "cubature"]
        smp = [r for r in rows if r["method"] == "sampling"]
        floor = 1e-16
        a1.loglog([r["parameter"] ** 3 for r in cub], [max(r["error"], floor) for r in cub], "o-",
                  label="Gauss–Hermite, n³ nodes per bond")
        a1.loglog([r["parameter"] for r in smp], [r["error"] for r in smp], "s-",
                  label=f"sampling, S draws (rms of {SEEDS} seeds)")
        s0 = smp[0]
        a1.loglog([r["parameter"] for r in smp], [s0["error"] * math.sqrt(s0["parameter"] / r["parameter"]) for r in smp],
                  ":", color="0.5", label="∝ S^(−1/2)")
        if math.isfinite(check["reference_error_estimate"]):
            a1.axhline(abs(check["reference_error_estimate"]), color="C3", ls=":", lw=1,
                       label=f"estimated error of the reference (order {ref_order})")
        for r in cub:
            a1.annotate(str(r["parameter"]), (r["parameter"] ** 3, max(r["error"], floor)), fontsize=7, xytext=(3, 3),
                        textcoords="offset points")
        a1.set_xlabel("evaluations per bond (n³ or S)")
        a1.set_ylabel("|E/N − E_ref/N| (ε)")
        a1.set_title(title, fontsize=9)
        a1.grid(alpha=0.3, which="both")
        a1.legend(fontsize=7)
        a2.loglog([r["time_s"] for r in cub], [max(r["error"], floor) for r in cub], "o-", label="Gauss–Hermite")
        a2.loglog([r["time_s"] for r in smp], [r["error"] for r in smp], "s-", label="sampling")
        par = [r for r in sorted(rows, key=lambda r: r["time_s"]) if r["pareto"]]
        a2.loglog([r["time_s"] for r in par], [max(r["error"], floor) for r in par], "k--", lw=0.8, label="Pareto front")
        a2.axvline(check["delta_time_s"], color="0.6", ls=":", label="delta body (start + read floor)")
        a2.set_xlabel("wall time of `pdcg energy` (s, 1 thread)")
        a2.set_ylabel("|E/N − E_ref/N| (ε)")
        a2.set_title("accuracy against cost (FCC LJ, 256 atoms)", fontsize=9)
        a2.grid(alpha=0.3, which="both")
        a2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "statistical.png"), dpi=110)
    with open(os.path.join(out, "statistical.csv"), "w") as f:
        f.write("case,method,parameter,evaluations_per_bond,seeds,energy_per_atom,error,time_s,pareto\n")
        for r in allrows:
            f.write(f"{r['case']},{r['method']},{r['parameter']},{r['evaluations']},{r['seeds']},"
                    f"{r['energy_per_atom']:.15g},{r['error']:.6e},{r['time_s']:.6f},{r['pareto']}\n")
    json.dump(dict(checks=checks, rows=allrows), open(os.path.join(out, "statistical.json"), "w"), indent=1)
    ok = all(c["numpy_mc_deviation_in_se"] < 4 for c in checks)
    print(f"  -> {out}/statistical.csv, statistical.png ({'references agree with NumPy MC' if ok else 'REFERENCE DISAGREES'})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
