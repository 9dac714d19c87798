"""Per-sample update of the pulse tracker (:mod:`hexdem.analysis.tracker`), vectorised over beads.

For every bead it keeps, in fixed-size arrays, exactly what the definitions of
:mod:`hexdem.analysis.peaks` need from a whole time series:

* the **peak window**: the samples from three before to three after the largest sample so
  far (the same 7 samples the dump analysis puts its cubic spline through);
* the **arrival candidates**. The arrival is the first sample at or above half of the final
  peak P. Such a sample exceeds every earlier one, so it is a *record* of the running
  maximum M; records below M/2 can never be it (P ≥ M) and are dropped, all but the last of
  them, which brackets the crossing from below. The records kept form
  a ladder in value: each is at least a factor ``q`` above the one before it, except the
  newest, which is always kept (a new record replaces the newest when that one had not
  climbed a rung). With :math:`q = 2^{1/(C − 4)}` at most C − 2 records lie in [M/2, M], so with the
  one below the C slots never overflow, whatever the sampling or the run's length.

  Each slot also remembers the first record that entered it (later ones in the same rung
  replace only the newest). For a level L = P/2 take the first slot whose record reaches L:
  if the first record that entered it reaches L, that record is the crossing, exactly (every
  earlier sample was below L), interpolated linearly from the sample before it; otherwise
  the crossing is among the slot's later records, within one rung of each other (on a rising
  edge, a few samples), and is interpolated between them. At the default sampling
  consecutive samples on a rising edge differ by more than a rung, so every record keeps its
  own slot and the crossing is exact. The one inexact case is a separate earlier pulse whose
  peak lies within a rung above both L and the slot's first record.

Sample s of a bead is its s-th sample; ``ring`` holds its last three samples. Each bead's
ladder is a circular buffer of the C slots from ``start``: dropping records moves ``start``
instead of copying the slots.

**Cost.** Most beads, at most samples, only enter the ring (and, for three samples after a
new maximum, the peak window); the ladder's bookkeeping runs on the few beads whose running
maximum rises at that sample (beads at rest never do: their samples stay below the noise floor).
Every step is a NumPy operation over those beads, for ranks too small to pay numba's start-up; a
large rank runs the same update compiled (:func:`~hexdem.analysis.compiled.update_pulses`).
"""

from __future__ import annotations

import numpy as np


def rung(capacity: int) -> float:
    """The ladder's ratio q for ``capacity`` slots (see the module docstring)."""
    return 2.0 ** (1.0 / (capacity - 4))


