r"""The in-run analysis's per-sample arithmetic compiled (numba): the pulse tracker's update and the
energy audit's contact and body sums, one loop over a rank's beads or candidate pairs each.

They compute what the NumPy code of :class:`~hexdem.analysis.tracker_kernel.PulseState` and
:class:`~hexdem.analysis.energy.EnergyAudit` computes, in the same order: the tests hold the
tracker's results equal to the bit and the energies to round-off (:math:`δ^{5/2}` is taken as :math:`δ^2 \sqrt{δ}`, see
:func:`pair_contact_energies`; sums run body by body where NumPy's go in pairs). The NumPy code
indexes arrays of beads and pairs, which at 29,701 beads cost about 300 ns per bead per sample for
the tracker and 480 ns per bead per audited sample for the audit, where one compiled pass over a
bead's few numbers takes a few nanoseconds. Loading numba and these kernels (cached on disk,
``cache=True``) costs about half a second, more than the whole analysis of a small run, so the
analysis uses them only for ranks that hold at least :data:`~hexdem.common.compiled.COMPILED_BEADS`
beads.

Compiled without fast-math, so that each operation is IEEE-exact, as NumPy's.
"""

from __future__ import annotations

import math

import numpy as np
from numba import float64, int64, njit

#: The argument types of the kernels: C-ordered float64 and int64 arrays of one and two axes.
F1, F2, I1, I2 = float64[::1], float64[:, ::1], int64[::1], int64[:, ::1]


def _jit(*argument_types):
    """Compiled as the module docstring says, for ``argument_types``: declared, each kernel's machine
    code loads from numba's disk cache as this module loads (in the background, see
    :func:`~hexdem.common.preload.load_in_background`), not at the run's first sample, where loading
    the tracker's first two kernels took 0.6 s of each rank (29,701 beads on 2 ranks, under cProfile).
    Arguments of other types still work: numba compiles for them at their first call. Loading each
    declared kernel takes about 60 ms, so only those that Python calls are declared; the kernels they
    call (:data:`_inner`) are compiled into them."""
    return njit([argument_types], cache=True, error_model="numpy")


#: A kernel called only from other kernels: compiled into each caller, and loaded with it.
_inner = njit(cache=True, error_model="numpy")


@_inner
def open_window(window, index, after, ring, b, v, s):
    """Row ``b``'s window centred on its sample ``s`` of speed ``v``
    (:func:`~hexdem.analysis.tracker_kernel._open`)."""
    for j in range(3):
        window[b, j] = ring[b, (s - 3 + j) % 3] if s - 3 + j >= 0 else np.nan
    window[b, 3] = v
    for j in range(4, 7):
        window[b, j] = np.nan
    index[b] = s
    after[b] = 0


@_jit(F1, int64, float64, float64, F2, F1, I1, F2, I1, I1, I1, I2, F2, F2, F2, I2, F2, F2, F2, F2, I1, I1)
def update_pulses(speeds, s, q, rival_ratio, ring, peak, peak_index, window, after, start, length, rec_index, rec_value,
                  rec_prev, rec_prev2, first_index, first_value, first_prev, first_prev2, rival, rival_index,
                  rival_after):
    """:meth:`~hexdem.analysis.tracker_kernel.PulseState.update` of every row but its refinement, row
    ``b`` taking ``speeds[b]`` as its sample ``s`` (the state arrays are the state's
    :meth:`~hexdem.analysis.tracker_kernel.PulseState.sample_arrays`, updated in place; ``rival_ratio``:
    :data:`~hexdem.analysis.tracker_kernel.RIVAL_RATIO`). Returns the rows whose rival window is
    complete, for :meth:`~hexdem.analysis.tracker_kernel.PulseState.challenge`."""
    capacity = rec_value.shape[1]
    nan = np.nan
    complete = np.empty(len(speeds), dtype=np.int64)
    count = 0
    for b in range(len(speeds)):
        v = speeds[b]
        if v > peak[b]:
            before = ring[b, (s - 1) % 3] if s >= 1 else nan
            before2 = ring[b, (s - 2) % 3] if s >= 2 else nan
            if after[b] == 3 and peak_index[b] >= 3:
                for j in range(7):
                    rival[b, j] = window[b, j]
                rival_index[b] = peak_index[b]
                complete[count] = b
                count += 1
            rival_after[b] = 3
            peak[b] = v
            open_window(window, peak_index, after, ring, b, v, s)
            n = length[b]
            half = 0.5 * v
            below = 0
            for k in range(capacity):
                if rec_value[b, k] < half:
                    below += 1
            below -= capacity - n
            drop = max(below - 1, 0)
            first = (start[b] + drop) % capacity
            n -= drop
            if n >= 2 and rec_value[b, (first + n - 1) % capacity] < q * rec_value[b, (first + n - 2) % capacity]:
                n -= 1
            else:
                slot = (first + n) % capacity
                first_index[b, slot] = s
                first_value[b, slot] = v
                first_prev[b, slot] = before
                first_prev2[b, slot] = before2
            slot = (first + n) % capacity
            rec_index[b, slot] = s
            rec_value[b, slot] = v
            rec_prev[b, slot] = before
            rec_prev2[b, slot] = before2
            start[b] = first
            length[b] = n + 1
        else:
            if after[b] < 3:
                window[b, 4 + after[b]] = v
                after[b] += 1
            earlier = -np.inf
            for k in range(1, min(s, 3) + 1):
                earlier = max(earlier, ring[b, (s - k) % 3])
            if v * rival_ratio >= peak[b] and v > earlier:
                open_window(rival, rival_index, rival_after, ring, b, v, s)
            elif rival_after[b] < 3:
                rival[b, 4 + rival_after[b]] = v
                rival_after[b] += 1
                if rival_after[b] == 3 and rival_index[b] >= 3:
                    complete[count] = b
                    count += 1
        ring[b, s % 3] = v
    return complete[:count]


