"""What a calibration compares: each record reduced to the pulse at its sensors.

A record is one impact seen by the configuration's sensors. Measured and simulated records are
reduced alike, as ``hexdem signals`` reduces a measured one
(:mod:`~hexdem.experiments.signals`): each sensor's acceleration, its offset removed, is
integrated to velocity, and the speed gives a peak and a half-maximum arrival. A record becomes
the vector of :func:`observation_names`: the log of each sensor's peak speed, and each later
sensor's arrival relative to the first sensor's [µs]. The relative arrivals carry no clock, so
the experiment's unknown time offset drops out, as the paper's Fig. 8 takes t = 0 at the first
sensor.

**The instruments.** A record is read as a lab writes it: in m/s², or in g
(``--acceleration-unit g``); with both axes of a tri-axial sensor, or one (a file without an
``ay`` column, or an axis whose channel is exactly constant: that axis is left out of the record,
and the simulations' records are reduced with the same axes, so that like is compared with like).
Every record must be sampled at one steady rate (the simulations then sample at it).

**Noise.** A measured record's observables are uncertain through its accelerometer noise. That
noise is measured channel by channel on the record itself, on the samples before the pulse
reaches any sensor (the quiet lead-in that a triggered acquisition keeps: up to
:data:`FOOT_SAMPLES` before a sensor's acceleration first reaches :data:`FOOT_LEVEL` of its peak,
:func:`lead_in`), as the
median absolute deviation of the channel about its own median × 1.4826 (the standard deviation of
white noise, blind to each channel's own offset and to the pulse's foot if a few of its samples
are in the window). A lead-in that is not at rest, whose second half departs from its first by
more than :data:`REST_TOLERANCE` standard errors (the pulse has begun: a record triggered late),
is refused, for the offset removal would take the pulse's foot for the sensor's offset. The
noise's effect is found by a parametric bootstrap: :data:`BOOTSTRAP_DRAWS` copies of the record,
each with fresh white noise of each channel's level added, reduced as the record is. The spread
of their observables is the noise covariance of the record's observables.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass

import numpy as np

from hexdem.errors import HexdemError
from hexdem.experiments.signals import BASELINE_SAMPLES, integrate_velocity, pulse

MEASURED_COLUMNS = ("sensor", "time", "ax", "ay")
#: The columns a measured file must have (``ay`` is absent for single-axis sensors; ``record`` optional).
REQUIRED_COLUMNS = ("sensor", "time", "ax")
#: Standard gravity [m/s²], by which records in g are read.
STANDARD_GRAVITY_M_S2 = 9.80665
#: The acceleration units a measured file may be in (``--acceleration-unit``) → their value in m/s².
ACCELERATION_UNITS = {"m/s2": 1.0, "g": STANDARD_GRAVITY_M_S2}
#: The largest relative difference between two sampling intervals of a steadily sampled record.
STEADY_RATE_RTOL = 0.01
#: Standard errors by which the second half of a lead-in may differ from its first while at rest.
REST_TOLERANCE = 6.0
#: Noisy copies of a record whose reduced observables give its noise covariance: enough that the
#: estimate's own scatter does not make the likelihood overconfident (docs/validation/benchmarks.md,
#: *Calibration from measurements*).
BOOTSTRAP_DRAWS = 400
#: The pulse's foot: where a sensor's acceleration first reaches this share of its peak.
FOOT_LEVEL = 0.1
#: Samples before the foot kept out of the quiet lead-in.
FOOT_SAMPLES = 10
#: Noise standard deviations that the foot of a weak pulse must reach (the magnitude of two axes of
#: white noise passes k of them with probability exp(−k²/2): 6 in one sample in 7 × 10⁷, and 4.8,
#: where 20 samples read the noise 20 % low, in one in 10⁵).
FOOT_NOISE = 6.0
#: A sensor's largest acceleration over the noise below which its record holds no pulse.
MIN_SIGNAL_TO_NOISE = 10.0
#: The median absolute deviation of white Gaussian noise times this is its standard deviation.
MAD_TO_SD = 1.4826
#: Arrivals are in µs, so that every observable is of order one.
ARRIVAL_UNIT_S = 1e-6


@dataclass(frozen=True)
class Record:
    """One impact as its sensors saw it: ``times`` [s] (K,) and ``accelerations`` [m/s²]
    (n_sensors, K, 2), the sensors in the configuration's order, and the ``axes`` (n_sensors, 2) of
    each sensor that were measured (an axis not measured holds zeros)."""

    name: str
    times: np.ndarray
    accelerations: np.ndarray
    axes: np.ndarray

    @property
    def rate_hz(self) -> float:
        """The sampling rate [Hz]."""
        return float(1.0 / np.median(np.diff(self.times)))


def observation_names(sensors) -> list[str]:
    """Names of the observables of a record of ``sensors``: ``log_peak:S`` then ``arrival:S``."""
    return [f"log_peak:{s}" for s in sensors] + [f"arrival:{s}" for s in sensors[1:]]


def pulses(times, accelerations) -> tuple[np.ndarray, np.ndarray]:
    """(peak speed [m/s], half-maximum arrival [s]) of each sensor's pulse (n,), its ``accelerations``
    (n, K, 2) at ``times`` (K,) [s] integrated to velocity (:mod:`hexdem.experiments.signals`); NaN
    arrival where a sensor holds no rising pulse."""
    found = [pulse(times, *integrate_velocity(times, channel[:, 0], channel[:, 1])) for channel in accelerations]
    peaks, arrivals = zip(*found)
    return np.asarray(peaks, float), np.asarray(arrivals, float)


def reduce_record(times, accelerations, axes=None) -> np.ndarray:
    """The observables of one record: log peak speeds [ln(m/s)], then arrivals relative to the
    first sensor's [µs]; with ``axes`` (n_sensors, 2), each sensor's speed from its measured axes
    alone."""
    if axes is not None:
        accelerations = np.asarray(accelerations) * np.asarray(axes, bool)[:, None, :]
    peaks, arrivals = pulses(times, accelerations)
    if not (np.all(np.isfinite(arrivals)) and np.all(peaks > 0)):
        raise HexdemError("no rising pulse at every sensor: is the record long enough?")
    relative = (arrivals[1:] - arrivals[0]) / ARRIVAL_UNIT_S
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


class NoPulse(HexdemError):
    """A record with a sensor that shows no pulse above its accelerometer's noise: on a disordered
    packing, one whose pulse took another path or waits at a gap (:func:`noise_covariance`)."""


def _centred(record: Record, sensor: int) -> np.ndarray:
    """Sensor ``sensor``'s measured axes of ``record`` less each channel's median over the record."""
    channel = record.accelerations[sensor][:, np.asarray(record.axes[sensor], bool)]
    return channel - np.median(channel, axis=0)


def lead_in(record: Record, sensors) -> int:
    """Samples of ``record`` (of ``sensors``) before the pulse's foot at the first sensor it reaches
    (its quiet lead-in; on a disordered packing the pulse may reach a later sensor first, by another
    path): a sensor's foot is where its acceleration, its offset removed, first reaches
    :data:`FOOT_LEVEL` of its peak, or :data:`FOOT_NOISE` times its noise where its pulse is so weak
    that the noise reaches that share. That noise is the standard deviation of the record's first
    2 × :data:`~hexdem.experiments.signals.BASELINE_SAMPLES` samples, quiet in any record with the
    lead-in a calibration needs: a median absolute deviation over the whole record would take a pulse
    that rings through a small packing's record for noise, and a sensor next to the impact for one
    without a pulse. A sensor whose peak is not :data:`MIN_SIGNAL_TO_NOISE` times that noise holds no
    pulse and has no foot (noise alone would give it one anywhere); a record in which no sensor has
    one is refused."""
    feet = []
    for sensor in range(len(record.accelerations)):
        centred = _centred(record, sensor)
        magnitude = np.sqrt(np.sum(centred**2, axis=1))
        noise = float(np.max(np.std(centred[: 2 * BASELINE_SAMPLES], axis=0)))
        if magnitude.max() >= MIN_SIGNAL_TO_NOISE * noise:
            feet.append(int(np.argmax(magnitude >= max(FOOT_LEVEL * magnitude.max(), FOOT_NOISE * noise))))
    if not feet:
        raise NoPulse(
            f"no sensor of {', '.join(sensors)} shows a pulse above the accelerometer's noise: is the "
            "record long enough to hold its pulse?"
        )
    return min(feet) - FOOT_SAMPLES


def noise_covariance(record: Record, sensors, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(covariance of the record's observables under its own accelerometer noise, each channel's
    noise standard deviation [m/s²] (n_sensors, 2), NaN where the axis was not measured), by the
    parametric bootstrap described above. A record without a quiet lead-in, a channel whose
    lead-in is exactly constant (its noise cannot be measured), and a sensor (of ``sensors``, the
    record's) whose largest acceleration is not :data:`MIN_SIGNAL_TO_NOISE` times its noise (it
    holds no pulse) are refused."""
    quiet = lead_in(record, sensors)
    if quiet < BASELINE_SAMPLES:
        raise HexdemError(
            f"it starts {max(quiet, 0)} samples before the pulse's foot at the first sensor it "
            f"reaches; a calibration needs at least {BASELINE_SAMPLES} quiet samples to measure the "
            "accelerometer's noise and offset (record with a pre-trigger lead-in)"
        )
    noise = np.full(record.axes.shape, np.nan)
    for (s, j), measured in np.ndenumerate(record.axes):
        if measured:
            noise[s, j] = _channel_noise(record.accelerations[s, :quiet, j], f"sensor {sensors[s]}'s {'xy'[j]} axis")
    for sensor, channel, levels in zip(sensors, record.accelerations, noise):
        peak = float(np.max(np.hypot(channel[:, 0], channel[:, 1])))
        level = float(np.nanmax(levels))
        if peak < MIN_SIGNAL_TO_NOISE * level:
            raise NoPulse(
                f"sensor {sensor} shows no pulse above the accelerometer's noise "
                f"(largest {peak:.3g} m/s², noise {level:.3g} m/s² rms): is the record long enough to "
                "hold its pulse?"
            )
    rng = np.random.default_rng(seed)
    scale = np.nan_to_num(noise)[:, None, :]
    draws = np.array(
        [
            reduce_record(
                record.times,
                record.accelerations + scale * rng.standard_normal(record.accelerations.shape),
                record.axes,
            )
            for _ in range(BOOTSTRAP_DRAWS)
        ]
    )
    return np.cov(draws, rowvar=False), noise


