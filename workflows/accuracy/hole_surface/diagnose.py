#!/usr/bin/env python3
"""Why the lateral strain of the plate with a hole does not converge (docs/accuracy-cost.md §1).

For the 'faces' layout of accuracy.py (d = 0.05, one step) at each spacing and m:
 (a) the internal force of pdcg's discrete operator at the FEM solution (P2 quarter mesh 48x24,
     evaluated at the points): on free points it is the consistency (truncation) residual;
     its rms over the hole's surface layer (points within 2.5 dx of the circle), divided by
     dx, is a traction error; printed with pdcg's own s_k (driver mode 0: the staircase until the
     grid path took the true circle, docs/solver.md §2; since then equal to mode 1) and with s_k
     from the true circle re-applied by the driver (mode 1, the prototype);
 (b) the solve with either s_k: reaction, field error e_u (x and y parts), mean lateral strain
     eps_yy (volume-weighted affine fit) and the vertical closure of the hole (u_y of the points
     just above and below it on x = 0.5), each against the FEM at the same points.
Usage: build.sh [BUILD]; python3 diagnose.py [--build BUILD] [--spacings 0.025 0.0125] [--factors 2 3]
"""
import argparse, os, subprocess, sys
import numpy as np
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "validation"))
sys.path.insert(0, os.path.join(HERE, ".."))
import plate_hole_fem as fem  # noqa: E402
import accuracy  # noqa: E402

R_HOLE, D = 0.2, 0.05


def fit(X, u, w):
    A = np.c_[np.ones(len(X)), X]
    W = np.sqrt(w)[:, None]
    return np.linalg.lstsq(A * W, u * W, rcond=None)[0]  # rows: const, d/dx, d/dy


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default=os.path.join(HERE, "..", "..", "..", "build"))
    ap.add_argument("--work", default="/tmp/hole_surface")
    ap.add_argument("--spacings", type=float, nargs="+", default=[0.025, 0.0125])
    ap.add_argument("--factors", type=float, nargs="+", default=[2, 3])
    a = ap.parse_args()
    drv = os.path.join(a.build, "hole_surface")
    os.makedirs(a.work, exist_ok=True)
    fem.STEPS, fem.D_FINAL = 1, D
    _, _, _, (nodes, tris, uq) = fem.solve(48, 24, log=lambda s: None, field=True)
    for h in a.spacings:
        for m in a.factors:
            scene = os.path.join(a.work, f"h{h}_m{m}.yaml")
            with open(scene, "w") as f:
                f.write(accuracy.SCENE.format(h=h, m=m + 0.015, d=D, steps=1, tol=1e-10, linear="umfpack",
                                              x0=repr(-h / 2), lx=repr(1.0 + h)))
            for mode, name in ((0, "pdcg"), (1, "circle")):
                out = os.path.join(a.work, f"h{h}_m{m}_{mode}")
                subprocess.run([drv, scene, "-", out + ".sol", str(mode), str(R_HOLE), str(D)], check=True,
                               capture_output=True)
                r = np.loadtxt(out + ".sol")
                X, V, u = r[:, :2], r[:, 2], r[:, 7:9]
                uf, _ = fem.evaluate(nodes, tris, uq, np.clip(X, 0, 1), D)
                np.savetxt(out + ".ufem", uf.ravel())
                subprocess.run([drv, scene, out + ".ufem", out + ".res", str(mode), str(R_HOLE)], check=True,
                               capture_output=True)
                f_at_fem = np.loadtxt(out + ".res")[:, 3:5]
                free = (X[:, 0] > 1e-9) & (X[:, 0] < 1 - 1e-9)
                rad = np.hypot(X[:, 0] - 0.5, X[:, 1] - 0.5)
                layer = free & (rad < R_HOLE + 2.5 * h)
                fa = np.hypot(*f_at_fem[layer].T) / h
                top = free & (X[:, 1] > 1 - 2.5 * h)
                ft = np.hypot(*f_at_fem[top].T) / h
                Rx = r[X[:, 0] > 1 - 1e-9, 3].sum()
                p, q = u.copy(), uf.copy()
                p[:, 1] -= np.average(p[:, 1], weights=V)
                q[:, 1] -= np.average(q[:, 1], weights=V)
                nrm = np.sum(V * (q**2).sum(1))
                ex = np.sqrt(np.sum(V * (p[:, 0] - q[:, 0])**2) / nrm)
                ey = np.sqrt(np.sum(V * (p[:, 1] - q[:, 1])**2) / nrm)
                eyy = fit(X, u, V)[2, 1] / fit(X, uf, V)[2, 1] - 1
                c = np.abs(X[:, 0] - 0.5) < 1e-9
                o = np.argsort(X[c, 1])
                y, vp, vf = X[c, 1][o], u[c, 1][o], uf[c, 1][o]
                k = np.where(y > 0.5)[0][0]
                clo = (vp[k] - vp[k - 1]) / (vf[k] - vf[k - 1]) - 1
                print(f"dx={h:g} m={m:g} s_k={name:9s}: residual at FEM |f|/dx hole layer rms {np.sqrt((fa**2).mean()):.2e} "
                      f"max {fa.max():.2e}, top edge rms {np.sqrt((ft**2).mean()):.2e} | solve: R {Rx:.6f} "
                      f"e_u {np.hypot(ex, ey):.2e} (x {ex:.2e}, y {ey:.2e}) eps_yy {eyy:+.4f} hole closure {clo:+.4f}",
                      flush=True)


if __name__ == "__main__":
    main()
