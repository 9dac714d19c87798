"""Figures a researcher would publish: bead maps and what the other figures share (the run's maps
are :mod:`hexdem.analysis.run_maps`, its peak decay :mod:`hexdem.analysis.decay_figure`).

Every function draws into a new figure and saves it atomically as PNG. Figures are
:class:`matplotlib.figure.Figure` objects on the Agg canvas (:func:`subplots`), never
``pyplot``: no display is needed, no global state is kept, and a run does not pay for
importing pyplot and its interactive backends (the times this module's choices save:
docs/validation/benchmarks.md, *Figures behind choices in the code*).
"""

from __future__ import annotations

import functools

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection
from matplotlib.colors import ListedColormap, LogNorm
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from matplotlib.ticker import FuncFormatter, LogFormatter

from hexdem.analysis.front_shape import HEXAGON_SIXFOLD
from hexdem.common.io import atomic_path
from hexdem.model.walls import CurvedWall

#: Axis units of the run's unit systems: SI, or the paper's (eq. 3): lengths in d, times in
#: :math:`T = \sqrt{M / (A d^{1/2})}`, so speeds in :math:`d/T = \sqrt{A/M}\, d^{5/4}`.
UNIT_LABELS = {
    "si": {"length": "m", "speed": "m/s", "time": "ms", "time_scale": 1e3},
    "nondimensional": {"length": "d", "speed": "d/T", "time": "T", "time_scale": 1.0},
}

#: Fixed margins of the one-panel figures every run writes: a constrained layout costs each
#: figure a layout pass.
SINGLE_PLOT_MARGINS = {"left": 0.13, "right": 0.97, "bottom": 0.12, "top": 0.92}


#: Digits as superscripts, for the decades of a logarithmic axis (10⁻²).
SUPERSCRIPTS = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


def decade_label(value: float, position=None) -> str:
    """A major tick of a logarithmic axis in plain text: 10⁻² at a decade, else the number."""
    exponent = np.log10(value)
    if np.isclose(exponent, round(exponent)):
        return "10" + str(int(round(exponent))).translate(SUPERSCRIPTS)
    return f"{value:g}"


class _PlainLogFormatter(LogFormatter):
    """matplotlib's choice of the minor ticks of a logarithmic axis to label, each labelled as a
    plain number (0.9, 0.75) rather than 9e-01."""

    def _num_to_string(self, x, vmin, vmax):
        return f"{x:.3g}"


def plain_log_ticks(axis) -> None:
    """Label a logarithmic axis in plain text at the ticks matplotlib itself picks: 10⁻² at a
    decade, and its labelled minor ticks as numbers (0.2, 0.9); on an axis of less than a decade,
    whose labels are mostly minor ticks, every label a number (1 beside 0.9, not 10⁰). Its
    default labels are mathtext, whose parser a run's first figure would load (the run's figures
    carry no other mathtext)."""

    def major(value, position=None) -> str:
        low, high = sorted(axis.get_view_interval())
        return f"{value:.3g}" if 0 < low and high < 10 * low else decade_label(value)

    axis.set_major_formatter(FuncFormatter(major))
    axis.set_minor_formatter(_PlainLogFormatter(labelOnlyBase=False))


def set_title(ax, title: str) -> None:
    """The title at the axes' top, in a fixed place: left to place it itself, matplotlib
    measures every tick label first."""
    ax.set_title(title, y=1.0)


#: PNG compression (zlib level 1 of 9): the figures' flat colours compress nearly as well as at
#: the default level 6, at a fraction of the encoding time.
PNG_COMPRESSION = 1


def subplots(nrows: int = 1, ncols: int = 1, figsize=None, layout=None, **kwargs):
    """(figure, axes) as ``pyplot.subplots`` gives them, on an Agg canvas of their own (see the
    module docstring); ``kwargs`` go to :meth:`matplotlib.figure.Figure.subplots`."""
    fig = Figure(figsize=figsize, layout=layout)
    FigureCanvasAgg(fig)
    return fig, fig.subplots(nrows, ncols, **kwargs)


#: Pixels per inch of the saved figures.
DPI = 150


def save(fig, path) -> None:
    """``fig`` as PNG at ``path``, written atomically."""
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI, pil_kwargs={"compress_level": PNG_COMPRESSION})


