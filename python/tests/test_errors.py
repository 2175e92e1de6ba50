"""pdcg's errors arrive as Python exceptions with the messages of the `pdcg` command (the
same library call raises them): pdcg.InputError (also a ValueError) and pdcg.NumericalError,
both pdcg.Error."""
import subprocess

import pytest

import pdcg

LJ = "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n"
DUMP = """ITEM: TIMESTEP
0
ITEM: NUMBER OF ATOMS
2
ITEM: BOX BOUNDS pp pp pp
0 5
0 5
0 5
ITEM: ATOMS id type x y z
1 1 1.0 1.0 1.0
2 1 2.1 1.0 abc
"""


def cli_error(exe, *args):
    r = subprocess.run([exe, *args], capture_output=True, text=True)
    assert r.returncode == 2, r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert line.startswith("pdcg: error: ")
    return line[len("pdcg: error: "):]


def test_hierarchy():
    assert issubclass(pdcg.InputError, pdcg.Error)
    assert issubclass(pdcg.InputError, ValueError)
    assert issubclass(pdcg.NumericalError, pdcg.Error)
    assert issubclass(pdcg.Error, RuntimeError)


def test_bad_dump_same_message_as_cli(tmp_path, pdcg_exe):
    dump = tmp_path / "bad.lammpstrj"
    dump.write_text(DUMP)
    pot = tmp_path / "lj.in"
    pot.write_text(LJ)
    with pytest.raises(pdcg.InputError) as e:
        pdcg.read_atoms(str(dump), frame=0)
    msg = cli_error(pdcg_exe, "atoms2pd", "--input", str(dump), "--potential", str(pot),
                    "-o", str(tmp_path / "b.h5"))
    assert str(e.value) == msg
    assert "bad.lammpstrj:11:" in msg  # file and line of the bad value (line 11: atom 2)


def test_bad_kernel_same_message_as_cli(tmp_path, pdcg_exe):
    dump = tmp_path / "ok.lammpstrj"
    dump.write_text(DUMP.replace("abc", "1.0"))
    pot = tmp_path / "lj.in"
    pot.write_text(LJ)
    body = pdcg.delta_body(pdcg.read_atoms(str(dump)), potential=str(pot))
    body.write(str(tmp_path / "b.h5"))
    with pytest.raises(pdcg.InputError) as e:
        pdcg.homogenize(body, kernel="box", width=1.0, spacing=1.0)
    msg = cli_error(pdcg_exe, "homogenize", str(tmp_path / "b.h5"), "--kernel", "box",
                    "--width", "1", "--spacing", "1", "-o", str(tmp_path / "h.h5"))
    assert str(e.value) == msg


def test_missing_file_and_bad_arguments(tmp_path):
    with pytest.raises(pdcg.InputError, match="nothing.lammpstrj"):
        pdcg.read_atoms(str(tmp_path / "nothing.lammpstrj"))
    dump = tmp_path / "ok.lammpstrj"
    dump.write_text(DUMP.replace("abc", "1.0"))
    atoms = pdcg.read_atoms(str(dump))
    with pytest.raises(pdcg.InputError, match="frame range out of bounds"):
        pdcg.read_atoms(str(dump), frame=3)
    with pytest.raises(pdcg.InputError, match="exactly one of potential= and commands="):
        pdcg.delta_body(atoms)
    body = pdcg.delta_body(atoms, commands=LJ)
    with pytest.raises(pdcg.InputError, match="exactly one of factor= and horizon="):
        pdcg.rescale(body)
    with pytest.raises(pdcg.InputError, match="ε|epsilon|factor"):
        pdcg.rescale(body, factor=-1.0)
    with pytest.raises(pdcg.InputError, match="wrong array shape"):
        body.forces(positions=[[0.0, 0.0]])
