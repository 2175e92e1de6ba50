"""pdcg.from_ase and Body.to_ase: the configuration round-trips, and the body's forces are
LAMMPS's for the same atoms (LAMMPS fed the ASE positions and cell through its Python API).
Tolerance 1e-10: the same double-precision formulas as LAMMPS (test_from_lammps.py)."""
import numpy as np
import pytest

import pdcg
from conftest import lammps_forces

ase = pytest.importorskip("ase")
from ase.build import bulk  # noqa: E402

TOL = 1e-10  # same formulas as LAMMPS, summation-order round-off only
CU = "units metal\npair_style eam\npair_coeff * * Cu_u3.eam\n"
CUNI = "units metal\npair_style eam/alloy\npair_coeff * * CuNi.eam.alloy Cu Ni\n"


def cuni_atoms():
    a = bulk("Cu", "fcc", a=3.58, cubic=True).repeat((2, 2, 3))
    sym = a.get_chemical_symbols()
    for i in range(0, len(a), 3):
        sym[i] = "Ni"
    a.set_chemical_symbols(sym)
    rng = np.random.default_rng(5)
    a.positions += rng.uniform(-0.05, 0.05, a.positions.shape)
    return a


def test_round_trip_periodic():
    a = cuni_atoms()
    body = pdcg.from_ase(a, commands=CUNI)
    b = body.to_ase()
    np.testing.assert_array_equal(b.get_atomic_numbers(), a.get_atomic_numbers())
    np.testing.assert_array_equal(b.positions, a.positions)  # same doubles, same order
    np.testing.assert_array_equal(b.cell.array, a.cell.array)
    np.testing.assert_array_equal(b.pbc, a.pbc)
    # types from the pair_coeff element list: Cu = 1, Ni = 2
    np.testing.assert_array_equal(body.types, np.where(a.get_atomic_numbers() == 29, 1, 2))


def test_round_trip_cluster_and_mixed_pbc():
    a = bulk("Cu", "fcc", a=3.615, cubic=True).repeat(2)
    a.pbc = (True, True, False)
    body = pdcg.from_ase(a, commands=CU)
    b = body.to_ase()
    np.testing.assert_array_equal(b.pbc, [True, True, False])
    np.testing.assert_array_equal(b.positions, a.positions)
    np.testing.assert_array_equal(b.cell.array, a.cell.array)
    cluster = ase.Atoms("Cu4", positions=[[0, 0, 0], [2.5, 0, 0], [0, 2.5, 0], [0, 0, 2.6]])
    cb = pdcg.from_ase(cluster, commands=CU)
    assert cb.box["periodic"] == (False, False, False)
    np.testing.assert_array_equal(cb.to_ase().positions, cluster.positions)
    assert list(cb.to_ase().get_chemical_symbols()) == ["Cu"] * 4


def test_forces_equal_lammps(lmp):
    a = cuni_atoms()
    body = pdcg.from_ase(a, commands=CUNI)
    c = a.cell.array
    lmp.commands_string(f"""units metal
atom_style atomic
boundary p p p
region b prism 0 {c[0,0]} 0 {c[1,1]} 0 {c[2,2]} {c[1,0]} {c[2,0]} {c[2,1]}
create_box 2 b
""")
    types = np.where(a.get_atomic_numbers() == 29, 1, 2)
    lmp.create_atoms(len(a), list(range(1, len(a) + 1)), types.tolist(),
                     a.positions.ravel().tolist())
    lmp.commands_string(CUNI.replace("units metal\n", ""))
    f = lammps_forces(lmp)
    assert np.abs(f).max() > 0.1
    assert np.abs(body.forces() - f).max() < TOL


def test_unmapped_species_refused():
    a = cuni_atoms()
    with pytest.raises(pdcg.InputError, match="nothing maps them"):
        pdcg.from_ase(a, commands="units metal\npair_style lj/cut 5.0\npair_coeff * * 0.1 2.3")
    with pytest.raises(pdcg.InputError, match="missing Ni"):
        pdcg.from_ase(a, commands=CUNI, species=["Cu"])
    rotated = a.copy()
    rotated.rotate(30, "z", rotate_cell=True)
    with pytest.raises(pdcg.InputError, match="not in LAMMPS's form"):
        pdcg.from_ase(rotated, commands=CUNI)


def test_triclinic_equals_lammps(lmp):
    """A sheared cell in LAMMPS's form (tilts within LAMMPS's half-length limit): positions,
    tilt and forces as LAMMPS has them for the same box."""
    a = bulk("Cu", "fcc", a=3.615, cubic=True).repeat((3, 3, 3))
    L = a.cell.array[0, 0]
    a.set_cell([[L, 0, 0], [0.2 * L, L, 0], [0.1 * L, -0.15 * L, L]], scale_atoms=True)
    a.positions += np.random.default_rng(1).uniform(-0.05, 0.05, a.positions.shape)
    body = pdcg.from_ase(a, commands=CU)
    c = a.cell.array
    assert body.box["tilt"] == (c[1, 0], c[2, 0], c[2, 1]) and c[1, 0] > 0
    lmp.commands_string(f"""units metal
atom_style atomic
boundary p p p
region b prism 0 {c[0,0]!r} 0 {c[1,1]!r} 0 {c[2,2]!r} {c[1,0]!r} {c[2,0]!r} {c[2,1]!r}
create_box 1 b
""")
    lmp.create_atoms(len(a), list(range(1, len(a) + 1)), [1] * len(a),
                     a.positions.ravel().tolist())
    lmp.commands_string("pair_style eam\npair_coeff * * Cu_u3.eam\n")
    f = lammps_forces(lmp)
    assert np.abs(f).max() > 0.1
    assert np.abs(body.forces() - f).max() < TOL


def test_masses_from_ase_when_nothing_else_gives_them():
    # lj/cut sets no masses and the commands have no `mass`: ASE's standard mass of Ar
    ar = ase.Atoms("Ar2", positions=[[0, 0, 0], [3.8, 0, 0]])
    body = pdcg.from_ase(ar, commands="units metal\npair_style lj/cut 8.0\n"
                                      "pair_coeff 1 1 0.0104 3.4")
    np.testing.assert_array_equal(body.masses, ar.get_masses())
    # the potential file's mass (Cu_u3.eam: 63.55) wins over ASE's standard 63.546
    cu = pdcg.from_ase(bulk("Cu", "fcc", a=3.615, cubic=True), commands=CU)
    assert cu.masses[0] == 63.55
