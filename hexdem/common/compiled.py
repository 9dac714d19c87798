"""Where hexdem's per-sample arithmetic runs compiled: the ranks that hold at least
:data:`COMPILED_BEADS` bodies.

The kernels themselves (:mod:`hexdem.analysis.compiled` for the tracker and its energy audit,
:mod:`hexdem.engines.lammps.full_step` for the samples LAMMPS hands over) import numba, which with
their on-disk cache costs about half a second to load: more than the whole analysis of a small
run. So a run decides once, from its bodies per rank, and a run that uses them loads them in the
background while the engine starts (:func:`~hexdem.common.preload.load_in_background`).
"""

from __future__ import annotations

#: From this many bodies per rank on, the samples and their analysis go through compiled kernels;
#: below, through NumPy. The default run (331 beads) stays below; a rank of 1,856 beads (29,701 on
#: 16 ranks) is above: its NumPy analysis pays the fixed cost of some 50 array operations at every
#: sample. The two give the same results.
COMPILED_BEADS = 1000


def runs_compiled(n_bodies: int, ranks: int = 1) -> bool:
    """Whether a run of ``n_bodies`` shared by ``ranks`` ranks takes its samples compiled: its
    largest rank share, ⌈n_bodies / ranks⌉, holds at least :data:`COMPILED_BEADS`."""
    return -(-n_bodies // ranks) >= COMPILED_BEADS

