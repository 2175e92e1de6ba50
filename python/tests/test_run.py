"""pdcg.run: a scene given as a dict gives the same results as `pdcg run` of the same YAML
(reactions bitwise: the same library call on the same scene), fields per step as numpy, and the
progress callback sees every load step."""
import os
import subprocess

import numpy as np
import pytest

import pdcg

YAML = """units: none
dimension: 2
plane: strain
geometry:
  shape: rectangle
  origin: [0.0, 0.0]
  size: [1.0, 0.5]
  spacing: 0.1
horizon: {factor: 3.015}
material: {model: neo-hookean, shear_modulus: 1.0, bulk_modulus: 10.0, density: 1.0}
boundary:
  - {name: left,  region: {x_max: 0.0},  displacement: {x: 0.0}}
  - {name: pin,   region: {point: [0.0, 0.0]}, displacement: {y: 0.0}}
  - {name: right, region: {x_min: 1.0},  displacement: {x: "0.1*t"}}
loading: {steps: 3}
solver: {type: newton, tolerance: 1.0e-10, max_iterations: 30, linear: umfpack}
output: {directory: out_yaml, every: 1}
"""

SCENE = {
    "units": "none", "dimension": 2, "plane": "strain",
    "geometry": {"shape": "rectangle", "origin": [0.0, 0.0], "size": [1.0, 0.5],
                 "spacing": 0.1},
    "horizon": {"factor": 3.015},
    "material": {"model": "neo-hookean", "shear_modulus": 1.0, "bulk_modulus": 10.0,
                 "density": 1.0},
    "boundary": [
        {"name": "left", "region": {"x_max": 0.0}, "displacement": {"x": 0.0}},
        {"name": "pin", "region": {"point": [0.0, 0.0]}, "displacement": {"y": 0.0}},
        {"name": "right", "region": {"x_min": 1.0}, "displacement": {"x": "0.1*t"}},
    ],
    "loading": {"steps": 3},
    "solver": {"type": "newton", "tolerance": 1.0e-10, "max_iterations": 30,
               "linear": "umfpack"},
    "output": {"directory": "out_dict", "every": 1},
}


def test_dict_equals_cli(tmp_path, pdcg_exe, monkeypatch):
    (tmp_path / "scene.yaml").write_text(YAML)
    subprocess.run([pdcg_exe, "-q", "run", str(tmp_path / "scene.yaml"), "-o",
                    str(tmp_path / "cli")], check=True)
    monkeypatch.chdir(tmp_path)
    seen = []
    result = pdcg.run(SCENE, progress=lambda label, done, total: seen.append((label, done, total)))
    assert result.directory == "out_dict"
    cli = (tmp_path / "cli" / "reactions.csv").read_text()
    py = (tmp_path / "out_dict" / "reactions.csv").read_text()
    assert py == cli  # bitwise: same scene, same library call
    assert sorted(os.listdir(tmp_path / "out_dict")) == sorted(os.listdir(tmp_path / "cli"))
    r = result.reactions
    assert len(r[next(iter(r))]) == 4  # steps 0..3
    assert seen[-1][1:] == (3, 3) and all(s[0] == "load steps" for s in seen)
    f = result.fields(-1)
    assert any(np.asarray(v).ndim >= 1 and np.asarray(v).size > 0 for v in f.values())
    assert len(result.steps()) == 3  # results_0001..0003 (every: 1)
    assert not [p for p in os.listdir(tmp_path) if p.startswith(".pdcg-scene-")]


def test_yaml_path_and_errors(tmp_path, monkeypatch):
    (tmp_path / "scene.yaml").write_text(YAML)
    monkeypatch.chdir(tmp_path)
    result = pdcg.run("scene.yaml", output="out_path")
    assert (tmp_path / "out_path" / "reactions.csv").exists()
    assert "reactions.csv" in os.listdir(result.directory)
    bad = dict(SCENE, loading={"steps": -2})
    with pytest.raises(pdcg.InputError, match="loading.steps") as e:
        pdcg.run(bad)
    assert "<scene dict>" in str(e.value)

    def stop(label, done, total):
        if done >= 1:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        pdcg.run(SCENE, output="out_stopped", progress=stop)
