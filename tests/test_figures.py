"""What a reader sees on a bead map: beads without a value are drawn outside the colour scale, in
a style its legend names, never in a colour the scale could mean."""

import numpy as np
from matplotlib.colors import LogNorm

from hexdem.analysis.figures import UNMEASURED_STYLES, bead_map, subplots


def test_beads_without_a_peak_are_drawn_outside_the_scale_and_named_in_the_legend():
    fig, ax = subplots()
    positions = np.column_stack([np.arange(5.0), np.zeros(5)])
    values = np.array([1.0, np.nan, 0.1, 0.0, np.nan])
    never = values == 0
    coloured = bead_map(ax, positions, np.ones(5), values, cmap="magma", norm=LogNorm(0.01, 1.0),
                        unmeasured={"never moved": never, "still rising at the run's end": np.arange(5) == 4})
    assert list(coloured.get_array()) == [1.0, 0.1], "only measured beads take a colour"
    others = [c for c in ax.collections if c is not coloured]
    assert sorted(len(c.get_offsets()) for c in others) == [1, 1, 1]
    assert all(collection.get_hatch() for collection in others), "outside the scale: hatched"
    assert len({collection.get_hatch() for collection in others}) == 3, "told apart"
    assert not coloured.get_hatch()
    assert {text.get_text() for text in fig.legends[0].get_texts()} == set(UNMEASURED_STYLES)


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
