"""Per-sample update of the pulse tracker (:mod:`hexdem.analysis.tracker`), vectorised over beads.

For every bead it keeps, in fixed-size arrays, exactly what the definitions of
:mod:`hexdem.analysis.peaks` need from a whole time series:

* the **peak window**: the samples from three before to three after the largest sample so
  far (the same 7 samples the dump analysis puts its cubic spline through);
* the **rival window**: the same 7 samples around the latest sample that exceeds the three
  before it and lies within :data:`~hexdem.analysis.peaks.PEAK_OVERSHOOT` of the largest sample so
  far without exceeding it (:func:`~hexdem.analysis.peaks.rival_maxima`). A sample that exceeds
  the rival within the three after it ends it (and may start the next); one that exceeds the
  running maximum also starts a new peak window, and a complete peak window that it replaces
  becomes the rival. At most one rival is open at a time: none opens within three samples of an
  open one unless it exceeds it. A complete rival (three samples after it) is refined at once
  (:meth:`PulseState.challenge`) and the largest refined (peak, time) kept, so that the peak can be
  the largest maximum of the interpolant wherever it lies, in fixed memory;
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

Most beads, at most samples, only enter the ring (and, for three samples after a new maximum,
the peak window): the ladder's bookkeeping runs only on beads whose running maximum rises (never
on beads at rest, whose samples stay below the noise floor), the refinement only on those whose
rival window completes. This NumPy code defines the results of the compiled update that runs take
(:func:`~hexdem.analysis.compiled.sample_pulses`, :mod:`hexdem.common.kernel_switch`).
"""

from __future__ import annotations

import numpy as np

from hexdem.analysis.peaks import PEAK_OVERSHOOT, may_overtake, refine_peaks

#: A local maximum of the samples this many times the running maximum or above may overtake it
#: (:func:`~hexdem.analysis.peaks.may_overtake`; the compiled update takes it as an argument).
RIVAL_RATIO = 1 + PEAK_OVERSHOOT
#: The state arrays a sample updates, bead first.
SAMPLED = (
    "ring",
    "peak",
    "peak_index",
    "window",
    "after",
    "start",
    "length",
    "rec_index",
    "rec_value",
    "rec_prev",
    "rec_prev2",
    "first_index",
    "first_value",
    "first_prev",
    "first_prev2",
    "rival",
    "rival_index",
    "rival_after",
)


def rung(capacity: int) -> float:
    """The ladder's ratio q for ``capacity`` slots (see the module docstring)."""
    return 2.0 ** (1.0 / (capacity - 4))


