"""Linear waves recorded inside the run: the velocity field's plane-wave components and the
beads' kinetic energy averaged over blocks of samples, without a dump.

:class:`WaveRecorder` observes an engine's samples (:mod:`hexdem.engines.sampling`) like the
pulse tracker, and keeps two things, both linear in the samples so that under MPI every rank
adds what its own beads give and one sum at the end merges them:

* **Plane-wave components.** At every sample and for each wave vector q of ``wave_vectors_m``,
  the lattice Fourier sum V(q, t) = Σ_j w_j v_j(t) exp(−i q·r_j) over the beads' packed positions
  r_j [m] (a complex 2-vector per q, in m/s), each bead weighted by ``weights`` w_j (1 unless
  given: a spatial window). Its spectrum in time is the measured dispersion
  (:mod:`hexdem.analysis.spectrum`).
* **Energy blocks.** Every ``block`` samples, each bead's kinetic energy ½ m |v|² [J] averaged
  over those samples: over whole periods of a wave, half its energy, without the oscillation at
  twice its frequency. What a wave packet's radius is read from (:mod:`hexdem.analysis.packet`).

Memory is S × Q complex pairs and F × N floats (S samples, Q wave vectors, F blocks), set by
what the caller asks for, never by a trajectory.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.engines.sampling import Sample
from hexdem.model.granular import GranularModel, RunSettings


@dataclass(frozen=True)
class RecordedWaves:
    """What a :class:`WaveRecorder` kept, in SI.

    ``times_s`` (S,) the samples' times; ``components`` (S, Q, 2) complex V(q, t) [m/s];
    ``block_times_s`` (F,) each energy block's mid time; ``block_kinetic_j`` (F, N) each bead's
    mean kinetic energy over the block; ``block_samples`` samples per block (block f holds samples
    f B … f B + B − 1); ``positions_m`` (N, 2) the packed positions the phases and the energies
    refer to.
    """

    times_s: np.ndarray
    components: np.ndarray
    block_times_s: np.ndarray
    block_kinetic_j: np.ndarray
    block_samples: int
    positions_m: np.ndarray

    def block_sample_times_s(self) -> np.ndarray:
        """(F, B) the times of each block's samples."""
        interval = self.times_s[1] - self.times_s[0] if len(self.times_s) > 1 else 0.0
        index = np.arange(len(self.block_times_s))[:, None] * self.block_samples + np.arange(self.block_samples)
        return index * interval


class WaveRecorder:
    """Observer of one run's samples (see the module docstring).

    ``wave_vectors_m`` (Q, 2) [1/m] (may be empty); ``block`` samples per energy block (0: no
    energies); ``comm`` the mpi4py communicator of the ranks that share the run (None: one rank);
    ``weights`` (N,) each bead's weight in the plane-wave components (None: all 1).
    """

    def __init__(
        self, model: GranularModel, settings: RunSettings, wave_vectors_m=(), block: int = 0, comm=None, weights=None
    ):
        self.settings, self.comm = settings, comm
        self.n_beads = len(model.packing)
        self.positions_m = model.packing.positions_m[: self.n_beads].copy()
        vectors = np.asarray(wave_vectors_m, float).reshape(-1, 2)
        self.phases = np.exp(-1j * self.positions_m @ vectors.T)  # (N, Q)
        if weights is not None:
            self.phases *= np.asarray(weights, float)[:, None]
        self.components = np.zeros((settings.n_samples, len(vectors), 2), complex)
        self.block = block
        n_blocks = settings.n_samples // block if block else 0
        self.kinetic = np.zeros((n_blocks, self.n_beads))
        self.half_masses = 0.5 * model.masses_kg[: self.n_beads]
        self.count = 0

    def __call__(self, sample: Sample) -> None:
        beads = sample.ids <= self.n_beads
        index = sample.ids[beads] - 1
        velocities = sample.velocities[beads] * self.settings.units.velocity_m_s
        if self.phases.shape[1]:
            self.components[sample.index] += self.phases[index].T @ velocities
        block = sample.index // self.block if self.block else len(self.kinetic)
        if block < len(self.kinetic):
            self.kinetic[block, index] += self.half_masses[index] * np.sum(velocities**2, axis=1) / self.block
        self.count = sample.index + 1

    def finish(self) -> RecordedWaves | None:
        """The records on rank 0, summed over the ranks (None on the other ranks)."""
        if self.comm is not None and self.comm.Get_size() > 1:
            from mpi4py import MPI

            root = self.comm.Get_rank() == 0
            for array in (self.components, self.kinetic):
                self.comm.Reduce(MPI.IN_PLACE if root else array, array if root else None, op=MPI.SUM, root=0)
            if not root:
                return None
        interval = self.settings.dump_every * self.settings.dt_s
        n_blocks = min(len(self.kinetic), self.count // self.block) if self.block else 0
        return RecordedWaves(
            times_s=np.arange(self.count) * interval,
            components=self.components[: self.count],
            block_times_s=(np.arange(n_blocks) + 0.5) * self.block * interval - 0.5 * interval,
            block_kinetic_j=self.kinetic[:n_blocks],
            block_samples=self.block,
            positions_m=self.positions_m,
        )
