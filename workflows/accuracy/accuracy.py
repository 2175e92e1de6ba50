#!/usr/bin/env python3
"""Accuracy against cost (issue 9 §1 items 1 and 4), summarised in docs/accuracy-cost.md.

Item 1 (``plate``): the plate with a hole of docs/validation.md §1 (plane strain Neo-Hookean,
mu = 1, K = 10, right edge u_x = d) run by ``pdcg run`` over grid spacings and horizon
factors m (delta = (m + 0.015) dx), each run a separate process timed by wall clock and its
peak resident memory read from the kernel (os.wait4 rusage). Error: relative deviation of
the right-edge reaction from the converged FEM reference (Richardson-extrapolated P2 FEM,
tests/data/plate_hole_fem.csv). The FEM's own error/time/memory curve on coarser meshes
comes from workflows/validation/plate_hole_fem.py (same load), each level its own process.

Item 4 (``nonlinear``): the large-stretch plate (same plate to d = 1: the 1 x 1 plate pulled to
twice its length) at one spacing and m, over the nominal load-step count and the
Newton tolerance; error of the final reaction against a tight pdcg solve (same
discretisation, 20 steps, tol 1e-12: this isolates the nonlinear-solve error) and against
the FEM reference (the total error a user sees).

Both write a CSV and a PNG with the Pareto front (runs no other run beats in both error and
time). Usage:
  python3 accuracy.py --pdcg build/pdcg --out DIR [--spacings 0.05 0.025 0.0125]
      [--factors 2 3 4] [--d 0.05] [--steps 1] [--fem-levels 6 12 24 48]
      [--nl-spacing 0.05] [--nl-steps 1 2 5 10 20] [--nl-tols 1e-3 1e-6 1e-10]
      [--parts plate nonlinear] [--smoke]
"""
import argparse
import csv
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
FEM_CSV = os.path.join(ROOT, "tests", "data", "plate_hole_fem.csv")
FEM_PY = os.path.join(ROOT, "workflows", "validation", "plate_hole_fem.py")
FLOOR = 5e-11  # plotted for errors below the 10 significant digits of reactions.csv

SCENE = """units: none
dimension: 2
plane: strain
geometry:
  shape: rectangle
  origin: [0.0, 0.0]
  size: [1.0, 1.0]
  spacing: {h}
  holes: [{{center: [0.5, 0.5], radius: 0.2}}]
horizon: {{factor: {m}}}
material: {{model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}}
boundary:
  - {{name: left,  region: {{x_max: 0.0}},  displacement: {{x: 0.0}}}}
  - {{name: pin,   region: {{point: [0.0, 0.0]}}, displacement: {{y: 0.0}}}}
  - {{name: right, region: {{x_min: 1.0}},  displacement: {{x: "{d}*t"}}}}
loading: {{steps: {steps}}}
solver: {{type: newton, tolerance: {tol}, max_iterations: 30, max_cutbacks: 12, linear: {linear}}}
output: {{directory: out, every: {steps}}}
"""


def timed(cmd, log_path, timeout=None):
    """Runs cmd; returns (wall seconds, peak RSS in MiB, exit code); exit code None = killed
    after timeout seconds."""
    with open(log_path, "w") as log:
        t0 = time.perf_counter()
        p = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT)
        while True:
            pid, status, ru = os.wait4(p.pid, os.WNOHANG)
            if pid == p.pid:
                break
            if timeout and time.perf_counter() - t0 > timeout:
                p.kill()  # only the process started here
                _, status, ru = os.wait4(p.pid, 0)
                return time.perf_counter() - t0, ru.ru_maxrss / 1024.0, None
            time.sleep(0.05)
        wall = time.perf_counter() - t0
    return wall, ru.ru_maxrss / 1024.0, os.waitstatus_to_exitcode(status)  # ru_maxrss: KiB


def fem_reference():
    """d -> extrapolated FEM reaction (tests/data/plate_hole_fem.csv)."""
    ref = {}
    with open(FEM_CSV) as f:
        rows = [l for l in f if not l.startswith("#")]
    for r in csv.DictReader(rows):
        ref[round(float(r["d"]), 6)] = float(r["R_extrapolated"])
    return ref


