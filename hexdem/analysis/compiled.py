r"""The in-run analysis's per-sample arithmetic compiled: the beads' speeds with the pulse
tracker's update, and the energy audit's contact and body sums, one loop over a rank's beads or
candidate pairs each, in C (``hexdem/common/kernels``, built when hexdem is installed).

They compute what the NumPy code of :class:`~hexdem.analysis.tracker_kernel.PulseState` and
:class:`~hexdem.analysis.energy.EnergyAudit` computes, in the same order: the tests hold the
tracker's results equal to the bit and the energies to round-off (:math:`δ^{5/2}` is taken as
:math:`δ^2 \sqrt{δ}`; sums run body by body where NumPy's go in pairs). The NumPy code defines
their results; every run uses the kernels (:mod:`hexdem.common.kernel_switch`), since one pass over a
bead's few numbers costs less than NumPy's indexing of whole arrays at every size.

Compiled without fast-math or contracted multiply-adds, so that each operation rounds as
NumPy's does. C rather than numba because numba's load at each MPI rank's start cost as much as
the whole run's analysis (measurements: docs/validation/benchmarks.md, *C instead of numba*).
"""

from __future__ import annotations

import numpy as np

from hexdem.analysis.tracker_kernel import RIVAL_RATIO, PulseState
from hexdem.common import _kernels

#: Raised by :func:`sample_pulses` for a sample whose bodies are not the previous sample's, in order.
BodiesReordered = _kernels.BodiesReordered


def pairs_within(positions, cutoff: float) -> tuple[np.ndarray, np.ndarray]:
    """The pairs ``(i, j)``, i < j, of rows of ``positions`` (n, 2) no farther apart than ``cutoff``:
    those of :meth:`scipy.spatial.cKDTree.query_pairs` (in another order), by a cell list, so that a
    rank does not import ``scipy.spatial`` at its start."""
    positions = np.ascontiguousarray(positions, float)
    i, j = (np.empty(4 * len(positions) + 16, np.int64) for _ in range(2))
    found = _kernels.pairs_within(positions=positions, cutoff=cutoff, i=i, j=j)
    if found > len(i):
        i, j = (np.empty(found, np.int64) for _ in range(2))
        _kernels.pairs_within(positions=positions, cutoff=cutoff, i=i, j=j)
    return i[:found], j[:found]


def bind_pulses(state: PulseState) -> _kernels.PulseArrays:
    """The tracker's ``state`` as :func:`sample_pulses` updates it: its arrays
    (:meth:`~hexdem.analysis.tracker_kernel.PulseState.kernel_arrays`), each checked by name, type and
    shape and held, its ladder's ratio ``q`` and :data:`~hexdem.analysis.tracker_kernel.RIVAL_RATIO`.
    A state's arrays are made once, with it: its binding holds for its life."""
    return _kernels.PulseArrays(**state.kernel_arrays(), q=state.q, rival_ratio=RIVAL_RATIO)


def sample_pulses(
    pulses: _kernels.PulseArrays, *, ids, previous_ids, velocities, rows, end_velocity, speeds, s: int
) -> np.ndarray:
    """Sample ``s`` into the tracker's state (``pulses``, :func:`bind_pulses`), in one pass: row ``b`` takes the
    speed ``|v|`` of its velocity ``v = velocities[rows[b]]`` (C's hypot, as ``np.hypot``) as its sample, as
    :meth:`~hexdem.analysis.tracker_kernel.PulseState.update` takes it, but for the refinement. Each row's
    ``v`` goes into ``end_velocity`` and, unless ``speeds`` is empty, its speed into ``speeds``.

    Most rows, at most samples, lie clearly below their running maximum (by more than the
    rival's margin, at a relative 1e-9) with no window open (its sum of squares below its
    ``lazy_below``, which the pass keeps): such a row's sample only enters its ring, as its
    velocity (``ring_velocity``, the speed −1), and its hypot, the pass's dearest
    arithmetic, is taken only if a window comes to need it. With ``speeds`` wanted, every row's is taken.

    Returns the rows whose rival window is complete, for
    :meth:`~hexdem.analysis.tracker_kernel.PulseState.challenge`. Raises
    :class:`BodiesReordered`, with the state as it was, if the sample's body ids ``ids`` are not
    ``previous_ids`` (``np.array_equal``)."""
    complete = np.empty(len(rows), np.int64)
    count = pulses.sample(
        ids=ids,
        previous_ids=previous_ids,
        velocities=velocities,
        rows=rows,
        end_velocity=end_velocity,
        speeds=speeds,
        complete=complete,
        s=s,
    )
    return complete[:count]


def bind_audit(**rows) -> _kernels.AuditRows:
    """What :func:`audit_part` reads of a listing of the contacts, each array checked by name, type
    and shape and held: ``listed_at`` (where the rows were when listed) and ``distance`` (how far
    one may move before they are listed again), the constants of
    :meth:`~hexdem.analysis.energy.EnergyAudit._row_constants`, and ``n_regions``."""
    return _kernels.AuditRows(**rows)


def audit_part(rows: _kernels.AuditRows, positions, velocities, spins, n_regions: int) -> np.ndarray:
    r""":meth:`~hexdem.analysis.energy.EnergyAudit.part` of a rank in one call (``rows``: :func:`bind_audit`,
    for ``n_regions`` regions): empty if a row of ``positions`` lies more than the listing's
    ``distance`` from where the contacts were listed (the caller lists them again), else the sums
    [total energy, translational and rotational kinetic, then each region's kinetic and contact
    energy] [J] of the audited rows (the first ``len(masses)``) with ``velocities`` and ``spins``
    (ω_z, empty for spheres that do not turn):

    * the candidate pairs' Hertz energies :math:`\tfrac{2}{5} k_n \sqrt{R_\text{eff}}\, δ^{5/2}`, half to each
      of its rows' regions (a ghost's half is not audited here), the i sides' halves pair by pair,
      then the j sides' (:func:`~hexdem.analysis.energy._pair_energies_j`); a pair apart adds +0
      rather than being skipped: ahead of a pulse, whether a pair at rest touches is round-off's
      coin toss, which a branch would mispredict;
    * the walls' contacts, member by member within a wall, then wall by wall
      (:func:`~hexdem.analysis.energy._add_wall_energies_j`), a flat wall's :math:`n \cdot x` term by term;
    * the bodies' own terms (kinetic energies and the constant forces' work), row by row.

    The total sums the regions' energies as NumPy sums a few numbers (the first, plus the rest in
    order), less the constant forces' work."""
    sums = np.empty(3 + 2 * n_regions)
    return sums if rows.part(positions=positions, velocities=velocities, spins=spins, sums=sums) else sums[:0]
