#!/usr/bin/env python3
"""Statistical bodies against LAMMPS NVT at a temperature (docs/temperature.md).

    analyse.py OUT T [T ...]        (after md.in wrote OUT/T_<T>/; run.sh calls it)
    SYSTEM=cu analyse.py OUT T ...  (after md_cu.in wrote OUT/T_<T>/: Cu EAM, T in K, p in GPa;
                                     the Gaussian expectations by sampling, EAM being many-body)

Reference (LAMMPS, md.in): every 10 steps pe and the pressure tensor p (with and without its
kinetic part); mean and error bar from block averages (20 blocks; the error of the mean is the
standard deviation of the block means / √20). The Cauchy stress is σ = −p; below, the
pressure p = −tr σ / 3 is tabulated, and the largest |shear| as a check of cubic symmetry.

Models (pdcg atoms2pd + pdcg energy --stress, family radius 3.0 = cutoff 2.5 + 0.5 skin, so
every pair that comes within the cutoff in a frame is a bond):
  empirical    the frames themselves: E = mean frame energy, P = mean virial (exact, check)
  gaussian     per-atom mean and covariance of the frames, independent atoms, Gauss–Hermite
               order 4 (order 6 for the cubature error; halves of the frames for the error of
               the fitted covariances)
  decorrelated the frames with each atom's frame index permuted independently (5 shuffles):
               independent atoms with the frames' own (non-Gaussian) marginals
  einstein     `--temperature T` from the relaxed T = 0 lattice (local-harmonic widths)
  static       delta body of the mean positions (no fluctuation)
The kinetic part of the model stress is the ideal-gas term ρ k_B T (exact in the classical
canonical ensemble): p_total(model) = p_virial(model) + ρ k_B T.
"""
import csv
import json
import os
import random
import subprocess
import sys

import numpy as np

PDCG = os.environ.get("PDCG", "pdcg")
SYSTEM = os.environ.get("SYSTEM", "lj")  # lj: md.in; cu: md_cu.in (Cu EAM, units metal)
if SYSTEM == "lj":
    POTENTIAL = """units lj
atom_style atomic
mass 1 1.0
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0 2.5
pair_modify shift yes
"""
    FAMILY = "3.0"  # cutoff 2.5 + skin 0.5: relative displacements stay far below 0.5 at T ≤ 0.4
    KB = 1.0  # k_B in the energy unit per temperature unit
    MD_TO_UNIT = PD_TO_UNIT = 1.0  # pressures in ε/σ³
    # Gaussian expectation: Gauss–Hermite order 4 (pair potential), order 6 for its error
    GAUSS, GAUSS_CHECK = ["--order", "4"], ["--order", "6"]
else:
    POTENTIAL = """units metal
atom_style atomic
mass 1 63.55
pair_style eam
pair_coeff 1 1 Cu_u3.eam
"""
    # cutoff 4.95 Å + skin 1.0 Å: the 5th shell (5.72 Å) comes within the cutoff in some frames
    # at 900 K (skin 0.5 Å: the empirical body missed those pairs, p 4.4e-5 off the frames)
    FAMILY = "5.95"
    KB = 8.617333262e-5  # eV/K
    # bar → GPa; eV/Å³ → GPa with LAMMPS's own factor (nktv2p of units metal, 1.6021765e6 bar)
    MD_TO_UNIT, PD_TO_UNIT = 1e-4, 160.21765
    # EAM is many-body: the expectation by sampling joint draws (docs/bodies.md §2);
    # 4× the samples for its error
    GAUSS, GAUSS_CHECK = ["--samples", "500"], ["--samples", "2000"]
BLOCKS = 20
rows_failures = []


def pdcg(*args):
    subprocess.run([PDCG, "-q", *args], check=True, stdout=subprocess.DEVNULL,
                   cwd="/usr/share/lammps/potentials")


