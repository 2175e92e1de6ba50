#!/usr/bin/env python3
"""Independent FEM reference for the pdcg plate-with-hole validation (docs/validation.md §1).

Problem (docs/theory.md §7–8, docs/solver.md, the plate-with-hole scene contract):
  plate [0,1]², circular hole centre (0.5,0.5), R = 0.2, plane strain, unit thickness,
  compressible Neo-Hookean  Ψ = μ/2 (J^(-2/3) tr C − 3) + K/8 (J − 1/J)²  (C = FᵀF, F₃₃ = 1),
  μ = 1, K = 10; left edge u_x = 0 (+ a pin u_y = 0 at (0,0)), right edge u_x = d (u_y free),
  top, bottom and hole traction-free; d = 1.0 in 20 equal load steps.
  Output: the right-edge reaction force R_x(d) per unit thickness.

Method (no code shared with pdcg): total-Lagrangian displacement FEM, isoparametric
6-node (P2) triangles, 6-point degree-4 Dunavant quadrature, full Newton–Raphson with the
consistent tangent (A = ∂P/∂F derived independently below and checked against a finite
difference of P with --check), sparse direct solve (scipy SuperLU).
The problem is symmetric about x = 0.5 and y = 0.5, so one quarter [0.5,1]² is meshed:
  x = 0.5: u_x = d/2 (antisymmetry of u_x − d/2), zero shear traction;
  y = 0.5: u_y = 0, zero shear traction;  x = 1: u_x = d;  top and hole free.
The pin at (0,0) only removes the rigid y-translation of the full plate and does not change
the reaction. Full-plate reaction = 2 × quarter reaction.
Mesh: structured, mapped from the hole arc to the outer edges (two blocks split at 45°),
each quad split into two curved P2 triangles whose mid-side nodes on the hole lie on the
circle. Refinement levels h, h/2, h/4, ...; Richardson extrapolation of the reaction with
the observed order.

Options --plane stress (P₃₃ = 0: F₃₃ from a Newton per quadrature point on the 3D energy, the
condensed tangent; --check tests it against finite differences) and --bulk K change the
problem; the defaults are the plane-strain K = 10 plate above.

Usage:  python3 plate_hole_fem.py [--levels 4] [--csv out.csv] [--check] [--plane strain|stress] [--bulk K]
"""
import argparse
import sys
import time

import numpy as np
import scipy
import scipy.sparse as sp
import scipy.sparse.linalg as spla

MU, KAPPA = 1.0, 10.0
PLANE = "strain"  # or "stress" (--plane): P₃₃ = 0 by a local Newton on F₃₃, condensed tangent
L, R, CX, CY = 1.0, 0.2, 0.5, 0.5
D_FINAL, STEPS = 1.0, 20


# --------------------------------------------------------------------------- material
def neo_hookean(F):
    """Plane-strain Neo-Hookean. F: (..., 2, 2) in-plane block (F₃₃ = 1).
    Returns P (..., 2, 2) and A (..., 2, 2, 2, 2) with A[a,J,b,L] = ∂P_aJ/∂F_bL."""
    J = F[..., 0, 0] * F[..., 1, 1] - F[..., 0, 1] * F[..., 1, 0]
    if np.any(J <= 0):
        raise FloatingPointError("inverted element (J <= 0)")
    # H = F^{-T}
    H = np.empty_like(F)
    H[..., 0, 0] = F[..., 1, 1] / J
    H[..., 0, 1] = -F[..., 1, 0] / J
    H[..., 1, 0] = -F[..., 0, 1] / J
    H[..., 1, 1] = F[..., 0, 0] / J
    I1 = np.einsum("...ij,...ij->...", F, F) + 1.0  # tr C with C₃₃ = 1
    Jm23 = J ** (-2.0 / 3.0)
    a = (MU * Jm23)[..., None, None]
    vol = (KAPPA / 4.0 * (J**2 - J**-2))[..., None, None]
    P = a * (F - (I1 / 3.0)[..., None, None] * H) + vol * H
    eye = np.eye(2)
    dd = np.einsum("ab,JL->aJbL", eye, eye)
    HH = np.einsum("...aJ,...bL->...aJbL", H, H)       # H_aJ H_bL
    HHt = np.einsum("...aL,...bJ->...aJbL", H, H)      # H_aL H_bJ
    FH = np.einsum("...bL,...aJ->...aJbL", F, H)       # F_bL H_aJ
    HF = np.einsum("...bL,...aJ->...aJbL", H, F)       # H_bL F_aJ
    e = lambda s: s[..., None, None, None, None]
    A = e(MU * Jm23) * (dd - 2.0 / 3.0 * (FH + HF) + e(2.0 / 9.0 * I1) * HH + e(I1 / 3.0) * HHt)
    A += e(KAPPA / 2.0 * (J**2 + J**-2)) * HH - e(KAPPA / 4.0 * (J**2 - J**-2)) * HHt
    return P, A


