"""Sensor particles as in the experiment (Secs. II and IV): what their accelerometers record.

The paper's sensors are beads with a triaxial accelerometer inside, sampled at 500 kS/s;
t = 0 of its arrival times is the first sensor's arrival. A run with ``sensors`` records,
for each of them, velocity and acceleration (total force / mass) at ``sensor_rate_hz``
(:class:`~hexdem.analysis.tracker.PulseTracker`), and writes, in SI:

* ``sensors.csv``: ``sensor,bead_id,time,vx,vy,ax,ay`` at every sensor sample;
* ``sensor_peaks.csv``: ``sensor,bead_id,peak_speed,peak_accel,arrival_time,relative_arrival_time``,
  the relative arrival measured from the first listed sensor's, as the experiments define t = 0.
"""

from __future__ import annotations

import numpy as np

from hexdem.analysis.impact import ImpactAnalysis
from hexdem.common.io import write_csv

SENSOR_COLUMNS = ("sensor", "bead_id", "time", "vx", "vy", "ax", "ay")
SENSOR_PEAK_COLUMNS = ("sensor", "bead_id", "peak_speed", "peak_accel", "arrival_time", "relative_arrival_time")


def _si_states(analysis: ImpactAnalysis) -> tuple[np.ndarray, np.ndarray]:
    """(times [s] (K,), states (K, n_sensors, 4) in m/s and m/s²) of the sensor record."""
    units, tracked = analysis.settings.units, analysis.tracked
    scale = np.array([units.velocity_m_s] * 2 + [units.length_m / units.time_s**2] * 2)
    return tracked.sensor_times * units.time_s, tracked.sensor_states * scale


def sensor_rows(analysis: ImpactAnalysis, labels) -> list[tuple]:
    """Rows of ``sensors.csv`` for the sensors ``labels`` (in the order of the model's sensor beads)."""
    times, states = _si_states(analysis)
    beads = analysis.model.sensor_beads
    return [
        (label, bead + 1, float(t), *(float(v) for v in states[k, s]))
        for s, (label, bead) in enumerate(zip(labels, beads))
        for k, t in enumerate(times)
    ]


def sensor_peak_rows(analysis: ImpactAnalysis, labels) -> list[tuple]:
    """Rows of ``sensor_peaks.csv``: peak speed, peak |acceleration|, arrival, arrival − first sensor's."""
    units, r = analysis.settings.units, analysis.results
    _, states = _si_states(analysis)
    arrivals = [float(r.arrival_time[b] * units.time_s) for b in analysis.model.sensor_beads]
    rows = []
    for s, (label, bead) in enumerate(zip(labels, analysis.model.sensor_beads)):
        accel = float(np.nanmax(np.hypot(states[:, s, 2], states[:, s, 3])))
        rows.append(
            (
                label,
                bead + 1,
                float(r.peak_speed[bead] * units.velocity_m_s),
                accel,
                arrivals[s],
                arrivals[s] - arrivals[0],
            )
        )
    return rows


def write_sensor_files(analysis: ImpactAnalysis, labels, out) -> None:
    write_csv(out / "sensors.csv", SENSOR_COLUMNS, sensor_rows(analysis, labels))
    write_csv(out / "sensor_peaks.csv", SENSOR_PEAK_COLUMNS, sensor_peak_rows(analysis, labels))
