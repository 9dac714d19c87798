"""A whole sampled trajectory in memory, for small runs and for dumps read back from disk.

hexdem's own runs stream their samples into a tracker (:mod:`hexdem.analysis.tracker`) and
keep no trajectory. A :class:`Trajectory` is what the dump path hands to the analysis (a
deck run by hand, read through MDAnalysis), and what :class:`TrajectoryRecorder` builds
from the samples of a small run when every sample is wanted (contact tests, one-off studies).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hexdem.analysis.energy import EnergyAudit, energy_error, kinetic_energy_j
from hexdem.engines.sampling import Sample
from hexdem.model.granular import GranularModel, RunSettings


@dataclass(frozen=True)
class Trajectory:
    """Samples of all bodies (beads, then the striker if any), in SI.

    ``times_s`` (F,) [s]; ``velocities_m_s`` and ``displacements_m`` (F, n_bodies, 2) [m/s, m],
    displacements from the initial positions; ``engine`` a dict describing the run
    (name, version, ranks, wall_time_s, ...); ``gravity_m_s2`` the uniform in-plane gravity
    (gx, gy) [m/s²] the run was under, if any (its work enters the energy audit).
    """

    times_s: np.ndarray
    velocities_m_s: np.ndarray
    displacements_m: np.ndarray
    engine: dict = field(default_factory=dict)
    gravity_m_s2: tuple[float, float] | None = None

    @property
    def speeds_m_s(self) -> np.ndarray:
        """(F, n_bodies) in-plane speeds |v|."""
        return np.linalg.norm(self.velocities_m_s, axis=2)

    def energies_j(self, model: GranularModel) -> np.ndarray:
        """Total conserved energy (kinetic + Hertz − work of gravity) at every sample [J]."""
        audit = EnergyAudit(model, self.gravity_m_s2)
        start = model.initial_positions_m()
        return np.array([audit(start + u, v) for u, v in zip(self.displacements_m, self.velocities_m_s)])

    def region_energies_j(self, model: GranularModel, samples: int) -> tuple[np.ndarray, np.ndarray]:
        """(times [s] (T,), (T, R, 2) kinetic and contact energy [J] of each region) at about
        ``samples`` evenly spaced samples (see :meth:`EnergyAudit.measure`)."""
        audit = EnergyAudit(model, self.gravity_m_s2)
        start = model.initial_positions_m()
        picked = np.unique(np.linspace(0, len(self.times_s) - 1, min(samples, len(self.times_s))).round().astype(int))
        return self.times_s[picked], np.array(
            [audit.measure(start + self.displacements_m[k], self.velocities_m_s[k])[1] for k in picked]
        )

    def energy_drift(self, model: GranularModel) -> float:
        """The energy audit's error (:func:`~hexdem.analysis.energy.energy_error`)."""
        return energy_error(self.energies_j(model), kinetic_energy_j(self.velocities_m_s[0], model), model.dissipative)


class TrajectoryRecorder:
    """An observer that keeps every sample of a one-rank run, then :meth:`trajectory` in SI.

    Memory grows with the run's length: for small runs only.
    """

    def __init__(self, model: GranularModel, settings: RunSettings):
        self.start = model.initial_positions_m() / settings.units.length_m
        self.units = settings.units
        self.samples: list[Sample] = []

    def __call__(self, sample: Sample) -> None:
        self.samples.append(sample)

    def trajectory(self, engine: dict) -> Trajectory:
        order = [np.argsort(s.ids) for s in self.samples]
        positions = np.array([s.positions[o] for s, o in zip(self.samples, order)])
        velocities = np.array([s.velocities[o] for s, o in zip(self.samples, order)])
        units = self.units
        return Trajectory(
            times_s=np.array([s.time for s in self.samples]) * units.time_s,
            velocities_m_s=velocities * units.velocity_m_s,
            displacements_m=(positions - self.start) * units.length_m,
            engine=engine,
        )
