"""The size of a bead map's figure, from the packing's extent: the axes hold the packing at true
aspect and as large as a page allows, the colour bar beside them is exactly as tall, and the
figure's margins hold the tick labels, title and legend, whatever the packing's shape; and a
chain (every bead on one line, :func:`chain_direction`), drawn as its values along it above its beads.

Laid out in inches and placed once (no constrained layout, which would cost about a tenth of a
second per figure): a wide packing gets a wide, low figure, a tall one a narrow, high one, a
strip of two rows no less than :data:`MIN_AXES_HEIGHT_IN` of axes (its y range widened about it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The largest axes box a map gets (width, height) [in]: about a page's column at the figures' DPI.
MAX_AXES_IN = (5.4, 5.0)
#: The lowest axes box of a map [in]: room for three y tick labels beside a packing of a few rows.
MIN_AXES_HEIGHT_IN = 1.6
#: The narrowest figure [in]: room for the legend's two entries below a tall, narrow packing.
MIN_FIGURE_WIDTH_IN = 4.2
#: Margins [in]: left (y tick labels and label), bottom (x tick labels and label), top (a title's
#: first line; each further line adds :data:`TITLE_LINE_IN`), the legend's row below the x label,
#: and right of the colour bar (its tick labels and label).
LEFT_IN, BOTTOM_IN, TOP_IN, LEGEND_IN, RIGHT_IN = 0.9, 0.7, 0.4, 0.35, 0.95
#: A title's line height and its characters' mean width [in] (matplotlib's default font at the
#: title's 12 pt): a title wider than its figure is wrapped, not cut by the canvas's edges.
TITLE_LINE_IN, TITLE_CHAR_IN = 0.22, 0.095
#: The colour bar's gap from the axes and its width [in].
BAR_PAD_IN, BAR_WIDTH_IN = 0.15, 0.18
#: White space about the packing, as a share of its larger side (matplotlib's own autoscale margin).
PAD_SHARE = 0.05


#: Beads lie on one line (a chain) when their rms distance from it is below this share of the
#: smallest diameter.
CHAIN_TOLERANCE = 1e-3


def chain_direction(positions, diameters, struck: int) -> np.ndarray | None:
    """The unit vector along which every bead of ``positions`` lies, pointing from the ``struck``
    bead into the chain (the side most beads lie on); None where the beads are not on one line."""
    positions = np.asarray(positions, float)
    if len(positions) < 2:
        return None
    _, spread, axes = np.linalg.svd(positions - positions.mean(axis=0), full_matrices=False)
    if spread[1] / np.sqrt(len(positions)) > CHAIN_TOLERANCE * float(np.min(diameters)):
        return None
    along = axes[0]
    return along if np.sum((positions - positions[struck]) @ along) >= 0 else -along


@dataclass(frozen=True)
class MapLayout:
    """Where a map's parts go: ``size`` the figure's (width, height) [in], ``axes`` and ``bar``
    their rectangles (left, bottom, width, height) in figure fractions, ``xlim`` and ``ylim`` the
    axes' data limits (equal scales on both axes), ``title`` the title wrapped to the figure's width."""

    title: str
    size: tuple[float, float]
    axes: tuple[float, float, float, float]
    bar: tuple[float, float, float, float]
    xlim: tuple[float, float]
    ylim: tuple[float, float]


def map_layout(low, high, title: str, legend: bool, colour_bar: bool = True) -> MapLayout:
    """The layout of a map of what lies between ``low`` and ``high`` ((x, y) data corners) under
    ``title``, with a legend row below its x label if ``legend``, a colour bar beside it if ``colour_bar``."""
    low, high = np.asarray(low, float), np.asarray(high, float)
    pad = PAD_SHARE * float(np.max(high - low))
    low, high = low - pad, high + pad
    width, height = high - low
    scale = min(MAX_AXES_IN[0] / width, MAX_AXES_IN[1] / height)  # inches per data unit
    axes_w, axes_h = width * scale, max(height * scale, MIN_AXES_HEIGHT_IN)
    centre_y, half_y = (low[1] + high[1]) / 2, axes_h / scale / 2
    bottom = BOTTOM_IN + (LEGEND_IN if legend else 0.0)
    bar_w = BAR_PAD_IN + BAR_WIDTH_IN + RIGHT_IN if colour_bar else RIGHT_IN / 3
    used = LEFT_IN + axes_w + bar_w
    fig_w = max(MIN_FIGURE_WIDTH_IN, used)
    lines = wrap_title(title, int(fig_w / TITLE_CHAR_IN))
    fig_h = bottom + axes_h + TOP_IN + TITLE_LINE_IN * (len(lines) - 1)
    left = (fig_w - used) / 2 + LEFT_IN
    bar_left = left + axes_w + BAR_PAD_IN
    return MapLayout(
        title="\n".join(lines),
        size=(fig_w, fig_h),
        axes=(left / fig_w, bottom / fig_h, axes_w / fig_w, axes_h / fig_h),
        bar=(bar_left / fig_w, bottom / fig_h, BAR_WIDTH_IN / fig_w, axes_h / fig_h),
        xlim=(low[0], high[0]),
        ylim=(centre_y - half_y, centre_y + half_y),
    )


def wrap_title(title: str, width: int) -> list[str]:
    """``title``'s lines of at most ``width`` characters, broken after its commas (a run's title is
    "what, packing, impact": a break inside "V₀ = 0.4 m/s" would split the impact); a part longer
    than a line is a line of its own."""
    lines = [""]
    for part in title.split(", "):
        joined = f"{lines[-1]}, {part}" if lines[-1] else part
        if len(joined) <= width or not lines[-1]:
            lines[-1] = joined
        else:
            lines[-1] += ","
            lines.append(part)
    return lines


def fit_map(ax, title: str, colour_bar: bool = True):
    """Size ``ax``'s figure to what ``ax`` holds (its data limits: beads, walls, marks) by
    :func:`map_layout`, place ``ax``, fix its limits and give it ``title`` (in a fixed place: left
    to place it itself, matplotlib measures every tick label first); returns the colour bar's
    axes, as tall as ``ax``, or None without ``colour_bar``."""
    fig = ax.figure
    (x0, y0), (x1, y1) = ax.dataLim.get_points()
    layout = map_layout((x0, y0), (x1, y1), title, legend=bool(fig.legends), colour_bar=colour_bar)
    ax.set_title(layout.title, y=1.0)
    fig.set_size_inches(*layout.size)
    ax.set_position(layout.axes)
    ax.set_xlim(*layout.xlim)
    ax.set_ylim(*layout.ylim)
    ax.set_aspect("equal", adjustable="datalim")
    return fig.add_axes(layout.bar) if colour_bar else None


#: A chain's figure (:func:`fit_chain`) [in]: its width, its profile's height, the gap between the
#: profile and the chain drawn below it, and the lowest and highest the chain's strip is drawn.
CHAIN_WIDTH_IN, PROFILE_HEIGHT_IN, CHAIN_GAP_IN, STRIP_IN = 7.0, 3.0, 0.12, (0.3, 0.8)


def fit_chain(profile, strip) -> None:
    """Size a chain's figure and place its two axes, which share their abscissa: ``profile`` (the
    values against the distance along the chain) above ``strip`` (the beads, true size and equal
    scales), both as wide as the figure allows, the strip as high as its beads are at that scale,
    within :data:`STRIP_IN` (a chain of a few beads is drawn no higher, centred in a wider range),
    the legend's row below."""
    fig = profile.figure
    (x0, y0), (x1, y1) = strip.dataLim.get_points()
    width, height = (x1 - x0) * (1 + 2 * PAD_SHARE), (y1 - y0) * (1 + 2 * PAD_SHARE)
    axes_w = CHAIN_WIDTH_IN - LEFT_IN - RIGHT_IN / 3
    scale = min(axes_w / width, STRIP_IN[1] / height)  # inches per data unit
    strip_h = max(height * scale, STRIP_IN[0])
    bottom = BOTTOM_IN + (LEGEND_IN if fig.legends else 0.0)
    fig_h = bottom + strip_h + CHAIN_GAP_IN + PROFILE_HEIGHT_IN + TOP_IN
    fig.set_size_inches(CHAIN_WIDTH_IN, fig_h)
    left, fraction = LEFT_IN / CHAIN_WIDTH_IN, axes_w / CHAIN_WIDTH_IN
    strip.set_position((left, bottom / fig_h, fraction, strip_h / fig_h))
    profile.set_position((left, (bottom + strip_h + CHAIN_GAP_IN) / fig_h, fraction, PROFILE_HEIGHT_IN / fig_h))
    centre_x, centre_y = (x0 + x1) / 2, (y0 + y1) / 2
    profile.set_xlim(centre_x - axes_w / scale / 2, centre_x + axes_w / scale / 2)
    strip.set_ylim(centre_y - strip_h / scale / 2, centre_y + strip_h / scale / 2)
    strip.set_aspect("equal", adjustable="datalim")