def neo_hookean_3d(F):
    """Full 3D compressible Neo-Hookean, F: (..., 3, 3). Returns P and A = ∂P/∂F (the same
    formulas as neo_hookean with the 3×3 identity; tr C over all three axes)."""
    J = np.linalg.det(F)
    if np.any(J <= 0):
        raise FloatingPointError("inverted element (J <= 0)")
    H = np.swapaxes(np.linalg.inv(F), -1, -2)
    I1 = np.einsum("...ij,...ij->...", F, F)
    Jm23 = J ** (-2.0 / 3.0)
    P = (MU * Jm23)[..., None, None] * (F - (I1 / 3.0)[..., None, None] * H) + \
        (KAPPA / 4.0 * (J**2 - J**-2))[..., None, None] * H
    eye = np.eye(3)
    dd = np.einsum("ab,JL->aJbL", eye, eye)
    HH = np.einsum("...aJ,...bL->...aJbL", H, H)
    HHt = np.einsum("...aL,...bJ->...aJbL", H, H)
    FH = np.einsum("...bL,...aJ->...aJbL", F, H)
    HF = np.einsum("...bL,...aJ->...aJbL", H, F)
    e = lambda s: s[..., None, None, None, None]
    A = e(MU * Jm23) * (dd - 2.0 / 3.0 * (FH + HF) + e(2.0 / 9.0 * I1) * HH + e(I1 / 3.0) * HHt)
    A += e(KAPPA / 2.0 * (J**2 + J**-2)) * HH - e(KAPPA / 4.0 * (J**2 - J**-2)) * HHt
    return P, A


def neo_hookean_plane_stress(F):
    """Plane stress: F₃₃ = λ with P₃₃(F, λ) = 0 (Newton per point, from λ = 1/√det F2 … 1),
    P = the in-plane block, A = A_ab − A_a33 A_33b / A_3333 (the condensed tangent)."""
    shape = F.shape[:-2]
    F3 = np.zeros(shape + (3, 3))
    F3[..., :2, :2] = F
    F3[..., 2, 2] = 1.0
    for _ in range(60):
        P3, A3 = neo_hookean_3d(F3)
        step = P3[..., 2, 2] / A3[..., 2, 2, 2, 2]
        lam = F3[..., 2, 2] - step
        F3[..., 2, 2] = np.where(lam > 0, lam, 0.5 * F3[..., 2, 2])
        if np.max(np.abs(step)) < 1e-15:
            break
    P3, A3 = neo_hookean_3d(F3)
    if np.max(np.abs(P3[..., 2, 2])) > 1e-10 * max(1.0, np.abs(P3).max()):
        raise FloatingPointError("plane stress: P33 = 0 not reached")
    A = A3[..., :2, :2, :2, :2] - np.einsum("...aJ,...bL->...aJbL", A3[..., :2, :2, 2, 2],
                                            A3[..., 2, 2, :2, :2]) / A3[..., 2, 2, 2, 2][..., None, None, None, None]
    return P3[..., :2, :2], A


