"""A run's figures as a reader sees them: the map fills its canvas in the packing's shape, its
colour bar is as tall as the map, no tick labels run into each other, a chain is drawn along its
length, and a line whose beads never moved is named, not drawn as a drop to a log axis' floor."""

from types import SimpleNamespace

import numpy as np
import pytest

from hexdem.analysis import plotting, run_maps
from hexdem.analysis.decay_figure import peak_decay
from hexdem.analysis.map_layout import chain_direction
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model

#: Packings of every aspect the gallery draws: a hexagon, a square, a strip far wider than high, a chain of two sizes.
PACKINGS = {
    "hexagon": RunConfig(edge_beads=6),
    "square": RunConfig(shape="square", rows=7, columns=7),
    "strip": RunConfig(shape="square", rows=2, columns=20),
    "tall": RunConfig(shape="parallelogram", edge_beads=16, depth_beads=2),
    "dimer": RunConfig(shape="chain", beads=40, diameters_m=[0.01905, 0.009525]),
}


def pulse(model, reach_d: float = 6.0) -> SimpleNamespace:
    """Results (nondimensional) of a pulse that has moved the beads within ``reach_d`` of the
    struck one, peaks falling and arrivals growing with the distance, the last diameter of it
    still rising (NaN) and every bead beyond never moved (peak 0, no arrival)."""
    d = model.packing.diameter_m
    positions = model.packing.positions_m / d
    r = np.hypot(*(positions - positions[model.struck_beads[0]]).T)
    peaks = np.where(r <= reach_d - 1, 1.0 / (1.0 + r), np.where(r <= reach_d, np.nan, 0.0))
    arrival = np.where(peaks > 0, r / 2.0, np.nan)
    return SimpleNamespace(
        positions=positions, length_unit_m=d, units="nondimensional", arrival_time=arrival, peak_speed=peaks
    )


def extent(artist, renderer):
    box = artist.get_window_extent(renderer)
    return box.x0, box.y0, box.x1, box.y1


def overlapping(axis, renderer) -> list[str]:
    """The tick labels of ``axis`` drawn (their tick within its view) whose boxes overlap another's."""
    low, high = sorted(axis.get_view_interval())
    boxes = [
        (tick.label1.get_text(), tick.label1.get_window_extent(renderer))
        for tick in axis.get_major_ticks()
        if low <= tick.get_loc() <= high and tick.label1.get_visible() and tick.label1.get_text()
    ]
    return [a for k, (a, box) in enumerate(boxes) for b, other in boxes[k + 1 :] if box.overlaps(other)]


def crowded(ax, renderer) -> list[str]:
    """The tick labels of ``ax``, on either axis, that run into another on the same axis."""
    return overlapping(ax.xaxis, renderer) + overlapping(ax.yaxis, renderer)


@pytest.mark.parametrize("name", ["hexagon", "square", "strip", "tall"])
@pytest.mark.parametrize("kind", ["arrival_map", "peak_map"])
def test_a_map_fills_its_canvas_and_its_colour_bar_is_as_tall_as_the_map(name, kind, tmp_path):
    """The map's axes, as drawn (true aspect applied), span at least half the canvas each way, but
    across a packing four times longer than wide, where they span the canvas along it and the
    canvas is no wider than its margins, colour bar and legend need; the colour bar's top and
    bottom are the map's, to a pixel; no tick labels overlap; the title and the axes' labels stay
    on the canvas; the figure saved is the canvas measured."""
    model = build_model(PACKINGS[name])
    draw = getattr(run_maps, kind)
    args = (1.0,) if kind == "peak_map" else ()
    fig = draw(pulse(model), model, *args, tmp_path / f"{kind}.png")
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    ax, bar = fig.axes
    width, height = fig.canvas.get_width_height()
    x0, y0, x1, y1 = extent(ax, renderer)
    spans = ((x1 - x0) / width, (y1 - y0) / height)
    assert min(spans) >= 0.5 or (name == "tall" and spans[1] >= 0.75 and width <= 4.2 * fig.dpi + 1), (name, spans)
    bx0, by0, bx1, by1 = extent(bar, renderer)
    assert abs(by0 - y0) <= 1 and abs(by1 - y1) <= 1, "the colour bar as tall as the map"
    assert x1 < bx0 < bx1 <= width, "beside the map, on the canvas"
    assert not crowded(ax, renderer) and not crowded(bar, renderer)
    for text in (ax.title, ax.xaxis.label, ax.yaxis.label, bar.yaxis.label):
        tx0, ty0, tx1, ty1 = extent(text, renderer)
        assert 0 <= tx0 and tx1 <= width and 0 <= ty0 and ty1 <= height, f"{text.get_text()!r} on the canvas"
    from PIL import Image

    with Image.open(tmp_path / f"{kind}.png") as image:
        assert np.all(np.abs(np.array(image.size) - fig.get_size_inches() * plotting.DPI) <= 1)


