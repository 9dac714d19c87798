"""Compiled per-sample update of the pulse tracker (:mod:`hexdem.analysis.tracker`).

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
  climbed a rung). With q = 2^(1/(C − 4)) at most C − 2 records lie in [M/2, M], so with the
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

Sample s of a bead is its s-th sample; ``ring`` holds its last three samples.
"""

from __future__ import annotations

import numpy as np
from numba import njit


def rung(capacity: int) -> float:
    """The ladder's ratio q for ``capacity`` slots (see the module docstring)."""
    return 2.0 ** (1.0 / (capacity - 4))


@njit(cache=True)
def update(beads, speeds, s, q, ring, peak, peak_index, window, after, rec_index, rec_value, rec_prev,
           rec_len, first_index, first_value, first_prev) -> None:
    """Take sample ``s`` (speeds of ``beads``) into the per-bead state arrays, in place."""
    for k in range(beads.shape[0]):
        b, v = beads[k], speeds[k]
        prev = ring[b, (s - 1) % 3] if s >= 1 else np.nan
        if v > peak[b]:
            peak[b] = v
            peak_index[b] = s
            for j in range(3):
                window[b, j] = ring[b, (s - 3 + j) % 3] if s - 3 + j >= 0 else np.nan
            window[b, 3] = v
            for j in range(4, 7):
                window[b, j] = np.nan
            after[b] = 0
            drop = 0
            while drop + 1 < rec_len[b] and rec_value[b, drop + 1] < 0.5 * v:
                drop += 1
            n = rec_len[b] - drop
            for j in range(n):
                rec_index[b, j] = rec_index[b, j + drop]
                rec_value[b, j] = rec_value[b, j + drop]
                rec_prev[b, j] = rec_prev[b, j + drop]
                first_index[b, j] = first_index[b, j + drop]
                first_value[b, j] = first_value[b, j + drop]
                first_prev[b, j] = first_prev[b, j + drop]
            if n >= 2 and rec_value[b, n - 1] < q * rec_value[b, n - 2]:
                n -= 1
            else:
                first_index[b, n] = s
                first_value[b, n] = v
                first_prev[b, n] = prev
            rec_index[b, n] = s
            rec_value[b, n] = v
            rec_prev[b, n] = prev
            rec_len[b] = n + 1
        elif after[b] < 3:
            window[b, 4 + after[b]] = v
            after[b] += 1
        ring[b, s % 3] = v


@njit(cache=True)
def first_crossing(level, rec_index, rec_value, rec_prev, first_index, first_value, first_prev, n_records) -> float:
    """Fractional sample index at which the samples first reached ``level`` (NaN if never)."""
    for j in range(n_records):
        if rec_value[j] >= level:
            s0, v0, before0 = first_index[j], first_value[j], first_prev[j]
            if v0 >= level:
                if s0 == 0 or not before0 < level:
                    return float(s0)
                return s0 - 1 + (level - before0) / (v0 - before0)
            s, before = rec_index[j], rec_prev[j]
            if before < level:
                return s - 1 + (level - before) / (rec_value[j] - before)
            return s0 + (level - v0) / (before - v0) * (s - 1 - s0)
    return np.nan
