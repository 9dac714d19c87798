"""Conical diffraction in the precompressed packing (issue part 4): a Gaussian packet built at
the Dirac point K opens into a ring at the cone's slope; a control packet built away from K
keeps its shape and drifts at its group velocity.

**Set-up.** A hexagon precompressed to f0, at rest, is given at t = 0 the packet of
:func:`~hexdem.waves.states.bloch_packet` (through ``initial_state_file``): envelope width σ
(``width_d`` diameters), peak speed ``speed_m_s`` (displacements a per cent of δ0 at 20 N, so
linear). At K it is circularly polarized (:data:`~hexdem.theory.conical.CIRCULAR`) and centred;
the control, on the lower band at ``control_fraction`` K, starts behind the centre by half the
way its group velocity takes it. The run lasts until v_D t = ``reach`` σ, and the hexagon is
sized to keep the ring (or the drifting packet) three widths clear of the walls.

**Measurement.** The run records each bead's kinetic energy averaged over blocks of
``block_periods`` periods at ω_K (:mod:`hexdem.analysis.wave_recorder`); half the wave's
energy, without its oscillation. The ring radius is R(t) = sqrt(⟨r²⟩(t) − ⟨r²⟩(0)) about the
packet's centre, the mean with those energies as weights, ⟨r²⟩(0) that of the packet's own
envelope G² on the beads (:mod:`hexdem.analysis.packet`). The cone's R(t) for the same σ and χ
(:func:`~hexdem.theory.conical.cone_ring_radius`) is the theory; fitting it to the measured R with
the slope v as its one parameter gives the growth rate, which must be v_D.

**Why not a straight line.** R grows as v_D t only slowly: the cone's apex leaves a diffuse
interior. Measured at σ = 8 d in a run to 5σ: a straight line through R over the last half of
the run has the slope 0.961 v_D, and the cone's own R(t) for v_D has 0.959 over the same window;
the cone's whole R(t) fits the measured R with v = 1.002 v_D.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import minimize_scalar

from hexdem.analysis.packet import energy_centroid, energy_spread, ring_radius
from hexdem.analysis.wave_recorder import RecordedWaves
from hexdem.common.checks import is_number, positive_int, positive_number
from hexdem.errors import HexdemError
from hexdem.experiments.wave_run import record_waves, steps_per_sample
from hexdem.model.config import RunConfig
from hexdem.model.granular import GranularModel
from hexdem.model.initial_state import write_initial_state
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings
from hexdem.theory.conical import CIRCULAR, cone_ring_radius
from hexdem.theory.phonons import Lattice2D, cone_slope, dynamical_matrix, frequencies
from hexdem.waves.states import bloch_packet

#: conical.csv's columns.
COLUMNS = ("time_s", "ring_radius_d", "theory_radius_d")
#: control.csv's columns: the control's centroid along its group velocity from where it started,
#: where the group velocity takes it, and its rms width, all in bead diameters.
CONTROL_COLUMNS = ("time_s", "centroid_along_d", "group_path_d", "width_d")
#: Widths σ between the packet's outermost extent and the walls.
CLEARANCE_WIDTHS = 3.0
#: The control keeps its shape and drifts if its drift velocity is within this of its group
#: velocity and its width grows by less than this share over the run (measured: 0.12 % and 3.8 %
#: at σ = 12 d to 5σ, 0.4 % and 6.5 % at σ = 8 d to 3σ).
CONTROL_DRIFT_BOUND = 0.02
CONTROL_WIDENING_BOUND = 0.10


@dataclass(frozen=True)
class ConicalSettings:
    """The packets' runs (see the module docstring): ``precompression_n`` [N] per contact,
    envelope width ``width_d`` σ [bead diameters], run until v_D t = ``reach`` σ, peak speed
    ``speed_m_s``; the control on the lower band at ``control_fraction`` K; sampled
    ``samples_per_period`` times per period at ω_K, energies averaged over ``block_periods``
    periods; ``engine``, ``ranks`` and ``steps_per_contact`` as in
    :class:`~hexdem.model.config.RunConfig`."""

    precompression_n: float = 20.0
    width_d: float = 12.0
    reach: float = 5.0
    speed_m_s: float = 5e-4
    control_fraction: float = 0.5
    samples_per_period: int = 8
    block_periods: int = 4
    engine: str = "lammps"
    ranks: int = 1
    steps_per_contact: int = 40

    def __post_init__(self):
        for name in ("samples_per_period", "block_periods", "ranks", "steps_per_contact"):
            positive_int(name, getattr(self, name))
        if self.samples_per_period < 3:
            raise HexdemError(f"samples_per_period must be at least 3, got {self.samples_per_period}")
        for name in ("precompression_n", "width_d", "reach", "speed_m_s"):
            positive_number(name, getattr(self, name))
        if not (is_number(self.control_fraction) and 0 < self.control_fraction < 1):
            raise HexdemError(f"control_fraction must lie between 0 and 1 (of K), got {self.control_fraction!r}")
        theory = self.theory()
        blocks = (
            self.reach
            * self.width_d
            * theory.spacing_m
            / cone_slope(theory)
            * theory.dirac_frequency()
            / (2 * math.pi * self.block_periods)
        )
        if blocks < 4:
            raise HexdemError(
                f"a reach of {self.reach:g} widths lasts {blocks:.1f} energy blocks of {self.block_periods} "
                "periods; the ring needs at least 4: widen the packet or reach farther"
            )
        self.config()  # its own checks, worded there

    def control_wave_vector(self) -> np.ndarray:
        """The control's wave vector [1/m]: ``control_fraction`` of K."""
        return self.control_fraction * self.theory().high_symmetry_points()["K"]

    def edge_beads(self) -> int:
        """Beads per edge of a hexagon whose apothem, (E − 1) √3/2 d, is ``clearance`` widths σ
        beyond the farthest the packets go: the ring to ``reach`` σ, the control (which starts
        behind the centre by half its path) to half its path, |v_g| / v_D ``reach`` σ."""
        theory = self.theory()
        speed = np.linalg.norm(group_velocity(theory, self.control_wave_vector(), 0))
        farthest = max(1.0, 0.5 * speed / cone_slope(theory)) * self.reach
        return math.ceil((farthest + CLEARANCE_WIDTHS) * self.width_d / (math.sqrt(3) / 2)) + 1

    def config(self) -> RunConfig:
        return RunConfig(
            edge_beads=self.edge_beads(),
            precompression_n=self.precompression_n,
            v0=1e-6,
            steps_per_contact=self.steps_per_contact,
            engine=self.engine,
            ranks=self.ranks,
        )

    def theory(self) -> Lattice2D:
        """The linear lattice (its size does not matter)."""
        return Lattice2D.of(RunConfig(precompression_n=self.precompression_n))


