"""``hexdem signals``: measured accelerometer signals beside a simulated run's sensor particles.

A lab's sensors record acceleration; the measured file has the columns ``sensor,time,ax,ay``
(SI, ``sensor`` named as in the run's ``sensors``: ``"0:1"``, ``"+30:6"``, … or a bead id).
Each measured signal is integrated to velocity (trapezoids, after removing the accelerometer's
offset, the mean of the first :data:`BASELINE_SAMPLES` samples, taken before the pulse), and its
speed gives a peak and a half-maximum arrival with the definitions of
:mod:`hexdem.analysis.peaks`; the run's sensor velocities (``sensors.csv``) get the same
treatment. The experiment's clock is unknown, so the two are aligned as the paper aligns them:
the measured time axis is shifted so that the first listed sensor arrives when the
simulation's does. Writes ``signals.csv``, ``signals.json`` and ``signals.png``.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from hexdem.analysis.peaks import refine_peak, rising_crossing
from hexdem.common.io import ensure_writable_dir, write_csv, write_json
from hexdem.errors import HexdemError

MEASURED_COLUMNS = ("sensor", "time", "ax", "ay")
SIGNAL_COLUMNS = (
    "sensor",
    "bead_id",
    "simulated_peak_speed",
    "measured_peak_speed",
    "peak_ratio",
    "simulated_arrival_time",
    "measured_arrival_time",
    "arrival_difference",
)
#: Samples at the start of a measured record that set the accelerometer's offset (before the pulse).
BASELINE_SAMPLES = 10


def _read_table(path: Path, columns) -> dict[str, dict[str, np.ndarray]]:
    """{sensor: {column: array}} of a CSV with at least ``columns``; one-line errors."""
    try:
        with open(path, newline="") as fh:
            reader = csv.DictReader(fh)
            missing = [c for c in columns if c not in (reader.fieldnames or ())]
            if missing:
                raise HexdemError(f"{path} lacks the column(s) {', '.join(missing)}; expected {','.join(columns)}")
            rows = list(reader)
        table: dict[str, dict[str, list]] = {}
        for row in rows:
            entry = table.setdefault(row["sensor"], {c: [] for c in columns if c != "sensor"})
            for c in entry:
                entry[c].append(float(row[c]))
    except OSError as exc:
        raise HexdemError(f"cannot read {path}: {exc.strerror}") from None
    except ValueError:
        raise HexdemError(f"{path} has a value that is not a number") from None
    return {sensor: {c: np.array(v) for c, v in entry.items()} for sensor, entry in table.items()}


def integrate_velocity(times, ax, ay) -> tuple[np.ndarray, np.ndarray]:
    """Velocity (vx, vy) [m/s] from acceleration [m/s²] by trapezoids, offset removed, v(t₀) = 0."""
    times = np.asarray(times, float)
    if len(times) < 2 * BASELINE_SAMPLES or np.any(np.diff(times) <= 0):
        raise HexdemError(f"a measured signal needs at least {2 * BASELINE_SAMPLES} samples at increasing times")
    out = []
    for a in (np.asarray(ax, float), np.asarray(ay, float)):
        a = a - a[:BASELINE_SAMPLES].mean()
        out.append(np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(times))]))
    return out[0], out[1]


def pulse(times, vx, vy) -> tuple[float, float]:
    """(peak speed, half-maximum arrival time) of a velocity record. Maxima below half the largest
    sample cannot hold the peak (:func:`~hexdem.analysis.peaks.may_overtake`): that half is the
    floor, so that a noisy record's lead-in is not refined maximum by maximum."""
    speed = np.hypot(vx, vy)
    k = int(np.argmax(speed))
    _, peak = refine_peak(times, speed, floor=0.5 * speed[k])
    return peak, rising_crossing(times[: k + 1], speed[: k + 1], 0.5 * peak)


def compare_signals(run_dir, measured_path, out=None) -> dict:
    """Align the measured signals with the run in ``run_dir`` and write the comparison files
    into ``out`` (default: ``run_dir``); returns the summary written to ``signals.json``."""
    run_dir = Path(run_dir)
    simulated = _read_table(run_dir / "sensors.csv", ("sensor", "bead_id", "time", "vx", "vy"))
    measured = _read_table(Path(measured_path), MEASURED_COLUMNS)
    order = [s for s in simulated if s in measured]
    if not order:
        raise HexdemError(
            f"no sensor of {measured_path} ({', '.join(measured) or 'none'}) is in the run "
            f"({', '.join(simulated) or 'none'})"
        )
    out = ensure_writable_dir(out if out is not None else run_dir)
    traces, rows = {}, []
    for sensor in order:
        sim, meas = simulated[sensor], measured[sensor]
        vx, vy = integrate_velocity(meas["time"], meas["ax"], meas["ay"])
        traces[sensor] = ((sim["time"], np.hypot(sim["vx"], sim["vy"])), (meas["time"], np.hypot(vx, vy)))
        rows.append(
            [sensor, int(sim["bead_id"][0]), *pulse(sim["time"], sim["vx"], sim["vy"]), *pulse(meas["time"], vx, vy)]
        )
    offset = rows[0][5] - rows[0][3]
    table = [(s, bead, sp, mp, mp / sp, sa, ma - offset, ma - offset - sa) for s, bead, sp, sa, mp, ma in rows]
    write_csv(out / "signals.csv", SIGNAL_COLUMNS, table)
    summary = {
        "run": str(run_dir),
        "measured": str(measured_path),
        "aligned_on": order[0],
        "time_offset_s": offset,
        "sensors": [dict(zip(SIGNAL_COLUMNS, row)) for row in table],
    }
    write_json(out / "signals.json", summary)
    _overlay(traces, offset, out / "signals.png")
    return summary


def _overlay(traces: dict, offset: float, path) -> None:
    """Speed of each sensor: simulated, and measured shifted by −offset."""
    from hexdem.analysis.plotting import save, subplots  # matplotlib: only where the figure is drawn

    count = len(traces)
    columns = min(2, count)
    fig, axes = subplots(
        math.ceil(count / columns),
        columns,
        figsize=(6 * columns, 3.2 * math.ceil(count / columns)),
        squeeze=False,
        layout="constrained",
    )
    for ax, (sensor, ((ts, vs), (tm, vm))) in zip(axes.flat, traces.items()):
        ax.plot(ts * 1e3, vs, label="simulated", color="C0")
        ax.plot((tm - offset) * 1e3, vm, label="measured (aligned)", color="C3", alpha=0.8)
        ax.set_title(f"sensor {sensor}")
        ax.set_xlabel("time [ms]")
        ax.set_ylabel("speed [m/s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    for ax in list(axes.flat)[count:]:
        ax.set_visible(False)
    save(fig, path)
