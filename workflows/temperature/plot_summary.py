#!/usr/bin/env python3
"""Summary figure of docs/temperature.md: each model against MD at a temperature.

    plot_summary.py [--lj DIR] [--cu DIR] [-o docs/img/temperature_summary.png]

One PNG, a row per system (fcc LJ, lj/cut 2.5 shifted, T* = 0.05 0.2 0.4; Cu EAM Cu_u3.eam,
300 600 900 K), panels against T: the thermal energy per atom E − E_static (E_static: the
delta body of the mean positions at that T), the total pressure at the T = 0 volume, and the
isothermal C11, C12, C44. MD with its block-average error bars; models: static, the fitted
Gaussian (independent atoms), Einstein (`--temperature`), quasi-harmonic (`--quasi-harmonic`).

Where the numbers come from. Nothing here is computed from a model; every value is read:
  * by default from the tables of docs/temperature.md (this script parses them): §2 and §2.1
    (E/N, p total of MD, gaussian, einstein, static; a model's p error is that of its p virial),
    §3 (LJ: the quasi-harmonic pressure table and the isothermal-stiffness table), §3.1 (Cu: the
    stiffness table, quasi-harmonic column = the secant slopes over ±0.01, MD's protocol, as
    LJ's; its thermal pressure from the sentence "p the thermal pressure of the model: …"
    under that table);
  * with --lj/--cu DIR, from the workflow's own outputs where they exist: DIR/table.csv
    (analyse.py: E/N, its error, p total, per T and model) and DIR/qha.txt (qha.py, LJ only),
    which replace the rows of the document at the temperatures they hold; each such value is
    checked against the document's printed digits (a mismatch stops the script: the page and
    the outputs disagree). The stiffness has no output file in the runs kept so far
    (elastic.py writes DIR/elastic.md, which is not parsed); it always comes from the document.
  * one closed form, stated in §3: the quasi-harmonic thermal energy at fixed volume,
    (3N − 3)/(2N) k_B T (N = 256, k_B = 8.617333e-5 eV/K for Cu), drawn as a line.
The statistical bodies (gaussian, einstein) have no C_IJ in the document (their d²W/dF² is not
the isothermal stiffness, §3), so the C_IJ panels show MD, quasi-harmonic and static only.
matplotlib Agg; ~1 s; writes a PNG of ≈ 100 kB.
"""
import argparse
import csv
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
DOC = os.path.join(ROOT, "docs", "temperature.md")
N_ATOMS = 256  # 4×4×4 fcc cells of md.in / md_cu.in
KB = {"lj": 1.0, "cu": 8.617333262e-5}  # k_B in energy/temperature units (lj; eV/K)
MODELS = {  # model row of the §2 / §2.1 tables -> key
    "MD (every 10 steps)": "md",
    "gaussian": "gaussian",
    "einstein (`--temperature`)": "einstein",
    "static (means)": "static",
}
CSV_MODELS = {"MD": "md", "gaussian": "gaussian", "einstein (--temperature)": "einstein",
              "static (means)": "static"}


def num(s):
    """'−7.38917 ± 1.9e-4' -> (value, error or None); '**+3.8 %**' -> 3.8."""
    s = s.replace("−", "-").replace("*", "").replace("%", "").strip()
    if "±" in s:
        v, e = s.split("±")
        return float(v), float(e)
    return float(s), None


def tables(text):
    """Every markdown table of the page: (heading it sits under, header cells, rows of cells)."""
    out, head, cur, heading = [], None, None, ""
    for line in text.splitlines():
        s = line.strip()
        if line.startswith("#"):
            heading = line.lstrip("#").strip()
        if s.startswith("|"):
            cells = [c.strip() for c in s.strip("|").split("|")]
            if cur is None:
                head, cur = cells, []
            elif not all(re.fullmatch(r":?-+:?", c) for c in cells):
                cur.append(cells)
        elif cur is not None:
            out.append((heading, head, cur))
            cur = None
    if cur is not None:
        out.append((heading, head, cur))
    return out


def find(tabs, section, first_cells):
    hits = [t for t in tabs if t[0].startswith(section) and len(t[1]) >= len(first_cells)
            and all(h == c or (c and h.startswith(c)) for h, c in zip(t[1], first_cells))]
    if len(hits) != 1:
        sys.exit(f"{DOC}: expected one table {first_cells} under '{section}', found {len(hits)}")
    return hits[0]


