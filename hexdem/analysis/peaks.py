"""Peak speed, time of peak and wavefront arrival time of sampled bead speeds (pure NumPy).

Definitions (used for LAMMPS dumps and for the reference integrator alike):

* **peak speed** V_n: the maximum of |v(t)| over the record: the largest maximum of the
  interpolant, a cubic spline through the 7 samples around a local maximum of the samples, so
  that dumps every few µs give peaks to < 0.1 % and times of peak to a small fraction of the
  sampling interval. The spline is put around the largest sample and around every **rival**
  (:func:`rival_maxima`): a sample that is the largest of its window and lies within
  :data:`PEAK_OVERSHOOT` of the largest sample before it. A narrow maximum that falls between
  samples can be higher than a broader one that holds the largest sample (the light beads of a
  dimer chain: two maxima 3e-4 apart), so the largest sample alone does not say where the peak is.
* **time of peak** t_peak: where that largest spline maximum lies.
* **arrival time**: when |v| first reaches half of the bead's own peak on the rising edge
  (the half-maximum of the leading pulse), again from the spline. It is insensitive to the
  sampling and, unlike a fixed threshold, to the pulse's decaying amplitude.

A bead whose largest sample is among the last two of the record has not yet been passed
by its pulse: its three values are NaN (the run was too short to see its peak). A bead
that never moved has peak speed 0, a measured value, and NaN time of peak and arrival: no
pulse passed it. Never moved means that |v| never rose above the run's **noise floor**
(:func:`noise_floor`): the speed that round-off alone gives a bead at rest (LAMMPS leaves
4e-17 m/s on a square crystal's still rows, the reference integrator 1e-58 m/s) is not motion.

* **reach time**: when |v| first reached half of its largest sample of the record: the
  arrival time where that is defined, and also for beads whose speed is largest at the end of
  the record (a bead still rising, or one that reflections keep driving, as in a
  precompressed packing). A bead reached it long before the end if a wave had got there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.analysis.local_spline import IMAGINARY_TOLERANCE, ROOT_TOLERANCE, LocalSpline

#: Samples on each side of the discrete maximum used for the spline refinement.
HALF_WINDOW = 3
#: The noise floor relative to the run's speed scale: the square root of a double's precision,
#: 1.49e-8. A bead that never moved faster than this has never held more than ε = 2.2e-16 of the
#: kinetic energy it would hold at the run's fastest speed (½ m v² ≤ ε ½ m V₀²): less than the
#: round-off of any sum of the run's energies, so nothing the run computes can tell such motion
#: from round-off. It lies far above what round-off gives a bead at rest (1e-16 V₀ in LAMMPS) and
#: far below any pulse the analysis reads (a front's precursor is measured from half its peak).
ROUND_OFF_SPEED = float(np.sqrt(np.finfo(float).eps))
#: The most a 7-point spline's maximum exceeds its largest sample, relative, at the runs' sampling
#: (20 samples per contact time: ``run_settings.SAMPLES_PER_CONTACT``): a maximum of relative
#: curvature κ = |v''|/v that falls half-way between samples h apart lies κh²/8 above them. Over every
#: bead of the default hexagon, a striker, a 9 × 9 square and a 20-bead dimer chain, the spline's
#: maximum lay at most 3.5e-3 above its largest sample, and κh²/8 at most 4.2e-3; a half-sine one
#: contact time long gives 1/cos(π/40) − 1 = 3.1e-3. This bound, 1e-2, leaves a factor 2.4 (a
#: sampling 1.5 times coarser): a local maximum further below than this cannot hold the peak, and
#: looking at more of them would only cost time.
PEAK_OVERSHOOT = 1e-2


def noise_floor(speed_scale: float) -> float:
    """The speed below which a bead counts as never moved, in the units of ``speed_scale``, the run's
    fastest speed at t = 0 (V₀; see :data:`ROUND_OFF_SPEED`)."""
    return ROUND_OFF_SPEED * float(speed_scale)


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


def may_overtake(values, running):
    """Whether local maxima of sample ``values`` may hold a spline maximum above ``running``, the
    largest sample before them: within :data:`PEAK_OVERSHOOT` of it (the one test of the whole
    record and of the tracker, so that both look at the same windows)."""
    return values * (1 + PEAK_OVERSHOOT) >= running


def rival_maxima(values, floor: float = 0.0) -> np.ndarray:
    """Sample indices k whose 7-sample window may hold a larger spline maximum than the largest
    sample's: k has three samples on each side, exceeds the three before it and is not exceeded
    by the three after it (the largest of its window, first reached), and
    :func:`may_overtake` the largest sample before it (and the noise floor ``floor``). The
    tracker, which cannot know the record's largest sample when a window completes, compares with
    the largest so far; this does the same, so that both refine the same windows (a few more than
    the final largest sample would need, never fewer)."""
    values = np.asarray(values, float)
    k = np.arange(HALF_WINDOW, len(values) - HALF_WINDOW)
    if not len(k):
        return k
    shifted = [values[HALF_WINDOW + j : len(values) - HALF_WINDOW + j] for j in range(-HALF_WINDOW, HALF_WINDOW + 1)]
    middle = shifted[HALF_WINDOW]
    before = np.max(shifted[:HALF_WINDOW], axis=0)
    after = np.max(shifted[HALF_WINDOW + 1 :], axis=0)
    running = np.maximum.accumulate(np.concatenate([[floor], values]))[k]
    return k[(middle > before) & (middle >= after) & may_overtake(middle, running)]


def _window_peak(times, values, k: int) -> tuple[float, float]:
    """(t, value) of the largest maximum of the spline through the samples around ``k`` (the
    sample itself at either end of the record)."""
    if k == 0 or k == len(values) - 1:
        return float(times[k]), float(values[k])
    spline, _ = _spline_window(times, values, k)
    candidates = [*spline.stationary_points(), times[k]]
    best = max(candidates, key=lambda t: float(spline(t)))
    return float(best), float(spline(best))


def refine_peak(times, values, floor: float = 0.0) -> tuple[float, float]:
    """(t_peak, peak) of one sampled pulse: the largest spline maximum around the largest sample
    and around every :func:`rival_maxima` (``floor``: the run's noise floor), the earliest of equal
    ones, the largest sample's first."""
    k = int(np.argmax(values))
    best = _window_peak(times, values, k)
    for rival in rival_maxima(values, floor):
        if rival != k:
            found = _window_peak(times, values, int(rival))
            if found[1] > best[1]:
                best = found
    return best


def _unit_window_operator() -> np.ndarray:
    """(6, 4, 7): the coefficients of the not-a-knot spline through 7 samples at unit spacing
    as linear functions of the samples (the spline is linear in its values)."""
    knots = np.arange(2 * HALF_WINDOW + 1, dtype=float)
    return np.stack([LocalSpline(knots, unit).coefficients for unit in np.eye(len(knots))], axis=-1)


_UNIT_OPERATOR = _unit_window_operator()


def refine_peaks(windows, interval: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`refine_peak` of many full windows at once: ``windows`` (B, 7) samples ``interval``
    apart, each with its largest sample first reached in the middle. Returns (B,) times of
    peak relative to the middle sample and (B,) peaks, equal to the one-window refinement to
    round-off (the same spline and candidates: every stationary point on the pieces and the
    middle sample, the largest taken)."""
    windows = np.asarray(windows, float).reshape(-1, 2 * HALF_WINDOW + 1)
    if not len(windows):
        return np.empty(0), np.empty(0)
    coefficients = np.einsum("pcs,bs->bpc", _UNIT_OPERATOR, windows)  # (B, pieces, 4)
    a, b, c, d = np.moveaxis(coefficients, -1, 0)
    quadratic, linear, constant = 3 * d, 2 * c, b
    with np.errstate(divide="ignore", invalid="ignore"):
        discriminant = linear**2 - 4 * quadratic * constant
        q = -0.5 * (linear + np.copysign(np.sqrt(np.maximum(discriminant, 0.0)), linear))
        curved = np.abs(quadratic) > ROOT_TOLERANCE * np.abs(linear)
        roots = np.where(
            curved[..., None],
            np.stack([q / quadratic, constant / q], axis=-1),
            np.stack([-constant / linear, np.full_like(linear, np.nan)], axis=-1),
        )
    real = ~curved | (discriminant >= -IMAGINARY_TOLERANCE * np.abs(linear) ** 2)
    on_piece = real[..., None] & np.isfinite(roots) & (roots >= -ROOT_TOLERANCE) & (roots <= 1 + ROOT_TOLERANCE)
    s = np.clip(np.where(on_piece, roots, 0.0), 0.0, 1.0)
    value = a[..., None] + s * (b[..., None] + s * (c[..., None] + s * d[..., None]))
    value = np.where(on_piece, value, -np.inf).reshape(len(windows), -1)
    offset = (np.arange(coefficients.shape[1])[:, None] + s).reshape(len(windows), -1) - HALF_WINDOW
    best = np.argmax(value, axis=1)
    rows = np.arange(len(windows))
    middle = windows[:, HALF_WINDOW]
    take = value[rows, best] > middle
    return np.where(take, offset[rows, best], 0.0) * interval, np.where(take, value[rows, best], middle)


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
    return float(min(roots)) if roots else float(np.interp(level, values[k - 1 : k + 1], times[k - 1 : k + 1]))


def pulse_times(times, speeds, floor: float = 0.0) -> PulseTimes:
    """Peak speed, time of peak and half-maximum arrival time of every bead.

    ``times`` (n_frames,) sample times; ``speeds`` (n_frames, n_beads) bead speeds |v|; ``floor``
    the run's :func:`noise_floor`, at or below which a bead never moved.
    """
    times = np.asarray(times, float)
    speeds = np.asarray(speeds, float)
    n_beads = speeds.shape[1]
    peak, t_peak, arrival, reach = (np.full(n_beads, np.nan) for _ in range(4))
    last_complete = len(times) - 3
    for bead in range(n_beads):
        series = speeds[:, bead]
        k = int(np.argmax(series))
        if series[k] <= floor:
            peak[bead] = 0.0
            continue
        if k > last_complete:
            reach[bead] = rising_crossing(times, series, 0.5 * series[k])
            continue
        t_peak[bead], peak[bead] = refine_peak(times, series, floor)
        arrival[bead] = reach[bead] = rising_crossing(times[: k + 1], series[: k + 1], 0.5 * peak[bead])
    return PulseTimes(peak, t_peak, arrival, reach)