def material(F):
    return neo_hookean(F) if PLANE == "strain" else neo_hookean_plane_stress(F)


def energy_plane_stress(F):
    F3 = np.zeros(F.shape[:-2] + (3, 3)); F3[..., :2, :2] = F; F3[..., 2, 2] = 1.0
    lo, hi = 1e-3, 1e3  # Ψ(λ) minimised by bisection on P₃₃ (independent of the Newton above)
    for _ in range(200):
        mid = np.sqrt(lo * hi)
        F3[..., 2, 2] = mid
        p33 = neo_hookean_3d(F3)[0][..., 2, 2]
        lo, hi = (mid, hi) if p33 < 0 else (lo, mid)
    J = np.linalg.det(F3)
    I1 = np.einsum("...ij,...ij->...", F3, F3)
    return MU / 2 * (J ** (-2 / 3) * I1 - 3) + KAPPA / 8 * (J - 1 / J) ** 2


def energy(F):
    J = F[..., 0, 0] * F[..., 1, 1] - F[..., 0, 1] * F[..., 1, 0]
    I1 = np.einsum("...ij,...ij->...", F, F) + 1.0
    return MU / 2 * (J ** (-2 / 3) * I1 - 3) + KAPPA / 8 * (J - 1 / J) ** 2


def check_material():
    rng = np.random.default_rng(1)
    worst_p = worst_a = 0.0
    for _ in range(20):
        F = np.eye(2) + 0.6 * rng.standard_normal((2, 2))
        if np.linalg.det(F) <= 0.2:
            continue
        P, A = material(F)
        W = energy if PLANE == "strain" else energy_plane_stress
        h = 1e-6
        for b in range(2):
            for Lx in range(2):
                dF = np.zeros((2, 2)); dF[b, Lx] = h
                fd_p = (W(F + dF) - W(F - dF)) / (2 * h)
                worst_p = max(worst_p, abs(fd_p - P[b, Lx]) / np.abs(P).max())
                fd_a = (material(F + dF)[0] - material(F - dF)[0]) / (2 * h)
                worst_a = max(worst_a, np.abs(fd_a - A[:, :, b, Lx]).max() / np.abs(A).max())
    print(f"material check: P vs FD(Ψ) {worst_p:.1e}, A vs FD(P) {worst_a:.1e}")
    return worst_p < 1e-7 and worst_a < 1e-7


