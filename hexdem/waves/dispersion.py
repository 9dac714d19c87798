"""The measured dispersion of the precompressed packing against its phonon bands (issue part 3).

**Set-up.** A hexagon of steel beads, every contact precompressed to f0
(:mod:`hexdem.model.precompression`), is given independent random velocities of rms
``speed_m_s`` per component (:func:`~hexdem.waves.states.broadband_state`, through
``initial_state_file``): white noise in wave vector and polarization, weak enough that the
contacts stay linear (the dynamic overlap is about speed / ω_K, a per cent of δ0 at 0.5 mm/s
under 20 N). The struck bead's impact is a token 1 µm/s (a run needs one).

**Measurement.** The run records, at every sample, the lattice Fourier sums V(q, t) at the wave
vectors of the path Γ–K–M–Γ (:mod:`hexdem.analysis.wave_recorder`), sampled ``samples_per_period``
times per period of the highest band. Each is projected on the theory's two polarizations at q,
and each branch's spectrum peaks at its measured ω (:mod:`hexdem.analysis.spectrum`). Γ itself is
left out: its ω = 0 is a rigid translation, which the walls forbid.

**Why it agrees, and how well.** A finite packing L beads across resolves wave vectors to about
2π/(L a), so a spectrum at q gathers the modes within that distance, spread in frequency by the
group velocity: the deviation falls as 1/L (measured, seed 1, 20 N: median 0.83 % at 20 per edge,
0.52 % at 30, 0.40 % at 40), largest near Γ where ω itself is small. A faint band near
4.5 kHz, below the bulk bands between K and M, is the walls': the experiment's delrin walls are
soft, and with steel ones its power falls 15-fold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hexdem.analysis.spectrum import branch_signals, peak_frequency, power_spectrum
from hexdem.common.checks import positive_int, positive_number
from hexdem.errors import HexdemError
from hexdem.experiments.wave_run import record_waves, steps_per_sample
from hexdem.model.config import RunConfig
from hexdem.model.initial_state import write_initial_state
from hexdem.theory.phonons import Lattice2D, band_path, dynamical_matrix
from hexdem.waves.states import broadband_state

#: Branch names of dispersion.csv, the lower band first.
BRANCHES = ("lower", "upper")
#: dispersion.csv's columns.
COLUMNS = ("path_position", "kx", "ky", "branch", "omega_theory", "omega_measured")


@dataclass(frozen=True)
class DispersionSettings:
    """One dispersion measurement: a hexagon of ``edge_beads`` per edge under ``precompression_n``
    [N] per contact, random velocities of ``speed_m_s`` rms per component (``seed``), recorded for
    ``duration_s`` at ``samples_per_period`` samples per period of the highest band, at
    ``points_per_segment`` wave vectors per segment of Γ–K–M–Γ; ``engine``, ``ranks`` and
    ``steps_per_contact`` as in :class:`~hexdem.model.config.RunConfig` (40 steps per contact resolve
    the highest band's period, about the contact time, to 0.2 % in frequency)."""

    edge_beads: int = 40
    precompression_n: float = 20.0
    speed_m_s: float = 5e-4
    seed: int = 1
    duration_s: float = 0.02
    samples_per_period: int = 6
    points_per_segment: int = 16
    engine: str = "lammps"
    ranks: int = 1
    steps_per_contact: int = 40

    def __post_init__(self):
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise HexdemError(f"seed must be an integer >= 0, got {self.seed!r}")
        for name in ("edge_beads", "samples_per_period", "points_per_segment", "ranks", "steps_per_contact"):
            positive_int(name, getattr(self, name))
        if self.samples_per_period < 3:
            raise HexdemError(f"samples_per_period must be at least 3 (the highest band's Nyquist limit is 2), "
                              f"got {self.samples_per_period}")
        for name in ("precompression_n", "speed_m_s", "duration_s"):
            positive_number(name, getattr(self, name))
        self.config()  # its own checks, worded there

    def config(self) -> RunConfig:
        """The run's configuration, before its initial state and sampling are set."""
        return RunConfig(edge_beads=self.edge_beads, precompression_n=self.precompression_n, v0=1e-6,
                         steps_per_contact=self.steps_per_contact, duration=self.duration_s, engine=self.engine,
                         ranks=self.ranks)

    def theory(self) -> Lattice2D:
        return Lattice2D.of(self.config())


@dataclass(frozen=True)
class Dispersion:
    """A measured dispersion along the path (Γ itself left out), SI.

    ``path_position`` (P,) [1/m]; ``wave_vectors`` (P, 2) [1/m]; ``omega_theory`` and
    ``omega_measured`` (P, 2) [rad/s], the lower band first; ``spectrum_omega`` (W,) [rad/s] and
    ``spectrum_power`` (W, P): both polarizations' power, each column scaled to its largest value;
    ``theory`` the linear lattice; ``settings``.
    """

    path_position: np.ndarray
    wave_vectors: np.ndarray
    omega_theory: np.ndarray
    omega_measured: np.ndarray
    spectrum_omega: np.ndarray
    spectrum_power: np.ndarray
    theory: Lattice2D
    settings: DispersionSettings = field(repr=False)

    @property
    def relative_deviation(self) -> np.ndarray:
        """(P, 2) abs(ω_measured − ω_theory) / ω_theory."""
        return np.abs(self.omega_measured - self.omega_theory) / self.omega_theory

    @property
    def median_deviation(self) -> float:
        return float(np.median(self.relative_deviation))

    def largest_deviation_distance_from_gamma(self) -> float:
        """The length [1/m] of the wave vector with the largest relative deviation (either branch)."""
        return float(np.linalg.norm(self.wave_vectors[np.argmax(self.relative_deviation.max(axis=1))]))

    def rows(self) -> list[list]:
        """dispersion.csv's rows (:data:`COLUMNS`), branch by branch along the path."""
        return [[repr(float(self.path_position[p])), repr(float(self.wave_vectors[p, 0])),
                 repr(float(self.wave_vectors[p, 1])), name, repr(float(self.omega_theory[p, b])),
                 repr(float(self.omega_measured[p, b]))]
                for b, name in enumerate(BRANCHES) for p in range(len(self.path_position))]


def polarizations(theory: Lattice2D, wave_vectors) -> np.ndarray:
    """(Q, 2, 2) the theory's unit eigenvectors at each wave vector, the lower band's first."""
    return np.array([np.linalg.eigh(dynamical_matrix(theory, q))[1] for q in wave_vectors])


def measure_dispersion(settings: DispersionSettings, workdir, log=None, show_progress: bool = True) -> Dispersion:
    """Run the set-up of the module docstring in ``workdir`` and measure its dispersion."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    theory, config = settings.theory(), settings.config()
    model = config.model()
    state = workdir / "initial_state.csv"
    write_initial_state(state, model.lattice, broadband_state(len(model.lattice), settings.speed_m_s, settings.seed))
    position, vectors, omega = band_path(theory, settings.points_per_segment)
    every = steps_per_sample(config.settings(model).dt_s, 2 * math.pi / omega.max(), settings.samples_per_period)
    config = config.replace(initial_state_file=str(state), dump_every=every)
    inside = np.linalg.norm(vectors, axis=1) > 0
    position, vectors, omega = position[inside], vectors[inside], omega[inside]
    recorded = record_waves(config, workdir / "run", vectors, log=log, show_progress=show_progress)
    spectrum_omega, power = power_spectrum(recorded.times_s, branch_signals(recorded.components,
                                                                             polarizations(theory, vectors)))
    total = power.sum(axis=2)
    return Dispersion(position, vectors, omega, peak_frequency(spectrum_omega, power), spectrum_omega,
                      total / total.max(axis=0), theory, settings)
