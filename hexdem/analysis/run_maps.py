"""A run's two bead maps, ``arrival_map.png`` and ``peak_map.png`` (like Fig. 8a): a packing drawn
in a figure of its own shape, its colour bar as tall as the map
(:func:`~hexdem.analysis.map_layout.fit_map`), or a chain, every bead on one line, drawn as its
values along it above its beads (:func:`chain_map`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import LogNorm, Normalize
from matplotlib.figure import Figure

from hexdem.analysis.map_layout import chain_direction, fit_chain, fit_map
from hexdem.analysis.plotting import (
    UNIT_LABELS,
    bead_map,
    colour_bar,
    draw_lattice,
    draw_walls,
    lattice_beads,
    other_materials,
    plain_log_ticks,
    save,
    set_title,
)
from hexdem.model.walls import CurvedWall


def unmeasured_beads(results) -> dict:
    """{name: mask} of the beads without a peak (:data:`UNMEASURED_GREYS`): still rising when
    the run ended (peak NaN), or never moved (peak 0)."""
    peaks = results.peak_speed
    return {"still rising at the run's end": np.isnan(peaks), "never moved": peaks == 0}


def _walls_along(walls, origin_m, along) -> list:
    """``walls`` in the frame of a chain: x the distance along ``along`` from ``origin_m``, y across."""
    frame = np.array([along, [-along[1], along[0]]])
    moved = []
    for wall in walls:
        if isinstance(wall, CurvedWall):
            moved.append(replace(wall, centre_m=tuple(frame @ (np.asarray(wall.centre_m) - origin_m))))
        else:
            normal = np.asarray(wall.normal, float)
            moved.append(replace(wall, normal=tuple(frame @ normal), offset_m=wall.offset_m - float(normal @ origin_m)))
    return moved


def chain_map(results, model, values, along, label: str, cmap="viridis", norm=None) -> Figure:
    """A chain's ``values`` against the distance along it (``along``, :func:`chain_direction`) from
    the struck bead, each bead a marker in its colour on the map's scale (logarithmic axis under a
    :class:`~matplotlib.colors.LogNorm`), above the chain itself, true size, on the same abscissa
    and in the same colours, its beads without a value in their greys: drawn as a 2D map, a
    chain would be a strip one bead high under a colour bar many times its height."""
    units = UNIT_LABELS[results.units]
    positions, diameters = lattice_beads(results, model)
    struck = int(model.struck_beads[0])
    origin = positions[struck]
    frame = (positions - origin) @ np.column_stack([along, [-along[1], along[0]]])
    fig = Figure()
    FigureCanvasAgg(fig)
    profile = fig.add_subplot()
    strip = fig.add_axes((0.0, 0.0, 1.0, 0.1), sharex=profile)
    unmeasured = unmeasured_beads(results)
    norm = norm or Normalize()
    bead_map(
        strip,
        frame,
        diameters,
        values,
        cmap=cmap,
        norm=norm,
        unmeasured=unmeasured,
        outlined=other_materials(model),
        colorbar=False,
    )
    draw_walls(
        strip,
        _walls_along(model.walls, origin * results.length_unit_m, along),
        frame,
        diameters / 2,
        scale=1.0 / results.length_unit_m,
    )
    strip.plot(*frame[np.unique(model.struck_beads)].T, linestyle="", marker="x", color="k", markersize=7, mew=1.5)
    values = np.asarray(values, float)
    coloured = np.isfinite(values) & ~np.any(list(unmeasured.values()), axis=0)
    order = np.argsort(frame[:, 0])
    shown = np.where(coloured, values, np.nan)[order]
    sizes = np.round(diameters[order], 9)
    kinds = sorted(set(sizes.tolist()), reverse=True)
    for kind, style in zip(kinds, ("-", "--", ":", "-.") * len(kinds)):  # a dimer's heavy and light beads apart
        mine = sizes == kind
        profile.plot(
            frame[order, 0][mine],
            shown[mine],
            color="0.55",
            linewidth=1,
            linestyle=style,
            zorder=1,
            label=f"beads of d = {kind:.4g} {units['length']}" if len(kinds) > 1 else None,
        )
    profile.scatter(
        frame[order, 0], shown, c=shown, cmap=colormaps[cmap], norm=norm, edgecolors="k", linewidths=0.4, zorder=2
    )
    if len(kinds) > 1:
        profile.legend(fontsize="small")
    if isinstance(norm, LogNorm) and np.any(coloured):  # (a log axis of no value cannot be drawn)
        profile.set_yscale("log")
        plain_log_ticks(profile.yaxis)
    profile.set_ylabel(label)
    profile.grid(True, which="both", alpha=0.3)
    profile.tick_params(labelbottom=False)
    strip.set_yticks([])
    strip.set_xlabel(f"distance from the struck bead along the chain [{units['length']}]")
    fit_chain(profile, strip)
    return fig


def lattice_map(results, model, values, path, label: str, title: str, cmap="viridis", norm=None) -> Figure:
    """One value per bead drawn on the lattice (like Fig. 8a), walls drawn, struck beads marked, in
    a figure the packing's shape (:func:`~hexdem.analysis.map_layout.fit_map`), its colour bar as
    tall as the packing is drawn; a chain's values drawn along it instead (:func:`chain_map`).
    Returns the figure, saved at ``path``."""
    along = chain_direction(*lattice_beads(results, model), int(model.struck_beads[0]))
    if along is not None:
        fig = chain_map(results, model, values, along, label, cmap, norm)
        set_title(fig.axes[0], title)
    else:
        fig = Figure()
        FigureCanvasAgg(fig)
        ax = fig.add_subplot()
        beads = draw_lattice(
            ax, results, model, values, label, cmap, norm, unmeasured=unmeasured_beads(results), colorbar=False
        )
        colour_bar(beads, label, cax=fit_map(ax, title))
    save(fig, path)
    return fig


def arrival_map(results, model, path, title="Wavefront arrival time") -> Figure:
    """Every bead's arrival time on the lattice (like Fig. 8a); the figure (:func:`lattice_map`)."""
    units = UNIT_LABELS[results.units]
    return lattice_map(
        results,
        model,
        results.arrival_time * units["time_scale"],
        path,
        f"arrival time [{units['time']}]",
        title,
        cmap="viridis_r",
    )


#: The share of its top that a peak map's scale spans at least (for peaks that are all equal).
FLAT_SCALE = 0.9


def peak_scale(ratio) -> tuple[float, float]:
    """(bottom, top) of a peak map's logarithmic colour scale for peaks ``ratio`` (over V0; 0 never
    moved, NaN still rising): it follows the peaks, from the smallest (down to 1e-3 at the lowest)
    to the largest, so that peaks that barely decay (a square crystal's row, 0.68 to 1) spread over
    the whole scale; equal peaks span :data:`FLAT_SCALE` of their value to it."""
    ratio = np.asarray(ratio, float)
    moved = ratio[ratio > 0]
    if not len(moved):
        return 1e-1, 1.0
    top = float(np.max(moved))
    return min(max(float(np.min(moved)), 1e-3), FLAT_SCALE * top), top


def peak_map(results, model, v0: float, path, title="Peak speed") -> Figure:
    """Every bead's peak speed over V0 on the lattice, on a logarithmic scale (the fronts decay
    by decades as they spread; :func:`peak_scale`); the figure (:func:`lattice_map`)."""
    ratio = results.peak_speed / v0
    return lattice_map(
        results, model, ratio, path, "peak speed Vₘₐₓ / V₀", title, cmap="magma", norm=LogNorm(*peak_scale(ratio))
    )
