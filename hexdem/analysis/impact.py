"""From a trajectory to the paper's observables: per-bead pulses, lines, energy audit.

:class:`ImpactAnalysis` follows MDAnalysis's run → results shape: construct it with the
model and the trajectory, call :meth:`run`, read ``results``. Values are reported in the
run's unit system (SI by default, or the paper's A = d = M = 1).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from hexdem.analysis.peaks import pulse_times
from hexdem.analysis.trajectory import Trajectory
from hexdem.model.granular import GranularModel, RunSettings
from hexdem.model.lattice import LINE_STEPS

#: Columns of ``peaks.csv`` (a contract: scripts read them by name).
PEAK_COLUMNS = ("line", "n", "bead_id", "x", "y", "peak_speed", "t_peak", "arrival_time")


class ImpactAnalysis:
    """Peaks, times of peak and arrival times of every bead, and the energy drift."""

    def __init__(self, model: GranularModel, settings: RunSettings, trajectory: Trajectory):
        self.model, self.settings, self.trajectory = model, settings, trajectory
        self.results = SimpleNamespace()

    def run(self) -> "ImpactAnalysis":
        units = self.settings.units
        n_beads = len(self.model.lattice)
        pulses = pulse_times(self.trajectory.times_s / units.time_s,
                             self.trajectory.speeds_m_s[:, :n_beads] / units.velocity_m_s)
        r = self.results
        r.units = units.name
        r.length_unit_m = units.length_m
        r.positions = self.model.lattice.positions_m / units.length_m
        r.peak_speed, r.t_peak, r.arrival_time = pulses.peak_speed, pulses.t_peak, pulses.arrival_time
        r.lines = self.model.lattice.lines()
        r.energy_drift = self.trajectory.energy_drift(self.model)
        r.far_wall_reached = self._far_wall_reached()
        return self

    def _far_wall_reached(self) -> bool:
        """Did the leading wave reach (and pass) every bead at the wall facing the strike?"""
        if not self.model.walls:
            return bool(np.all(np.isfinite(self.results.arrival_time)))
        far = min(self.model.walls, key=lambda wall: float(np.dot(wall.normal, self.model.impact.direction)))
        return bool(np.all(np.isfinite(self.results.arrival_time[far.members])))

    def line_rows(self) -> list[tuple]:
        """Rows of ``peaks.csv``: one per bead on each observation line, n from 0."""
        r = self.results
        rows = []
        for name in LINE_STEPS:
            for n, bead in enumerate(r.lines[name]):
                rows.append((name, n, int(bead) + 1, *(float(v) for v in r.positions[bead]),
                             float(r.peak_speed[bead]), float(r.t_peak[bead]), float(r.arrival_time[bead])))
        return rows
