"""Where hexdem's per-sample arithmetic runs compiled: the ranks that hold at least
:data:`COMPILED_BEADS` bodies.

The kernels themselves (C, ``hexdem/common/kernels``, bound by :mod:`hexdem.analysis.compiled` for
the tracker and its energy audit and :mod:`hexdem.engines.lammps.full_step` for the samples LAMMPS
hands over) give the NumPy code's peaks, times and velocities to the bit, and its energies to
round-off: their sums run body by body where NumPy's go in pairs. Below the threshold a run keeps
the NumPy code, whose results define the kernels', and the default run its files to the byte;
there the NumPy code's fixed cost a sample, some 50 array operations, is small beside the run.
"""

from __future__ import annotations

#: From this many bodies per rank on, the samples and their analysis go through compiled kernels;
#: below, through NumPy. The default run (331 beads) stays below; a rank of 1,856 beads (29,701 on
#: 16 ranks) is above.
COMPILED_BEADS = 1000


def runs_compiled(n_bodies: int, ranks: int = 1) -> bool:
    """Whether a run of ``n_bodies`` shared by ``ranks`` ranks takes its samples compiled: its
    largest rank share, ⌈n_bodies / ranks⌉, holds at least :data:`COMPILED_BEADS`."""
    return -(-n_bodies // ranks) >= COMPILED_BEADS

