"""The measured dispersion of the precompressed packing against its phonon bands (issue part 3).

**Set-up.** A hexagon of steel beads, every contact precompressed to f0
(:mod:`hexdem.model.precompression`), is given independent random velocities of rms
``speed_m_s`` per component (:func:`~hexdem.waves.states.broadband_state`, through
``initial_state_file``): white noise in wave vector and polarization, weak enough that the
contacts stay linear (the dynamic overlap is about speed / ω_K, a per cent of δ0 at 0.5 mm/s
under 20 N). The struck bead's impact is a token 1 µm/s (a run needs one).

**Measurement.** The run records, at every sample, the lattice Fourier sums V(q, t) at the wave
vectors of the path Γ–K–M–Γ (:mod:`hexdem.analysis.wave_recorder`), sampled ``samples_per_period``
times per period of the highest band, each bead weighted by a spatial window (:func:`taper`: 1
over the inner half of the packing's inscribed circle, falling as cos² to 0 at its rim). Each
sum is projected on the theory's two polarizations at q, every frequency bin goes to the band
whose polarization holds the larger share of its power, and each band's peak among its own bins
is its measured ω (:func:`~hexdem.analysis.spectrum.band_peaks`). Γ itself is left out: its
ω = 0 is a rigid translation, which the walls forbid.

**Resolution, and the bound on every point.** The packing is L wide (its smallest width, bead
centre to bead centre: √3 (n − 1) a for n per edge), so it has no plane waves, only its own
modes, each a mixture of the wave vectors within about δq = 2π/L of its own; and a record T
long separates frequencies to 2π/T. The spectrum at q thus gathers the modes of the disc of
radius δq about q, each with the random energy the initial state gave it, and its peak is the
strongest of them: anywhere in the band's range over that disc. Each point's bound is that
range plus 2π/T (:func:`band_spread`), relative to ω_b(q): it falls as 1/L. Below |q| = 2δq
(fewer than two wavelengths across the packing) the disc reaches the packing's lowest modes,
set by its walls and shape rather than by the bulk bands; those points are reported, but not
resolved and not judged.

**Why the window and the polarization.** Without them, one random state at 20 per edge put the
worst point 94 % off: the lower band at |q| a = 0.30 measured on the upper band's line, whose
polarization only partly follows e_upper there. Beyond 2δq it was still 12 % at |q| a = 0.91
(upper band, inside its bound) and 9 % at |q| a = 3.49, where a single mode at 6.87 kHz outshone
the bulk modes; in other seeds the worst point came from the walls' modes (4.75 kHz at the
lower band's |q| a = 3.33, 16 %) or from the abrupt edge's side lobes at K, where the cone's density of
states vanishes and few modes lie inside the disc (7.9 kHz, 7.7 %). The soft delrin walls hold
a band of their own near 4.5 kHz, in the outer rows of beads (with steel walls its power falls
15-fold): the window gives those rows no weight (the band's share of the power between K and M,
4.3–4.9 kHz, falls from 1.9 % to 1.5e-5), and its smooth edge keeps the side lobes down. With
it, six seeds at 20 per edge put every resolved point within its bound (at most 0.78 of it),
at a median of 0.9–1.4 %, and three at 40 per edge (at most 0.95 of it, at K), at 0.6–0.7 %.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hexdem.analysis.spectrum import band_peaks, branch_signals, power_spectrum
from hexdem.common.checks import positive_int, positive_number
from hexdem.errors import HexdemError
from hexdem.experiments.wave_run import record_waves, steps_per_sample
from hexdem.model.config import RunConfig
from hexdem.model.initial_state import write_initial_state
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings
from hexdem.theory.phonons import Lattice2D, band_path, dynamical_matrix, frequencies
from hexdem.waves.states import broadband_state

#: Branch names of dispersion.csv, the lower band first.
BRANCHES = ("lower", "upper")
#: dispersion.csv's columns: a point's verdict after its wave vector and frequencies.
COLUMNS = (
    "path_position",
    "kx",
    "ky",
    "branch",
    "omega_theory",
    "omega_measured",
    "relative_deviation",
    "bound",
    "resolved",
    "within_bound",
)
#: Rings and directions that sample the disc of :func:`band_spread`.
SPREAD_RINGS, SPREAD_DIRECTIONS = 8, 48


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
            raise HexdemError(
                f"samples_per_period must be at least 3 (the highest band's Nyquist limit is 2), "
                f"got {self.samples_per_period}"
            )
        for name in ("precompression_n", "speed_m_s", "duration_s"):
            positive_number(name, getattr(self, name))
        self.config()  # its own checks, worded there

    def config(self) -> RunConfig:
        """The run's configuration, before its initial state and sampling are set."""
        return RunConfig(
            edge_beads=self.edge_beads,
            precompression_n=self.precompression_n,
            v0=1e-6,
            steps_per_contact=self.steps_per_contact,
            duration=self.duration_s,
            engine=self.engine,
            ranks=self.ranks,
        )

    def theory(self) -> Lattice2D:
        return Lattice2D.of(self.config())