class PulseState:
    """The per-bead state of :mod:`hexdem.analysis.tracker` for ``n`` beads and a ladder of
    ``capacity`` slots (module docstring); every array is indexed by bead first. ``floor``: the
    run's noise floor (:func:`~hexdem.analysis.peaks.noise_floor`), the running maximum's start: a
    bead's samples enter it only once they rise above the floor (``peak_index`` stays −1 for a bead
    that never moved).

    Sample s of a bead is its s-th sample; ``ring`` holds its last three samples, stored slot by
    slot (``ring_slots``), so that a sample writes one contiguous row. The compiled update may keep
    a sample there as its velocity, in ``ring_velocity`` (slot by slot too), with −1 for its speed,
    until a window needs it; ``lazy_below`` is the sum of squares below which a sample can neither
    be a new maximum nor open a rival while no window is open (−1 while one is). Each bead's
    ladder is a circular buffer of the C slots from ``start``: dropping records moves ``start``
    instead of copying the slots."""

    def __init__(self, n: int, capacity: int, floor: float = 0.0):
        self.q = rung(capacity)
        self.ring_slots = np.zeros((3, n))  # slot by slot: a sample writes one contiguous row of it
        self.ring = self.ring_slots.T  # (n, 3), bead first as every other array
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
        self.rival = np.full((n, 7), np.nan)
        self.rival_index = np.full(n, -1, dtype=np.int64)
        self.rival_after = np.full(n, 3, dtype=np.int64)  # 3: no rival open
        # the compiled update's: its ring slots as velocities (vx, vy), slot by slot, and each bead's
        # sum of squares below which a sample only enters the ring (-1: none)
        self.velocity_slots = np.zeros((3, 2 * n))
        self.ring_velocity = self.velocity_slots.reshape(3, n, 2).transpose(1, 0, 2)  # (n, 3, 2)
        self.lazy_below = np.full(n, -1.0)
        self.best_peak = np.full(n, -np.inf)
        self.best_index = np.zeros(n, dtype=np.int64)
        self.best_offset = np.zeros(n)

    def arrays(self) -> list[np.ndarray]:
        """Every state array, bead first (for merging the beads' states across MPI ranks): those a
        sample updates (:data:`SAMPLED`), the compiled update's own, and the best refined rival's
        peak, sample index and offset from it (in samples)."""
        return [
            *(getattr(self, name) for name in SAMPLED),
            self.ring_velocity,
            self.lazy_below,
            self.best_peak,
            self.best_index,
            self.best_offset,
        ]

    def kernel_arrays(self) -> dict[str, np.ndarray]:
        """The arrays :func:`~hexdem.analysis.compiled.sample_pulses` updates, by name: the ring and
        its velocities slot by slot (``ring_slots``, ``velocity_slots``), the rest of :data:`SAMPLED`,
        and ``lazy_below``."""
        names = ("ring_slots", *SAMPLED[1:], "velocity_slots", "lazy_below")
        return {name: getattr(self, name) for name in names}

    def update(self, beads, speeds, s: int) -> None:
        """Take sample ``s`` (speeds of ``beads``, distinct) into the state, in place."""
        peak = self.peak[beads]
        rising = speeds > peak
        complete = [beads[:0]]  # (a rank may own no bead)
        if not rising.all():
            calm = ~rising
            _fill(self.window, self.after, beads[calm], speeds[calm])
            complete.append(self._follow_rivals(beads[calm], speeds[calm], peak[calm], s))
        if rising.any():
            complete.append(self._new_maxima(beads[rising], speeds[rising], s))
        self.ring[beads, s % 3] = speeds
        self.challenge(np.concatenate(complete))

    def challenge(self, beads) -> None:
        """Refine the complete rival windows of ``beads`` and keep each bead's largest maximum (the
        earliest of equal ones)."""
        if not len(beads):
            return
        offset, value = refine_peaks(self.rival[beads], 1.0)
        better = value > self.best_peak[beads]
        beads = beads[better]
        self.best_peak[beads] = value[better]
        self.best_index[beads] = self.rival_index[beads]
        self.best_offset[beads] = offset[better]

    def _follow_rivals(self, beads, speeds, peak, s: int) -> np.ndarray:
        """Beads at or below their running maximum ``peak``: a sample that may overtake it and
        exceeds the three before it opens a rival window; any other fills the open rival's next
        slot. Returns the beads whose rival this completes (with three samples before it)."""
        near = np.flatnonzero(may_overtake(speeds, peak))
        if s:
            earlier = self.ring[beads[near]][:, [(s - k) % 3 for k in range(1, min(s, 3) + 1)]].max(axis=1)
            near = near[speeds[near] > earlier]
        _open(self.rival, self.rival_index, self.rival_after, self.ring, beads[near], speeds[near], s)
        rest = np.ones(len(beads), dtype=np.bool_)
        rest[near] = False
        done = _fill(self.rival, self.rival_after, beads[rest], speeds[rest])
        return done[self.rival_index[done] >= 3]

    def _new_maxima(self, beads, speeds, s: int) -> np.ndarray:
        """Beads whose running maximum rises to ``speeds`` at sample ``s``: the open rival ends, a
        complete peak window (with three samples before it) becomes the rival, a new peak window
        opens, and the new record, with the two samples before it, climbs the ladder (module
        docstring). Returns the beads whose old peak window became their rival."""
        before, before2 = ((self.ring[beads, (s - k) % 3] if s >= k else np.full(len(beads), np.nan)) for k in (1, 2))
        replaced = beads[(self.after[beads] == 3) & (self.peak_index[beads] >= 3)]
        self.rival[replaced] = self.window[replaced]
        self.rival_index[replaced] = self.peak_index[replaced]
        self.rival_after[beads] = 3
        self.peak[beads] = speeds
        _open(self.window, self.peak_index, self.after, self.ring, beads, speeds, s)
        capacity = self.rec_value.shape[1]
        # records below half the new maximum cannot be the arrival: all but the last of them go.
        # Records rise along the ladder, and a free slot holds -inf or a dropped record, which was
        # below half of an earlier maximum: every free slot is below half of any new one. So the
        # ladder's records below half are all slots below it but the free ones.
        length = self.length[beads]
        below = np.add.reduce(self.rec_value[beads] < 0.5 * speeds[:, None], axis=1, dtype=np.int64) - (
            capacity - length
        )
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
        return replaced

    def first_crossing(self, bead: int, level: float) -> float:
        """Fractional sample index at which ``bead``'s samples first reached ``level`` (NaN if never)."""
        order = (self.start[bead] + np.arange(self.length[bead])) % self.rec_value.shape[1]
        records = zip(
            self.rec_index[bead, order],
            self.rec_value[bead, order],
            self.rec_prev[bead, order],
            self.rec_prev2[bead, order],
            self.first_index[bead, order],
            self.first_value[bead, order],
            self.first_prev[bead, order],
            self.first_prev2[bead, order],
        )
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


def _open(window, index, after, ring, beads, speeds, s: int) -> None:
    """A window (peak or rival) centred on sample ``s`` of ``beads``: the three samples before it
    from the ``ring`` (NaN before the first), ``speeds``, and three free slots."""
    for j in range(3):
        window[beads, j] = ring[beads, (s - 3 + j) % 3] if s - 3 + j >= 0 else np.nan
    window[beads, 3] = speeds
    window[beads, 4:] = np.nan
    index[beads] = s
    after[beads] = 0


def _fill(window, after, beads, speeds) -> np.ndarray:
    """The next free slot after the centre of each of ``beads``' windows takes its speed, while any
    is left; returns the beads whose window this completes."""
    open_ = after[beads] < 3
    beads = beads[open_]
    window[beads, 4 + after[beads]] = speeds[open_]
    after[beads] += 1
    return beads[after[beads] == 3]


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
