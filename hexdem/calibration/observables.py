"""What a calibration compares: each record reduced to the pulse at its sensors.

A record is one impact seen by the configuration's sensors. Measured and simulated records are
reduced alike, as ``hexdem signals`` reduces a measured one
(:mod:`~hexdem.experiments.signals`): each sensor's acceleration, its offset removed, is
integrated to velocity, and the speed gives a peak and a half-maximum arrival. A record becomes
the vector of :func:`observation_names`: the log of each sensor's peak speed, and each later
sensor's arrival relative to the first sensor's [µs]. The relative arrivals carry no clock, so
the experiment's unknown time offset drops out, as the paper's Fig. 8 takes t = 0 at the first
sensor.

**Noise.** A measured record's observables are uncertain through its accelerometer noise. That
noise is measured on the record itself, on the samples before the pulse reaches its first sensor
(the quiet lead-in that a triggered acquisition keeps: up to :data:`FOOT_SAMPLES` before its
acceleration first reaches :data:`FOOT_LEVEL` of its peak), as the median absolute deviation
× 1.4826 (the standard deviation of white noise, and blind to the pulse's foot if a few of its
samples are in the window). Its effect is found by a parametric bootstrap: :data:`BOOTSTRAP_DRAWS` copies of the record, each
with fresh white noise of that level added, reduced as the record is. The spread of their
observables is the noise covariance of the record's observables.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError
from hexdem.experiments.signals import BASELINE_SAMPLES, integrate_velocity, pulse

MEASURED_COLUMNS = ("sensor", "time", "ax", "ay")
#: Noisy copies of a record whose reduced observables give its noise covariance: enough that the
#: estimate's own scatter does not make the likelihood overconfident (with 64, the posterior's spread
#: along the parameters was 1.2 times the one it claimed; docs/validation/benchmarks.md).
BOOTSTRAP_DRAWS = 400
#: The pulse's foot: where the first sensor's acceleration first reaches this share of its peak.
FOOT_LEVEL = 0.1
#: Samples before the foot kept out of the quiet lead-in.
FOOT_SAMPLES = 10
#: A sensor's largest acceleration over the noise below which its record holds no pulse.
MIN_SIGNAL_TO_NOISE = 10.0
#: The median absolute deviation of white Gaussian noise times this is its standard deviation.
MAD_TO_SD = 1.4826
#: Arrivals are in µs, so that every observable is of order one.
ARRIVAL_UNIT_S = 1e-6


@dataclass(frozen=True)
class Record:
    """One impact as its sensors saw it: ``times`` [s] (K,) and ``accelerations`` [m/s²]
    (n_sensors, K, 2), the sensors in the configuration's order."""

    name: str
    times: np.ndarray
    accelerations: np.ndarray


def observation_names(sensors) -> list[str]:
    """Names of the observables of a record of ``sensors``: ``log_peak:S`` then ``arrival:S``."""
    return [f"log_peak:{s}" for s in sensors] + [f"arrival:{s}" for s in sensors[1:]]


def reduce_record(times, accelerations) -> np.ndarray:
    """The observables of one record: log peak speeds [ln(m/s)], then arrivals relative to the
    first sensor's [µs]."""
    peaks, arrivals = [], []
    for channel in accelerations:
        vx, vy = integrate_velocity(times, channel[:, 0], channel[:, 1])
        peak, arrival = pulse(times, vx, vy)
        peaks.append(peak)
        arrivals.append(arrival)
    if not (np.all(np.isfinite(arrivals)) and np.all(np.asarray(peaks) > 0)):
        raise HexdemError("no rising pulse at every sensor: is the record long enough?")
    relative = (np.asarray(arrivals[1:]) - arrivals[0]) / ARRIVAL_UNIT_S
    return np.concatenate([np.log(peaks), relative])


def at_rest_before(times, accelerations) -> tuple[np.ndarray, np.ndarray]:
    """A simulated record (``times`` (K,), ``accelerations`` (n, K, 2)), which starts at the impact,
    preceded by :data:`~hexdem.experiments.signals.BASELINE_SAMPLES` samples at rest: the offset
    removal then reads the sensors at rest, as it reads a measured record's lead-in, and not the
    first sensor's pulse, which starts within a few samples of the impact."""
    interval = times[1] - times[0]
    lead = times[0] - interval * np.arange(BASELINE_SAMPLES, 0, -1)
    rest = np.zeros((accelerations.shape[0], BASELINE_SAMPLES, accelerations.shape[2]))
    return np.concatenate([lead, times]), np.concatenate([rest, accelerations], axis=1)


