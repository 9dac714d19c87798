"""The friction study's figure (:mod:`hexdem.paper.friction_study`): four panels against μ."""

from __future__ import annotations

import numpy as np

from hexdem.paper.friction_study import COMBINATIONS, FRICTION_SIGMA_PER_TOL, LINES
from hexdem.paper.settings import STUDY_VELOCITY_M_S

#: Marker of each striker speed [m/s].
SPEED_MARKERS = {0.25: "v", 0.40: "o", 0.70: "^"}
#: Colour of each line of the study and each decay combination.
COLOURS = {"0": "C0", "±30": "C3", "0/0": "C0", "0/30": "C3"}


def _against_mu(ax, rows, column: int, sigma_tol: float, style: str) -> None:
    """Column ``column`` of the effect rows at ``sigma_tol`` against μ, one curve per line and speed
    (± 2 standard errors where there are several packings)."""
    for line in LINES:
        for v, marker in SPEED_MARKERS.items():
            chosen = sorted(r for r in rows if r[3] == line and r[2] == sigma_tol and np.isclose(r[1], v))
            if not chosen:
                continue
            mu, value = np.array([r[0] for r in chosen]), np.array([r[column] for r in chosen])
            sem = np.nan_to_num(np.array([r[5] for r in chosen])) if column == 4 else None
            ax.errorbar(
                mu,
                value,
                yerr=None if sem is None else 2 * sem,
                fmt=style,
                marker=marker,
                color=COLOURS[line],
                capsize=2,
                label=f"{line}°, {v:.2f} m/s" if sigma_tol == 0 else None,
            )


def friction_figure(rows: list[tuple], decay: list[tuple], conditions: list[dict], edge_beads: int, path) -> None:
    """On the hexagon of ``edge_beads`` per edge: (a) leading-pulse amplitude and (b) arrival
    shift against μ, over the frictionless run of the same packing (solid: ideal lattice, dashed:
    σ = 6 tol, mean ± 2 SEM); (c) Sec. V's decay rate c over its frictionless value; (d) the
    disorder study with friction: disordered / ideal transmission at σ = 6 tol (mean ± 2 SEM),
    above 1 where disorder helps."""
    from hexdem.analysis import plotting as plots

    fig, axes = plots.subplots(2, 2, figsize=(11, 8.5), layout="constrained")
    (amplitude, arrival), (rates, disorder) = axes
    for sigma_tol, style in ((0.0, "-"), (FRICTION_SIGMA_PER_TOL, "--")):
        _against_mu(amplitude, rows, 4, sigma_tol, style)
        _against_mu(arrival, rows, 6, sigma_tol, style)
    amplitude.set_ylabel(r"leading pulse $V_n(\mu) / V_n(0)$, mean over $n \geq 2$")
    arrival.set_ylabel(r"arrival shift $t_n(\mu) - t_n(0)$ [µs]")
    low, high = amplitude.get_ylim()
    amplitude.set_ylim(low - 0.6 * (high - low), high)  # room for the legend below the curves
    amplitude.legend(
        fontsize=7,
        ncol=2,
        loc="lower left",
        title="solid: ideal lattice; dashed: σ = 6 tol (± 2 SEM)",
        title_fontsize=7,
    )
    for name, _, _ in COMBINATIONS:
        for v, marker in SPEED_MARKERS.items():
            chosen = sorted(r for r in decay if r[2] == name and np.isclose(r[1], v))
            rates.plot(
                [r[0] for r in chosen],
                [r[5] for r in chosen],
                "-",
                marker=marker,
                color=COLOURS[name],
                label=f"{name}, {v:.2f} m/s",
            )
    rates.set_ylabel(r"decay rate $c(\mu) / c(0)$ (Sec. V, ideal lattice)")
    rates.set_title("the three speeds coincide: Hertz–Mindlin–Coulomb is scale invariant", fontsize=9)
    rates.legend(fontsize=7, ncol=2, loc="lower left")
    for measure, style in (("peak", "o-"), ("lead", "s--")):
        for line, key in (("0", "zero"), ("±30", "pm30")):
            chosen = sorted((c for c in conditions if c["measure"] == measure), key=lambda c: c["friction"])
            disorder.errorbar(
                [c["friction"] for c in chosen],
                [c[f"{key}_ratio"] for c in chosen],
                yerr=[2 * np.nan_to_num(c[f"{key}_sem"]) for c in chosen],
                fmt=style,
                color=COLOURS[line],
                capsize=3,
                label=f"{line}°, {measure}",
            )
    disorder.axhline(1.0, color="k", lw=0.8)
    disorder.set_ylabel(f"disordered / ideal at σ = 6 tol, {STUDY_VELOCITY_M_S:.2f} m/s")
    disorder.legend(fontsize=7)
    for ax in (amplitude, rates):
        ax.axhline(1.0, color="k", lw=0.8)
    arrival.axhline(0.0, color="k", lw=0.8)
    for ax in axes.flat:
        ax.set_xlabel(r"Coulomb friction $\mu$")
        ax.grid(True, alpha=0.3)
    fig.suptitle(
        f"Mindlin friction and rotation in the hexagon of {edge_beads} per edge, against the frictionless spheres"
    )
    plots.save(fig, path)
