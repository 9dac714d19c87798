"""What an engine hands to the analysis: the sampled motion of every body, in SI.

Engines (LAMMPS, the reference integrator) differ in how they integrate; the analysis
only sees a :class:`Trajectory`, so both are judged by the same definitions.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hexdem.analysis.energy import total_energy_j
from hexdem.model.granular import GranularModel


@dataclass(frozen=True)
class Trajectory:
    """Samples of all bodies (beads, then the striker if any).

    ``times_s`` (F,) [s]; ``velocities_m_s`` and ``displacements_m`` (F, n_bodies, 2) [m/s, m],
    displacements from the initial positions; ``engine`` a dict describing the run
    (name, version, ranks, wall_time_s, ...).
    """

    times_s: np.ndarray
    velocities_m_s: np.ndarray
    displacements_m: np.ndarray
    engine: dict = field(default_factory=dict)

    @property
    def speeds_m_s(self) -> np.ndarray:
        """(F, n_bodies) in-plane speeds |v|."""
        return np.linalg.norm(self.velocities_m_s, axis=2)

    def energies_j(self, model: GranularModel) -> np.ndarray:
        """Total energy (kinetic + Hertz) at every sample [J]."""
        start = model.initial_positions_m()
        return np.array([total_energy_j(start + u, v, model)
                         for u, v in zip(self.displacements_m, self.velocities_m_s)])

    def energy_drift(self, model: GranularModel) -> float:
        """max_t |E(t) − E(0)| / E(0): 0 for an exact integrator of this conservative model."""
        energy = self.energies_j(model)
        return float(np.max(np.abs(energy - energy[0])) / energy[0])
