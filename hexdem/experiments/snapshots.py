"""Wavefront snapshots (Figs. 3 and 4): every bead's speed at chosen times after the impact.

The ideal lattice is struck at the centre of an edge by a striker sphere (V_striker =
0.40 m/s in both figures): Fig. 3 (fig:smallsim) is the 11-per-edge hexagon of the
experiment, Fig. 4 (fig:largesim) the half-hexagon with a long edge of 91 beads and short
edges of 46, on which the walls of the small hexagon are outlined (both packings put the
struck bead {0, 0} at the origin, so the outline needs no shift).

Samples fall exactly on the requested times: the times are rounded to whole microseconds,
and the time step and sampling interval are the default ones shortened just enough that
the times' greatest common divisor is a whole number of samples of whole numbers of steps.
The fields are taken inside the run (no dump), on one or several ranks.
"""

from __future__ import annotations

import math
import sys
import time
from dataclasses import dataclass
from importlib.metadata import version
from pathlib import Path

import numpy as np

from hexdem.analysis import plotting as plots
from hexdem.common.io import ensure_writable_dir, write_csv, write_json
from hexdem.errors import HexdemError
from hexdem.experiments.tracked_run import ImpactJob, track_impact
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel
from hexdem.model.model_builder import build_model
from hexdem.model.packing import Packing
from hexdem.model.run_settings import run_settings
from hexdem.model.triangular import hexagon

#: Default snapshot times [ms]: at V_striker = 0.4 m/s the leading wave reaches the far wall
#: of the hexagon after about 0.95 ms, that of the half-hexagon after about 2.5 ms.
DEFAULT_TIMES_MS = {"hexagon": (0.15, 0.3, 0.45, 0.6, 0.75, 0.9), "half-hexagon": (0.4, 0.8, 1.2, 1.6, 2.0, 2.4)}
#: Output names (PNG and CSV) per shape, after the paper's figure labels.
FIGURE_NAMES = {"hexagon": "fig3_smallsim", "half-hexagon": "fig4_largesim"}
SNAPSHOT_COLUMNS = ("time", "bead_id", "m", "n", "x", "y", "speed")


def snapshot_config(config: RunConfig, model: GranularModel, times_s) -> RunConfig:
    """``config`` (whose model ``model`` is) with the time step, sampling interval and length that
    put a sample on every time.

    The times' greatest common divisor (whole µs) is split into a whole number of samples no
    longer than the default sampling interval, each a whole number of steps no longer than
    the default time step.
    """
    if config.units != "si":
        raise HexdemError("snapshots need an SI configuration (times are in seconds)")
    micro = [round(float(t) * 1e6) for t in times_s]
    if not micro or min(micro) < 1 or len(set(micro)) != len(micro):
        raise HexdemError(f"snapshot times must be distinct and at least 1 µs, got {list(times_s)}")
    unit_s = math.gcd(*micro) * 1e-6
    default = run_settings(config, model)
    samples = math.ceil(unit_s / (default.dt_s * default.dump_every))
    every = math.ceil(unit_s / samples / default.dt_s)
    return config.replace(dt=unit_s / (samples * every), duration=max(micro) * 1e-6, dump_every=every)


@dataclass(frozen=True)
class Snapshots:
    """Bead speeds [m/s] ``speeds`` (T, N) at ``times_s`` (T,) of the run of ``config``."""

    config: RunConfig
    packing: Packing
    times_s: np.ndarray
    speeds: np.ndarray
    engine: dict


def take_snapshots(config: RunConfig, model: GranularModel, times_s, directory) -> Snapshots:
    """Run ``config`` (striker impact, ideal lattice; its model ``model``) in LAMMPS on
    ``config.ranks`` ranks and keep every bead's speed at ``times_s``, taken inside the run (no
    dump)."""
    config = snapshot_config(config, model, sorted(times_s))
    settings = run_settings(config, model)
    wanted = np.array([round(t * 1e6) * 1e-6 for t in sorted(times_s)])
    samples = np.rint(wanted / (settings.dump_every * settings.dt_s)).astype(int)
    job = ImpactJob(model, settings, "lammps", Path(directory), dump=config.dump, field_samples=tuple(samples))
    analysis = track_impact(job, config.ranks, launcher=config.launcher)
    tracked = analysis.tracked
    return Snapshots(
        config, model.packing, tracked.field_times * settings.units.time_s, tracked.field_speeds, analysis.engine
    )


def snapshot_rows(snapshots: Snapshots) -> list[tuple]:
    lattice = snapshots.packing
    return [
        (float(t), bead + 1, int(m), int(n), float(x), float(y), float(speed))
        for t, speeds in zip(snapshots.times_s, snapshots.speeds)
        for bead, ((m, n), (x, y), speed) in enumerate(zip(lattice.labels, lattice.positions_m, speeds))
    ]