@_inner
def pair_contact_energies(positions, i, j, contact_m, coefficient, region_i, region_j, n_regions):
    r"""(R,) Hertz energy [J] of the touching candidate pairs ``i``, ``j`` (rows of ``positions``):
    :math:`\tfrac{2}{5} k_n \sqrt{R_\text{eff}}\, δ^{5/2}` each, δ = ``contact_m`` (the pair's sum of radii) less
    its distance, ``coefficient`` = :math:`\tfrac{2}{5} k_n \sqrt{R_\text{eff}}`, half to each of its bodies'
    regions ``region_i``, ``region_j`` (−1: a ghost, not audited here):
    :func:`~hexdem.analysis.energy._pair_energies_j`, summed in its order (the i sides' halves, pair by
    pair, then the j sides'). :math:`δ^{5/2}` is taken as δ² √δ, within an ulp of NumPy's power and a
    third quicker. A pair apart adds +0 rather than being skipped, which leaves every sum as it was: at
    rest, ahead of a pulse, whether a pair touches is round-off's coin toss, which a branch mispredicts
    (16 ns a pair at 29,701 beads against 6.5 without the branch)."""
    sides = np.zeros((2, n_regions))
    for p in range(len(i)):
        a, b = i[p], j[p]
        dx = positions[a, 0] - positions[b, 0]
        dy = positions[a, 1] - positions[b, 1]
        overlap = max(contact_m[p] - math.sqrt(dx * dx + dy * dy), 0.0)
        half = coefficient[p] * (overlap * overlap * math.sqrt(overlap)) / 2
        if region_i[p] >= 0:
            sides[0, region_i[p]] += half
        if region_j[p] >= 0:
            sides[1, region_j[p]] += half
    contact = np.zeros(n_regions)
    contact += sides[0]
    contact += sides[1]
    return contact


@_inner
def add_wall_energies(positions, bounds, curved, points, lengths, rows, radii, coefficient, regions, contact):
    r"""Add to ``contact`` (R,) the Hertz energy [J] of the wall contacts of the rows ``rows`` of
    ``positions``, wall by wall: wall ``w``'s members are ``bounds[w]`` to ``bounds[w + 1]`` of the
    member arrays; a flat wall {x : n·x = ``lengths[w]``} of normal n = ``points[w]``, or (``curved[w]``)
    the inside of the circle of centre ``points[w]`` and radius ``lengths[w]``. A member of radius
    r = ``radii`` overlapping its wall by δ > 0 stores ``coefficient`` (:math:`\tfrac{2}{5} k_n \sqrt{R_\text{eff}}`)
    × :math:`δ^{5/2}`, taken as δ² √δ (one apart adds +0, see :func:`pair_contact_energies`), added to its
    region ``regions``:
    :func:`~hexdem.analysis.energy._add_wall_energies_j` (its gaps from
    :meth:`~hexdem.model.walls.Wall.gaps_m`, :meth:`~hexdem.model.walls.CurvedWall.gaps_m`), summed in its
    order, member by member within a wall, then wall by wall."""
    wall_sum = np.zeros(len(contact))
    for w in range(len(bounds) - 1):
        wall_sum[:] = 0.0
        for e in range(bounds[w], bounds[w + 1]):
            x, y = positions[rows[e], 0], positions[rows[e], 1]
            if curved[w]:
                dx, dy = x - points[w, 0], y - points[w, 1]
                depth = -(lengths[w] - math.sqrt(dx * dx + dy * dy) - radii[e])
            else:
                depth = -(x * points[w, 0] + y * points[w, 1] - radii[e] - lengths[w])
            depth = max(depth, 0.0)
            wall_sum[regions[e]] += coefficient[e] * (depth * depth * math.sqrt(depth))
        for k in range(len(contact)):
            contact[k] += wall_sum[k]


