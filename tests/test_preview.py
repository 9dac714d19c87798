"""``hexdem preview``: a packing drawn without running it, refused exactly as ``hexdem run`` refuses it."""

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from hexdem.cli.main import main
from hexdem.errors import HexdemError
from hexdem.experiments.preview import MATERIAL_COLOURS, PREVIEW_NAME, STRUCK_COLOUR, preview
from hexdem.model.config import RunConfig

GALLERY = Path(__file__).resolve().parents[1] / "docs" / "gallery" / "configs"


def colour_pixels(path, colour: str) -> int:
    """How many pixels of the PNG at ``path`` have the colour ``#rrggbb``."""
    rgb = np.asarray(Image.open(path).convert("RGB")).reshape(-1, 3)
    return int(np.all(rgb == [int(colour[k : k + 2], 16) for k in (1, 3, 5)], axis=1).sum())


def test_the_default_hexagon_is_drawn_with_its_struck_bead_and_nothing_is_run(tmp_path):
    path = preview(RunConfig(), tmp_path / "out")
    assert path == tmp_path / "out" / PREVIEW_NAME and [p.name for p in path.parent.iterdir()] == [PREVIEW_NAME]
    assert Image.open(path).format == "PNG"
    assert colour_pixels(path, MATERIAL_COLOURS[0]) > 10_000, "the steel beads"
    assert colour_pixels(path, STRUCK_COLOUR) > 100, "the struck bead's ring and its arrow"
    assert colour_pixels(path, MATERIAL_COLOURS[1]) == 0, "one material"


def test_a_packing_file_of_two_materials_shows_both(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["preview", "--config", str(GALLERY / "packing.toml"), "--out", str(out)]) == 0
    assert capsys.readouterr().err.strip() == f"hexdem: preview in {out / PREVIEW_NAME}"
    assert colour_pixels(out / PREVIEW_NAME, MATERIAL_COLOURS[1]) > 1000, "the five brass beads"


@pytest.mark.parametrize(
    "config_text",
    [
        "edge_beads = 1",
        'shape = "packing"\npacking_file = "missing.csv"',
        "dt = 1e-3",
        f'shape = "packing"\npacking_file = "{GALLERY / "packing.csv"}"\nstruck_bead = 500',
        f'shape = "packing"\npacking_file = "{GALLERY / "packing.csv"}"\nwalls = "box"',
    ],
)
def test_a_packing_run_refuses_is_refused_in_the_same_line_and_nothing_is_written(tmp_path, capsys, config_text):
    config = tmp_path / "bad.toml"
    config.write_text(config_text)
    errors = []
    for command in ("run", "preview"):
        assert main([command, "--config", str(config), "--out", str(tmp_path / command)]) == 3
        errors.append([line for line in capsys.readouterr().err.splitlines() if line.startswith("hexdem: error:")])
        assert not (tmp_path / command).exists()
    assert len(errors[0]) == 1 and errors[0] == errors[1]


def test_a_random_disc_must_be_packed_before_it_is_drawn(tmp_path):
    with pytest.raises(HexdemError, match='then preview OUT/preparation/packing.csv as shape = "packing"'):
        preview(RunConfig(shape="random", radius_m=0.06), tmp_path / "out")
    assert not (tmp_path / "out").exists()
