"""The amplitude of a bead's leading pulse, as opposed to its largest speed over the run.

In an ideal lattice a bead's speed has one clear maximum, the passing wavefront. In a
disordered packing the front can break up: a weaker pulse arrives first and later motion
(a slower part of the front, scattered waves, the walls' echoes) can outgrow it. The peak
speed over the run (:mod:`hexdem.analysis.peaks`) then measures the largest of these, not
what the front transmitted.

**Definition.** The leading pulse of a bead is its first maximum of |v| that reaches
:data:`LEAD_THRESHOLD` of the bead's largest speed over the run and after which |v| falls
below :data:`LEAD_FALL` of that maximum before it rises above it again: the first clear
hump of the signal, wiggles of less than 20 % not counting as one. Its amplitude is the
vertex of the parabola through the largest sample and its two neighbours (the speed at a
sampled maximum, corrected for the sampling grid). A bead whose signal never falls that far
after its first hump, whose hump peaks at the first or last sample, or that never moved,
gets NaN.
"""

from __future__ import annotations

import numpy as np

#: The leading pulse must reach this fraction of the bead's largest speed.
LEAD_THRESHOLD = 0.2
#: ... and be followed by a fall below this fraction of its own maximum.
LEAD_FALL = 0.8


def parabola_vertex(before: float, peak: float, after: float) -> float:
    """The largest value of the parabola through three evenly spaced samples, the middle one
    the highest (the sample itself where they do not curve down)."""
    curvature = before - 2 * peak + after
    if curvature >= 0:
        return peak
    return peak - (after - before) ** 2 / (8 * curvature)


def leading_maximum(signal, threshold: float = LEAD_THRESHOLD, fall: float = LEAD_FALL) -> int:
    """Index of the highest sample of the leading pulse of one speed signal (see the module
    docstring), −1 if it has none."""
    largest = np.nanmax(signal) if np.any(np.isfinite(signal)) else 0.0
    if not largest > 0:
        return -1
    best, index = -np.inf, -1
    for k in range(np.flatnonzero(signal >= threshold * largest)[0], len(signal)):
        if signal[k] > best:
            best, index = signal[k], k
        elif signal[k] < fall * best:
            return index if 0 < index < len(signal) - 1 else -1
    return -1


def leading_pulse_amplitude(speeds, threshold: float = LEAD_THRESHOLD, fall: float = LEAD_FALL) -> np.ndarray:
    """(B,) leading-pulse amplitudes of the speed signals ``speeds`` (S samples, B beads)."""
    speeds = np.asarray(speeds, float)
    amplitudes = np.full(speeds.shape[1], np.nan)
    for bead, signal in enumerate(speeds.T):
        index = leading_maximum(signal, threshold, fall)
        if index >= 0:
            amplitudes[bead] = parabola_vertex(signal[index - 1], signal[index], signal[index + 1])
    return amplitudes