@dataclass(frozen=True)
class Dispersion:
    """A measured dispersion along the path (Γ itself left out), SI.

    ``path_position`` (P,) [1/m]; ``wave_vectors`` (P, 2) [1/m]; ``omega_theory`` and
    ``omega_measured`` (P, 2) [rad/s], the lower band first; ``spectrum_omega`` (W,) [rad/s] and
    ``spectrum_power`` (W, P): both polarizations' power, each column scaled to its largest value;
    ``packing_width_m`` L and ``frequency_resolution_rad_s`` 2π/T (module docstring);
    ``bound`` (P, 2) each point's bound on its relative deviation (:func:`band_spread` plus
    2π/T, over ω_theory); ``theory`` the linear lattice; ``settings``.
    """

    path_position: np.ndarray
    wave_vectors: np.ndarray
    omega_theory: np.ndarray
    omega_measured: np.ndarray
    spectrum_omega: np.ndarray
    spectrum_power: np.ndarray
    packing_width_m: float
    frequency_resolution_rad_s: float
    bound: np.ndarray
    theory: Lattice2D
    settings: DispersionSettings = field(repr=False)

    @property
    def relative_deviation(self) -> np.ndarray:
        """(P, 2) abs(ω_measured − ω_theory) / ω_theory."""
        return np.abs(self.omega_measured - self.omega_theory) / self.omega_theory

    @property
    def median_deviation(self) -> float:
        return float(np.median(self.relative_deviation))

    @property
    def resolution_per_m(self) -> float:
        """δq = 2π/L [1/m], the packing's resolution in wave vector."""
        return 2 * math.pi / self.packing_width_m

    @property
    def smallest_resolved_per_m(self) -> float:
        """2δq [1/m]: the resolution limit, two wavelengths across the packing."""
        return 2 * self.resolution_per_m

    @property
    def resolved(self) -> np.ndarray:
        """(P,) whether the wave vector lies beyond the resolution limit."""
        return np.linalg.norm(self.wave_vectors, axis=1) >= self.smallest_resolved_per_m

    @property
    def within_bound(self) -> np.ndarray:
        """(P, 2) whether each point's relative deviation is at most its bound."""
        return self.relative_deviation <= self.bound

    def largest_deviation_distance_from_gamma(self) -> float:
        """The length [1/m] of the wave vector with the largest relative deviation (either branch)."""
        return float(np.linalg.norm(self.wave_vectors[np.argmax(self.relative_deviation.max(axis=1))]))

    def largest_resolved(self) -> tuple[int, int]:
        """(point, branch) of the largest relative deviation beyond the resolution limit."""
        deviation = np.where(self.resolved[:, None], self.relative_deviation, -np.inf)
        point, branch = np.unravel_index(np.argmax(deviation), deviation.shape)
        return int(point), int(branch)

    def rows(self) -> list[list]:
        """dispersion.csv's rows (:data:`COLUMNS`), branch by branch along the path."""
        deviation, resolved, within = self.relative_deviation, self.resolved, self.within_bound
        return [
            [
                repr(float(self.path_position[p])),
                repr(float(self.wave_vectors[p, 0])),
                repr(float(self.wave_vectors[p, 1])),
                name,
                repr(float(self.omega_theory[p, b])),
                repr(float(self.omega_measured[p, b])),
                repr(float(deviation[p, b])),
                repr(float(self.bound[p, b])),
                str(bool(resolved[p])).lower(),
                str(bool(within[p, b])).lower(),
            ]
            for b, name in enumerate(BRANCHES)
            for p in range(len(self.path_position))
        ]