#: How beads without a value are drawn, outside every colour scale, with their legend entry: in
#: greys that no colour map used here holds, light for a bead that never moved, mid for one whose
#: pulse was still rising when the run ended, dark for any other bead without a value. (Hatches
#: would tell them apart in print too, but matplotlib renders a hatch path by path: in a run where
#: most beads never moved, the hatched beads cost many times the map.)
UNMEASURED_GREYS = {"still rising at the run's end": "0.6", "never moved": "0.85", "no value": "0.35"}
#: The edges of the beads without a value.
UNMEASURED_EDGE = "0.45"


#: A colour bar cut from its axes' right (:func:`colour_bar`): its width and gap, in the axes' width.
BAR_SIZE, BAR_PAD = "4%", 0.12

#: Ring colours of the beads of other materials, outside every colour map the maps use.
OUTLINE_COLOURS = ("#00c8ff", "#3cdc3c", "#ff3cc8", "#0050ff")


def bead_circles(ax, positions, diameters, **style) -> EllipseCollection:
    """Circles of the true ``diameters`` (in ``ax``'s data units) centred at ``positions``, one
    collection drawn in ``style`` (edges 0.2 pt wide unless ``linewidths`` says), for the caller to
    colour and add: the bead maps' beads and the preview's bodies."""
    return EllipseCollection(
        diameters,
        diameters,
        np.zeros(len(diameters)),
        units="xy",
        offsets=positions,
        offset_transform=ax.transData,
        **{"linewidths": 0.2, **style},
    )


#: Above this many beads a map is drawn as an image (:func:`_pixel_beads`): matplotlib's cost
#: grows with each circle drawn, an image's with its pixels (docs/validation/benchmarks.md, *At scale*).
PIXEL_MAP_BEADS = 10_000
#: Pixels across such a map (about the axes' width at the figures' DPI).
MAP_PIXELS = 700
#: A pixel shows the bead whose centre is nearest if that centre lies within this many of the
#: bead's diameters (or within half the pixel's diagonal, if more): a packing's beads then tile
#: it without gaps (the farthest point from every centre of a touching triangular packing is
#: d/√3 = 0.577 d away; drawing each bead's own disc left its gaps as a moiré), while a void
#: wider than 1.2 d stays white.
PIXEL_REACH_D = 0.6


@functools.lru_cache(maxsize=1)
def _pixel_tiling(positions_bytes: bytes, diameters_bytes: bytes) -> tuple[np.ndarray, tuple]:
    """(the bead of each pixel, −1 for none, (rows, columns); the image's extent) of the beads at
    ``positions`` of ``diameters`` (as raw bytes of float arrays, so that the maps of one run, which
    share their beads, find them once): :data:`MAP_PIXELS` across, a pixel the bead whose centre is
    nearest, within :data:`PIXEL_REACH_D` of its diameter (each bead a cell of the packing's
    Voronoi tiling). The nearest centres are sought on every core: the run is over."""
    from scipy.spatial import cKDTree

    positions, diameters = np.frombuffer(positions_bytes).reshape(-1, 2), np.frombuffer(diameters_bytes)
    radius = float(np.max(diameters)) / 2
    low, high = positions.min(axis=0) - radius, positions.max(axis=0) + radius
    step = float(np.max(high - low)) / MAP_PIXELS
    shape = tuple(np.maximum(np.ceil((high - low) / step).astype(int), 1))
    centres = [low[axis] + (np.arange(shape[axis]) + 0.5) * step for axis in (0, 1)]
    grid = np.stack(np.meshgrid(*centres), axis=-1).reshape(-1, 2)
    distance, nearest = cKDTree(positions).query(grid, workers=-1)
    inside = distance <= np.maximum(PIXEL_REACH_D * diameters[nearest], step / np.sqrt(2))
    bead = np.where(inside, nearest, -1).reshape(shape[1], shape[0])
    return bead, (low[0], low[0] + shape[0] * step, low[1], low[1] + shape[1] * step)