def from_doc():
    text = open(DOC, encoding="utf-8").read()
    tabs = tables(text)
    data = {"lj": {}, "cu": {}}
    src = {"lj": {}, "cu": {}}
    # E/N and p total per model (§2, §2.1)
    for sys_, sec, tcol in (("lj", "2. Results", "T*"), ("cu", "2.1 Cu", "T (K)")):
        _, head, rows = find(tabs, sec, [tcol, "model", "E/N"])
        ie, iv, ip = 2, head.index("p virial"), head.index("p total")
        for r in rows:
            if r[1] not in MODELS:
                continue
            T = float(r[0])
            e, de = num(r[ie])
            p, dp = num(r[ip])
            if dp is None:  # p total = p virial + ρ k_B T (a constant): the virial's error
                dp = num(r[iv])[1]
            d = data[sys_].setdefault(T, {})
            d[MODELS[r[1]]] = dict(E=e, dE=de, p=p, dp=dp)
            src[sys_][(T, MODELS[r[1]], "E/p")] = f"docs §{sec.split()[0]}"
    # LJ quasi-harmonic pressure (§3 table)
    _, head, rows = find(tabs, "3. What", ["T*", "p total, MD", "quasi-harmonic"])
    for r in rows:
        T = float(r[0])
        data["lj"][T].setdefault("qha", {})["p"] = num(r[2])[0]
        src["lj"][(T, "qha", "p")] = "docs §3 pressure table"
    # Cu quasi-harmonic thermal pressure (§3.1, sentence under the stiffness table)
    m = re.search(r"p the thermal pressure\s+of the model: ([0-9.]+), ([0-9.]+), ([0-9.]+) GPa",
                  text.replace("\n", " "))
    if not m:
        sys.exit(f"{DOC}: §3.1 sentence 'p the thermal pressure of the model: …' not found")
    for T, v in zip(sorted(data["cu"]), m.groups()):
        data["cu"][T].setdefault("qha", {})["p"] = float(v)
        src["cu"][(T, "qha", "p")] = "docs §3.1 text"
    # isothermal stiffness: LJ (§3), Cu (§3.1)
    for sys_, sec, tcol, qcol in (("lj", "3. What", "T*", "quasi-harmonic"),
                                  ("cu", "3.1", "T (K)", "quasi-harmonic, secant ±0.01")):
        _, head, rows = find(tabs, sec, [tcol, ""])
        im, iq, is_ = 2, head.index(qcol), head.index("static lattice")
        for r in rows:
            T, k = float(r[0]), r[1]
            d = data[sys_][T]
            d["md"][k], d["md"]["d" + k] = num(r[im])
            d.setdefault("qha", {})[k] = num(r[iq])[0]
            d["static"][k] = num(r[is_])[0]
    return data, src


def digits(s):
    """Number of decimals the document prints for a value."""
    s = s.replace("−", "-").split("±")[0].strip()
    if "e" in s:
        return None
    return len(s.split(".")[1]) if "." in s else 0


def from_outputs(data, src, sys_, d):
    """Replace the document's E/N and p total by DIR/table.csv (and the LJ quasi-harmonic
    pressure by DIR/qha.txt) where they exist; check them against the printed digits."""
    used = []
    path = os.path.join(d, "table.csv")
    if os.path.exists(path):
        for r in csv.DictReader(open(path)):
            key = CSV_MODELS.get(r["model"])
            T = float(r["T"])
            if key is None or T not in data[sys_]:
                continue
            doc = data[sys_][T][key]
            new = dict(E=float(r["e_per_atom"]), p=float(r["p_total"]),
                       dE=float(r["e_err"]) or None, dp=float(r["p_virial_err"]) or None)
            if key == "md":  # MD's p total error is in the note ("±0.0012 (p total)")
                m = re.search(r"±([0-9.e-]+) \(p total\)", r["note"])
                new["dp"] = float(m.group(1)) if m else doc["dp"]
            for q, nd in (("E", 5), ("p", 4)):
                if abs(new[q] - doc[q]) > 0.51 * 10 ** -nd:
                    sys.exit(f"{path}: {sys_} T = {T:g} {key} {q} = {new[q]} but {DOC} prints "
                             f"{doc[q]}: the page and the workflow's output disagree")
            doc.update(new)
            src[sys_][(T, key, "E/p")] = path
            used.append((T, key))
    path = os.path.join(d, "qha.txt")
    if sys_ == "lj" and os.path.exists(path):
        for line in open(path):
            f = line.strip().split(",")
            try:
                T, p = float(f[0]), float(f[1])
            except (ValueError, IndexError):
                continue
            if T in data[sys_]:
                doc = data[sys_][T]["qha"]
                if abs(p - doc["p"]) > 0.51e-4:
                    sys.exit(f"{path}: T = {T:g} quasi-harmonic p = {p} but {DOC} prints {doc['p']}")
                doc["p"] = p
                src[sys_][(T, "qha", "p")] = path
                used.append((T, "qha p"))
    return used


STYLE = {  # key: (label, colour, marker, linestyle)
    "static": ("static (delta body / T = 0 lattice)", "k", "s", ":"),
    "gaussian": ("gaussian (fitted, independent atoms)", "tab:red", "v", "--"),
    "einstein": ("einstein (--temperature)", "tab:orange", "^", "--"),
    "qha": ("quasi-harmonic free energy", "tab:blue", "o", "-"),
}


