"""Shared fixtures of the Python module's tests (docs/python.md, docs/testing.md).

The module comes from the build tree (PYTHONPATH set by ctest, python/CMakeLists.txt); the
reference is LAMMPS itself, through its own Python module (python3-lammps)."""
import os

import numpy as np
import pytest

lammps = pytest.importorskip("lammps")


@pytest.fixture
def lmp():
    """A serial LAMMPS instance that prints nothing."""
    inst = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    yield inst
    inst.close()


def lammps_forces(inst):
    """LAMMPS's own forces after `run 0`, rows sorted by atom id."""
    inst.command("run 0 post no")
    n = inst.extract_global("nlocal")
    ids = np.array(inst.numpy.extract_atom("id")[:n])
    f = np.array(inst.numpy.extract_atom("f")[:n]).reshape(n, 3)
    return f[np.argsort(ids)]


@pytest.fixture
def pdcg_exe():
    exe = os.environ.get("PDCG_EXECUTABLE")
    if not exe:
        pytest.skip("PDCG_EXECUTABLE not set (run through ctest)")
    return exe