def energy(body):
    out = subprocess.run([PDCG, "-q", "energy", body, "--F", "1 0 0 0 1 0 0 0 1", "--json",
                          "--stress"], check=True, capture_output=True, text=True).stdout
    j = json.loads(out)
    return j["energy"], np.array(j["stress"]).reshape(3, 3) * PD_TO_UNIT, j["volume"]


def block_mean(x, blocks=BLOCKS):
    x = np.asarray(x, dtype=float)
    n = len(x) // blocks * blocks
    b = x[:n].reshape(blocks, -1).mean(axis=1)
    return float(x.mean()), float(b.std(ddof=1) / np.sqrt(blocks))


def read_dump(path):
    """Frames of a LAMMPS text dump: list of (header lines, ids, types, xyz, extra columns)."""
    frames = []
    with open(path) as f:
        lines = f.read().splitlines()
    i = 0
    while i < len(lines):
        assert lines[i].startswith("ITEM: TIMESTEP")
        n = int(lines[i + 3])
        head = lines[i:i + 9]
        cols = head[8].split()[2:]
        rows = np.array([l.split() for l in lines[i + 9:i + 9 + n]], dtype=float)
        frames.append((head, cols, rows))
        i += 9 + n
    return frames


def write_dump(path, frames):
    with open(path + ".tmp", "w") as f:
        for head, cols, rows in frames:
            f.write("\n".join(head[:8]) + "\nITEM: ATOMS id type x y z\n")
            for r in rows:
                f.write(f"{int(r[0])} {int(r[1])} {r[2]!r} {r[3]!r} {r[4]!r}\n")
    os.replace(path + ".tmp", path)


def box_lengths(head):
    return np.array([float(head[5 + a].split()[1]) - float(head[5 + a].split()[0])
                     for a in range(3)])