# --------------------------------------------------------------------------- mesh
def mesh(nt, nr, grading=1.4):
    """Quarter plate [0.5,1]² minus the hole. nt elements along the boundary (u ∈ [0,2]),
    nr elements radially. Returns nodes (N,2) and P2 connectivity (E,6)."""
    mu_, mr = 2 * nt + 1, 2 * nr + 1
    u = np.linspace(0.0, 2.0, mu_)
    s = np.linspace(0.0, 1.0, mr) ** grading  # finer near the hole
    X = np.empty((mu_, mr, 2))
    for i, ui in enumerate(u):
        if ui <= 1.0:
            t = ui
            outer = np.array([CX + 0.5, CY + 0.5 * t])
            th = np.arctan(t)
        else:
            t = 2.0 - ui
            outer = np.array([CX + 0.5 * t, CY + 0.5])
            th = np.pi / 2 - np.arctan(t)
        inner = np.array([CX + R * np.cos(th), CY + R * np.sin(th)])
        X[i] = (1 - s)[:, None] * inner + s[:, None] * outer
    nodes = X.reshape(-1, 2)
    idx = lambda i, j: i * mr + j
    tris = []
    for i in range(nt):
        for j in range(nr):
            a, b, c, d = (2 * i, 2 * j), (2 * i + 2, 2 * j), (2 * i + 2, 2 * j + 2), (2 * i, 2 * j + 2)
            m = lambda p, q: ((p[0] + q[0]) // 2, (p[1] + q[1]) // 2)
            for (p, q, r) in ((a, b, c), (a, c, d)):
                tris.append([idx(*p), idx(*q), idx(*r), idx(*m(p, q)), idx(*m(q, r)), idx(*m(r, p))])
    tris = np.array(tris)
    # orient counter-clockwise
    v = nodes[tris[:, :3]]
    area2 = (v[:, 1, 0] - v[:, 0, 0]) * (v[:, 2, 1] - v[:, 0, 1]) - (v[:, 2, 0] - v[:, 0, 0]) * (v[:, 1, 1] - v[:, 0, 1])
    flip = area2 < 0
    tris[flip] = tris[flip][:, [0, 2, 1, 5, 4, 3]]
    return nodes, tris


# 6-point degree-4 Dunavant rule on the reference triangle (weights sum to 1/2)
_a, _b = 0.445948490915965, 0.091576213509771
QP = np.array([[_a, _a], [1 - 2 * _a, _a], [_a, 1 - 2 * _a], [_b, _b], [1 - 2 * _b, _b], [_b, 1 - 2 * _b]])
QW = 0.5 * np.array([0.223381589678011] * 3 + [0.109951743655322] * 3)


def shape_derivs(xi, eta):
    l0, l1, l2 = 1 - xi - eta, xi, eta
    # dN/dxi, dN/deta for N0..N5 (vertices, then mid 01, 12, 20)
    dxi = np.array([-(4 * l0 - 1), 4 * l1 - 1, 0.0, 4 * (l0 - l1), 4 * l2, -4 * l2])
    deta = np.array([-(4 * l0 - 1), 0.0, 4 * l2 - 1, -4 * l1, 4 * l1, 4 * (l0 - l2)])
    return np.stack([dxi, deta], axis=1)  # (6,2)


class Model:
    def __init__(self, nodes, tris):
        self.nodes, self.tris = nodes, tris
        dref = np.stack([shape_derivs(*q) for q in QP])  # (Q,6,2)
        Xe = nodes[tris]  # (E,6,2)
        Jac = np.einsum("enI,qnk->eqIk", Xe, dref)  # dX_I/dξ_k
        det = Jac[..., 0, 0] * Jac[..., 1, 1] - Jac[..., 0, 1] * Jac[..., 1, 0]
        if np.any(det <= 0):
            raise RuntimeError("bad mesh")
        inv = np.linalg.inv(Jac)  # dξ_k/dX_I
        self.G = np.einsum("qnk,eqkI->eqnI", dref, inv)  # dN/dX (E,Q,6,2)
        self.w = det * QW[None, :]
        self.area = self.w.sum()
        dofs = (2 * tris[:, :, None] + np.arange(2)[None, None, :]).reshape(len(tris), 12)
        self.dofs = dofs
        self.rows = np.repeat(dofs, 12, axis=1).ravel()
        self.cols = np.tile(dofs, (1, 12)).ravel()
        self.ndof = 2 * len(nodes)

    def assemble(self, u):
        ue = u[self.dofs].reshape(-1, 6, 2)
        F = np.eye(2) + np.einsum("ena,eqnJ->eqaJ", ue, self.G)
        P, A = material(F)
        re = np.einsum("eq,eqaJ,eqnJ->ena", self.w, P, self.G).reshape(-1, 12)
        Ke = np.einsum("eq,eqnJ,eqaJbL,eqmL->enamb", self.w, self.G, A, self.G).reshape(-1, 144)
        r = np.bincount(self.dofs.ravel(), re.ravel(), minlength=self.ndof)
        K = sp.csr_matrix((Ke.ravel(), (self.rows, self.cols)), shape=(self.ndof, self.ndof))
        return r, K


def solve(nt, nr, log=print, field=False):
    """Newton over STEPS load steps to D_FINAL. Returns (reactions (d, R) per step, elements,
    dofs), and with field=True also (nodes, tris, u) of the quarter model at the last step
    (u: 2·nodes, interleaved x, y) for evaluate()."""
    nodes, tris = mesh(nt, nr)
    m = Model(nodes, tris)
    tol = 1e-9
    x, y = nodes[:, 0], nodes[:, 1]
    eps = 1e-12
    right = np.where(abs(x - 1.0) < eps)[0]
    symx = np.where(abs(x - CX) < eps)[0]
    symy = np.where(abs(y - CY) < eps)[0]
    fixed = np.concatenate([2 * right, 2 * symx, 2 * symy + 1])
    fixed = np.unique(fixed)
    free = np.setdiff1d(np.arange(m.ndof), fixed)
    u = np.zeros(m.ndof)
    out = [(0.0, 0.0)]
    t0 = time.time()
    for step in range(1, STEPS + 1):
        d = D_FINAL * step / STEPS
        ub = np.zeros(m.ndof)
        ub[2 * right] = d
        ub[2 * symx] = d / 2
        ub[2 * symy + 1] = 0.0
        du_c = ub[fixed] - u[fixed]
        r, K = m.assemble(u)
        # consistent predictor: K_ff Δu_f = −r_f − K_fc Δu_c
        rhs = -r[free] - K[free][:, fixed] @ du_c
        u[fixed] = ub[fixed]
        hist = []
        for it in range(30):
            du = spla.spsolve(K[free][:, free].tocsc(), rhs)
            alpha = 1.0
            while True:
                try:
                    trial = u.copy(); trial[free] += alpha * du
                    r, K = m.assemble(trial)
                    break
                except FloatingPointError:
                    alpha *= 0.5
                    if alpha < 1e-4:
                        raise
            u = trial
            rn = np.linalg.norm(r[free]) / max(np.linalg.norm(r[fixed]), 1e-30)
            hist.append(rn)
            if rn < tol and np.linalg.norm(alpha * du) < 1e-9 * max(np.linalg.norm(u), 1e-3):
                break
            rhs = -r[free]
        else:
            raise RuntimeError(f"Newton did not converge at step {step}: {hist}")
        reaction = 2.0 * r[2 * right].sum()  # full plate (two symmetric quarters)
        out.append((d, reaction))
        log(f"  nt={nt} nr={nr} step {step:2d} d={d:.3f} R={reaction:.8f} it={len(hist)} "
            f"res={' '.join(f'{h:.1e}' for h in hist)}")
    area = 4 * m.area
    log(f"  mesh nt={nt} nr={nr}: {len(tris)} P2 triangles (quarter), {m.ndof} dofs, "
        f"area check {area:.10f} vs {L*L-np.pi*R*R:.10f}, {time.time()-t0:.1f} s")
    if field:
        return np.array(out), len(tris), m.ndof, (nodes, tris, u)
    return np.array(out), len(tris), m.ndof


def shape_values(xi, eta):
    """P2 shape functions N0..N5 (vertices, then mid 01, 12, 20) at (xi, eta), (..., 6)."""
    l0, l1, l2 = 1 - xi - eta, xi, eta
    return np.stack([l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1),
                     4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0], axis=-1)


