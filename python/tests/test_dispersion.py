"""pdcg.dispersion chooses what `pdcg dispersion` does (one library call, dispersion/plan.hpp):
a crystal with a basis gets its primitive cell's 3n branches along a labelled path, equal to the
CLI's CSV; a defective crystal is refused with the CLI's message in Python's option names.
On the code before the shared plan both fail: the binding refused --path on a crystal with a
basis ("cannot tell the Bravais lattice") and computed one-point curves for a vacancy body."""
import os
import re
import subprocess

import numpy as np
import pytest

import pdcg

SI = """units metal
boundary p p p
lattice diamond 5.431
region b block 0 2 0 2 0 2
create_box 2 b
create_atoms 1 region b
mass * 28.0855
"""
SW = "units metal\nmass * 28.0855\npair_style sw\npair_coeff * * Si.sw Si Si\n"


def si_body(tmp_path, lmp, pdcg_exe, name, vacancy=False):
    """Diamond Si (2×2×2 cubic cells, 64 atoms; with one atom deleted) written by LAMMPS and
    turned into a body by `pdcg atoms2pd` (the file both the CLI and Python read)."""
    lmp.commands_string(SI + ("group v id 1\ndelete_atoms group v\n" if vacancy else "")
                        + f"write_data {tmp_path / name}.data\n")
    (tmp_path / "sw.pot").write_text(SW)
    subprocess.run([pdcg_exe, "-q", "atoms2pd", "--input", str(tmp_path / f"{name}.data"),
                    "--potential", str(tmp_path / "sw.pot"), "-o", str(tmp_path / f"{name}.h5")],
                   check=True, capture_output=True,
                   env={**os.environ, "LAMMPS_POTENTIALS": os.environ.get(
                       "LAMMPS_POTENTIALS", "/usr/share/lammps/potentials")})
    return str(tmp_path / f"{name}.h5")


def test_crystal_with_basis_equals_cli(tmp_path, lmp, pdcg_exe):
    path = si_body(tmp_path, lmp, pdcg_exe, "si")
    d = pdcg.dispersion(pdcg.read_body(path), path="G-X-W-K-G-L", nk=4)
    out = subprocess.run([pdcg_exe, "dispersion", path, "--path", "G-X-W-K-G-L", "--nk", "4",
                          "-o", str(tmp_path / "si.csv")], check=True, capture_output=True,
                         text=True)
    assert "primitive cell of 2 basis atoms (6 branches" in out.stdout + out.stderr
    lines = (tmp_path / "si.csv").read_text().splitlines()
    corners = [(float(t.split("@")[1]), t.split("@")[0]) for t in lines[1].split(":", 1)[1].split()]
    rows = [ln for ln in lines if not ln.startswith("#")]
    names = rows[0].split(",")
    table = np.array([[float(v) for v in ln.split(",")] for ln in rows[1:]])
    omega = table[:, [names.index(f"omega_{i}") for i in range(1, 7)]]
    assert d.omega.shape == (21, 6) and omega.shape == (21, 6)
    assert [lab for _, lab in d.labels] == ["G", "X", "W", "K", "G", "L"]
    assert d.labels == corners and d.lattice == "fcc" and d.a == pytest.approx(5.431, rel=1e-9)
    np.testing.assert_array_equal(d.kappa, table[:, names.index("kappa")])
    np.testing.assert_array_equal(d.kvec, table[:, [names.index(c) for c in ("kx", "ky", "kz")]])
    # the same library call on the same file: equal up to the CSV's 17 digits (round trip exact;
    # 1e-12 of ω_max leaves room for nothing but the decimal text)
    assert np.abs(d.omega - omega).max() <= 1e-12 * np.abs(omega).max()
    assert (d.omega[0, :3] == 0).all() and d.omega[0, 3] > 100  # Γ: acoustic 0, optical ≈ 112


def test_vacancy_refused_with_cli_message(tmp_path, lmp, pdcg_exe):
    path = si_body(tmp_path, lmp, pdcg_exe, "si_v", vacancy=True)
    with pytest.raises(pdcg.InputError) as e:
        pdcg.dispersion(pdcg.read_body(path), path="G-X")
    cli = subprocess.run([pdcg_exe, "dispersion", path, "--path", "G-X", "-o",
                          str(tmp_path / "v.csv")], capture_output=True, text=True)
    assert cli.returncode == 2 and not (tmp_path / "v.csv").exists()
    msg = str(e.value)
    assert "path: path needs a perfect crystal" in msg and "--" not in msg
    # the CLI's message with Python's option names
    expected = cli.stderr.strip().split(f"{path}: ", 1)[1]
    for cli_name, py_name in (("--path", "path"), ("--cell", "cell=True"),
                              ("--lattice", "lattice"), ("--a", "a"), ("--point", "point")):
        expected = re.sub(re.escape(cli_name) + r"\b", py_name, expected)
    assert msg.strip() == expected
