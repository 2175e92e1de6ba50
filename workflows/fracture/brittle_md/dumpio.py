"""Reader of the LAMMPS text dumps written by in.fracture (id type x y c_coord, sorted by id)."""
import numpy as np


def frames(path):
    """Yield (step, array[n, 5]) for each frame of a dump file (columns id type x y coord)."""
    with open(path) as f:
        while True:
            line = f.readline()
            if not line:
                return
            if not line.startswith("ITEM: TIMESTEP"):
                continue
            step = int(f.readline())
            f.readline()
            n = int(f.readline())
            for _ in range(4):
                f.readline()  # box bounds header + 3 lines
            f.readline()  # ITEM: ATOMS ...
            data = np.loadtxt(f, max_rows=n, ndmin=2)
            yield step, data