def shape_grads(xi, eta):
    """shape_derivs for arrays of points: (..., 6, 2)."""
    l0, l1, l2 = 1 - xi - eta, xi, eta
    z = np.zeros_like(xi)
    dxi = np.stack([-(4 * l0 - 1), 4 * l1 - 1, z, 4 * (l0 - l1), 4 * l2, -4 * l2], axis=-1)
    deta = np.stack([-(4 * l0 - 1), z, 4 * l2 - 1, -4 * l1, 4 * l1, 4 * (l0 - l2)], axis=-1)
    return np.stack([dxi, deta], axis=-1)


def locate(nodes, tris, pts, candidates=12, iterations=12):
    """Element and reference coordinates (xi, eta) of each point pts (n, 2) of the quarter
    [0.5,1]² minus the hole: the isoparametric P2 map x(ξ) = Σ N_a(ξ) X_a is inverted by
    Newton in each of the `candidates` elements with the nearest centroids, and the element
    whose smallest barycentric coordinate is largest is taken (inside: ≥ 0; a point in the
    sliver between the circle and an element's parabolic hole edge, or round-off, gets the
    nearest element's polynomial, i.e. a short extrapolation). Returns (element (n,),
    xi (n,), eta (n,), smallest barycentric coordinate (n,))."""
    from scipy.spatial import cKDTree
    cen = nodes[tris[:, :3]].mean(axis=1)
    _, cand = cKDTree(cen).query(pts, k=min(candidates, len(tris)))
    cand = np.atleast_2d(cand)
    if len(pts) > 2048:  # chunks: the (n, k, 6, 2) work arrays stay a few MB
        parts = [locate(nodes, tris, pts[i:i + 2048], candidates, iterations)
                 for i in range(0, len(pts), 2048)]
        return tuple(np.concatenate([q[j] for q in parts]) for j in range(4))
    Xe = nodes[tris[cand]]  # (n, k, 6, 2)
    xi = np.full(cand.shape, 1.0 / 3.0)
    eta = np.full(cand.shape, 1.0 / 3.0)
    P = pts[:, None, :]
    for _ in range(iterations):
        N = shape_values(xi, eta)  # (n, k, 6)
        dref = shape_grads(xi, eta)  # (n, k, 6, 2)
        x = np.einsum("nka,nkai->nki", N, Xe)
        J = np.einsum("nkai,nkaj->nkij", Xe, dref)  # dx_i/dξ_j
        r = P - x
        det = J[..., 0, 0] * J[..., 1, 1] - J[..., 0, 1] * J[..., 1, 0]
        dxi = (J[..., 1, 1] * r[..., 0] - J[..., 0, 1] * r[..., 1]) / det
        deta = (-J[..., 1, 0] * r[..., 0] + J[..., 0, 0] * r[..., 1]) / det
        # keep the iterate near the element: a far-away candidate must not overflow
        xi = np.clip(xi + dxi, -2.0, 3.0)
        eta = np.clip(eta + deta, -2.0, 3.0)
    lam = np.minimum(np.minimum(xi, eta), 1 - xi - eta)
    best = np.argmax(lam, axis=1)
    n = np.arange(len(pts))
    return cand[n, best], xi[n, best], eta[n, best], lam[n, best]