def test_a_wide_packing_gets_a_wide_canvas_and_a_square_one_a_squarer_canvas(tmp_path):
    """The canvas follows the packing's extent: a strip of two rows is drawn in a figure far wider
    than high, a square crystal in one nearly as high as wide."""
    shapes = {}
    for name in ("strip", "square"):
        model = build_model(PACKINGS[name])
        fig = run_maps.peak_map(pulse(model), model, 1.0, tmp_path / f"{name}.png")
        shapes[name] = np.divide(*fig.get_size_inches())
    assert shapes["strip"] > 2.0 and 0.9 < shapes["square"] < 1.3, shapes


@pytest.mark.parametrize("kind", ["arrival_map", "peak_map"])
def test_a_chain_is_drawn_along_its_length_beside_its_beads(kind, tmp_path):
    """A dimer chain's map is its values against the distance along the chain: one marker per
    measured bead, at its distance from the struck bead, above the chain drawn true size on the
    same abscissa, both as wide as the canvas allows; the values' axes is most of the canvas's
    height (not a strip one bead high under a colour bar five times taller), and no tick labels
    overlap."""
    model = build_model(PACKINGS["dimer"])
    results = pulse(model, reach_d=20.0)
    args = (1.0,) if kind == "peak_map" else ()
    fig = getattr(run_maps, kind)(results, model, *args, tmp_path / f"{kind}.png")
    renderer = fig.canvas.get_renderer()
    fig.draw(renderer)
    profile, strip = fig.axes
    width, height = fig.canvas.get_width_height()
    px0, py0, px1, py1 = extent(profile, renderer)
    sx0, sy0, sx1, sy1 = extent(strip, renderer)
    assert (px1 - px0) / width >= 0.75 and (py1 - py0) / height >= 0.5
    assert abs(px0 - sx0) <= 1 and abs(px1 - sx1) <= 1 and sy1 < py0, "the chain below, on the same abscissa"
    measured = np.isfinite(results.peak_speed) & (results.peak_speed > 0)
    (markers,) = profile.collections
    distance = results.positions[:, 0] - results.positions[model.struck_beads[0], 0]
    drawn = markers.get_offsets()
    shown = np.isfinite(np.ma.filled(drawn[:, 1], np.nan))
    assert np.allclose(np.sort(drawn[shown, 0]), np.sort(distance[measured]))
    beads = [c for c in strip.collections if len(c.get_offsets()) == measured.sum()]
    assert beads and np.allclose(np.sort(beads[0].get_offsets()[:, 0]), np.sort(distance[measured]))
    assert not crowded(profile, renderer) and not crowded(strip, renderer)


def test_the_direction_of_a_chain_is_found_whatever_its_orientation():
    """Beads on one line, at any angle, give the line's direction, from the struck bead into the
    chain; a 2D packing, or beads off the line by more than round-off, give none."""
    angle = np.radians(120.0)
    along = np.array([np.cos(angle), np.sin(angle)])
    positions = np.arange(8.0)[:, None] * along + np.array([3.0, -2.0])
    assert np.allclose(chain_direction(positions, np.ones(8), struck=0), along)
    assert np.allclose(chain_direction(positions, np.ones(8), struck=7), -along)
    bent = positions.copy()
    bent[4] += 0.1 * np.array([-along[1], along[0]])
    assert chain_direction(bent, np.ones(8), struck=0) is None
    assert chain_direction(build_model(PACKINGS["hexagon"]).packing.positions_m, np.ones(91), 0) is None