def _channel_noise(lead, name: str) -> float:
    """The noise standard deviation [m/s²] of one channel's ``lead``-in, which must be at rest."""
    centre = np.median(lead)
    noise = float(MAD_TO_SD * np.median(np.abs(lead - centre)))
    if noise == 0.0:
        noise = float(np.std(lead))
    if noise == 0.0:
        raise HexdemError(
            f"{name} is exactly constant over the lead-in: its noise cannot be measured "
            "(a channel constant over the whole record is left out)"
        )
    half = len(lead) // 2
    drift = abs(float(np.median(lead[half:]) - np.median(lead[:half])))
    standard_error = noise * np.sqrt(np.pi / 2) * np.sqrt(1 / half + 1 / (len(lead) - half))  # of two medians
    if drift > REST_TOLERANCE * standard_error:
        raise HexdemError(
            f"{name} is not at rest before the pulse (its lead-in drifts by {drift:.3g} m/s², "
            f"{drift / noise:.1f} times its noise): the record starts after the pulse has begun; a "
            f"calibration needs at least {BASELINE_SAMPLES} quiet samples before it (record with a "
            "pre-trigger lead-in)"
        )
    return noise


#: Bytes read at the start of a measured file to tell a binary file (one holding NUL) from a CSV.
BINARY_PROBE_BYTES = 8192