def tile_lattice(results, model) -> None:
    """Find the pixel tiling that :func:`draw_lattice` rasterizes the beads of ``results`` on
    (:func:`_pixel_tiling`, kept for the maps that follow), where they are many enough for one: the
    result's maps, drawn in processes forked after this, then share one search on every core rather
    than each making its own at once."""
    if len(model.packing.diameters_m) > PIXEL_MAP_BEADS:
        _tiling_of(*lattice_beads(results, model))


def _tiling_of(positions, diameters) -> tuple[np.ndarray, tuple]:
    """:func:`_pixel_tiling` of the beads at ``positions`` of ``diameters``, found once for the same beads."""
    return _pixel_tiling(
        np.ascontiguousarray(positions, float).tobytes(), np.ascontiguousarray(diameters, float).tobytes()
    )


def _pixel_beads(ax, positions, diameters, values, coloured, groups: dict, outlined: dict, cmap, norm, clim):
    """The beads rasterized (:func:`_pixel_tiling`): a pixel takes its bead's value; an unmeasured
    bead's pixels take its grey (:data:`UNMEASURED_GREYS`), and each ring group's region is
    outlined by a contour of its pixels. Returns the image and the legend's patches."""
    bead, extent = _tiling_of(positions, diameters)
    covered = bead >= 0
    legend = []
    for name, beads in groups.items():
        if np.any(beads):
            grey = np.where(covered & beads[bead], 1.0, np.nan)
            ax.imshow(
                grey,
                origin="lower",
                extent=extent,
                cmap=ListedColormap([UNMEASURED_GREYS[name]]),
                interpolation="nearest",
                vmin=0.0,
                vmax=1.0,
            )
            legend.append(Patch(label=name, facecolor=UNMEASURED_GREYS[name], edgecolor=UNMEASURED_EDGE))
    shown = np.where(covered & coloured[bead], values[bead], np.nan)
    image = ax.imshow(shown, origin="lower", extent=extent, cmap=colormaps[cmap], norm=norm, interpolation="nearest")
    if clim is not None:
        image.set_clim(*clim)
    for (name, beads), colour in zip(outlined.items(), OUTLINE_COLOURS):
        ax.contour(
            (covered & beads[bead]).astype(float),
            levels=[0.5],
            colors=[colour],
            linewidths=1.2,
            origin="lower",
            extent=extent,
        )
        legend.append(Patch(label=name, linewidth=1.2, facecolor="none", edgecolor=colour))
    return image, legend


def bead_map(
    ax,
    positions,
    diameters,
    values,
    cmap="viridis",
    label="",
    clim=None,
    norm=None,
    unmeasured=None,
    outlined=None,
    colorbar=True,
):
    """Beads as true-size circles (one collection, sized in data units) coloured by ``values``
    through ``norm`` (None: linear), with a colour bar labelled ``label`` (:func:`colour_bar`) unless
    ``colorbar`` is False (panels that share a scale share one bar; a map laid out by
    :func:`~hexdem.analysis.map_layout.fit_map` places its own); returns the mappable.
    ``unmeasured``: {name in :data:`UNMEASURED_GREYS`: mask of the beads it describes}, drawn in
    its grey outside the colour scale and named in a legend; any other NaN is drawn as "no value". ``outlined``:
    {name: mask} of beads to ring in a colour of :data:`OUTLINE_COLOURS` (a region of another
    material: an interface, intruders), named in the same legend. A packing of more than
    :data:`PIXEL_MAP_BEADS` beads is drawn rasterized instead (:func:`_pixel_beads`)."""
    values = np.asarray(values, float)
    groups = {name: np.asarray(beads, bool) for name, beads in (unmeasured or {}).items()}
    flagged = np.any([np.zeros(len(values), bool), *groups.values()], axis=0)
    groups["no value"] = ~np.isfinite(values) & ~flagged
    coloured = ~np.any(list(groups.values()), axis=0)
    if len(values) > PIXEL_MAP_BEADS:
        mappable, legend = _pixel_beads(
            ax, positions, diameters, values, coloured, groups, outlined or {}, cmap, norm, clim
        )
    else:
        mappable, legend = _circle_beads(
            ax, positions, diameters, values, coloured, groups, outlined or {}, cmap, norm, clim
        )
    if legend:
        ax.figure.legend(handles=legend, loc="lower center", ncol=len(legend), frameon=False, fontsize="small")
    radius = np.max(diameters) / 2
    ax.update_datalim(np.vstack([positions.min(axis=0) - radius, positions.max(axis=0) + radius]))
    ax.set_aspect("equal")
    ax.autoscale_view()
    if colorbar:
        colour_bar(mappable, label)
    return mappable


