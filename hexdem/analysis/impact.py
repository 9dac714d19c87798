"""The paper's observables of one impact: per-bead pulses, observation lines, energy audit.

An :class:`ImpactAnalysis` holds one run's ``model``, ``settings``, ``engine`` description
and ``results`` (in the run's unit system, SI or the paper's A = d = M = 1). It is made
either from the tracker that followed the run (:meth:`ImpactAnalysis.from_tracker`,
hexdem's own runs) or from a whole trajectory (:meth:`ImpactAnalysis.from_trajectory`, a
dump read back from disk), with the same definitions (:mod:`hexdem.analysis.peaks`).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hexdem.analysis.energy import energy_regions
from hexdem.analysis.peaks import pulse_times
from hexdem.analysis.tracker import ENERGY_SAMPLES, TrackedPulses, run_noise_floor
from hexdem.analysis.trajectory import Trajectory
from hexdem.errors import HexdemError
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.walls import wall_normals

#: Columns of ``peaks.csv`` (a contract: scripts read them by name).
#: A wall bead faces the strike when its inward normal points against it at least cos 30° as
#: much as the most-facing wall bead's (a disc's far arc of ±30°; a hexagon's far wall alone).
FAR_WALL_COSINE = np.cos(np.radians(30.0))
PEAK_COLUMNS = ("line", "n", "bead_id", "x", "y", "peak_speed", "t_peak", "arrival_time")


class ImpactAnalysis:
    """Peaks, times of peak and arrival times of every bead, and the energy drift.

    ``results``: ``units``, ``length_unit_m``, ``positions`` (N, 2), ``peak_speed``, ``t_peak``,
    ``arrival_time``, ``reach_time`` (N,), ``lines`` {name: bead indices}, ``energy_drift``,
    ``far_wall_reached``, ``end_velocity`` (N, 2) each bead's velocity at the last sample, ``region_names``,
    ``region_times`` (T,) and ``region_energies`` (T, R, 2)
    [J] (:func:`~hexdem.analysis.energy.energy_regions`), ``peak_angular_speed`` (N,) each bead's
    largest |ω_z| and ``rotational_energy_fraction`` the largest share of the energy held in
    rotation (0 for spheres that do not turn; NaN for a frictional run read from a dump, which
    holds no spins). ``tracked``: the :class:`TrackedPulses` (traces, fields) of a tracked run,
    else None.
    """

    def __init__(
        self,
        model: GranularModel,
        settings: RunSettings,
        engine: dict,
        peak_speed,
        t_peak,
        arrival_time,
        reach_time,
        energy_drift: float,
        region_energies,
        end_velocity,
        tracked: TrackedPulses | None = None,
    ):
        self.model, self.settings, self.engine, self.tracked = model, settings, engine, tracked
        units = settings.units
        self.results = r = SimpleNamespace()
        r.units = units.name
        r.length_unit_m = units.length_m
        r.positions = model.initial_positions_m()[: len(model.packing)] / units.length_m  # where the beads start
        r.peak_speed, r.t_peak, r.arrival_time, r.reach_time = peak_speed, t_peak, arrival_time, reach_time
        r.end_velocity = np.asarray(end_velocity, float)
        r.lines = model.packing.lines()
        r.energy_drift = energy_drift
        r.region_names = energy_regions(model)[0]
        r.region_times, r.region_energies = region_energies
        r.far_wall_reached = self._far_wall_reached()
        unknown = np.nan if model.laws.tangential else 0.0  # (without a tracker: read from a dump)
        r.peak_angular_speed = np.full(len(peak_speed), unknown) if tracked is None else tracked.peak_angular_speed
        r.rotational_energy_fraction = unknown if tracked is None else tracked.rotational_energy_fraction

    @classmethod
    def from_tracker(
        cls, model: GranularModel, settings: RunSettings, tracked: TrackedPulses, engine: dict
    ) -> ImpactAnalysis:
        return cls(
            model,
            settings,
            engine,
            tracked.peak_speed,
            tracked.t_peak,
            tracked.arrival_time,
            tracked.reach_time,
            tracked.energy_drift,
            (tracked.energy_times, tracked.region_energies),
            tracked.end_velocity,
            tracked,
        )

    @classmethod
    def from_trajectory(cls, model: GranularModel, settings: RunSettings, trajectory: Trajectory) -> ImpactAnalysis:
        units = settings.units
        pulses = pulse_times(
            trajectory.times_s / units.time_s,
            trajectory.speeds_m_s[:, : len(model.packing)] / units.velocity_m_s,
            run_noise_floor(model, settings),
        )
        times_s, energies = trajectory.region_energies_j(model, ENERGY_SAMPLES)
        return cls(
            model,
            settings,
            trajectory.engine,
            pulses.peak_speed,
            pulses.t_peak,
            pulses.arrival_time,
            pulses.reach_time,
            trajectory.energy_drift(model),
            (times_s / units.time_s, energies),
            trajectory.velocities_m_s[-1, : len(model.packing)] / units.velocity_m_s,
        )

    def _far_wall_reached(self) -> bool:
        """Did the leading waves cross the packing within the run? They did when every bead they
        set moving at the walls facing the strikes was passed by its front, and at least one was.

        For each impact, the beads at the walls facing it are those whose inward normal points
        against its direction within 30° as much as the most-facing one's does (the far wall of a
        hexagon, both far walls of a triangle, the far arc of a disc; a double strike's two far
        walls); without such a wall (no walls, or only the struck edge's) every bead counts.
        Beads that never moved (their speed never rose above the noise floor,
        :func:`~hexdem.analysis.peaks.noise_floor`) do not count: no wave reaches a square
        crystal's other rows, nor a packing's rattlers, however long the run. A bead counts as
        passed when its speed rose to half of its largest value at least one impact time scale
        (``settings.contact_time_s``) before the run ended: a bead still on its first rise at the
        end has not been passed by the front, while one whose speed keeps growing under
        reflections (a precompressed box rings) has."""
        r = self.results
        members, normals = wall_normals(self.model.walls, self.model.packing.positions_m)
        facing = []
        for impact in self.model.impacts:
            against = -normals @ impact.direction
            if not (len(against) and against.max() > 1e-9):
                facing = [np.arange(len(r.reach_time))]
                break
            facing.append(members[against >= against.max() * FAR_WALL_COSINE - 1e-9])
        beads = np.unique(np.concatenate(facing))
        beads = beads[r.peak_speed[beads] != 0.0]  # (NaN: still rising, it moved)
        units = self.settings.units
        latest = (self.settings.duration_s - self.settings.contact_time_s) / units.time_s
        return bool(len(beads)) and bool(np.all(r.reach_time[beads] <= latest))

    def line_trace(self, line: str) -> tuple[np.ndarray, np.ndarray]:
        """(times (S,), speeds (S, L)) of the beads of observation ``line`` at every sample, in
        the run's units; the run must have traced them (``trace_lines`` of ``simulate``)."""
        beads = self.results.lines[line]
        traced = {} if self.tracked is None else {int(b): k for k, b in enumerate(self.tracked.trace_beads)}
        if not all(int(b) in traced for b in beads):
            raise HexdemError(f"line {line} was not traced in this run; pass trace_lines=[{line!r}]")
        return self.tracked.trace_times, self.tracked.trace_speeds[:, [traced[int(b)] for b in beads]]

    @property
    def v0(self) -> float:
        """The fastest impact's speed in the run's units: the scale of the run's peaks."""
        return max(impact.speed_m_s for impact in self.model.impacts) / self.settings.units.velocity_m_s

    def line_rows(self) -> list[tuple]:
        """Rows of ``peaks.csv``: one per bead on each observation line (the paper's three first,
        then the extra ones), n from 0."""
        r = self.results
        rows = []
        for name, beads in r.lines.items():
            for n, bead in enumerate(beads):
                rows.append(
                    (
                        name,
                        n,
                        int(bead) + 1,
                        *(float(v) for v in r.positions[bead]),
                        float(r.peak_speed[bead]),
                        float(r.t_peak[bead]),
                        float(r.arrival_time[bead]),
                    )
                )
        return rows