def analyse(out, T):
    d = os.path.join(out, f"T_{T}")
    T = float(T)
    with open(os.path.join(d, "potential.in"), "w") as f:
        f.write(POTENTIAL)
    pot = os.path.join(d, "potential.in")
    th = np.loadtxt(os.path.join(d, "thermo.txt"))
    fr = np.loadtxt(os.path.join(d, "frames.txt"))
    th[:, 2:14] *= MD_TO_UNIT
    fr[:, 2:8] *= MD_TO_UNIT
    frames = read_dump(os.path.join(d, "frames.dump"))
    N = len(frames[0][2])
    L = box_lengths(frames[0][0])
    V = float(np.prod(L))
    rho = N / V
    kin = rho * KB * T * PD_TO_UNIT  # ideal-gas pressure ρ k_B T
    rows = []

    def row(name, e, e_err, pv, pv_err, shear, note=""):
        rows.append(dict(T=T, model=name, e_per_atom=e, e_err=e_err, p_virial=pv,
                         p_virial_err=pv_err, p_total=pv + (kin if name != "MD" else 0),
                         max_shear=shear, note=note))

    # MD: every 10 steps; p total = thermo p, p virial = compute pressure NULL virial
    e, ee = block_mean(th[:, 1])
    pt, pte = block_mean(th[:, 2:5].mean(axis=1))
    pv, pve = block_mean(th[:, 8:11].mean(axis=1))
    shear = float(np.abs(th[:, 5:8].mean(axis=0)).max())
    rows.append(dict(T=T, model="MD", e_per_atom=e, e_err=ee, p_virial=pv, p_virial_err=pve,
                     p_total=pt, max_shear=shear, note=f"±{pte:.2g} (p total)"))
    # the dumped frames' own values (what the models see)
    fe, fee = block_mean(fr[:, 1], 10)
    fp, fpe = block_mean(fr[:, 2:5].mean(axis=1), 10)
    row("MD frames", fe, fee, fp, fpe, float(np.abs(fr[:, 5:8].mean(axis=0)).max()),
        f"{len(fr)} frames every {int(fr[1, 0] - fr[0, 0])} steps")

    def model(name, body, note="", err=0.0, perr=0.0):
        E, P, vol = energy(body)
        row(name, E / N, err, -np.trace(P) / 3, perr,
            float(max(abs(P[0, 1]), abs(P[0, 2]), abs(P[1, 2]))), note)
        return E / N, -np.trace(P) / 3

    dump = os.path.join(d, "frames.dump")
    nf = len(frames)
    pdcg("atoms2pd", "--input", dump, "--frames", "0:-1", "--potential", pot, "--density",
         "statistical", "--statistics", "empirical", "--family-cutoff", FAMILY, "-o",
         os.path.join(d, "empirical.h5"))
    model("empirical", os.path.join(d, "empirical.h5"), "the frames (exact: = MD frames)", fee, fpe)
    for name, rule in (("gauss4", GAUSS), ("gauss6", GAUSS_CHECK)):
        pdcg("atoms2pd", "--input", dump, "--frames", "0:-1", "--potential", pot, "--density",
             "statistical", *rule, "--family-cutoff", FAMILY, "-o", os.path.join(d, f"{name}.h5"))
    g6 = energy(os.path.join(d, "gauss6.h5"))
    half = nf // 2
    halves = []
    for a, b in ((0, half - 1), (half, nf - 1)):
        h = os.path.join(d, f"gauss_{a}.h5")
        pdcg("atoms2pd", "--input", dump, "--frames", f"{a}:{b}", "--potential", pot,
             "--density", "statistical", *GAUSS, "--family-cutoff", FAMILY, "-o", h)
        halves.append(energy(h))
    herr = abs(halves[0][0] - halves[1][0]) / 2 / N
    hperr = abs(np.trace(halves[0][1]) - np.trace(halves[1][1])) / 6
    E4, P4, _ = energy(os.path.join(d, "gauss4.h5"))
    cub = abs(E4 - g6[0]) / N
    model("gaussian", os.path.join(d, "gauss4.h5"),
          f"{' '.join(GAUSS)}; |{' '.join(GAUSS_CHECK)} − that| = {cub:.1e}; error: halves of "
          "the frames", herr, hperr)
    # decorrelated frames: each atom's frame index permuted independently, 5 shuffles
    rng = random.Random(12345)
    ids = frames[0][2][:, 0].astype(int)
    order_by_id = [np.argsort(f[2][:, 0]) for f in frames]
    pos = np.array([f[2][o][:, 2:5] for f, o in zip(frames, order_by_id)])  # S×N×3, id order
    # unwrap against frame 0 (minimum image), as pdcg does
    dd = pos - pos[0]
    dd -= L * np.round(dd / L)
    pos = pos[0] + dd
    shuffled = []
    for s in range(5):
        perm = np.array([rng.sample(range(nf), nf) for _ in range(N)]).T  # S×N
        for f in range(nf):
            head, cols, _ = frames[f]
            r = np.zeros((N, 5))
            r[:, 0] = np.sort(ids)
            r[:, 1] = 1
            r[:, 2:5] = pos[perm[f], np.arange(N)]
            h2 = list(head)
            h2[1] = str(s * nf + f)
            shuffled.append((h2, cols, r))
    write_dump(os.path.join(d, "decorrelated.dump"), shuffled)
    pdcg("atoms2pd", "--input", os.path.join(d, "decorrelated.dump"), "--frames", "0:-1",
         "--potential", pot, "--density", "statistical", "--statistics", "empirical",
         "--family-cutoff", FAMILY, "-o", os.path.join(d, "decorrelated.h5"))
    model("decorrelated frames", os.path.join(d, "decorrelated.h5"),
          f"{len(shuffled)} shuffled frames")
    # static lattice of the means, and the --temperature estimate on the relaxed lattice
    mean = pos.mean(axis=0)
    r = np.zeros((N, 5))
    r[:, 0] = np.sort(ids)
    r[:, 1] = 1
    r[:, 2:5] = mean
    write_dump(os.path.join(d, "mean.dump"), [(frames[0][0], None, r)])
    pdcg("atoms2pd", "--input", os.path.join(d, "mean.dump"), "--potential", pot, "--density",
         "delta", "--family-cutoff", FAMILY, "-o", os.path.join(d, "static.h5"))
    model("static (means)", os.path.join(d, "static.h5"), "no fluctuation")
    lattice = os.path.join(d, "lattice.dump")
    pdcg("atoms2pd", "--input", lattice, "--potential", pot, "--density", "statistical",
         "--temperature", str(T), *GAUSS, "--family-cutoff", FAMILY, "-o",
         os.path.join(d, "einstein.h5"))
    model("einstein (--temperature)", os.path.join(d, "einstein.h5"),
          f"local-harmonic widths, {' '.join(GAUSS)}")
    # widths: fitted (frames) vs --temperature
    var_fit = float(dd.var(axis=0).mean())  # per direction, averaged over atoms and x y z
    import h5py
    with h5py.File(os.path.join(d, "einstein.h5"), "r") as f:
        c = np.array(f["statistics/covariance"])
    var_ein = float(np.mean([np.trace(m) / 3 for m in c]))
    # acceptance (exit 1 in main): the empirical body is the frames' LAMMPS average (round-off
    # of 17-digit dumps); the Gaussian equals the decorrelated frames within 4 errors of its
    # fitted covariances plus the cubature error (non-Gaussian marginals: docs/temperature.md)
    by = {r["model"]: r for r in rows}
    emp, frm = by["empirical"], by["MD frames"]
    g, dec = by["gaussian"], by["decorrelated frames"]
    failures = []
    if abs(emp["e_per_atom"] - frm["e_per_atom"]) > 1e-9 * abs(frm["e_per_atom"]):
        failures.append(f"T={T}: empirical E/N {emp['e_per_atom']} != frames {frm['e_per_atom']}")
    if abs(emp["p_virial"] - frm["p_virial"]) > 1e-8 * abs(frm["p_virial"]):
        failures.append(f"T={T}: empirical p {emp['p_virial']} != frames {frm['p_virial']}")
    if abs(g["e_per_atom"] - dec["e_per_atom"]) > 4 * herr + cub + 1e-5:
        failures.append(f"T={T}: gaussian E/N {g['e_per_atom']} vs decorrelated {dec['e_per_atom']}")
    rows_failures.extend(failures)
    return rows, dict(T=T, var_fitted=var_fit, var_einstein=var_ein,
                      ratio=var_fit / var_ein, cubature_4_vs_6=cub)