def test_lines_that_never_moved_are_named_not_drawn_as_drops(tmp_path):
    """The 15 × 15 square's case: its ±45° and ±90° lines hold peak 0 beyond their first bead.
    Nothing is drawn for them (on a log axis, 0 would be a drop to the floor): the legend names
    them, a line and its mirror at once; a line that moved only partly leaves its never-moved
    beads out; the axis spans the measured peaks only. A line of its own name (up) carries no
    degree sign."""
    n = np.arange(15)
    decay = 0.7 + 0.3 * np.exp(-n)
    still = np.r_[1.0, np.zeros(14)]
    rows = {
        "0": (n, 0.4 * decay),
        "+45": (n, 0.4 * still),
        "-45": (n, 0.4 * still),
        "+90": (n[:8], 0.4 * still[:8]),
        "-90": (n[:8], 0.4 * still[:8]),
        "up": (n, 0.4 * np.r_[decay[:5], np.zeros(10)]),
    }
    fig = peak_decay(rows, tmp_path / "peak_decay.png", "si", 0.4)
    ax = fig.axes[0]
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == ["0°", "up", "±45°: never moved", "±90°: never moved"]
    drawn = {line.get_label(): line.get_ydata() for line in ax.get_lines() if not line.get_label().startswith("_")}
    assert sorted(drawn) == ["0°", "up"]
    assert np.all(np.isnan(drawn["up"][5:])) and np.allclose(drawn["up"][:5], decay[:5])
    assert ax.get_ylim()[0] > 0.5, "no drop towards the floor"


def test_a_line_drawn_over_its_mirror_stays_visible(tmp_path):
    """A symmetric strike's −45° line coincides with its +45°: drawn open and dashed over the
    filled markers of +45°, so that a reader sees both."""
    n = np.arange(6)
    peaks = 0.4 * 0.8**n
    fig = peak_decay({"0": (n, peaks), "+45": (n, peaks), "-45": (n, peaks)}, tmp_path / "decay.png", "si", 0.4)
    lines = {line.get_label(): line for line in fig.axes[0].get_lines()}
    assert lines["-45°"].get_linestyle() == "--" and lines["-45°"].get_markerfacecolor() == "none"
    assert lines["+45°"].get_linestyle() == "-" and lines["+45°"].get_markerfacecolor() != "none"


def test_a_chain_of_two_beads_is_drawn_no_higher_than_a_strip(tmp_path):
    """A pair of beads (a listed-sites chain, its wall beside the second bead) is drawn at a scale
    that keeps its strip low, not two beads blown up to the figure's width; a run in which no bead
    has a value yet still draws its figure (a log axis of no value cannot be drawn)."""
    from hexdem.analysis.map_layout import STRIP_IN

    model = build_model(RunConfig(shape="sites", sites=[[0, 0], [2, 0]], site_walls_deg=[0]))
    for reach in (3.0, 0.5):
        fig = run_maps.peak_map(pulse(model, reach_d=reach), model, 1.0, tmp_path / "peak_map.png")
        profile, strip = fig.axes
        assert strip.get_position().height * fig.get_size_inches()[1] <= STRIP_IN[1] + 1e-9
        assert profile.get_position().height > 2 * strip.get_position().height


def test_a_title_wider_than_its_figure_breaks_after_a_comma():
    """A narrow figure's title is wrapped after its commas, every line within the width, never
    inside a part ("V₀ = 0.4 m/s" stays whole), the text unchanged."""
    from hexdem.analysis.map_layout import wrap_title

    title = "Peak speed, parallelogram, 9 per edge, 6 deep, V₀ = 0.4 m/s"
    lines = wrap_title(title, 40)
    assert len(lines) == 2 and all(len(line) <= 40 for line in lines)
    assert " ".join(lines) == title and lines[1].endswith("V₀ = 0.4 m/s")
    assert wrap_title(title, 200) == [title]
