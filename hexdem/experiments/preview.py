"""``hexdem preview``: a packing drawn as the run would build it, without running it.

:func:`preview` builds the model of a configuration exactly as a run does
(:func:`~hexdem.model.model_builder.build_model`, then
:func:`~hexdem.model.run_settings.run_settings`), so that it refuses what a run refuses, in the
same one line, and draws it into ``OUT/preview.png``: every body at its true size coloured by its
material, the walls, each struck bead ringed with its impact's arrow (a striker drawn where it
starts, touching its bead), the observation lines from their first bead to their last, and the
sensor beads. A user checks a packing file there before spending hours on it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch

from hexdem.analysis.plotting import bead_circles, draw_walls, save, set_title, subplots
from hexdem.common.io import staged_directory
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

PREVIEW_NAME = "preview.png"
#: Fill colours of the materials by id (the beads' own first), light enough for the marks on top.
MATERIAL_COLOURS = ("#b8c2cc", "#e8b64c", "#7fb8e6", "#e68a7f", "#9bd18b", "#c39be0", "#f0d17a", "#8fd6cf")
STRUCK_COLOUR, LINE_COLOUR, WALL_COLOUR = "#d62728", "#1f4e9c", "0.15"
#: The impact's arrow: its length and the gap it leaves before the struck body, in diameters.
ARROW_LENGTH_D, ARROW_GAP_D = 2.5, 0.15
#: An observation line's name stands this many diameters beyond its last bead's centre, outside the packing.
LABEL_BEYOND_D = 1.4


def preview_figure(config: RunConfig, path) -> str:
    """Draw ``config``'s packing into the PNG ``path`` (see the module docstring); returns a
    one-line description of what was drawn."""
    model = build_model(config)
    run_settings(config, model)  # the checks a run makes of its time step, samples and memory
    lattice, positions = model.packing, model.initial_positions_m()
    diameters, ids = model.diameters_m, model.material_ids
    beads = len(lattice)
    fig, ax = subplots(figsize=(7, 7.2))
    fig.subplots_adjust(left=0.13, right=0.97, bottom=0.17, top=0.94)  # room for the legend below
    legend = []
    for k, material in enumerate(model.materials):
        body = np.flatnonzero(ids[:beads] == k)
        if len(body):
            colour = MATERIAL_COLOURS[k % len(MATERIAL_COLOURS)]
            ax.add_collection(
                bead_circles(ax, positions[body], diameters[body], facecolor=colour, edgecolor="0.3", linewidths=0.4)
            )
            legend.append(Patch(facecolor=colour, edgecolor="0.3", label=f"{material.name} ({len(body)})"))
    if model.walls:
        draw_walls(ax, model.walls, positions[:beads], diameters[:beads] / 2, color=WALL_COLOUR, linewidth=2.5)
        legend.append(Line2D([], [], color=WALL_COLOUR, linewidth=2.5, label=f"walls ({model.wall.name})"))
    _draw_lines(ax, lattice, positions, legend)
    _draw_impacts(ax, model, positions, diameters, legend)
    if model.sensor_beads:
        sensors = positions[list(model.sensor_beads)]
        ax.plot(sensors[:, 0], sensors[:, 1], linestyle="", marker="s", markersize=5, color="k")
        legend.append(Line2D([], [], linestyle="", marker="s", color="k", label="sensors"))
    margin = diameters.max()
    ax.update_datalim(np.vstack([positions.min(axis=0) - margin, positions.max(axis=0) + margin]))
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    description = lattice.shape if f"{beads} beads" in lattice.shape else f"{lattice.shape}, {beads} beads"
    walls = len(model.walls)
    description += f", {walls} wall{'s' if walls > 1 else ''}" if walls else ", no walls"
    set_title(ax, description)
    fig.legend(handles=legend, loc="lower center", ncol=3, frameon=False, fontsize="small")
    save(fig, path)
    return description


def _draw_lines(ax, lattice, positions, legend) -> None:
    """Each observation line from its first bead to its last, named at its end."""
    drawn = False
    for name, beads in lattice.lines().items():
        if len(beads) < 2:
            continue
        ends = positions[beads[[0, -1]]]
        ax.plot(ends[:, 0], ends[:, 1], color=LINE_COLOUR, linewidth=1.2, linestyle="--")
        along = (ends[1] - ends[0]) / np.linalg.norm(ends[1] - ends[0])
        label = ends[1] + LABEL_BEYOND_D * lattice.diameters_m[beads[-1]] * along
        ax.text(
            *label,
            name,
            ha="center",
            va="center",
            color=LINE_COLOUR,
            fontsize="small",
            fontweight="bold",
            bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.85},
        )
        ax.update_datalim([label])
        drawn = True
    if drawn:
        legend.append(Line2D([], [], color=LINE_COLOUR, linewidth=1.2, linestyle="--", label="observation lines"))


def _draw_impacts(ax, model, positions, diameters, legend) -> None:
    """Each struck bead ringed, its striker (if any) dashed where it starts, and an arrow of the
    impact's direction ending just short of the body it sets moving."""
    struck = model.struck_beads
    ax.add_collection(
        bead_circles(
            ax, positions[struck], diameters[struck], facecolor="none", edgecolor=STRUCK_COLOUR, linewidths=2.0
        )
    )
    legend.append(
        Line2D(
            [],
            [],
            linestyle="",
            marker="o",
            markerfacecolor="none",
            markeredgecolor=STRUCK_COLOUR,
            markeredgewidth=2,
            label="struck bead",
        )
    )
    bodies = model.impact_bodies()
    strikers = bodies[bodies >= len(model.packing)]
    if len(strikers):
        ax.add_collection(
            bead_circles(
                ax,
                positions[strikers],
                diameters[strikers],
                facecolor="white",
                edgecolor=STRUCK_COLOUR,
                linewidths=1.5,
                linestyles="--",
            )
        )
        legend.append(
            Line2D(
                [],
                [],
                linestyle="",
                marker="o",
                markerfacecolor="white",
                markeredgecolor=STRUCK_COLOUR,
                label="striker",
            )
        )
    for impact, body in zip(model.impacts, bodies):
        d = diameters[body]
        tip = positions[body] - (0.5 + ARROW_GAP_D) * d * impact.direction
        tail = tip - ARROW_LENGTH_D * d * impact.direction
        ax.annotate(
            "",
            xy=tip,
            xytext=tail,
            arrowprops={"arrowstyle": "-|>", "color": STRUCK_COLOUR, "linewidth": 2, "mutation_scale": 18},
        )
        ax.update_datalim([tail])
    speeds = sorted({f"{impact.speed_m_s:g} m/s at {impact.angle_deg:g}°" for impact in model.impacts})
    legend.append(Line2D([], [], color=STRUCK_COLOUR, linewidth=2, label=f"impact: {', '.join(speeds)}"))


def preview(config: RunConfig, out) -> Path:
    """``OUT/preview.png`` of ``config``'s packing (see the module docstring); a configuration a
    run would refuse is refused in the same one line, and nothing is written."""
    if config.shape == "random":
        raise HexdemError(
            "a random disc is packed by LAMMPS before it can be drawn: run it, then preview "
            'OUT/preparation/packing.csv as shape = "packing"'
        )
    with staged_directory(out) as staging:
        preview_figure(config, staging / PREVIEW_NAME)
    return Path(out) / PREVIEW_NAME
