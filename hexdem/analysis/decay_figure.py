"""The peak speed's decay along the observation lines (Figs. 6, 9), as ``peak_decay.png`` draws it."""

from __future__ import annotations

import re

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from hexdem.analysis.plotting import SINGLE_PLOT_MARGINS, UNIT_LABELS, plain_log_ticks, save, set_title, subplots

#: An observation line named by its angle with a sign ("+30", "-45"): its mirror line has the other sign.
SIGNED_ANGLE = re.compile(r"[+-]\d+(\.\d*)?")
#: A line named by an angle, signed, unsigned or mirrored (±).
ANGLE = re.compile(r"[+±-]?\d+(\.\d*)?")


def peak_decay(
    rows_by_line: dict, path, units_name: str, v0: float, title="Peak speed along the observation lines"
) -> Figure:
    """Peak speed V_n / V0 vs n for each observation line, logarithmic axis; the figure, saved.

    A bead that never moved (peak 0) has no place on a logarithmic axis: it is left out, not drawn
    as a drop to the axis' floor, and a line none of whose beads beyond its first (the struck bead,
    which every line shares) moved is named in the legend as never moved, with its mirror line
    ("±45°: never moved") where both never moved. A line whose mirror is drawn (a symmetric
    strike's +30° and −30° coincide) is drawn open and dashed over the mirror's filled markers."""
    units = UNIT_LABELS[units_name]
    fig, ax = subplots(figsize=(6, 4.5))
    fig.subplots_adjust(**SINGLE_PLOT_MARGINS)
    peaks = {line: np.asarray(peak, float) / v0 for line, (_, peak) in rows_by_line.items()}
    still = [line for line, peak in peaks.items() if len(peak) > 1 and np.all(peak[1:] == 0)]
    for line, (n, _) in rows_by_line.items():
        if line in still:
            continue
        style = {"marker": "o", "linestyle": "-"}
        if SIGNED_ANGLE.fullmatch(line):
            style["marker"] = "^" if line[0] == "+" else "v"
            if line[0] == "-" and _mirror(line) in peaks and _mirror(line) not in still:
                style.update(markerfacecolor="none", linestyle="--", markersize=9)
        ax.semilogy(n, np.where(peaks[line] > 0, peaks[line], np.nan), label=line_label(line), **style)
    handles, labels = ax.get_legend_handles_labels()
    for name in _mirrored_names(still):
        handles.append(Line2D([], [], linestyle="none"))
        labels.append(f"{line_label(name)}: never moved")
    ax.set_xlabel("bead n along the line")
    ax.set_ylabel(f"Vₙ / V₀   (V₀ = {v0:.4g} {units['speed']})")
    plain_log_ticks(ax.yaxis)
    set_title(ax, title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(handles, labels, title="observation line")
    save(fig, path)
    return fig


def line_label(name: str) -> str:
    """An observation line's name in a legend: an angle with its degree sign (0°, +30°, ±45°), a
    line of the configuration's own name as it is (up, diagonal)."""
    return f"{name}°" if ANGLE.fullmatch(name) else name


def _mirror(line: str) -> str:
    """The name of the mirror of a line named by a signed angle: "-45" for "+45"."""
    return ("-" if line[0] == "+" else "+") + line[1:]


def _mirrored_names(lines) -> list[str]:
    """``lines``' names, a line and its mirror ("+45", "-45") named once as "±45"."""
    names = []
    for line in lines:
        if SIGNED_ANGLE.fullmatch(line) and _mirror(line) in lines:
            if line[0] == "+":
                names.append("±" + line[1:])
        else:
            names.append(line)
    return names