def main():
    out = os.path.abspath(sys.argv[1])
    rows, widths = [], []
    for T in sys.argv[2:]:
        r, w = analyse(out, T)
        rows += r
        widths.append(w)
    with open(os.path.join(out, "table.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(out, "widths.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(widths[0].keys()))
        w.writeheader()
        w.writerows(widths)
    md = ["| T* | model | E/N | p virial | p total | max shear | note |",
          "|---:|---|---:|---:|---:|---:|---|"]
    for r in rows:
        e = f"{r['e_per_atom']:.5f}" + (f" ± {r['e_err']:.1e}" if r["e_err"] else "")
        p = f"{r['p_virial']:.4f}" + (f" ± {r['p_virial_err']:.1e}" if r["p_virial_err"] else "")
        md.append(f"| {r['T']} | {r['model']} | {e} | {p} | {r['p_total']:.4f} | "
                  f"{r['max_shear']:.1e} | {r['note']} |")
    md += ["", "| T* | ⟨u²⟩ per direction, frames | --temperature | ratio |", "|---:|---:|---:|---:|"]
    for w in widths:
        md.append(f"| {w['T']} | {w['var_fitted']:.3e} | {w['var_einstein']:.3e} | "
                  f"{w['ratio']:.3f} |")
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    print("\n".join(md))
    if rows_failures:
        print("FAILED:\n  " + "\n  ".join(rows_failures))
        sys.exit(1)


if __name__ == "__main__":
    main()