def evaluate(nodes, tris, u, pts, d):
    """FEM displacement of the FULL plate at points pts (n, 2) of [0,1]² minus the hole, from
    the quarter solution (u interleaved x, y) by the symmetries of the quarter model:
    u_x(1 − x, y) = d − u_x(x, y), u_y(1 − x, y) = u_y(x, y) (antisymmetry of u_x − d/2 about
    x = 0.5) and u_x(x, 1 − y) = u_x(x, y), u_y(x, 1 − y) = −u_y(x, y) (mirror about y = 0.5);
    inside the containing element by its P2 shape functions. The field has u_y = 0 on
    y = 0.5 (the symmetric gauge; the full plate's pin at (0, 0) differs from it by a rigid
    translation in y). Returns (u (n, 2), smallest barycentric coordinate (n,))."""
    pts = np.asarray(pts, dtype=float)
    sx = pts[:, 0] < CX
    sy = pts[:, 1] < CY
    q = np.stack([np.where(sx, 2 * CX - pts[:, 0], pts[:, 0]),
                  np.where(sy, 2 * CY - pts[:, 1], pts[:, 1])], axis=1)
    e, xi, eta, lam = locate(nodes, tris, q)
    N = shape_values(xi, eta)  # (n, 6)
    ue = u.reshape(-1, 2)[tris[e]]  # (n, 6, 2)
    v = np.einsum("na,nai->ni", N, ue)
    v[:, 0] = np.where(sx, d - v[:, 0], v[:, 0])
    v[:, 1] = np.where(sy, -v[:, 1], v[:, 1])
    return v, lam


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--levels", type=int, default=4)
    ap.add_argument("--base", type=int, default=6, help="coarsest nt (elements along the boundary); nr = nt/2")
    ap.add_argument("--csv", default=None)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--bulk", type=float, default=10.0, help="bulk modulus K (mu = 1)")
    ap.add_argument("--plane", choices=["strain", "stress"], default="strain")
    args = ap.parse_args()
    global KAPPA, PLANE
    KAPPA, PLANE = args.bulk, args.plane
    if not check_material():
        sys.exit("material tangent check failed")
    if args.check:
        return
    results = []
    for lev in range(args.levels):
        nt = args.base * 2**lev
        nr = nt // 2
        res, ne, nd = solve(nt, nr)
        results.append((nt, nr, ne, nd, res))
        print(f"level {lev}: R(d=1) = {res[-1,1]:.10f}", flush=True)
    Rs = np.array([r[4][:, 1] for r in results])  # (levels, steps+1)
    # Richardson with the observed order from the last three levels (per step, then the order at d = 1)
    r1, r2, r3 = Rs[-3], Rs[-2], Rs[-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = (r2[-1] - r1[-1]) / (r3[-1] - r2[-1])
    p = np.log2(abs(ratio)) if np.isfinite(ratio) and abs(ratio) > 1 else 2.0
    ext = r3 + (r3 - r2) / (2**p - 1)
    print(f"observed order at d=1: p = {p:.2f}; R(d=1): " +
          ", ".join(f"{r[-1]:.8f}" for r in Rs) + f"; extrapolated {ext[-1]:.8f}")
    print(f"finest-vs-extrapolated max relative difference over steps: "
          f"{np.max(np.abs(r3[1:]-ext[1:])/np.abs(ext[1:])):.2e}")
    if args.csv:
        with open(args.csv, "w") as f:
            f.write(f"# Plate with a hole, plane-{PLANE} compressible Neo-Hookean, mu=1, K={KAPPA:g}, L=1, R=0.2,\n")
            f.write("# right edge u_x = d (u_y free), left edge u_x = 0 + pin, other edges free; unit thickness.\n")
            f.write(f"# Code: workflows/validation/plate_hole_fem.py (independent of pdcg): isoparametric P2 triangles,\n")
            f.write(f"#   total-Lagrangian Newton, quarter model by symmetry; numpy {np.__version__}, scipy {scipy.__version__}, python {sys.version.split()[0]}.\n")
            f.write("# Meshes (quarter, nt x nr quads -> 2 P2 triangles each): " +
                    "; ".join(f"{nt}x{nr}: {ne} elements, {nd} dofs" for nt, nr, ne, nd, _ in results) + "\n")
            f.write(f"# Columns: reaction on each mesh, and Richardson extrapolation of the last three with the observed order p = {p:.3f} (at d = 1).\n")
            f.write("# Regenerate: python3 workflows/validation/plate_hole_fem.py --levels "
                    f"{args.levels} --base {args.base}" + ("" if (PLANE, KAPPA) == ("strain", 10.0) else f" --plane {PLANE} --bulk {KAPPA:g}") +
                    f" --csv {args.csv}" + (" (or workflows/validation/run.sh)" if (PLANE, KAPPA) == ("strain", 10.0) else "") + "\n")
            f.write("step,d," + ",".join(f"R_{nt}x{nr}" for nt, nr, *_ in results) + ",R_extrapolated\n")
            for k in range(STEPS + 1):
                f.write(f"{k},{Rs[0][k] if False else results[0][4][k,0]:.6f}," +
                        ",".join(f"{Rs[l][k]:.10f}" for l in range(len(results))) + f",{ext[k]:.10f}\n")
        print(f"wrote {args.csv}")


if __name__ == "__main__":
    main()