class PulseState:
    """The per-bead state of :mod:`hexdem.analysis.tracker` for ``n`` beads and a ladder of
    ``capacity`` slots (module docstring); every array is indexed by bead first. ``floor``: the
    run's noise floor (:func:`~hexdem.analysis.peaks.noise_floor`), the running maximum's start: a
    bead's samples enter it only once they rise above the floor (``peak_index`` stays −1 for a bead
    that never moved)."""

    def __init__(self, n: int, capacity: int, floor: float = 0.0):
        self.q = rung(capacity)
        self.ring = np.zeros((n, 3))
        self.peak = np.full(n, float(floor))
        self.peak_index = np.full(n, -1, dtype=np.int64)
        self.window = np.full((n, 7), np.nan)
        self.after = np.zeros(n, dtype=np.int64)
        self.start = np.zeros(n, dtype=np.int64)
        self.length = np.zeros(n, dtype=np.int64)
        self.rec_index = np.zeros((n, capacity), dtype=np.int64)
        self.rec_value = np.full((n, capacity), -np.inf)  # a free slot: below every record
        self.rec_prev = np.zeros((n, capacity))
        self.rec_prev2 = np.zeros((n, capacity))
        self.first_index = np.zeros((n, capacity), dtype=np.int64)
        self.first_value = np.zeros((n, capacity))
        self.first_prev = np.zeros((n, capacity))
        self.first_prev2 = np.zeros((n, capacity))

    def arrays(self) -> list[np.ndarray]:
        """Every state array (for merging the beads' states across MPI ranks)."""
        return [self.ring, self.peak, self.peak_index, self.window, self.after, self.start, self.length, self.rec_index,
                self.rec_value, self.rec_prev, self.rec_prev2, self.first_index, self.first_value, self.first_prev,
                self.first_prev2]

    def update(self, beads, speeds, s: int) -> None:
        """Take sample ``s`` (speeds of ``beads``, distinct) into the state, in place."""
        rising = speeds > self.peak[beads]
        if not rising.all():
            self._enter_window(beads[~rising], speeds[~rising])
        if rising.any():
            self._new_maxima(beads[rising], speeds[rising], s)
        self.ring[beads, s % 3] = speeds

    def _enter_window(self, beads, speeds) -> None:
        """Beads past their running maximum: the sample fills the next of the three window slots
        after the peak, while any is left."""
        slot = self.after[beads]
        open_ = slot < 3
        self.window[beads[open_], 4 + slot[open_]] = speeds[open_]
        self.after[beads[open_]] += 1

    def _new_maxima(self, beads, speeds, s: int) -> None:
        """Beads whose running maximum rises to ``speeds`` at sample ``s``: a new peak window, and
        the new record, with the two samples before it, climbs the ladder (module docstring)."""
        before, before2 = ((self.ring[beads, (s - k) % 3] if s >= k else np.full(len(beads), np.nan)) for k in (1, 2))
        self.peak[beads] = speeds
        self.peak_index[beads] = s
        for j in range(3):
            self.window[beads, j] = self.ring[beads, (s - 3 + j) % 3] if s - 3 + j >= 0 else np.nan
        self.window[beads, 3] = speeds
        self.window[beads, 4:] = np.nan
        self.after[beads] = 0
        capacity = self.rec_value.shape[1]
        # records below half the new maximum cannot be the arrival: all but the last of them go.
        # Records rise along the ladder, and a free slot holds -inf or a dropped record, which was
        # below half of an earlier maximum: every free slot is below half of any new one. So the
        # ladder's records below half are all slots below it but the free ones.
        length = self.length[beads]
        below = np.add.reduce(self.rec_value[beads] < 0.5 * speeds[:, None], axis=1, dtype=np.int64) - (capacity - length)
        drop = np.maximum(below - 1, 0)
        start = (self.start[beads] + drop) % capacity
        n = length - drop
        newest = self.rec_value[beads, (start + n - 1) % capacity]
        same_rung = (n >= 2) & (newest < self.q * self.rec_value[beads, (start + n - 2) % capacity])
        n = n - same_rung
        slot = (start + n) % capacity
        climbed = ~same_rung
        self.first_index[beads[climbed], slot[climbed]] = s
        self.first_value[beads[climbed], slot[climbed]] = speeds[climbed]
        self.first_prev[beads[climbed], slot[climbed]] = before[climbed]
        self.first_prev2[beads[climbed], slot[climbed]] = before2[climbed]
        self.rec_index[beads, slot] = s
        self.rec_value[beads, slot] = speeds
        self.rec_prev[beads, slot] = before
        self.rec_prev2[beads, slot] = before2
        self.start[beads] = start
        self.length[beads] = n + 1

    def first_crossing(self, bead: int, level: float) -> float:
        """Fractional sample index at which ``bead``'s samples first reached ``level`` (NaN if never)."""
        order = (self.start[bead] + np.arange(self.length[bead])) % self.rec_value.shape[1]
        records = zip(self.rec_index[bead, order], self.rec_value[bead, order], self.rec_prev[bead, order],
                      self.rec_prev2[bead, order], self.first_index[bead, order], self.first_value[bead, order],
                      self.first_prev[bead, order], self.first_prev2[bead, order])
        for s, value, before, before2, s0, v0, before0, before0_2 in records:
            if value >= level:
                if v0 >= level:
                    if s0 == 0 or not before0 < level:
                        return float(s0)
                    return s0 - 1 + parabolic_crossing(before0_2, before0, v0, level)
                if before < level:
                    return s - 1 + parabolic_crossing(before2, before, value, level)
                return s0 + (level - v0) / (before - v0) * (s - 1 - s0)
        return np.nan


def parabolic_crossing(before2: float, before: float, value: float, level: float) -> float:
    """Where in [0, 1] the parabola through the samples (−1, ``before2``), (0, ``before``),
    (1, ``value``) first reaches ``level`` (before < level <= value): the crossing's error is
    third order in the sampling interval, where the straight line between the last two samples
    is second order. The line is taken where ``before2`` is unknown (NaN) or the parabola does
    not rise all through [0, 1]: at a rounded top it would turn over and cross too early."""
    gap = level - before
    slope, curvature = (value - before2) / 2, (before2 - 2 * before + value) / 2
    if np.isfinite(before2) and slope >= 0 and slope + 2 * curvature >= 0:
        return 2 * gap / (slope + np.sqrt(slope * slope + 4 * curvature * gap))
    return gap / (value - before)