def plot(data, path):
    fig, axes = plt.subplots(2, 5, figsize=(17, 6.6))
    for row, sys_ in enumerate(("lj", "cu")):
        D = data[sys_]
        Ts = sorted(D)
        lj = sys_ == "lj"
        tl = "T* (k_B T/ε)" if lj else "T (K)"
        eu, pu, cu_ = ("ε", "ε/σ³", "ε/σ³") if lj else ("eV", "GPa", "GPa")
        name = "fcc LJ (lj/cut 2.5)" if lj else "fcc Cu (EAM Cu_u3)"
        # thermal energy E − E_static
        ax = axes[row, 0]
        base = [D[T]["static"]["E"] for T in Ts]
        ax.errorbar(Ts, [D[T]["md"]["E"] - b for T, b in zip(Ts, base)],
                    yerr=[D[T]["md"]["dE"] for T in Ts], fmt="o", color="tab:green", ms=6,
                    capsize=4, label="MD (NVT, block errors)", zorder=5)
        for k in ("static", "gaussian", "einstein"):
            lab, c, mk, ls = STYLE[k]
            ax.errorbar(Ts, [D[T][k]["E"] - b for T, b in zip(Ts, base)],
                        yerr=[D[T][k]["dE"] or 0 for T in Ts], color=c, marker=mk, ls=ls,
                        ms=4, capsize=3, label=lab)
        lab, c, mk, ls = STYLE["qha"]
        ax.plot(Ts, [(3 * N_ATOMS - 3) / (2 * N_ATOMS) * KB[sys_] * T for T in Ts], color=c,
                ls=ls, label="quasi-harmonic, (3N−3)/(2N) k_B T")
        ax.set_title(f"{name}: E − E_static per atom", fontsize=9)
        ax.set_ylabel(eu)
        # total pressure at the T = 0 volume
        ax = axes[row, 1]
        ax.errorbar(Ts, [D[T]["md"]["p"] for T in Ts], yerr=[D[T]["md"]["dp"] for T in Ts],
                    fmt="o", color="tab:green", ms=6, capsize=4, label="MD", zorder=5)
        for k in ("static", "gaussian", "einstein", "qha"):
            lab, c, mk, ls = STYLE[k]
            ax.errorbar(Ts, [D[T][k]["p"] for T in Ts],
                        yerr=[D[T][k].get("dp") or 0 for T in Ts], color=c, marker=mk, ls=ls,
                        ms=4, capsize=3, label=lab)
        ax.set_title("p total (+ ρk_BT for the bodies), T = 0 volume", fontsize=9)
        ax.set_ylabel(pu)
        # isothermal C11, C12, C44
        for j, k in enumerate(("C11", "C12", "C44")):
            ax = axes[row, 2 + j]
            ax.errorbar(Ts, [D[T]["md"][k] for T in Ts], yerr=[D[T]["md"]["d" + k] for T in Ts],
                        fmt="o", color="tab:green", ms=6, capsize=4,
                        label="MD (strains ±0.01)", zorder=5)
            for m in ("static", "qha"):
                lab, c, mk, ls = STYLE[m]
                ax.plot(Ts, [D[T][m][k] for T in Ts], color=c, marker=mk, ls=ls, ms=4,
                        label="static lattice (T = 0)" if m == "static" else
                        lab + " (secant ±0.01)")
            mds = [D[T]["md"][k] for T in Ts]
            ax.fill_between(Ts, [0.97 * v for v in mds], [1.03 * v for v in mds],
                            color="tab:green", alpha=0.12, lw=0, label="MD ± 3 %")
            ax.set_title(f"isothermal {k}", fontsize=9)
            ax.set_ylabel(cu_)
        for ax in axes[row]:
            ax.set_xlabel(tl)
            ax.set_xticks(Ts)
            ax.tick_params(labelsize=8)
        axes[row, 0].legend(fontsize=6.5, loc="upper left")
        axes[row, 2].legend(fontsize=6.5, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=80)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lj", help="LJ output directory of run.sh (table.csv, qha.txt)")
    ap.add_argument("--cu", help="Cu output directory of SYSTEM=cu run.sh (table.csv)")
    ap.add_argument("-o", default=os.path.join(ROOT, "docs", "img", "temperature_summary.png"))
    a = ap.parse_args()
    data, src = from_doc()
    for sys_, d in (("lj", a.lj), ("cu", a.cu)):
        if d:
            used = from_outputs(data, src, sys_, d)
            print(f"{sys_}: from {d}: " + (", ".join(f"T={T:g} {k}" for T, k in used) or "nothing"))
    plot(data, a.o)
    for sys_ in ("lj", "cu"):
        for T in sorted(data[sys_]):
            D = data[sys_][T]
            print(f"{sys_} T={T:g}: " + "; ".join(
                f"{k} E={D[k]['E']:.5f} p={D[k]['p']:.4f}" for k in ("md", "static", "gaussian",
                                                                      "einstein"))
                + f"; qha p={D['qha']['p']:.4f}; C11/C12/C44 MD "
                + "/".join(f"{D['md'][c]:.2f}±{D['md']['d' + c]:.2f}" for c in ("C11", "C12", "C44"))
                + " QH " + "/".join(f"{D['qha'][c]:.2f}" for c in ("C11", "C12", "C44")))
    print(f"wrote {a.o} ({os.path.getsize(a.o) / 1024:.0f} kB)")


if __name__ == "__main__":
    main()