def colour_bar(mappable, label: str, cax=None):
    """The colour bar of ``mappable`` labelled ``label``, in ``cax`` or else in axes cut from the
    right of ``mappable``'s axes (:func:`~mpl_toolkits.axes_grid1.make_axes_locatable`), as tall
    as they are drawn, true aspect included; a logarithmic scale's decades in plain text."""
    if cax is None:
        from mpl_toolkits.axes_grid1 import make_axes_locatable

        cax = make_axes_locatable(mappable.axes).append_axes("right", size=BAR_SIZE, pad=BAR_PAD)
    bar = mappable.axes.figure.colorbar(mappable, cax=cax, label=label)
    if isinstance(mappable.norm, LogNorm):
        plain_log_ticks(bar.ax.yaxis)
    return bar


def _circle_beads(ax, positions, diameters, values, coloured, groups: dict, outlined: dict, cmap, norm, clim):
    """The beads as true-size circles (see :func:`bead_map`); returns their collection and the
    legend's patches."""
    circles = bead_circles(ax, positions[coloured], diameters[coloured], norm=norm, cmap=colormaps[cmap], edgecolor="k")
    circles.set_array(values[coloured])
    if clim is not None:
        circles.set_clim(*clim)
    ax.add_collection(circles)
    legend = []
    for name, beads in groups.items():
        if np.any(beads):
            style = {"facecolor": UNMEASURED_GREYS[name], "edgecolor": UNMEASURED_EDGE}
            ax.add_collection(bead_circles(ax, positions[beads], diameters[beads], **style))
            legend.append(Patch(label=name, **style))
    for (name, beads), colour in zip(outlined.items(), OUTLINE_COLOURS):
        ring = {"facecolor": "none", "edgecolor": colour}
        ax.add_collection(bead_circles(ax, positions[beads], diameters[beads] * 0.9, **ring, linewidths=1.6))
        legend.append(Patch(label=name, linewidth=1.6, **ring))
    return circles, legend


def draw_walls(ax, walls, positions, radii, scale=1.0, **style):
    """Each flat wall as the segment along its member beads, at its plane; a curved wall as its circle."""
    for wall in walls:
        if isinstance(wall, CurvedWall):
            angle = np.linspace(0.0, 2 * np.pi, 361)
            circle = np.asarray(wall.centre_m) * scale + wall.radius_m * scale * np.column_stack(
                [np.cos(angle), np.sin(angle)]
            )
            ax.plot(circle[:, 0], circle[:, 1], **{"color": "k", "linewidth": 2, **style})
            continue
        normal = np.asarray(wall.normal)
        tangent = np.array([-normal[1], normal[0]])
        along = positions[wall.members] @ tangent
        lo, hi = along.min() - radii.max(), along.max() + radii.max()
        base = normal * wall.offset_m * scale
        ends = np.array([base + lo * tangent, base + hi * tangent])
        ax.plot(ends[:, 0], ends[:, 1], **{"color": "k", "linewidth": 2, **style})


def lattice_beads(results, model) -> tuple[np.ndarray, np.ndarray]:
    """The beads' positions and diameters in the run's length unit, as the lattice maps draw them."""
    return results.positions, model.packing.diameters_m * (1.0 / results.length_unit_m)


def draw_lattice(
    ax, results, model, values, label: str, cmap="viridis", norm=None, marker_colour="w", unmeasured=None, colorbar=True
):
    """The packing's beads coloured by ``values`` (one per bead, in the run's units), its walls,
    its struck beads marked with crosses of ``marker_colour``, axes labelled; returns the beads'
    mappable. ``unmeasured`` and ``colorbar`` as for :func:`bead_map`."""
    units = UNIT_LABELS[results.units]
    scale = 1.0 / results.length_unit_m
    positions, diameters = lattice_beads(results, model)
    circles = bead_map(
        ax,
        positions,
        diameters,
        values,
        cmap=cmap,
        label=label,
        norm=norm,
        unmeasured=unmeasured,
        outlined=other_materials(model),
        colorbar=colorbar,
    )
    draw_walls(ax, model.walls, positions, diameters / 2, scale=scale)
    struck = positions[np.unique(model.struck_beads)]
    ax.plot(struck[:, 0], struck[:, 1], linestyle="", marker="x", color=marker_colour, markersize=8, mew=2)
    ax.set_xlabel(f"x [{units['length']}]")
    ax.set_ylabel(f"y [{units['length']}]")
    return circles


