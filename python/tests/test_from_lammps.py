"""pdcg.from_lammps against LAMMPS's own forces (the reference nobody here wrote).

Tolerance 1e-10 (absolute, forces of order 1 eV/Å or 1 ε/σ): pdcg evaluates the same
double-precision formulas as LAMMPS (EAM splines of PairEAM, LJ of PairLJCut); what differs is
the summation order, a round-off of ~1e-14."""
import numpy as np
import pytest

import pdcg
from conftest import lammps_forces

TOL = 1e-10  # see the module docstring

CU = """units metal
atom_style atomic
boundary p p p
lattice fcc 3.615
region b block 0 3 0 3 0 3
create_box 1 b
create_atoms 1 region b
"""


def test_cu_eam_perturbed(lmp):
    lmp.commands_string(CU + "pair_style eam\npair_coeff * * Cu_u3.eam\n"
                        "displace_atoms all random 0.08 0.08 0.08 4711\n")
    body = pdcg.from_lammps(lmp, commands=["units metal", "pair_style eam",
                                           "pair_coeff * * Cu_u3.eam"])
    f = lammps_forces(lmp)
    assert body.kind == "delta" and len(body) == 108
    assert np.abs(f).max() > 0.5  # perturbed: real forces, not a perfect lattice's zeros
    assert np.abs(body.forces() - f).max() < TOL
    # energy: LAMMPS's total potential energy (thermo pe is extensive in metal units)
    assert body.energy() == pytest.approx(lmp.get_thermo("pe"), rel=1e-12, abs=1e-10)
    np.testing.assert_array_equal(body.ids, np.arange(1, 109))


def test_cuni_eam_alloy_triclinic(lmp):
    lmp.commands_string("""units metal
atom_style atomic
boundary p p p
lattice fcc 3.58
region b prism 0 3 0 3 0 3 1.0 0.0 0.0
create_box 2 b
create_atoms 1 region b
set type 1 type/fraction 2 0.4 8
pair_style eam/alloy
pair_coeff * * CuNi.eam.alloy Cu Ni
displace_atoms all random 0.06 0.06 0.06 99
""")
    body = pdcg.from_lammps(lmp, commands="units metal\npair_style eam/alloy\n"
                                          "pair_coeff * * CuNi.eam.alloy Cu Ni\n")
    f = lammps_forces(lmp)
    types = np.asarray(body.types)
    assert set(types) == {1, 2}
    assert body.box["tilt"][0] != 0.0
    assert np.abs(body.forces() - f).max() < TOL
    assert body.energy() == pytest.approx(lmp.get_thermo("pe"), rel=1e-12)


def lj_cluster(lmp):
    """A 3x3x3 cube of LJ atoms, spacing 1.12 σ, randomly displaced, in a shrink-wrapped box."""
    rng = np.random.default_rng(3)
    lmp.commands_string("""units lj
atom_style atomic
boundary s s s
region b block -4 4 -4 4 -4 4
create_box 1 b
mass 1 1.0
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
""")
    # a 3x3x3 cube of spacing 1.12 with random displacements
    g = np.array([[i, j, k] for i in range(3) for j in range(3) for k in range(3)], float)
    x = 1.12 * g - 1.12 + rng.uniform(-0.05, 0.05, g.shape)
    lmp.create_atoms(len(x), list(range(1, len(x) + 1)), [1] * len(x), x.ravel().tolist())
    return x


def test_lj_cluster_shrink_wrapped(lmp):
    x = lj_cluster(lmp)
    body = pdcg.from_lammps(lmp, commands="units lj\npair_style lj/cut 2.5\n"
                                          "pair_coeff 1 1 1.0 1.0\n")
    assert body.box["periodic"] == (False, False, False)
    f = lammps_forces(lmp)
    assert np.abs(f).max() > 0.1
    assert np.abs(body.forces() - f).max() < TOL
    # LAMMPS lj units normalise thermo pe per atom
    assert body.energy() / len(x) == pytest.approx(lmp.get_thermo("pe"), rel=1e-12)


def test_pylammps_history(lmp):
    pl = pytest.importorskip("lammps").PyLammps(ptr=lmp)
    pl.enable_cmd_history = True
    for line in (CU + "pair_style eam\npair_coeff * * Cu_u3.eam\n"
                 "displace_atoms all random 0.05 0.05 0.05 7\n").splitlines():
        pl.command(line)
    body = pdcg.from_lammps(pl)  # the commands come from the history
    assert np.abs(body.forces() - lammps_forces(lmp)).max() < TOL


def test_wrong_coefficients_refused(lmp):
    lj_cluster(lmp)
    with pytest.raises(pdcg.InputError, match="do not reproduce the LAMMPS instance's forces"):
        pdcg.from_lammps(lmp, commands="units lj\npair_style lj/cut 2.5\npair_coeff 1 1 1.1 1.0")
    with pytest.raises(pdcg.InputError, match="pair_style: the commands and the LAMMPS instance"):
        pdcg.from_lammps(lmp, commands="units lj\npair_style morse 2.5\npair_coeff 1 1 1 1 1")
    with pytest.raises(pdcg.InputError, match="different units"):
        pdcg.from_lammps(lmp, commands="units metal\npair_style lj/cut 2.5\npair_coeff 1 1 1 1")
    with pytest.raises(pdcg.InputError, match="cannot be read through LAMMPS's library"):
        pdcg.from_lammps(lmp)


def test_bead_spring_chains_with_bonds(lmp):
    """Molecular bonds come from the instance (gather_bonds): LJ beads with harmonic bonds and
    LAMMPS's default special_bonds 0 0 0 (bonded pairs have no LJ term)."""
    lmp.commands_string("""units lj
atom_style bond
boundary p p p
region b block 0 12 0 12 0 12
create_box 1 b bond/types 1 extra/bond/per/atom 2 extra/special/per/atom 4
mass 1 1.0
pair_style lj/cut 2.5
pair_coeff 1 1 1.0 1.0
bond_style harmonic
bond_coeff 1 100.0 1.0
""")
    rng = np.random.default_rng(2)
    x = [[1.0 + 1.0 * i + rng.uniform(-0.05, 0.05), 2.0 + 2.5 * c, 3.0 + rng.uniform(-0.05, 0.05)]
         for c in range(4) for i in range(10)]
    lmp.create_atoms(40, list(range(1, 41)), [1] * 40, np.ravel(x).tolist())
    for c in range(4):
        for i in range(9):
            lmp.command(f"create_bonds single/bond 1 {10 * c + i + 1} {10 * c + i + 2}")
    body = pdcg.from_lammps(lmp, commands="units lj\natom_style bond\nmass 1 1.0\n"
                            "pair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n"
                            "bond_style harmonic\nbond_coeff 1 100.0 1.0\n")
    f = lammps_forces(lmp)
    assert np.abs(f).max() > 1.0
    assert np.abs(body.forces() - f).max() < TOL
    # a missing bond_style is refused by the style check, before any evaluation
    with pytest.raises(pdcg.InputError, match="bond_style: the commands and the LAMMPS instance"):
        pdcg.from_lammps(lmp, commands="units lj\nmass 1 1.0\npair_style lj/cut 2.5\n"
                                       "pair_coeff 1 1 1.0 1.0\n")