def polarizations(theory: Lattice2D, wave_vectors) -> np.ndarray:
    """(Q, 2, 2) the theory's unit eigenvectors at each wave vector, the lower band's first."""
    return np.linalg.eigh(dynamical_matrix(theory, wave_vectors))[1]


def packing_width(positions_m) -> float:
    """L [m]: the smallest width of the beads' centres ``positions_m`` (N, 2), over directions
    every half degree."""
    angles = np.radians(np.arange(0.0, 180.0, 0.5))
    extent = np.asarray(positions_m, float) @ np.array([np.cos(angles), np.sin(angles)])
    return float(np.min(extent.max(axis=0) - extent.min(axis=0)))


def taper(positions_m) -> np.ndarray:
    """(N,) the spatial window of the module docstring: about the centres' mean, radius r, in the
    inscribed circle of radius R = L/2: 1 for r ≤ R/2, cos²(π (r − R/2)/R) up to R, 0 beyond."""
    positions_m = np.asarray(positions_m, float)
    radius = packing_width(positions_m) / 2
    r = np.linalg.norm(positions_m - positions_m.mean(axis=0), axis=1)
    return np.cos(0.5 * math.pi * np.clip(2 * r / radius - 1, 0.0, 1.0)) ** 2


def band_spread(theory: Lattice2D, wave_vectors, radius_per_m: float) -> np.ndarray:
    """(Q, 2) each band's largest |ω_b(q') − ω_b(q)| [rad/s] over the disc |q' − q| ≤
    ``radius_per_m`` about each of ``wave_vectors`` (Q, 2) [1/m], sampled on
    :data:`SPREAD_RINGS` rings of :data:`SPREAD_DIRECTIONS` directions."""
    wave_vectors = np.asarray(wave_vectors, float)
    angles = np.linspace(0.0, 2 * math.pi, SPREAD_DIRECTIONS, endpoint=False)
    rings = radius_per_m * np.arange(1, SPREAD_RINGS + 1) / SPREAD_RINGS
    disc = (rings[:, None, None] * np.stack([np.cos(angles), np.sin(angles)], axis=-1)).reshape(-1, 2)
    spread = frequencies(theory, wave_vectors[:, None, :] + disc) - frequencies(theory, wave_vectors)[:, None, :]
    return np.abs(spread).max(axis=1)


def measure_dispersion(settings: DispersionSettings, workdir, log=None, show_progress: bool = True) -> Dispersion:
    """Run the set-up of the module docstring in ``workdir`` and measure its dispersion."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    theory, config = settings.theory(), settings.config()
    model = build_model(config)
    state = workdir / "initial_state.csv"
    write_initial_state(state, model.packing, broadband_state(len(model.packing), settings.speed_m_s, settings.seed))
    position, vectors, omega = band_path(theory, settings.points_per_segment)
    every = steps_per_sample(run_settings(config, model).dt_s, 2 * math.pi / omega.max(), settings.samples_per_period)
    config = config.replace(initial_state_file=str(state), dump_every=every)
    inside = np.linalg.norm(vectors, axis=1) > 0
    position, vectors, omega = position[inside], vectors[inside], omega[inside]
    positions = model.packing.positions_m[: len(model.packing)]
    recorded = record_waves(
        config, workdir / "run", vectors, log=log, show_progress=show_progress, weights=taper(positions)
    )
    spectrum_omega, power = power_spectrum(
        recorded.times_s, branch_signals(recorded.components, polarizations(theory, vectors))
    )
    total = power.sum(axis=2)
    width = packing_width(positions)
    resolution = 2 * math.pi / (len(recorded.times_s) * (recorded.times_s[1] - recorded.times_s[0]))
    bound = (band_spread(theory, vectors, 2 * math.pi / width) + resolution) / omega
    return Dispersion(
        position,
        vectors,
        omega,
        band_peaks(spectrum_omega, power),
        spectrum_omega,
        total / total.max(axis=0),
        width,
        resolution,
        bound,
        theory,
        settings,
    )