def snapshot_figure(snapshots: Snapshots, walls, path, outline: Packing | None = None) -> None:
    """Bead-speed maps, one panel per time, at most three to a row, walls drawn; ``outline``: a
    smaller packing whose walls are drawn dashed (Fig. 4). The panels share one colour scale
    and its one bar, from 0 to the median of the panels' largest speeds: the pulse's slow decay
    shows, and the few faster beads of the first panels, by the striker, take the top colour
    (the bar's arrow). Sized so that its smallest text is at least 10 px in the report."""

    lattice, config = snapshots.packing, snapshots.config
    count = len(snapshots.times_s)
    aspect = np.ptp(lattice.positions_m[:, 1]) / max(np.ptp(lattice.positions_m[:, 0]), lattice.diameter_m)
    columns = min(3, count)
    rows = math.ceil(count / columns)
    width = 3.2 if aspect > 1.5 else 4.0
    fig, axes = plots.subplots(
        rows,
        columns,
        figsize=(width * columns + 1.0, 0.85 * width * aspect * rows + 0.9),
        squeeze=False,
        layout="constrained",
    )
    top = float(np.median(np.max(snapshots.speeds, axis=1)))
    for ax, t, speeds in zip(axes.flat, snapshots.times_s, snapshots.speeds):
        circles = plots.bead_map(
            ax, lattice.positions_m, lattice.diameters_m, speeds, cmap="hot_r", clim=(0.0, top), colorbar=False
        )
        plots.draw_walls(ax, walls, lattice.positions_m, lattice.radii_m, linewidth=1)
        if outline is not None:
            plots.draw_walls(ax, outline.walls, outline.positions_m, outline.radii_m, linestyle="--", linewidth=1.2)
        ax.set_title(f"t = {t * 1e3:.3g} ms", fontsize=12)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in list(axes.flat)[count:]:
        ax.set_visible(False)
    bar = fig.colorbar(
        circles, ax=axes.ravel().tolist(), shrink=0.6, extend="max" if snapshots.speeds.max() > top else "neither"
    )
    bar.set_label("bead speed [m/s]", fontsize=12)
    bar.ax.tick_params(labelsize=11)
    fig.suptitle(
        f"Wavefront, {lattice.shape}, striker at {config.v0:g} m/s"
        + (f";\ndashed: walls of the {outline.shape}" if outline is not None else ""),
        fontsize=12,
    )
    plots.save(fig, path)


def run_snapshots(config: RunConfig, times_s, out, outline_edge: int | None = None, log=None) -> Snapshots:
    """Simulate, then write ``<figure>.png``, ``<figure>.csv`` and ``snapshots.json`` into ``out``.

    ``outline_edge``: draw the walls of a hexagon with this many beads per edge (Fig. 4: 11).
    """
    log = log or (lambda message: print(f"hexdem snapshots: {message}", file=sys.stderr, flush=True))
    model = build_model(config)
    snapshot_config(config, model, times_s)
    outline = hexagon(outline_edge, config.diameter_m) if outline_edge else None
    out = ensure_writable_dir(out)
    start = time.perf_counter()
    log(
        f"{model.packing.shape}, striker at {config.v0:g} m/s, {config.ranks} rank(s), "
        f"{len(times_s)} snapshots up to {max(times_s) * 1e3:g} ms"
    )
    snapshots = take_snapshots(config, model, times_s, out / "deck")
    name = FIGURE_NAMES.get(config.shape, "snapshots")
    write_csv(out / f"{name}.csv", SNAPSHOT_COLUMNS, snapshot_rows(snapshots))
    snapshot_figure(snapshots, model.walls, out / f"{name}.png", outline)
    settings = run_settings(snapshots.config, model)
    engine = snapshots.engine
    write_json(
        out / "snapshots.json",
        {
            "hexdem_version": version("hexdem"),
            "config": snapshots.config.shape_dict(),
            "times_s": snapshots.times_s.tolist(),
            "n_beads": len(snapshots.packing),
            "lammps_version": engine["version"],
            "ranks": engine["ranks"],
            "lammps_wall_time_s": engine["wall_time_s"],
            "atom_steps_per_s": (len(snapshots.packing) + 1) * settings.n_steps / engine["wall_time_s"],
            "wall_time_s": time.perf_counter() - start,
        },
    )
    log(f"LAMMPS {engine['wall_time_s']:.1f} s on {engine['ranks']} rank(s); results in {out}")
    return snapshots