@_inner
def body_energies(positions, velocities, spins, masses, inertia, regions, start, external, n_regions):
    """The audited bodies' own terms of :meth:`~hexdem.analysis.energy.EnergyAudit.part`, one pass
    over their rows: ``positions``, ``velocities``, ``spins`` (ω_z, empty for spheres that do not
    turn) and each row's body's ``masses``, ``inertia``, ``regions``, ``start`` positions and constant
    forces ``external``: (translational and rotational kinetic energy [J], (R,) kinetic energy [J]
    of each region, the work −Σ F·u [J] of the constant forces over the displacements from
    ``start``), summed row by row (NumPy sums in pairs: the two differ by round-off)."""
    translational, rotational, work = 0.0, 0.0, 0.0
    kinetic = np.zeros(n_regions)
    for r in range(len(masses)):
        vx, vy = velocities[r, 0], velocities[r, 1]
        moving = 0.5 * masses[r] * (vx * vx + vy * vy)
        turning = 0.5 * inertia[r] * spins[r] ** 2 if len(spins) else 0.0
        translational += moving
        rotational += turning
        kinetic[regions[r]] += moving + turning
        work += (positions[r, 0] - start[r, 0]) * external[r, 0] + (positions[r, 1] - start[r, 1]) * external[r, 1]
    return translational, rotational, kinetic, work


@_inner
def moved_beyond(positions, listed_at, distance) -> bool:
    """Whether a row of ``positions`` lies more than ``distance`` from the same row of ``listed_at``."""
    limit = distance * distance
    for r in range(len(positions)):
        dx = positions[r, 0] - listed_at[r, 0]
        dy = positions[r, 1] - listed_at[r, 1]
        if dx * dx + dy * dy > limit:
            return True
    return False


@_jit(F2, F2, F1, F2, float64, I1, I1, F1, F1, I1, I1, F1, F1, I1, F2, F2, I1, I1, F2, F1, I1, F1, F1, I1, int64)
def audit_part(positions, velocities, spins, listed_at, distance, i, j, contact_m, coefficient, region_i, region_j,
               masses, inertia, regions, start, external, bounds, curved, points, lengths, rows, radii,
               wall_coefficient, wall_regions, n_regions):
    """:meth:`~hexdem.analysis.energy.EnergyAudit.part` of a rank in one call: empty if a row of
    ``positions`` lies more than ``distance`` from where the contacts were listed (``listed_at``,
    :func:`moved_beyond`: the caller lists them again), else the sums [total energy, translational and
    rotational kinetic, then each region's kinetic and contact energy] [J] of the audited rows (the
    first ``len(masses)``) with ``velocities`` and ``spins``: the pairs' halves
    (:func:`pair_contact_energies`), then the walls' contacts (:func:`add_wall_energies`), the
    bodies' own terms (:func:`body_energies`); the total sums the regions' energies as NumPy sums a
    few numbers (the first, plus the rest in order), less the constant forces' work. The arguments
    after ``distance`` are :meth:`~hexdem.analysis.energy.EnergyAudit._row_constants`'s."""
    if moved_beyond(positions, listed_at, distance):
        return np.empty(0)
    contact = pair_contact_energies(positions, i, j, contact_m, coefficient, region_i, region_j, n_regions)
    add_wall_energies(positions, bounds, curved, points, lengths, rows, radii, wall_coefficient, wall_regions, contact)
    translational, rotational, kinetic, work = body_energies(positions, velocities, spins, masses, inertia, regions,
                                                             start, external, n_regions)
    sums = np.empty(3 + 2 * n_regions)
    for r in range(n_regions):
        sums[3 + 2 * r] = kinetic[r]
        sums[4 + 2 * r] = contact[r]
    rest = 0.0
    for k in range(4, len(sums)):
        rest += sums[k]
    sums[0] = (sums[3] + rest) - work
    sums[1] = translational
    sums[2] = rotational
    return sums


@_jit(I1, I1, F2, I1, F1, F2)
def sample_speeds(ids, previous_ids, velocities, rows, speeds, end_velocity) -> bool:
    """The speeds ``|v|`` of the sample's rows ``rows`` into ``speeds``, and their velocities into
    ``end_velocity`` (``np.hypot``'s arithmetic, C's hypot); returns whether the sample's body ids
    ``ids`` are ``previous_ids`` (``np.array_equal``), in the same pass."""
    for k in range(len(rows)):
        vx, vy = velocities[rows[k], 0], velocities[rows[k], 1]
        speeds[k] = math.hypot(vx, vy)
        end_velocity[k, 0] = vx
        end_velocity[k, 1] = vy
    if len(ids) != len(previous_ids):
        return False
    for r in range(len(ids)):
        if ids[r] != previous_ids[r]:
            return False
    return True