def other_materials(model) -> dict:
    """{"NAME beads": mask} of the beads of each material but the packing's first, for their rings."""
    ids, names = model.packing.material_ids, [material.name for material in model.materials]
    return {f"{names[k]} beads": ids == k for k in np.unique(ids) if k > 0}


def energy_regions_figure(results, path, title="Where the energy is") -> None:
    """Each region's share of the total mechanical energy (kinetic + contact) against time: what
    an interface transmits, or traps on one side."""
    units = UNIT_LABELS[results.units]
    energies = results.region_energies.sum(axis=2)
    shares = energies / energies.sum(axis=1, keepdims=True)
    fig, ax = subplots(figsize=(6, 4.5))
    fig.subplots_adjust(**SINGLE_PLOT_MARGINS)
    for k, name in enumerate(results.region_names):
        ax.plot(results.region_times * units["time_scale"], shares[:, k], label=name)
    ax.set_xlabel(f"time [{units['time']}]")
    ax.set_ylabel("share of the energy")
    ax.set_ylim(0.0, 1.0)
    set_title(ax, title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    save(fig, path)


def front_shape_figure(
    curves: dict, path, title="Roundness of the wavefront", fits: dict | None = None, signed: bool = False
) -> None:
    """Relative sixfold amplitude of the front vs its mean radius, one curve per labelled packing.

    ``curves`` maps a label to a :class:`~hexdem.analysis.front_shape.FrontShape` (or anything
    with ``mean_radius`` in bead diameters and ``sixfold_amplitude``). A regular hexagon's value
    is drawn dashed and a circle's, 0, solid. ``fits`` maps labels to
    :class:`~hexdem.analysis.roundness_fit.RoundnessFit`: each law is drawn over its fronts
    (with its constant A∞ dotted) on a logarithmic radius axis. ``signed``: the sixfold component
    a6/a0 with its sign (see :class:`~hexdem.analysis.front_shape.FrontShape`) instead of the
    amplitude, a hexagon of either orientation drawn dashed.
    """
    fig, ax = subplots(figsize=(6, 4.5))
    fig.subplots_adjust(**SINGLE_PLOT_MARGINS)
    for label, shape in curves.items():
        values = shape.sixfold_cos if signed else shape.sixfold_amplitude
        (line,) = ax.plot(
            shape.mean_radius,
            values,
            marker="o",
            linestyle="-" if not fits else "",
            markersize=4 if fits else 6,
            label=label,
        )
        fit = (fits or {}).get(label)
        if fit is not None:
            radius = np.geomspace(fit.radius_min_d, fit.radius_max_d, 100)
            ax.plot(
                radius,
                fit(radius),
                color=line.get_color(),
                label=f"A∞ + B (R/d)⁻ᵖ: A∞ = {fit.a_inf:.4f} ± {fit.a_inf_se:.4f}, p = {fit.p:.2f}",
            )
            ax.axhline(fit.a_inf, color=line.get_color(), linestyle=":", linewidth=1)
    if fits:
        ax.set_xscale("log")
        plain_log_ticks(ax.xaxis)
    ax.axhline(
        HEXAGON_SIXFOLD, color="k", linestyle="--", linewidth=1, label=f"regular hexagon ({HEXAGON_SIXFOLD:.4f})"
    )
    if signed:
        ax.axhline(-HEXAGON_SIXFOLD, color="k", linestyle="--", linewidth=1)
    ax.axhline(0.0, color="grey", linestyle="-", linewidth=1, label="circle (0)")
    ax.set_xlabel("mean front radius a₀ [d]")
    ax.set_ylabel("sixfold component a₆/a₀  [–]" if signed else "sixfold amplitude √(a₆² + b₆²) / a₀  [–]")
    set_title(ax, title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    save(fig, path)