def ref_at(ref, d):
    key = round(d, 6)
    if key not in ref:
        sys.exit(f"d = {d} is not a load level of {FEM_CSV} (multiples of 0.05 up to 1)")
    return ref[key]


def run_pdcg(pdcg, work, h, m, d, steps, tol, timeout=None, linear="umfpack"):
    tag = f"h{h}_m{m}_d{d}_s{steps}_tol{tol}_{linear}"
    wd = os.path.join(work, tag)
    os.makedirs(wd, exist_ok=True)
    scene = os.path.join(wd, "plate.yaml")
    with open(scene, "w") as f:
        f.write(SCENE.format(h=h, m=m + 0.015, d=d, steps=steps, tol=tol, linear=linear))
    wall, rss, rc = timed([pdcg, "run", scene, "-o", os.path.join(wd, "out")],
                          os.path.join(wd, "run.log"), timeout)
    R, points = float("nan"), 0
    if rc == 0:
        with open(os.path.join(wd, "out", "reactions.csv")) as f:
            rows = list(csv.DictReader(f))
        R = float(rows[-1]["right_fx"])
        for line in open(os.path.join(wd, "run.log")):
            if "body:" in line and " points" in line:  # "body: N points, spacing ..."
                points = int(line.split("body:")[1].split()[0])
    return dict(wall=wall, rss=rss, rc=rc, R=R, points=points, log=os.path.join(wd, "run.log"))


def run_fem(work, nt, d, steps):
    code = (f"import sys; sys.path.insert(0, {os.path.dirname(FEM_PY)!r}); "
            "import plate_hole_fem as f; "
            f"f.STEPS = {steps}; f.D_FINAL = {d}; "
            "import time; t0 = time.perf_counter(); "
            f"out, ne, nd = f.solve({nt}, {nt // 2}, log=lambda s: None); "
            "print('RESULT', out[-1][1], ne, nd, time.perf_counter() - t0)")
    log = os.path.join(work, f"fem_nt{nt}.log")
    wall, rss, rc = timed(["/usr/bin/python3", "-c", code], log)
    R, ne, nd, solve = float("nan"), 0, 0, float("nan")
    for line in open(log):
        if line.startswith("RESULT"):
            _, R, ne, nd, solve = line.split()
    # wall = the solve (mesh, assembly, Newton) in-process: the python + scipy start-up (1-7 s
    # on this shared machine) is not FEM work; peak RSS includes the interpreter (~40 MiB)
    return dict(wall=float(solve), process_s=wall, rss=rss, rc=rc, R=float(R), elements=int(ne),
                dofs=int(nd))


def pareto(points):
    """Indices of the non-dominated (time, error) pairs (lower is better in both)."""
    idx = []
    for i, (t, e) in enumerate(points):
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for t2, e2 in points):
            idx.append(i)
    return set(idx)


