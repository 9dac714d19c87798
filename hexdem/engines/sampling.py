"""What an engine hands to the analysis while it runs: samples of the bodies' state.

Engines do not keep trajectories. Every ``settings.dump_every`` steps (step 0 included, as
a LAMMPS dump would) they hand a :class:`Sample` of the bodies each MPI rank owns to an
observer (:class:`Observer`). The analysis (a tracker) keeps only what its
outputs need, so memory grows with the number of beads, never with the run's length.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, TypeVar

import numpy as np


@dataclass(frozen=True)
class Sample:
    """The bodies one rank owns at one sampled step, in the run's unit system.

    ``index`` sample number (step // dump_every); ``step`` the time step; ``time`` the
    simulated time; ``ids`` (n,) body ids, 1-based (beads 1..N as in the data file, then
    the striker); ``positions`` and ``velocities`` (n, 2) full-step values at ``step``;
    ``accelerations`` (n, 2), total force / mass, only at the sensor samples (every
    ``settings.sensor_every`` steps), else None; ``angular_velocities`` (n,) ω_z, the spins of a
    frictional model's spheres (None: the engine gives none; frictionless spheres never turn).

    Under MPI: ``migrated`` False promises that every rank owns the same bodies as at its previous
    sample, in the same order (LAMMPS moves atoms between ranks, and reorders them, only when it
    rebuilds its neighbour lists), the same on every rank; True (the default) that they may have
    changed. ``ghost_ids`` and ``ghost_positions`` (g, 2): the other ranks' bodies that this rank
    keeps copies of at ``step`` (LAMMPS's ghost atoms: all those within contact of its own);
    None: none (one rank).
    """

    index: int
    step: int
    time: float
    ids: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray | None = None
    angular_velocities: np.ndarray | None = None
    migrated: bool = True
    ghost_ids: np.ndarray | None = None
    ghost_positions: np.ndarray | None = None


class Observer(Protocol):
    """What an engine hands its samples to: called with each :class:`Sample` of the bodies its
    rank owns, in the order of the run."""

    def __call__(self, sample: Sample) -> None: ...


Results = TypeVar("Results", covariant=True)


class InRunAnalysis(Observer, Protocol[Results]):
    """An observer that analyses the run as it goes (a pulse tracker, a wave recorder):
    ``finish()``, called on every rank after the engine's last sample, gathers the ranks' parts
    and returns the results on rank 0, None on the other ranks."""

    def finish(self) -> Results | None: ...