def read_measured(path, sensors, unit: str = "m/s2") -> list[Record]:
    """The records of the measured file ``path`` (columns ``sensor,time,ax``, optionally ``ay`` and
    ``record``; accelerations in ``unit``, one of :data:`ACCELERATION_UNITS`), each holding exactly
    ``sensors`` sampled at the same increasing times, at one steady rate shared by every record.
    An axis whose column is absent, or exactly constant in a record, is left out for its sensor."""
    if unit not in ACCELERATION_UNITS:
        raise HexdemError(f"--acceleration-unit {unit!r}: use one of {', '.join(ACCELERATION_UNITS)}")
    try:
        with open(path, "rb") as fh:
            if b"\0" in fh.read(BINARY_PROBE_BYTES):
                raise HexdemError(f"{path} is a binary file, not a CSV of measured samples")
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            columns = reader.fieldnames or ()
            missing = [c for c in REQUIRED_COLUMNS if c not in columns]
            if missing:
                raise HexdemError(
                    f"{path} lacks the column(s) {', '.join(missing)}; expected "
                    f"{','.join(MEASURED_COLUMNS)} (ay may be absent for single-axis sensors) and "
                    "optionally record"
                )
            present = [c for c in MEASURED_COLUMNS[1:] if c in columns]
            grouped: dict[str, dict[str, list]] = {}
            for line, row in enumerate(reader, start=2):
                try:
                    values = [float(row[c]) for c in present]
                except (TypeError, ValueError):
                    raise HexdemError(f"{path}, line {line}: a value that is not a number") from None
                if not np.all(np.isfinite(values)):
                    raise HexdemError(f"{path}, line {line}: a value that is NaN or infinite")
                grouped.setdefault(row.get("record") or "0", {}).setdefault(row["sensor"], []).append(
                    values + [0.0] * (3 - len(values))
                )
    except OSError as exc:
        raise HexdemError(f"cannot read {path}: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise HexdemError(f"{path} is not UTF-8 text: a binary file, or a CSV saved in another encoding") from None
    if not grouped:
        raise HexdemError(f"{path} holds no measured samples")
    scale = ACCELERATION_UNITS[unit]
    records = [
        _record(path, name, channels, [str(s) for s in sensors], scale, "ay" in present)
        for name, channels in grouped.items()
    ]
    rates = [record.rate_hz for record in records]
    if max(rates) > (1 + STEADY_RATE_RTOL) * min(rates):
        raise HexdemError(
            f"{path}: the records are sampled at different rates ({min(rates):.6g} to "
            f"{max(rates):.6g} Hz); calibrate records of one rate together"
        )
    return _common_axes(path, records, [str(s) for s in sensors])


def _record(path, name: str, channels: dict, sensors: list[str], scale: float, has_y: bool) -> Record:
    """One record's channels checked against the configuration's ``sensors``."""
    extra = [s for s in channels if s not in sensors]
    if extra:
        raise HexdemError(
            f"{path}, record {name}: sensor(s) {', '.join(extra)} are not among the configuration's "
            f"sensors ({', '.join(sensors) or 'none'})"
        )
    lacking = [s for s in sensors if s not in channels]
    if lacking:
        raise HexdemError(
            f"{path}, record {name}: the configuration's sensor(s) {', '.join(lacking)} were not "
            "measured; list only measured sensors in the configuration's sensors"
        )
    arrays = [np.array(channels[s]) for s in sensors]
    for sensor, array in zip(sensors, arrays):
        if np.any(np.diff(array[:, 0]) <= 0):
            raise HexdemError(f"{path}, record {name}: the times of sensor {sensor} do not increase")
    times = arrays[0][:, 0]
    if any(len(a) != len(times) or not np.array_equal(a[:, 0], times) for a in arrays):
        raise HexdemError(f"{path}, record {name}: the sensors are not sampled at the same times")
    if len(times) < 4 * BASELINE_SAMPLES:
        raise HexdemError(
            f"{path}, record {name}: {len(times)} samples are too few to hold a pulse (at least {4 * BASELINE_SAMPLES})"
        )
    intervals = np.diff(times)
    if np.max(np.abs(intervals / np.median(intervals) - 1)) > STEADY_RATE_RTOL:
        raise HexdemError(
            f"{path}, record {name}: not sampled at a steady rate (intervals from "
            f"{intervals.min() * 1e6:.4g} to {intervals.max() * 1e6:.4g} µs)"
        )
    accelerations = np.stack([a[:, 1:] for a in arrays]) * scale
    axes = np.ptp(accelerations, axis=1) > 0
    axes[:, 1] &= has_y
    return Record(name, times, accelerations * axes[:, None, :], axes)


def _common_axes(path, records: list[Record], sensors: list[str]) -> list[Record]:
    """``records`` with each sensor's axes those measured (not constant) in every record; a
    sensor left with no axis is refused."""
    axes = np.logical_and.reduce([record.axes for record in records])
    for sensor, measured in zip(sensors, axes):
        if not measured.any():
            raise HexdemError(
                f"{path}: sensor {sensor} has no axis that varies in every record (exactly constant "
                "channels hold no signal)"
            )
    return [Record(r.name, r.times, r.accelerations * axes[:, None, :], axes) for r in records]
