"""What a reader sees on a bead map: beads without a value are drawn outside the colour scale, in
a style its legend names, never in a colour the scale could mean; and on every figure, text in
mathtext or Unicode, never raw notation."""

import ast
import re
from pathlib import Path

import numpy as np
from matplotlib import colormaps
from matplotlib.colors import LogNorm, to_rgb

from hexdem.analysis.plotting import PIXEL_MAP_BEADS, PIXEL_REACH_D, UNMEASURED_GREYS, bead_map, subplots
from hexdem.model.triangular import hexagon

ROOT = Path(__file__).resolve().parents[1]


def test_beads_without_a_peak_are_drawn_outside_the_scale_and_named_in_the_legend():
    """Beads without a value are drawn in greys outside the colour scale, one collection per kind,
    told apart and named in the legend; never hatched (matplotlib renders a hatch bead by bead: a
    run where most beads never moved would spend seconds on them)."""
    fig, ax = subplots()
    positions = np.column_stack([np.arange(5.0), np.zeros(5)])
    values = np.array([1.0, np.nan, 0.1, 0.0, np.nan])
    never = values == 0
    coloured = bead_map(
        ax,
        positions,
        np.ones(5),
        values,
        cmap="magma",
        norm=LogNorm(0.01, 1.0),
        unmeasured={"never moved": never, "still rising at the run's end": np.arange(5) == 4},
    )
    assert list(coloured.get_array()) == [1.0, 0.1], "only measured beads take a colour"
    others = [c for c in ax.collections if c is not coloured]
    assert sorted(len(c.get_offsets()) for c in others) == [1, 1, 1]
    assert not any(collection.get_hatch() for collection in ax.collections)
    faces = [tuple(np.round(collection.get_facecolor()[0][:3], 3)) for collection in others]
    assert sorted(faces) == sorted(tuple(np.round(to_rgb(grey), 3)) for grey in UNMEASURED_GREYS.values()), "told apart"
    assert {text.get_text() for text in fig.legends[0].get_texts()} == set(UNMEASURED_GREYS)


def test_a_large_packing_is_drawn_as_an_image_of_its_beads_values():
    """Above PIXEL_MAP_BEADS beads a map is an image: inside the packing every pixel shows a bead
    (no gap, no moiré), the bead whose centre is nearest (here the value is x, so within
    PIXEL_REACH_D diameters of the pixel's x); the unmeasured beads fill theirs with greys that
    no colour map holds (the circles' greys too), named in the legend, and the ringed beads' region is outlined."""
    lattice = hexagon(60, 1.0)
    assert len(lattice) > PIXEL_MAP_BEADS
    x = lattice.positions_m[:, 0]
    values = np.where(x < 0.8 * x.max(), x, np.nan)
    fig, ax = subplots()
    image = bead_map(
        ax,
        lattice.positions_m,
        lattice.diameters_m,
        values,
        cmap="magma",
        unmeasured={"still rising at the run's end": np.isnan(values)},
        outlined={"far": x > 0.5 * x.max()},
    )
    left, right, bottom, top = image.get_extent()
    pixels = np.ma.filled(image.get_array(), np.nan)
    step = (right - left) / pixels.shape[1]
    cx, cy = np.meshgrid(
        left + (np.arange(pixels.shape[1]) + 0.5) * step, bottom + (np.arange(pixels.shape[0]) + 0.5) * step
    )
    middle = lattice.positions_m.mean(axis=0)
    inside = (np.hypot(cx - middle[0], cy - middle[1]) < 0.8 * 60) & (cx < 0.8 * x.max() - 1)
    assert np.all(np.isfinite(pixels[inside])), "no gap inside the packing"
    assert np.max(np.abs(pixels[inside] - cx[inside])) <= PIXEL_REACH_D
    greys = [np.array(to_rgb(colour)) for colour in UNMEASURED_GREYS.values()]
    for name in ("magma", "viridis", "viridis_r", "inferno", "hot_r"):
        table = colormaps[name](np.linspace(0, 1, 256))[:, :3]
        assert min(np.min(np.abs(table - grey).max(axis=1)) for grey in greys) > 0.05, name
    assert [text.get_text() for text in fig.legends[0].get_texts()] == ["still rising at the run's end", "far"]
    assert len(ax.images) == 2 and ax.collections, "the grey layer, the values; the outline"


