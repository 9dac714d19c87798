"""The samples LAMMPS hands over, taken in one compiled pass.

At the sampling callback a rank's velocities are at the half step; the sample holds the full
step's, v(t) = v(t − dt/2) + (dt/2) f/m (see :mod:`hexdem.engines.lammps.driver`). One pass over
the strided (n, 3) arrays into kept memory takes the positions' copy and the velocities together,
where NumPy takes five (the "samples" part of ``benchmarks/bench_analysis.py``). The arithmetic
is NumPy's, operation by operation (compiled in C without fast-math, as
:mod:`hexdem.analysis.compiled`'s kernels), so the two give the same bits.
"""

from __future__ import annotations

import numpy as np

from hexdem.common import _kernels


def full_step_state(positions, velocities, forces, masses, half_dt: float) -> tuple[np.ndarray, np.ndarray]:
    """((n, 2) positions, (n, 2) full-step velocities) of the first ``n = len(masses)`` rows of
    LAMMPS's per-atom ``positions``, ``velocities`` and ``forces`` (n, 3), with ``masses`` (n,) and
    ``half_dt`` = dt/2: v + (half_dt / m) f, row by row."""
    n = len(masses)
    x, v = np.empty((n, 2)), np.empty((n, 2))
    _kernels.full_step_state(
        masses=masses, positions=positions, velocities=velocities, forces=forces, half_dt=half_dt, x=x, v=v
    )
    return x, v
