"""Whether hexdem's per-sample arithmetic runs compiled: in every run.

The kernels (C, ``hexdem/common/kernels``, bound by :mod:`hexdem.analysis.compiled` for the tracker
and its energy audit and :mod:`hexdem.engines.lammps.full_step` for the samples LAMMPS hands over)
give the NumPy code's peaks, times and velocities to the bit, and its energies to round-off: their
sums run body by body where NumPy's go in pairs, and an overlap, a small difference of large
coordinates, rounds its own way. Their cost a sample lies below the NumPy code's at every size, so
every run takes them, the default run (331 beads) included (measurements: ``benchmarks/bench_analysis.py``,
docs/validation/benchmarks.md, *Every run compiled*). The NumPy code stays as their definition,
which the tests hold them to (:data:`COMPILED` False).
"""

from __future__ import annotations

#: Whether the samples and their analysis go through the compiled kernels (True: every run) or
#: through the NumPy code that defines them (False: the tests' reference).
COMPILED = True


def runs_compiled() -> bool:
    """Whether this process's samples and their analysis go through the compiled kernels
    (:data:`COMPILED`, read at each call, so that a test may switch it)."""
    return COMPILED