@dataclass(frozen=True)
class PacketRun:
    """One packet's run: its ``centre_m`` and ``width_m``, and what was recorded."""

    centre_m: np.ndarray
    width_m: float
    recorded: RecordedWaves = field(repr=False)

    @property
    def times_s(self) -> np.ndarray:
        return self.recorded.block_times_s

    def ring_radius_m(self) -> np.ndarray:
        return ring_radius(self.recorded.positions_m, self.recorded.block_kinetic_j, self.centre_m, self.width_m)


@dataclass(frozen=True)
class Conical:
    """Both packets measured, SI: ``cone_slope_m_s`` v_D, ``fitted_slope_m_s`` the growth rate;
    ``theory_radius_m`` the cone's R(t) at the K packet's block times; the control's
    ``group_velocity_m_s`` (2,) from the bands and ``drift_velocity_m_s`` (2,) fitted to its
    centroid, its width (rms distance from the centroid) ``control_width_m`` (F,); the beads'
    ``diameter_m``, the unit of the CSVs."""

    dirac: PacketRun
    control: PacketRun
    theory_radius_m: np.ndarray
    cone_slope_m_s: float
    fitted_slope_m_s: float
    group_velocity_m_s: np.ndarray
    drift_velocity_m_s: np.ndarray
    control_width_m: np.ndarray
    diameter_m: float
    settings: ConicalSettings = field(repr=False)

    @property
    def slope_deviation(self) -> float:
        """The growth rate's relative deviation from v_D, abs(v − v_D) / v_D."""
        return abs(self.fitted_slope_m_s / self.cone_slope_m_s - 1.0)

    @property
    def drift_deviation(self) -> float:
        """The control's drift velocity's relative deviation from its group velocity (vector norms)."""
        return float(
            np.linalg.norm(self.drift_velocity_m_s - self.group_velocity_m_s) / np.linalg.norm(self.group_velocity_m_s)
        )

    @property
    def control_widening(self) -> float:
        """The control's width at the end over its width at the first block, minus 1."""
        return float(self.control_width_m[-1] / self.control_width_m[0] - 1.0)

    @property
    def control_keeps_shape(self) -> bool:
        """Whether the control drifts at its group velocity and keeps its width (the bounds above)."""
        return self.drift_deviation <= CONTROL_DRIFT_BOUND and self.control_widening <= CONTROL_WIDENING_BOUND

    def rows(self) -> list[list]:
        """conical.csv's rows (:data:`COLUMNS`)."""
        d = self.diameter_m
        return [
            [repr(float(t)), repr(float(r / d)), repr(float(theory / d))]
            for t, r, theory in zip(self.dirac.times_s, self.dirac.ring_radius_m(), self.theory_radius_m)
        ]

    def control_path_m(self) -> np.ndarray:
        """(F,) the control's centroid's distance from its start along its group velocity."""
        run = self.control
        centroids = energy_centroid(run.recorded.positions_m, run.recorded.block_kinetic_j)
        return (centroids - run.centre_m) @ (self.group_velocity_m_s / np.linalg.norm(self.group_velocity_m_s))

    def control_rows(self) -> list[list]:
        """control.csv's rows (:data:`CONTROL_COLUMNS`)."""
        d, speed = self.diameter_m, np.linalg.norm(self.group_velocity_m_s)
        return [
            [repr(float(t)), repr(float(along / d)), repr(float(speed * t / d)), repr(float(width / d))]
            for t, along, width in zip(self.control.times_s, self.control_path_m(), self.control_width_m)
        ]