def test_beads_of_other_materials_are_ringed_and_named():
    """An interface or an intruder is marked on the map: its beads ringed in a colour of their
    own, named in the legend, their fill still the measured value's."""
    fig, ax = subplots()
    positions = np.column_stack([np.arange(4.0), np.zeros(4)])
    brass = np.array([False, False, True, True])
    coloured = bead_map(ax, positions, np.ones(4), np.ones(4), outlined={"brass beads": brass})
    assert len(coloured.get_array()) == 4
    (ring,) = [c for c in ax.collections if c is not coloured]
    assert len(ring.get_offsets()) == 2 and len(ring.get_facecolor()) == 0
    assert [text.get_text() for text in fig.legends[0].get_texts()] == ["brass beads"]


#: Modules that draw the report's and the runs' figures.
FIGURE_MODULES = sorted(
    {
        *(ROOT / "hexdem" / "paper").glob("*.py"),
        *(ROOT / "hexdem").glob("*/*figures.py"),
        ROOT / "hexdem" / "analysis" / "plotting.py",
        ROOT / "hexdem" / "analysis" / "movie.py",
        ROOT / "hexdem" / "analysis" / "decay_figure.py",
        ROOT / "hexdem" / "experiments" / "snapshots.py",
    }
)
#: Calls and keywords whose string is text on a figure.
TEXT_CALLS = {"set_xlabel", "set_ylabel", "set_title", "suptitle", "set_label", "text", "annotate", "legend"}
TEXT_KEYWORDS = {"label", "title", "xlabel", "ylabel"}
#: Notation meant for a typesetter: a caret or an underscore before a script ("d^(5/4)", "T_0"),
#: or V0 for V₀.
RAW_NOTATION = re.compile(r"\^[-({\w]|_[{\w]|\bV0\b")


def _shown(node) -> list[str]:
    """The texts a string, f-string (placeholders as 0) or conditional node can give."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return [node.value]
    if isinstance(node, ast.JoinedStr):
        return ["".join(part.value if isinstance(part, ast.Constant) else "0" for part in node.values)]
    if isinstance(node, ast.IfExp):
        return _shown(node.body) + _shown(node.orelse)
    return []


def test_no_figure_text_is_raw_notation():
    """Axis labels, titles and legends use mathtext ($T_0$, $d^{5/4}$) or Unicode (V₀), never the
    raw notation a reader would have to decode (issue 35)."""
    raw = []
    for path in FIGURE_MODULES:
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.Call):
                continue
            name = node.func.attr if isinstance(node.func, ast.Attribute) else getattr(node.func, "id", "")
            texts = [
                *(node.args[:1] if name in TEXT_CALLS else []),
                *(k.value for k in node.keywords if k.arg in TEXT_KEYWORDS),
            ]
            for text in (text for item in texts for text in _shown(item)):
                if RAW_NOTATION.search(re.sub(r"\$[^$]*\$", "", text)):
                    raw.append(f"{path.name}:{node.lineno}: {text}")
    assert len(FIGURE_MODULES) > 15 and not raw, raw


def test_the_maps_of_a_large_run_share_the_tiling_found_before_they_are_drawn(tmp_path):
    """``write_results`` finds the pixel tiling once (``tile_lattice``) before its maps are drawn
    in separate processes: the arrival and peak maps then find the very tiling, not one each."""
    from types import SimpleNamespace

    from hexdem.analysis import plotting, run_maps
    from hexdem.model.config import RunConfig
    from hexdem.model.model_builder import build_model

    model = build_model(RunConfig(edge_beads=60))
    assert model.n_bodies > PIXEL_MAP_BEADS
    d = model.packing.diameter_m
    x = model.packing.positions_m[:, 0] / d
    results = SimpleNamespace(
        positions=model.packing.positions_m / d,
        length_unit_m=d,
        units="nondimensional",
        arrival_time=x - x.min(),
        peak_speed=np.exp(-np.abs(x) / 30),
    )
    plotting._pixel_tiling.cache_clear()
    plotting.tile_lattice(results, model)
    run_maps.arrival_map(results, model, tmp_path / "arrival_map.png")
    run_maps.peak_map(results, model, 1.0, tmp_path / "peak_map.png")
    found = plotting._pixel_tiling.cache_info()
    assert (found.misses, found.hits) == (1, 2)
