"""The samples LAMMPS hands over, taken in one compiled pass (numba) on large ranks.

At the sampling callback a rank's velocities are at the half step; the sample holds the full
step's, v(t) = v(t − dt/2) + (dt/2) f/m (see :mod:`hexdem.engines.lammps.driver`). NumPy takes
them, with the positions' copy, in five passes over strided (n, 3) arrays: 0.9 ms a sample at
29,701 beads as it was, against 0.12 ms in one pass into kept memory (the "samples" part of
``benchmarks/bench_analysis.py``). The arithmetic is NumPy's, operation by operation (compiled
without fast-math), so the two give the same bits. Its argument types are declared, so that its
machine code loads with this module (in the background, as :mod:`hexdem.analysis.compiled`'s does).
"""

from __future__ import annotations

import numpy as np
from numba import float64, njit


@njit([(float64[:, ::1], float64[:, ::1], float64[:, ::1], float64[::1], float64)], cache=True, error_model="numpy")
def full_step_state(positions, velocities, forces, masses, half_dt):
    """((n, 2) positions, (n, 2) full-step velocities) of the first ``n = len(masses)`` rows of
    LAMMPS's per-atom ``positions``, ``velocities`` and ``forces`` (n, 3), with ``masses`` (n,) and
    ``half_dt`` = dt/2: v + (half_dt / m) f, row by row."""
    n = len(masses)
    x, v = np.empty((n, 2)), np.empty((n, 2))
    for r in range(n):
        h = half_dt / masses[r]
        x[r, 0], x[r, 1] = positions[r, 0], positions[r, 1]
        v[r, 0] = velocities[r, 0] + h * forces[r, 0]
        v[r, 1] = velocities[r, 1] + h * forces[r, 1]
    return x, v
