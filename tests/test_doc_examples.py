"""The user guide's Python example runs verbatim and its configs build what they say, so the
documentation cannot rot."""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np

from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.random_disc import random_diameters

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "guide"


def python_api_example() -> str:
    blocks = re.findall(r"```python\n(.*?)```", (GUIDE / "python-api.md").read_text(), flags=re.DOTALL)
    assert len(blocks) == 1, "the Python API page holds one example"
    return blocks[0]


def test_the_python_api_example_runs(tmp_path):
    script = tmp_path / "example.py"
    script.write_text(python_api_example())
    done = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[-2] == "omega = 0.381966, c = 0.845276"
    assert lines[-1].startswith("30/30: c = ")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["example.py"], "no files unless asked for"


def test_every_packing_config_of_the_guide_builds_the_packing_its_comment_names():
    section = (GUIDE / "packings.md").read_text()
    blocks = re.findall(r"```toml\n(.*?)```", section, flags=re.DOTALL)
    assert len(blocks) == 12
    packing = [k for k, block in enumerate(blocks) if "packing_file" in block]
    assert len(packing) == 1, "the packing file's example names a file of the reader's"
    (random,) = [k for k, block in enumerate(blocks) if 'shape = "random"' in block]  # packed by LAMMPS
    disc = RunConfig(**tomllib.loads(blocks[random]))
    assert len(random_diameters(disc.radius_m, disc.diameter_m, disc.diameter_spread, disc.seed)) == 196
    lattices = [
        build_packing(RunConfig(**tomllib.loads(block)))
        for k, block in enumerate(blocks)
        if k not in packing and k != random
    ]
    # 9 x 12 corners and 8 x 11 interstitials; the intruder's and the dimer's chains of 40 beads
    assert [len(lattice) for lattice in lattices] == [28, 30, 514, 329, 10, 225, 9 * 12 + 8 * 11, 40, 40, 1]
    assert [len(lattice.walls) for lattice in lattices] == [3, 4, 1, 6, 1, 4, 4, 0, 0, 1]


def test_the_guides_interface_config_builds_its_materials():
    section = (GUIDE / "materials.md").read_text()
    (block,) = re.findall(r"```toml\n(.*?)```", section, flags=re.DOTALL)
    model = build_model(RunConfig(**tomllib.loads(block)))
    assert [m.name for m in model.materials] == ["steel316", "brass", "ptfe", "glass"]
    # brass: the layers n with (√3/2) n >= 10, n = 12 … 20, holding 11 + (20 − n) beads each: 135
    brass = sum(11 + 20 - n for n in range(12, 21))
    assert list(np.bincount(model.material_ids)) == [331 - brass - 2, brass, 2, 1] and model.diameters_m[-1] == 0.012


def test_the_guides_impact_configs_build_their_impacts_and_lines():
    section = (GUIDE / "impacts.md").read_text()
    blocks = re.findall(r"```toml\n(.*?)```", section, flags=re.DOTALL)
    assert len(blocks) == 4
    *impacts, lines = [RunConfig(**tomllib.loads(block)) for block in blocks]
    models = [build_model(config) for config in impacts]
    assert [len(model.impacts) for model in models] == [2, 11, 1]  # double strike, the 11 beads of an edge, interior
    assert [len(model.strikers) for model in models] == [0, 11, 0]
    assert [list(lattice.labels[b]) for lattice in [models[2].packing] for b in models[2].struck_beads] == [[0, 14]]
    assert len(build_packing(lines).line("across")) == 21  # the middle column of 11 per edge: 2 * 11 - 1 beads


def test_the_configuration_pages_file_is_the_built_in_default():
    """The guide's key-by-key file of the paper's experiment is the default configuration, whatever
    the defaults become."""
    (block,) = re.findall(r"```toml\n(.*?)```", (GUIDE / "configuration.md").read_text(), flags=re.DOTALL)
    assert RunConfig(**tomllib.loads(block)) == RunConfig()
