"""`cmake --install` puts an importable pdcg into <prefix>/lib/python3.X/dist-packages that
still works after the prefix is moved (run path relative to the module, docs/python.md)."""
import os
import shutil
import subprocess
import sys

import pytest


def test_installed_module_imports_after_move(tmp_path):
    build = os.environ.get("PDCG_BINARY_DIR")
    if not build:
        pytest.skip("PDCG_BINARY_DIR not set (run through ctest)")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True,
                   capture_output=True)
    moved = tmp_path / "moved"
    shutil.move(str(prefix), str(moved))
    site = moved / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / \
        "dist-packages"
    assert (site / "pdcg" / "__init__.pyi").exists()
    code = ("import pdcg, numpy as np\n"
            "b = pdcg.delta_body(pdcg.Atoms([1, 2], [1, 1], [[0, 0, 0], [1.2, 0, 0]], (-3, -3, -3),"
            " (3, 3, 3), periodic=(False, False, False)),"
            " commands='units lj\\nmass 1 1\\npair_style lj/cut 2.5\\npair_coeff 1 1 1 1')\n"
            "print(pdcg.__file__, b.energy())\n")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    path, energy = r.stdout.split()
    assert path.startswith(str(site))
    # LJ dimer at r = 1.2: 4(1.2^-12 - 1.2^-6) (lj/cut without shift), 1e-14: round-off
    assert abs(float(energy) - 4 * (1.2 ** -12 - 1.2 ** -6)) < 1e-14
