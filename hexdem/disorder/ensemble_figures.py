r"""Figures of a disorder ensemble (Sec. VI-B): Fig. 9 (fig:all_directions) and Fig. 8
(fig:expnumsim), drawn from the tables :mod:`hexdem.disorder.ensemble` writes.

The fitted laws of Fig. 9 are the paper's eqs. (10) (0° line, n ≥ 2) and (11) (±30°
lines, n ≥ 1) with the coefficients of a ``scaling.json`` from ``hexdem scaling`` (keys
"0/0" and "0/30"; nondimensional, turned into m/s by the paper's rule :math:`V → V \sqrt{M/A} / d^{5/4}`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from hexdem.analysis import plotting as plots
from hexdem.errors import HexdemError
from hexdem.model.materials import STEEL_316
from hexdem.model.units import nondimensional

#: Observation lines of Fig. 9 (0° strike): the 0° line and the −30° line.
FIG9_LINES = ("0", "-30")
#: scaling.json key of the law of each observation line (0° strike; ±30° are mirror images).
LAW_KEYS = {"0": "0/0", "+30": "0/30", "-30": "0/30"}


def fitted_laws(path, diameter_m: float) -> dict:
    """{line: ScalingLaw in m/s} from a ``scaling.json`` (eqs. (10), (11))."""
    from hexdem.theory.scaling import ScalingLaw

    path = Path(path)
    try:
        data = json.loads(path.read_text())
        laws = {}
        for line, key in LAW_KEYS.items():
            entry = data[key]
            amplitude = tuple(float(entry[name]) for name in ("alpha", "beta", "gamma") if entry.get(name) is not None)
            law = ScalingLaw(key, int(entry["start_bead"]), float(entry["m"]), float(entry["b"]), amplitude)
            laws[line] = law.physical(nondimensional(diameter_m, STEEL_316).velocity_m_s)
    except OSError as exc:
        raise HexdemError(f"cannot read scaling laws {path}: {exc.strerror}") from None
    except (ValueError, KeyError, TypeError):
        raise HexdemError(
            f'{path} is not a scaling.json of hexdem scaling (needs keys "0/0" and "0/30" '
            "with m, b, alpha, beta, gamma, start_bead)"
        ) from None
    return laws


def _by_velocity_line(rows, value_columns: slice):
    table: dict = {}
    for row in rows:
        table.setdefault((row[0], row[1]), []).append((row[2], *row[value_columns]))
    return {key: np.array(sorted(values), dtype=float) for key, values in table.items()}


def fig9_lines(lattice) -> tuple[str, str]:
    """The lines of Fig. 9: :data:`FIG9_LINES` on the triangular lattice; elsewhere the 0° ray and
    the first ray below it (a square's −45°)."""
    if lattice.bond_steps:
        return FIG9_LINES
    return "0", next(name for name in lattice.lines() if name.startswith("-"))


def all_directions(stats_rows, ideal_rows, laws: dict, path, lines=FIG9_LINES) -> None:
    """Fig. 9: peak speed against n along the 0° and −30° ``lines``, one row per striker speed.

    Grey band: mean ± σ over the disordered realizations (dotted: the mean); black dots:
    the ideal lattice struck by the same striker; red: the fitted law, if any.
    """
    from matplotlib.ticker import MaxNLocator

    stats = _by_velocity_line(stats_rows, slice(3, 5))
    ideal = _by_velocity_line(ideal_rows, slice(3, 4))
    velocities = sorted({v for v, _ in stats})
    fig, axes = plots.subplots(len(velocities), 2, figsize=(10, 3.2 * len(velocities)), squeeze=False, sharex="col")
    for row, v in enumerate(velocities):
        for col, line in enumerate(lines):
            ax = axes[row, col]
            n, mean, std = stats[(v, line)].T
            ax.fill_between(n, mean - std, mean + std, color="0.8", label=r"disordered $\mu \pm \sigma$")
            ax.plot(n, mean, ":", color="0.35", label=r"disordered $\mu$")
            n_ideal, peak = ideal[(v, line)].T
            ax.plot(n_ideal, peak, "ko", markersize=4, label="ideal lattice")
            if line in laws:
                law = laws[line]
                n_law = n_ideal[n_ideal >= law.start]
                ax.plot(n_law, law(v, n_law), "r-", label=f"fitted law ({law.combination})")
            ax.set_ylim(bottom=0)
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
            ax.grid(True, alpha=0.3)
            ax.set_title(f"0° strike, {line}° line, $V_{{\\rm striker}}$ = {v:g} m/s", fontsize=10)
            ax.set_ylabel("peak speed [m/s]")
            if row == len(velocities) - 1:
                ax.set_xlabel("bead n along the line")
    for ax in axes[0]:
        ax.legend(fontsize=8)
    fig.suptitle("Peak speed along the lines, weak disorder vs ideal (Fig. 9)")
    plots.save(fig, path)


def expnumsim(
    lattice, walls, ideal_relative, mean_relative, reference: int, v_striker: float, realizations: int, path
) -> None:
    """Fig. 8 (a), (c): arrival time relative to the reference bead (white x), ideal lattice
    beside the mean over the disordered realizations, one colour scale and its one bar [ms]."""

    finite = np.concatenate([ideal_relative[np.isfinite(ideal_relative)], mean_relative[np.isfinite(mean_relative)]])
    clim = (float(finite.min()) * 1e3, float(finite.max()) * 1e3)
    positions, diameters = lattice.positions_m, lattice.diameters_m
    fig, axes = plots.subplots(1, 2, figsize=(13, 5.5))
    panels = (
        ("(a) ideal lattice", ideal_relative),
        (f"(c) weak disorder, mean of {realizations} realizations", mean_relative),
    )
    for ax, (title, values) in zip(axes, panels):
        circles = plots.bead_map(ax, positions, diameters, values * 1e3, cmap="viridis_r", clim=clim, colorbar=False)
        plots.draw_walls(ax, walls, positions, diameters / 2)
        ax.plot(*positions[reference], marker="x", color="w", markersize=8, mew=2)
        ax.set_title(title)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.colorbar(circles, ax=list(axes), label="relative arrival time [ms]", shrink=0.8)
    fig.suptitle(
        f"Wavefront arrival relative to the marked bead, $V_{{\\rm striker}}$ = {v_striker:g} m/s (Fig. 8; "
        "its panel (b), the experiments' mean, is measured, not simulated)"
    )
    plots.save(fig, path)