def plate(args, ref):
    work = os.path.join(args.out, "runs")
    os.makedirs(work, exist_ok=True)
    R_ref = ref_at(ref, args.d)
    rows = []
    for h in args.spacings:
        for m in args.factors:
            r = run_pdcg(args.pdcg, work, h, m, args.d, args.steps, args.tol, args.timeout, args.linear)
            err = abs(r["R"] - R_ref) / R_ref if r["rc"] == 0 else float("nan")
            rows.append(dict(method="pdcg-BA" + ("" if args.linear == "umfpack" else f"-{args.linear}"), spacing=h, m=m, size=r["points"], wall_s=r["wall"],
                             peak_rss_MiB=r["rss"], R=r["R"], R_ref=R_ref, rel_error=err,
                             status="ok" if r["rc"] == 0 else
                             (f"killed after {args.timeout:g} s" if r["rc"] is None else f"exit {r['rc']}")))
            print(f"pdcg h={h} m={m}: R={r['R']:.7f} err={err:.3e} {r['wall']:.1f} s "
                  f"{r['rss']:.0f} MiB", flush=True)
    for nt in args.fem_levels:
        r = run_fem(work, nt, args.d, args.steps)
        err = abs(r["R"] - R_ref) / R_ref
        rows.append(dict(method="FEM-P2", spacing=f"quarter {nt}x{nt // 2}", m="", size=r["dofs"],
                         wall_s=r["wall"], peak_rss_MiB=r["rss"], R=r["R"], R_ref=R_ref,
                         rel_error=err, status="ok" if r["rc"] == 0 else f"exit {r['rc']}"))
        print(f"FEM nt={nt}: R={r['R']:.9f} err={err:.3e} {r['wall']:.1f} s {r['rss']:.0f} MiB",
              flush=True)
    ok = [i for i, r in enumerate(rows) if r["status"] == "ok" and r["rel_error"] == r["rel_error"]]
    front = pareto([(rows[i]["wall_s"], max(rows[i]["rel_error"], 1e-16)) for i in ok])
    for k, i in enumerate(ok):
        rows[i]["pareto"] = int(k in front)
    path = os.path.join(args.out, "accuracy_plate_hole.csv")
    with open(path + ".tmp", "w", newline="") as f:
        f.write(f"# plate with a hole, d = {args.d} in {args.steps} step(s), Newton tol {args.tol}; "
                f"reference R = {R_ref:.10f} (extrapolated FEM, {os.path.relpath(FEM_CSV, ROOT)})\n")
        f.write("# size = points (pdcg) or dofs of the quarter model (FEM); wall_s and peak_rss_MiB "
                "of the whole process on this machine; pareto = 1 if no other run is both faster "
                "and more accurate\n")
        w = csv.DictWriter(f, fieldnames=["method", "spacing", "m", "size", "wall_s", "peak_rss_MiB",
                                          "R", "R_ref", "rel_error", "pareto", "status"])
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    os.replace(path + ".tmp", path)
    plot_plate(rows, os.path.join(args.out, "accuracy_plate_hole.png"), args)
    print(f"wrote {path}")
    return rows


def plot_plate(rows, png, args):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    markers = {0.1: "v", 0.05: "o", 0.025: "s", 0.0125: "D", 0.00625: "^"}
    colors = {2: "tab:blue", 3: "tab:orange", 4: "tab:green"}
    for ax, key, label in ((axes[0], "wall_s", "wall time per run [s]"),
                           (axes[1], "peak_rss_MiB", "peak memory [MiB]")):
        for m in args.factors:
            pts = [r for r in rows if r["method"].startswith("pdcg-BA") and r["m"] == m and r["status"] == "ok"]
            ax.plot([r[key] for r in pts], [r["rel_error"] for r in pts], "-", color=colors.get(m, "k"),
                    alpha=0.5)
            for r in pts:
                ax.plot(r[key], r["rel_error"], markers.get(r["spacing"], "o"), color=colors.get(m, "k"),
                        ms=7, label=f"pdcg m={m}, dx={r['spacing']}")
        fem = [r for r in rows if r["method"] == "FEM-P2" and r["status"] == "ok"]
        ax.plot([r[key] for r in fem], [max(r["rel_error"], 1e-12) for r in fem], "k*-", ms=9,
                label="FEM P2 (quarter model)")
        if key == "wall_s":
            fr = sorted([r for r in rows if r.get("pareto") == 1], key=lambda r: r["wall_s"])
            ax.plot([r["wall_s"] for r in fr], [max(r["rel_error"], 1e-12) for r in fr], "r--", lw=1,
                    label="Pareto front")
        if not ax.has_data():
            continue
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(label)
        ax.set_ylabel("relative error of the reaction")
        ax.grid(True, which="both", alpha=0.3)
    h, l = axes[0].get_legend_handles_labels()
    seen = {}
    for hh, ll in zip(h, l):
        seen.setdefault(ll, hh)
    fig.legend(seen.values(), seen.keys(), loc="center right", fontsize=7)
    fig.suptitle(f"Plate with a hole, d = {args.d}: reaction error vs cost")
    fig.tight_layout(rect=(0, 0, 0.8, 1))
    fig.savefig(png + ".tmp.png", dpi=110)
    os.replace(png + ".tmp.png", png)


