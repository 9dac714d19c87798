"""The leading pulse's shape bead by bead: amplitude, width, arrival and its profile, and how
far the profiles of beads at growing distance are from collapsing onto one shape.

**Per bead** (:func:`pulse_shapes`), from its speed signal |v|(t): the leading pulse is the
first clear hump (:mod:`hexdem.analysis.leading_pulse`: the first maximum reaching 20 % of the
bead's largest speed and followed by a fall below 80 % of itself); its amplitude v_m is the
vertex of the parabola through the highest sample and its neighbours; its arrival t_a and its
end are the crossings of v_m/2 before and after that maximum, interpolated linearly between
samples; its width w is the time between them.

**Profiles** (:func:`profiles`): v(t)/v_m against τ = (t − t_a)/w, interpolated on a grid of τ:
every pulse then rises through 1/2 at τ = 0 and falls through it at τ = 1. A decaying pulse is
self-similar if these profiles converge onto one shape as it travels. :func:`collapse_residuals`
measures each profile's RMS distance from a reference shape (the mean profile of the farthest
beads, :func:`reference_profile`).

**Power laws** (:func:`power_law`): p and its standard error in :math:`y ∝ r^p`, least squares of
log y on log r.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.analysis.leading_pulse import leading_maximum, parabola_vertex

#: The profile grid: τ = (t − t_a)/w from a width before the arrival to two after.
PROFILE_GRID = np.linspace(-1.0, 3.0, 81)


@dataclass(frozen=True)
class PulseShapes:
    """(B,) arrays of B beads: ``peak`` v_m, ``arrival`` t_a, ``width`` w, ``peak_time``, in the
    signal's units. All four are NaN where a bead has no clear leading pulse; ``arrival`` is NaN
    where the rise through v_m/2 is not in the signal, ``width`` where either crossing is not."""

    peak: np.ndarray
    arrival: np.ndarray
    width: np.ndarray
    peak_time: np.ndarray


def _crossing(times: np.ndarray, signal: np.ndarray, level: float, start: int, step: int) -> float:
    """The time where ``signal`` crosses ``level`` going from sample ``start`` by ``step``
    (−1: back in time, +1: forward), interpolated linearly; NaN if it does not."""
    k = start
    while 0 <= k + step < len(signal) and signal[k + step] >= level:
        k += step
    if not 0 <= k + step < len(signal):
        return float("nan")
    inside, outside = signal[k], signal[k + step]
    return float(times[k] + (times[k + step] - times[k]) * (inside - level) / (inside - outside))


def pulse_shapes(times, speeds) -> PulseShapes:
    """The leading pulse of each of the B signals ``speeds`` (S, B) sampled at ``times`` (S,)."""
    times, speeds = np.asarray(times, float), np.asarray(speeds, float)
    peak, arrival, width, peak_time = (np.full(speeds.shape[1], np.nan) for _ in range(4))
    for bead, signal in enumerate(speeds.T):
        index = leading_maximum(signal)
        if index < 0:
            continue
        peak[bead] = amplitude = parabola_vertex(signal[index - 1], signal[index], signal[index + 1])
        peak_time[bead] = times[index]
        rise = _crossing(times, signal, amplitude / 2, index, -1)
        fall = _crossing(times, signal, amplitude / 2, index, +1)
        arrival[bead], width[bead] = rise, fall - rise
    return PulseShapes(peak, arrival, width, peak_time)


def profiles(times, speeds, shapes: PulseShapes, grid=PROFILE_GRID) -> np.ndarray:
    """(B, G) profiles v/v_m at τ = ``grid`` (see the module docstring); NaN rows for beads
    without a pulse, NaN where τ falls outside the signal."""
    times, speeds = np.asarray(times, float), np.asarray(speeds, float)
    out = np.full((speeds.shape[1], len(grid)), np.nan)
    for bead in np.flatnonzero(np.isfinite(shapes.width)):
        at = shapes.arrival[bead] + grid * shapes.width[bead]
        values = np.interp(at, times, speeds[:, bead] / shapes.peak[bead], left=np.nan, right=np.nan)
        out[bead] = values
    return out


def reference_profile(shape_rows: np.ndarray) -> np.ndarray:
    """The mean of the given profiles (G,), ignoring missing values."""
    return np.nanmean(shape_rows, axis=0)


def collapse_residuals(shape_rows: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """(B,) RMS distance over the grid of each profile from ``reference`` (in units of the
    peak: 0 for the same shape)."""
    return np.sqrt(np.nanmean((shape_rows - reference) ** 2, axis=1))


def power_law(r, y) -> tuple[float, float]:
    """(p, standard error of p) of :math:`y ∝ r^p` over the finite, positive points (NaN if fewer
    than four)."""
    r, y = np.asarray(r, float), np.asarray(y, float)
    keep = np.isfinite(r) & np.isfinite(y) & (r > 0) & (y > 0)
    if np.count_nonzero(keep) < 4:
        return float("nan"), float("nan")
    (slope, _), covariance = np.polyfit(np.log(r[keep]), np.log(y[keep]), 1, cov=True)
    return float(slope), float(np.sqrt(covariance[0, 0]))
