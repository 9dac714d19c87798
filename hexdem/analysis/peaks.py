"""Peak speed, time of peak and wavefront arrival time of sampled bead speeds (pure NumPy).

Definitions (used for LAMMPS dumps and for the reference integrator alike):

* **peak speed** V_n: the maximum of |v(t)| over the record. Between samples it is located
  by a cubic spline through the 7 samples around the largest one, so that dumps every few
  µs give peaks to < 0.1 % and times of peak to a small fraction of the sampling interval.
* **time of peak** t_peak: where that spline maximum lies.
* **arrival time**: when |v| first reaches half of the bead's own peak on the rising edge
  (the half-maximum of the leading pulse), again from the spline. It is insensitive to the
  sampling and, unlike a fixed threshold, to the pulse's decaying amplitude.

A bead whose largest sample is among the last two of the record has not yet been passed
by its pulse: its three values are NaN (the run was too short to see its peak). A bead
that never moved (peak exactly 0) also gets NaN.

* **reach time**: when |v| first reached half of its largest sample of the record: the
  arrival time where that is defined, and also for beads whose speed is largest at the end of
  the record (a bead still rising, or one that reflections keep driving, as in a
  precompressed packing). A bead reached it long before the end if a wave had got there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.analysis.local_spline import LocalSpline

#: Samples on each side of the discrete maximum used for the spline refinement.
HALF_WINDOW = 3


@dataclass(frozen=True)
class PulseTimes:
    """Per-bead results, each an (n_beads,) array: ``peak_speed``, ``t_peak``, ``arrival_time``,
    ``reach_time``."""

    peak_speed: np.ndarray
    t_peak: np.ndarray
    arrival_time: np.ndarray
    reach_time: np.ndarray


def _spline_window(times, values, centre) -> tuple[LocalSpline, int]:
    """The spline through the samples around ``centre`` and the index of its first sample."""
    lo, hi = max(0, centre - HALF_WINDOW), min(len(times), centre + HALF_WINDOW + 1)
    return LocalSpline(times[lo:hi], values[lo:hi]), lo


def refine_peak(times, values) -> tuple[float, float]:
    """(t_peak, peak) of one sampled pulse, refined between samples by a local cubic spline."""
    k = int(np.argmax(values))
    if k == 0 or k == len(values) - 1:
        return float(times[k]), float(values[k])
    spline, _ = _spline_window(times, values, k)
    candidates = [*spline.stationary_points(), times[k]]
    best = max(candidates, key=lambda t: float(spline(t)))
    return float(best), float(spline(best))


def rising_crossing(times, values, level) -> float:
    """First time the sampled ``values`` reach ``level`` (spline-refined), or NaN if never."""
    above = np.flatnonzero(values >= level)
    if len(above) == 0:
        return float("nan")
    k = int(above[0])
    if k == 0:
        return float(times[0])
    spline, lo = _spline_window(times, values, k)
    roots = [t for t in spline.crossings(level, piece=k - 1 - lo) if times[k - 1] <= t <= times[k]]
    return float(min(roots)) if roots else float(np.interp(level, values[k - 1:k + 1], times[k - 1:k + 1]))


def pulse_times(times, speeds) -> PulseTimes:
    """Peak speed, time of peak and half-maximum arrival time of every bead.

    ``times`` (n_frames,) sample times; ``speeds`` (n_frames, n_beads) bead speeds |v|.
    """
    times = np.asarray(times, float)
    speeds = np.asarray(speeds, float)
    n_beads = speeds.shape[1]
    peak, t_peak, arrival, reach = (np.full(n_beads, np.nan) for _ in range(4))
    last_complete = len(times) - 3
    for bead in range(n_beads):
        series = speeds[:, bead]
        k = int(np.argmax(series))
        if series[k] <= 0.0:
            continue
        if k > last_complete:
            reach[bead] = rising_crossing(times, series, 0.5 * series[k])
            continue
        t_peak[bead], peak[bead] = refine_peak(times, series)
        arrival[bead] = reach[bead] = rising_crossing(times[:k + 1], series[:k + 1], 0.5 * peak[bead])
    return PulseTimes(peak, t_peak, arrival, reach)