def nonlinear(args, ref):
    work = os.path.join(args.out, "runs")
    os.makedirs(work, exist_ok=True)
    h, m, d = args.nl_spacing, args.nl_factor, 1.0
    R_fem = ref_at(ref, d)
    tight = run_pdcg(args.pdcg, work, h, m, d, args.nl_tight_steps, 1e-12)
    if tight["rc"] != 0:
        sys.exit(f"tight reference run failed: {tight['log']}")
    R_tight = tight["R"]
    print(f"tight pdcg solve (20 steps, tol 1e-12): R = {R_tight:.12f} ({tight['wall']:.1f} s)",
          flush=True)
    rows = []
    for steps in args.nl_steps:
        for tol in args.nl_tols:
            r = run_pdcg(args.pdcg, work, h, m, d, steps, tol)
            ok = r["rc"] == 0
            cut = sum(1 for l in open(r["log"]) if "cutting back" in l)
            # Newton iterations of the converged steps: a cost measure that machine load
            # does not change (wall time on a shared machine does)
            its = sum(int(l.split(" Newton iterations")[0].split()[-1]) for l in open(r["log"])
                      if " Newton iterations" in l)
            rows.append(dict(steps=steps, tolerance=tol, wall_s=r["wall"], peak_rss_MiB=r["rss"],
                             cutbacks=cut, newton_iterations=its, R=r["R"],
                             solve_error=abs(r["R"] - R_tight) / R_tight if ok else float("nan"),
                             error_vs_fem=abs(r["R"] - R_fem) / R_fem if ok else float("nan"),
                             status="ok" if ok else f"exit {r['rc']}"))
            print(f"steps={steps} tol={tol:g}: R={r['R']:.12f} solve err={rows[-1]['solve_error']:.2e} "
                  f"{r['wall']:.1f} s, {cut} cutbacks", flush=True)
    ok = [i for i, r in enumerate(rows) if r["status"] == "ok"]
    front = pareto([(rows[i]["wall_s"], max(rows[i]["solve_error"], 1e-16)) for i in ok])
    for k, i in enumerate(ok):
        rows[i]["pareto"] = int(k in front)
    path = os.path.join(args.out, "accuracy_nonlinear.csv")
    with open(path + ".tmp", "w", newline="") as f:
        f.write(f"# large-stretch plate with a hole, d = 1, spacing {h}, m = {m}; solve_error vs a "
                f"tight pdcg solve (20 steps, tol 1e-12, R = {R_tight:.12f}, {tight['wall']:.1f} s); "
                f"error_vs_fem vs R_FEM = {R_fem:.10f}\n")
        w = csv.DictWriter(f, fieldnames=["steps", "tolerance", "wall_s", "peak_rss_MiB", "cutbacks",
                                          "newton_iterations", "R", "solve_error", "error_vs_fem", "pareto", "status"])
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in r.items()})
    os.replace(path + ".tmp", path)
    plot_nonlinear(rows, args, h, m, R_tight, R_fem)
    print(f"wrote {path}")
    return rows