def lead_in(record: Record) -> int:
    """Samples of ``record`` before the pulse's foot at its first sensor (its quiet lead-in)."""
    magnitude = np.hypot(*record.accelerations[0].T)
    return int(np.argmax(magnitude >= FOOT_LEVEL * magnitude.max())) - FOOT_SAMPLES


def noise_covariance(record: Record, sensors, seed: int) -> tuple[np.ndarray, float]:
    """(covariance of the record's observables under its own accelerometer noise, that noise's
    standard deviation [m/s²]), by the parametric bootstrap described above; a sensor (of
    ``sensors``, the record's) whose largest acceleration is not :data:`MIN_SIGNAL_TO_NOISE`
    times the noise holds no pulse and is refused."""
    quiet = lead_in(record)
    if quiet < BASELINE_SAMPLES:
        raise HexdemError(f"it starts {max(quiet, 0)} samples before the pulse's foot at its first "
                          f"sensor; a calibration needs at least {BASELINE_SAMPLES} quiet samples to measure the "
                          "accelerometer's noise")
    quiet_samples = record.accelerations[:, :quiet, :]
    noise = float(MAD_TO_SD * np.median(np.abs(quiet_samples - np.median(quiet_samples))))
    for sensor, channel in zip(sensors, record.accelerations):
        peak = float(np.max(np.hypot(channel[:, 0], channel[:, 1])))
        if peak < MIN_SIGNAL_TO_NOISE * noise:
            raise HexdemError(f"sensor {sensor} shows no pulse above the accelerometer's noise "
                              f"(largest {peak:.3g} m/s², noise {noise:.3g} m/s² rms): is the record long enough to "
                              "hold its pulse?")
    rng = np.random.default_rng(seed)
    draws = np.array([reduce_record(record.times, record.accelerations + rng.normal(0, noise, record.accelerations.shape))
                      for _ in range(BOOTSTRAP_DRAWS)])
    return np.cov(draws, rowvar=False), noise


def read_measured(path, sensors) -> list[Record]:
    """The records of the measured file ``path`` (columns ``sensor,time,ax,ay`` and an optional
    ``record``), each holding exactly ``sensors`` sampled at the same increasing times."""
    try:
        with open(path, newline="") as fh:
            reader = csv.DictReader(fh)
            columns = reader.fieldnames or ()
            missing = [c for c in MEASURED_COLUMNS if c not in columns]
            if missing:
                raise HexdemError(f"{path} lacks the column(s) {', '.join(missing)}; expected "
                                  f"{','.join(MEASURED_COLUMNS)} and optionally record")
            grouped: dict[str, dict[str, list]] = {}
            for line, row in enumerate(reader, start=2):
                try:
                    values = [float(row[c]) for c in MEASURED_COLUMNS[1:]]
                except (TypeError, ValueError):
                    raise HexdemError(f"{path}, line {line}: a value that is not a number") from None
                if not np.all(np.isfinite(values)):
                    raise HexdemError(f"{path}, line {line}: a value that is NaN or infinite")
                grouped.setdefault(row.get("record") or "0", {}).setdefault(row["sensor"], []).append(values)
    except OSError as exc:
        raise HexdemError(f"cannot read {path}: {exc.strerror}") from None
    if not grouped:
        raise HexdemError(f"{path} holds no measured samples")
    return [_record(path, name, channels, [str(s) for s in sensors]) for name, channels in grouped.items()]


def _record(path, name: str, channels: dict, sensors: list[str]) -> Record:
    """One record's channels checked against the configuration's ``sensors``."""
    extra = [s for s in channels if s not in sensors]
    if extra:
        raise HexdemError(f"{path}, record {name}: sensor(s) {', '.join(extra)} are not among the configuration's "
                          f"sensors ({', '.join(sensors) or 'none'})")
    lacking = [s for s in sensors if s not in channels]
    if lacking:
        raise HexdemError(f"{path}, record {name}: the configuration's sensor(s) {', '.join(lacking)} were not "
                          "measured; list only measured sensors in the configuration's sensors")
    arrays = [np.array(channels[s]) for s in sensors]
    for sensor, array in zip(sensors, arrays):
        if np.any(np.diff(array[:, 0]) <= 0):
            raise HexdemError(f"{path}, record {name}: the times of sensor {sensor} do not increase")
    times = arrays[0][:, 0]
    if any(len(a) != len(times) or not np.array_equal(a[:, 0], times) for a in arrays):
        raise HexdemError(f"{path}, record {name}: the sensors are not sampled at the same times")
    if len(times) < 4 * BASELINE_SAMPLES:
        raise HexdemError(f"{path}, record {name}: {len(times)} samples are too few to hold a pulse "
                          f"(at least {4 * BASELINE_SAMPLES})")
    return Record(name, times, np.stack([a[:, 1:] for a in arrays]))
