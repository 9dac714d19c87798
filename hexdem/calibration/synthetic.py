"""Synthetic experiments: accelerometer records of a known truth, as a lab would record them.

A record is the run of a configuration at a time step ``finer`` times shorter than a
calibration's runs take, its sensors' accelerations sampled at their rate (500 kS/s, the paper's
acquisition), after a quiet pre-trigger lead-in, with white accelerometer noise and an unknown
clock offset. A calibration given such records does not fit a model to its own output: its runs
integrate at another step and sample at other instants. A record of a disordered packing is
struck on a packing prepared as a calibration prepares its own
(:mod:`~hexdem.calibration.packings`), from a seed of its own. A record may also differ from the
model as the calibration's discrepancy term says a real one may
(:class:`~hexdem.calibration.nuisance.Discrepancy`): each sensor's peak and arrival off by a
relative error of its own.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from hexdem.calibration.observables import ACCELERATION_UNITS, MEASURED_COLUMNS, pulses
from hexdem.calibration.simulations import disordered_impact
from hexdem.common.io import write_csv
from hexdem.common.progress import silenced
from hexdem.model.config import RunConfig

#: The pre-trigger lead-in a record keeps before the impact [s].
LEAD_IN_S = 100e-6


@dataclass(frozen=True)
class LabFaults:
    """What a lab's acquisition does to a record that the calibration does not model, for the
    coverage study's misspecified arm: the samples taken ``sample_phase`` (0 to 1) of a sampling
    interval off the simulation's instants (the runs are sampled on their own clock); each sensor's
    channels ``skew_s`` (n_sensors,) late (a multiplexed card's trigger); each axis's own gain
    ``axis_gains`` (n_sensors, 2), where the calibration models one gain a sensor; noise coloured
    as a first-order autoregression of coefficient ``noise_memory`` at the channel's level; and a
    slow drift of each channel, ``drift_m_s2`` (n_sensors, 2) over the record."""

    sample_phase: float
    skew_s: np.ndarray
    axis_gains: np.ndarray
    noise_memory: float
    drift_m_s2: np.ndarray

    @classmethod
    def drawn(cls, sensors: int, rng) -> LabFaults:
        """Faults of the sizes a lab's acquisition has: a phase uniform in [0, 1), skews uniform in
        ±1 µs, axis gains N(1, 0.02), noise memory uniform in [0.5, 0.9], drifts uniform in ±2 m/s²."""
        return cls(
            float(rng.random()),
            rng.uniform(-1e-6, 1e-6, sensors),
            1 + 0.02 * rng.standard_normal((sensors, 2)),
            float(rng.uniform(0.5, 0.9)),
            rng.uniform(-2.0, 2.0, (sensors, 2)),
        )

    def resampled(self, times, accelerations, interval: float) -> np.ndarray:
        """``accelerations`` (K, n_sensors, 2) sampled at ``times`` (K,), as the lab samples them: each
        sensor at times + (phase × ``interval``) + its skew, the cubic spline through the samples
        (zero before the first), times each axis's gain."""
        return sampled_at(times, accelerations, self.sample_phase * interval + self.skew_s) * self.axis_gains[None]

    def recorded(self, accelerations, level, rng) -> np.ndarray:
        """``accelerations`` (K, n_sensors, 2) with noise of each channel's ``level`` (n_sensors, 2),
        coloured (unit variance per sample, each sample ``noise_memory`` of the one before), and the drift."""
        white = rng.standard_normal(accelerations.shape)
        coloured = np.empty_like(white)
        coloured[0] = white[0]
        memory = self.noise_memory
        for k in range(1, len(white)):
            coloured[k] = memory * coloured[k - 1] + np.sqrt(1 - memory**2) * white[k]
        ramp = np.linspace(0.0, 1.0, len(accelerations))[:, None, None]
        return accelerations + level * coloured + ramp * self.drift_m_s2


def synthetic_rows(
    config: RunConfig,
    record: str,
    noise_m_s2,
    offset_s: float,
    rng,
    finer: int = 2,
    disorder: tuple[float, int, int] | None = None,
    packings=None,
    gains=None,
    offsets_m_s2=None,
    lead_in_s: float = LEAD_IN_S,
    model_error=None,
    faults: LabFaults | None = None,
) -> list:
    """Rows ``sensor,time,ax,ay,record`` of one synthetic record of ``config``: on the ideal
    lattice, or with ``disorder`` = (σ [m], seed, k) on that packing, settled in (or read from)
    the folder ``packings``. As a lab's instruments record it: ``noise_m_s2``, white noise of one
    level or of one per channel (n_sensors, 2); ``gains`` (n_sensors,), each sensor's sensitivity
    over its nominal one; ``offsets_m_s2`` (n_sensors, 2), each channel's DC offset; a pre-trigger
    lead-in of ``lead_in_s``. ``model_error`` (n_sensors, 2): the relative errors of the model's
    observables that the record holds (:func:`model_error_applied`). ``faults``: what a lab's
    acquisition does that the calibration does not model (:class:`LabFaults`)."""
    from hexdem.experiments.run import simulate

    fine = config.replace(steps_per_contact=config.steps_per_contact * finer)
    with tempfile.TemporaryDirectory() as workdir, silenced():
        analysis = (
            simulate(fine, workdir)
            if disorder is None
            else disordered_impact(
                fine, *disorder, Path(workdir) / "deck", Path(packings or Path(workdir) / "packings")
            )
        )
    units, tracked = analysis.settings.units, analysis.tracked
    times = tracked.sensor_times * units.time_s
    accelerations = tracked.sensor_states[:, :, 2:4] * (units.length_m / units.time_s**2)
    if model_error is not None:
        accelerations = model_error_applied(times, accelerations, model_error)
    interval = 1.0 / config.sensor_rate_hz
    if faults is not None:
        accelerations = faults.resampled(times, accelerations, interval)
    lead = np.arange(-round(lead_in_s / interval), 0) * interval
    times = np.concatenate([lead, times]) + offset_s
    accelerations = np.concatenate([np.zeros((len(lead), *accelerations.shape[1:])), accelerations])
    if gains is not None:
        accelerations = accelerations * np.asarray(gains, float)[None, :, None]
    level = np.broadcast_to(np.asarray(noise_m_s2, float), accelerations.shape[1:])
    if faults is None:
        accelerations = accelerations + level * rng.standard_normal(accelerations.shape)
    else:
        accelerations = faults.recorded(accelerations, level, rng)
    if offsets_m_s2 is not None:
        accelerations = accelerations + np.asarray(offsets_m_s2, float)
    return [
        (str(sensor), float(t), float(a[s, 0]), float(a[s, 1]), record)
        for s, sensor in enumerate(config.sensors)
        for t, a in zip(times, accelerations)
    ]


def model_error_applied(times, accelerations, model_error) -> np.ndarray:
    """The noise-free ``accelerations`` (K, n_sensors, 2), sampled at ``times`` (K,) [s], as they
    would be if the model erred by the relative ``model_error`` (n_sensors, 2) of the discrepancy
    term: sensor i's peak speed times exp(``model_error[i, 0]``), its arrival after the first
    sensor's, t_i, later by ``model_error[i, 1]`` t_i (the first sensor's arrival is the reference:
    its column is unused). The delayed signal is the cubic spline through its samples, zero before
    the first."""
    model_error = np.asarray(model_error, float)
    arrivals = pulses(times, accelerations.transpose(1, 0, 2))[1]
    delays = np.nan_to_num(model_error[:, 1] * (arrivals - arrivals[0]))  # a sensor without a pulse: none
    return sampled_at(times, accelerations, -delays) * np.exp(model_error[:, 0])[None, :, None]


def sampled_at(times, accelerations, offsets_s) -> np.ndarray:
    """``accelerations`` (K, n_sensors, 2), sampled at ``times`` (K,) [s], at times + ``offsets_s[i]``
    for each sensor i: the cubic spline through its samples, zero outside them."""
    from scipy.interpolate import CubicSpline

    shifted = np.empty_like(accelerations)
    for sensor, offset in enumerate(offsets_s):
        spline = CubicSpline(times, accelerations[:, sensor], axis=0, extrapolate=False)
        shifted[:, sensor] = np.nan_to_num(spline(times + offset))
    return shifted


def write_measured(path, rows, unit: str = "m/s2", single_axis: bool = False) -> None:
    """A measured file of ``rows`` (:func:`synthetic_rows`), as ``hexdem calibrate`` reads it: its
    accelerations in ``unit`` (:data:`~hexdem.calibration.observables.ACCELERATION_UNITS`), and
    without the ``ay`` column if ``single_axis``."""
    scale = ACCELERATION_UNITS[unit]
    rows = [(sensor, t, ax / scale, ay / scale, record) for sensor, t, ax, ay, record in rows]
    if single_axis:
        write_csv(path, ("sensor", "time", "ax", "record"), [(s, t, ax, r) for s, t, ax, _, r in rows])
    else:
        write_csv(path, (*MEASURED_COLUMNS, "record"), rows)