def plot_nonlinear(rows, args, h, m, R_tight, R_fem):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    cmap = plt.get_cmap("viridis")
    for k, tol in enumerate(args.nl_tols):
        pts = [r for r in rows if r["tolerance"] == tol and r["status"] == "ok"]
        ax.plot([r["wall_s"] for r in pts], [max(r["solve_error"], FLOOR) for r in pts], "o-",
                color=cmap(k / max(1, len(args.nl_tols) - 1)), label=f"tol {tol:g}")
        for r in pts:
            ax.annotate(str(r["steps"]), (r["wall_s"], max(r["solve_error"], FLOOR)), fontsize=7,
                        xytext=(3, 3), textcoords="offset points")
    fr = sorted([r for r in rows if r.get("pareto") == 1], key=lambda r: r["wall_s"])
    ax.plot([r["wall_s"] for r in fr], [max(r["solve_error"], FLOOR) for r in fr], "r--", lw=1,
            label="Pareto front")
    ax.axhline(abs(R_tight - R_fem) / R_fem, color="gray", ls=":", label="discretisation error vs FEM")
    ax.axhline(FLOOR, color="k", lw=0.5, ls="-.", label="below reactions.csv resolution (10 digits)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per run [s]")
    ax.set_ylabel("relative error of the final reaction vs tight solve")
    ax.set_title(f"Nonlinear solve, plate with a hole to d = 1 (dx = {h}, m = {m}); labels = load steps",
                 fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    png = os.path.join(args.out, "accuracy_nonlinear.png")
    fig.savefig(png + ".tmp.png", dpi=110)
    os.replace(png + ".tmp.png", png)



def replot(args):
    import re

    def load(path):
        with open(path) as f:
            lines = f.readlines()
        head = "".join(l for l in lines if l.startswith("#"))
        rows = list(csv.DictReader([l for l in lines if not l.startswith("#")]))
        for r in rows:
            for k, v in r.items():
                try:
                    r[k] = float(v) if k not in ("steps", "m", "pareto") else int(float(v))
                except (TypeError, ValueError):
                    pass
        return head, rows

    p = os.path.join(args.out, "accuracy_plate_hole.csv")
    if os.path.exists(p):
        head, rows = load(p)
        args.d = float(re.search(r"d = ([0-9.e+-]+)", head).group(1))
        args.factors = sorted({r["m"] for r in rows if r["method"].startswith("pdcg-BA")})
        plot_plate(rows, os.path.join(args.out, "accuracy_plate_hole.png"), args)
    p = os.path.join(args.out, "accuracy_nonlinear.csv")
    if os.path.exists(p):
        head, rows = load(p)
        h = float(re.search(r"spacing ([0-9.e+-]+)", head).group(1))
        m = int(re.search(r"m = ([0-9]+)", head).group(1))
        R_tight = float(re.search(r"tol 1e-12, R = ([0-9.e+-]+)", head).group(1))
        R_fem = float(re.search(r"R_FEM = ([0-9.e+-]+)", head).group(1))
        args.nl_tols = sorted({r["tolerance"] for r in rows}, reverse=True)
        plot_nonlinear(rows, args, h, m, R_tight, R_fem)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--pdcg", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--parts", nargs="+", default=["plate", "nonlinear"])
    ap.add_argument("--spacings", nargs="+", type=float, default=[0.05, 0.025, 0.0125])
    ap.add_argument("--factors", nargs="+", type=int, default=[2, 3, 4])
    ap.add_argument("--d", type=float, default=0.05)
    ap.add_argument("--steps", type=int, default=1)
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--timeout", type=float, default=240, help="seconds per pdcg run before it is "
                    "stopped and reported as too slow")
    ap.add_argument("--fem-levels", nargs="*", type=int, default=[6, 12, 24, 48])
    ap.add_argument("--nl-spacing", type=float, default=0.05)
    ap.add_argument("--nl-factor", type=int, default=3)
    ap.add_argument("--nl-steps", nargs="+", type=int, default=[1, 2, 5, 10, 20])
    ap.add_argument("--nl-tols", nargs="+", type=float, default=[1e-3, 1e-6, 1e-10])
    ap.add_argument("--nl-tight-steps", type=int, default=20)
    ap.add_argument("--linear", default="umfpack", help="solver.linear of the plate runs")
    ap.add_argument("--replot", action="store_true", help="only redraw the PNGs from the CSVs in --out")
    ap.add_argument("--smoke", action="store_true", help="tiny variant for ctest (seconds)")
    args = ap.parse_args()
    if args.smoke:
        args.spacings, args.factors, args.fem_levels = [0.1], [3], [6]
        args.nl_spacing, args.nl_steps, args.nl_tols, args.nl_tight_steps = 0.1, [2], [1e-6], 4
        try:
            import scipy  # noqa: F401  (the FEM curve needs it; the smoke test runs without)
        except ImportError:
            print("scipy missing: FEM curve skipped (apt-get install python3-scipy)")
            args.fem_levels = []
    os.makedirs(args.out, exist_ok=True)
    if args.replot:
        replot(args)
        return
    ref = fem_reference()
    rows = []
    if "plate" in args.parts:
        rows += plate(args, ref)
    if "nonlinear" in args.parts:
        rows += nonlinear(args, ref)
    bad = [r for r in rows if r["status"] != "ok"]
    if args.smoke and bad:
        sys.exit(f"smoke: {len(bad)} run(s) failed: {bad}")


if __name__ == "__main__":
    main()