def group_velocity(theory: Lattice2D, wave_vector, branch: int) -> np.ndarray:
    """∇ω of ``branch`` (0 lower) at ``wave_vector`` [m/s], by central differences."""
    step = 1e-6 / theory.spacing_m
    return np.array(
        [
            (
                frequencies(theory, wave_vector + step * unit)[branch]
                - frequencies(theory, wave_vector - step * unit)[branch]
            )
            / (2 * step)
            for unit in np.eye(2)
        ]
    )


def _run_packet(
    settings: ConicalSettings,
    config: RunConfig,
    model: GranularModel,
    workdir: Path,
    wave_vector,
    polarization,
    omega: float,
    centre,
    log,
    show_progress,
) -> PacketRun:
    """Write the packet's state on ``model``'s (precompressed) positions, run ``config`` from it
    and record its energy blocks."""
    lattice, theory = model.packing, settings.theory()
    width = settings.width_d * config.diameter_m
    velocities, displacements = bloch_packet(
        lattice.positions_m, centre, width, wave_vector, polarization, omega, settings.speed_m_s
    )
    workdir.mkdir(parents=True, exist_ok=True)
    write_initial_state(workdir / "initial_state.csv", lattice, velocities, displacements)
    period, dt_s = 2 * math.pi / theory.dirac_frequency(), run_settings(config, model).dt_s
    every = steps_per_sample(dt_s, period, settings.samples_per_period)
    config = config.replace(
        initial_state_file=str(workdir / "initial_state.csv"),
        duration=settings.reach * width / cone_slope(theory),
        dump_every=every,
    )
    recorded = record_waves(
        config,
        workdir / "run",
        block=max(1, round(settings.block_periods * period / (every * dt_s))),
        log=log,
        show_progress=show_progress,
    )
    return PacketRun(np.asarray(centre, float), width, recorded)


def _block_cone(theory: Lattice2D, run: PacketRun):
    """speed ↦ the cone's R at ``run``'s blocks for that slope, measured as the run measures it:
    R² averaged over each block's samples. R = σ F(v t/σ) (:mod:`hexdem.theory.conical`): F is
    integrated once, at 301 values of v t/σ up to twice the run's reach."""
    width, times = run.width_m, run.recorded.block_sample_times_s()
    v_d = cone_slope(theory)
    scaled = np.linspace(0.0, 2.0 * v_d * times.max() / width, 301)
    profile_squared = (cone_ring_radius(theory, width, scaled * width / v_d) / width) ** 2

    def radius(speed):
        return width * np.sqrt(np.mean(np.interp(speed * times / width, scaled, profile_squared), axis=1))

    return radius


def measure_conical(settings: ConicalSettings, workdir, log=None, show_progress: bool = True) -> Conical:
    """Run both packets of the module docstring in ``workdir`` and measure them."""
    workdir = Path(workdir)
    theory, config = settings.theory(), settings.config()
    model = build_model(config)
    centre = model.packing.positions_m.mean(axis=0)
    k_point = theory.high_symmetry_points()["K"]
    dirac = _run_packet(
        settings,
        config,
        model,
        workdir / "dirac",
        k_point,
        CIRCULAR,
        theory.dirac_frequency(),
        centre,
        log,
        show_progress,
    )
    measured = dirac.ring_radius_m()
    v_d = cone_slope(theory)
    cone = _block_cone(theory, dirac)
    fitted = minimize_scalar(
        lambda speed: float(np.sum((cone(speed) - measured) ** 2)),
        bounds=(0.5 * v_d, 1.5 * v_d),
        method="bounded",
        options={"xatol": 1e-6 * v_d},
    ).x
    q = settings.control_wave_vector()
    omega2, vectors = np.linalg.eigh(dynamical_matrix(theory, q))
    velocity = group_velocity(theory, q, 0)
    duration = settings.reach * dirac.width_m / v_d
    control = _run_packet(
        settings,
        config,
        model,
        workdir / "control",
        q,
        vectors[:, 0],
        math.sqrt(omega2[0]),
        centre - velocity * duration / 2,
        log,
        show_progress,
    )
    centroids = energy_centroid(control.recorded.positions_m, control.recorded.block_kinetic_j)
    drift = np.polyfit(control.times_s, centroids, 1)[0]
    spread = energy_spread(control.recorded.positions_m, control.recorded.block_kinetic_j, centroids)
    return Conical(dirac, control, cone(v_d), v_d, float(fitted), velocity, drift, spread, config.diameter_m, settings)
