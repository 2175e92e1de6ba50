"""The rest of the API against the `pdcg` command on the same files (same library calls:
exact equality) and against closed forms (mass conservation of homogenisation, ω(Γ) = 0)."""
import json
import subprocess

import numpy as np
import pytest

import pdcg

LJ = "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n"


def fcc_dump(path, frames=3, a=1.5496, n=3, jitter=0.0):
    """A dump of an fcc LJ crystal (near its zero-stress lattice constant), n³ cells."""
    rng = np.random.default_rng(11)
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    x = np.array([(np.array([i, j, k]) + b) * a for i in range(n) for j in range(n)
                  for k in range(n) for b in basis])
    with open(path, "w") as f:
        for s in range(frames):
            y = x + jitter * rng.standard_normal(x.shape)
            f.write(f"ITEM: TIMESTEP\n{s}\nITEM: NUMBER OF ATOMS\n{len(x)}\n"
                    f"ITEM: BOX BOUNDS pp pp pp\n0 {n*a}\n0 {n*a}\n0 {n*a}\n"
                    "ITEM: ATOMS id type x y z\n")
            for i, p in enumerate(y):
                f.write(f"{i+1} 1 {p[0]:.12f} {p[1]:.12f} {p[2]:.12f}\n")
    return x


def test_read_atoms_frames(tmp_path):
    x = fcc_dump(tmp_path / "d.lammpstrj", jitter=0.01)
    a = pdcg.read_atoms(str(tmp_path / "d.lammpstrj"), frame=-1)
    assert a.timestep == 2 and len(a) == len(x)
    assert a.positions.shape == (len(x), 3) and a.box["periodic"] == (True, True, True)
    frames = pdcg.read_frames(str(tmp_path / "d.lammpstrj"), "0:2")
    assert [f.timestep for f in frames] == [0, 1, 2]


def test_pipeline_equals_cli(tmp_path, pdcg_exe):
    fcc_dump(tmp_path / "d.lammpstrj", frames=1)
    (tmp_path / "lj.in").write_text(LJ)
    body = pdcg.delta_body(pdcg.read_atoms(str(tmp_path / "d.lammpstrj")),
                           potential=str(tmp_path / "lj.in"))
    subprocess.run([pdcg_exe, "-q", "atoms2pd", "--input", str(tmp_path / "d.lammpstrj"),
                    "--potential", str(tmp_path / "lj.in"), "-o", str(tmp_path / "b.h5")],
                   check=True, capture_output=True)
    cli_body = pdcg.read_body(str(tmp_path / "b.h5"))
    np.testing.assert_array_equal(body.forces(), cli_body.forces())
    assert body.energy() == cli_body.energy()
    # homogenisation conserves mass: Σ_p m_p = Σ_k M_k (docs/theory.md §3; 1e-12: round-off)
    hom = pdcg.homogenize(body, kernel="wendland-c2", width=2.0, spacing=1.5496)
    assert abs(hom.point_masses.sum() / body.masses.sum() - 1) < 1e-12
    assert abs(hom.point_energies().sum() / body.energy() - 1) < 1e-12
    # elastic constants: the CLI's JSON, same numbers
    r = subprocess.run([pdcg_exe, "-q", "elastic", str(tmp_path / "b.h5"), "--json"],
                       check=True, capture_output=True, text=True)
    ref = json.loads(r.stdout)
    el = pdcg.elastic(body)
    np.testing.assert_array_equal(el.C_voigt, np.array(ref["C_voigt"]))
    assert el.unit == ref["unit"]
    assert el.C_voigt[0, 1] == pytest.approx(el.C_voigt[1, 0], rel=1e-12)
    # dispersion along a labelled path: the CLI's CSV, same numbers; ω(Γ) = 0
    d = pdcg.dispersion(body, path="G-X-W-K-G-L", nk=4)
    assert [lab for _, lab in d.labels] == ["G", "X", "W", "K", "G", "L"]
    assert d.omega.shape == (21, 3) and np.abs(d.omega[0]).max() < 1e-6
    subprocess.run([pdcg_exe, "-q", "dispersion", str(tmp_path / "b.h5"), "--path",
                    "G-X-W-K-G-L", "--nk", "4", "-o", str(tmp_path / "d.csv")], check=True,
                   capture_output=True)
    lines = [ln for ln in (tmp_path / "d.csv").read_text().splitlines() if not ln.startswith("#")]
    names = lines[0].split(",")
    table = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    np.testing.assert_array_equal(d.kappa, table[:, names.index("kappa")])
    np.testing.assert_array_equal(d.omega[:, 2], table[:, names.index("omega_3")])
    dd = pdcg.dispersion(body, direction=(1, 0, 0), nk=5)
    assert dd.kappa[-1] == pytest.approx(2 * np.pi / 1.5496, rel=1e-9)  # fcc [100] zone edge 2π/a


def test_statistical_body(tmp_path):
    fcc_dump(tmp_path / "d.lammpstrj", frames=4, jitter=0.02)
    frames = pdcg.read_frames(str(tmp_path / "d.lammpstrj"), "0:3")
    sb = pdcg.statistical_body(frames, commands=LJ, order=3)
    assert sb.kind == "statistical" and len(sb) == 108
    one = pdcg.statistical_body(frames[0], commands=LJ, width=0.01)
    assert np.isfinite(one.energy())


def test_statistical_body_temperature_and_stress(tmp_path, pdcg_exe):
    """temperature= gives the CLI's --temperature body; Body.stress equals `pdcg energy
    --stress` (the same library call), and 300 in lj units is refused by both."""
    fcc_dump(tmp_path / "d.lammpstrj", frames=1)
    (tmp_path / "lj.in").write_text(LJ)
    frame = pdcg.read_atoms(str(tmp_path / "d.lammpstrj"))
    b = pdcg.statistical_body(frame, commands=LJ, temperature=0.2, order=4)
    b.write(str(tmp_path / "py.h5"))
    out = subprocess.run([pdcg_exe, "-q", "energy", str(tmp_path / "py.h5"), "--F",
                          "1.01 0 0 0 1 0 0 0 1", "--json", "--stress"],
                         check=True, capture_output=True, text=True).stdout
    cli = np.array(json.loads(out)["stress"]).reshape(3, 3)
    # same call on the same body; OpenMP's reduction order may differ between the two runs
    np.testing.assert_allclose(b.stress([1.01, 0, 0, 0, 1, 0, 0, 0, 1]), cli, rtol=1e-12,
                               atol=1e-12 * np.abs(cli).max())
    with pytest.raises(pdcg.InputError, match="kelvin"):
        pdcg.statistical_body(frame, commands=LJ, temperature=300)
    r = subprocess.run([pdcg_exe, "atoms2pd", "--input", str(tmp_path / "d.lammpstrj"),
                        "--potential", str(tmp_path / "lj.in"), "--density", "statistical",
                        "--temperature", "300", "-o", str(tmp_path / "t.h5")],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "--temperature" in r.stderr and "kelvin" in r.stderr, r.stderr


def test_stub_names_the_api():
    """pdcg/__init__.pyi declares every public name (the stub does not drift from the API)."""
    import ast
    import os
    stub = os.path.join(os.path.dirname(pdcg.__file__), "__init__.pyi")
    tree = ast.parse(open(stub).read())
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
    assert set(pdcg.__all__) <= names, set(pdcg.__all__) - names
