"""Sensor particles: sampling at the acquisition rate, records consistent with the run and with
Newton's law, heavier sensor beads in both engines, and measured signals aligned with a run."""

import json

import numpy as np
import pytest
from conftest import read_csv, settings_of

from hexdem.cli.main import main
from hexdem.errors import HexdemError
from hexdem.experiments.compare import compare_analyses
from hexdem.experiments.run import run_experiment, simulate
from hexdem.experiments.sensors import SENSOR_COLUMNS, SENSOR_PEAK_COLUMNS
from hexdem.experiments.signals import SIGNAL_COLUMNS
from hexdem.model.config import RunConfig
from hexdem.model.materials import sphere_mass
from hexdem.model.model_builder import build_model, build_packing
from hexdem.model.sensors import sensor_beads

SENSORS = ["0:1", "+30:3", "-30:5", "0:4"]
CONFIG = RunConfig(edge_beads=7, sensors=SENSORS, duration=6e-4)


@pytest.fixture(scope="module")
def sensor_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("sensors")
    return out, run_experiment(CONFIG, out, log=lambda message: None)


def test_sensors_are_sampled_exactly_at_the_acquisition_rate():
    settings = settings_of(CONFIG)
    assert settings.dt_s * settings.sensor_every == pytest.approx(1 / 500e3, rel=1e-12)
    assert settings.sensor_every % settings.dump_every == 0
    assert settings.dt_s <= settings_of(RunConfig(edge_beads=7)).dt_s


@pytest.mark.parametrize(
    "sensors, message",
    [
        (["1:2"], "neither a bead id nor 'line:n'"),
        (["+30:99"], "has beads 0 to 9"),
        ([10_000], "not in the packing"),
        (["0:1", "0:1"], "the same bead twice"),
    ],
)
def test_bad_sensors_are_refused(sensors, message):
    with pytest.raises(HexdemError, match=message):
        build_model(RunConfig(edge_beads=7, sensors=sensors))


def test_sensors_may_name_the_extra_lines():
    """A sensor on bead 3 of an extra line up the middle column: the bead {−20 + 2·3, 10}; a
    misspelt line is refused with the extra line among the known ones."""
    lines = [{"name": "across", "site": [-20, 10], "angle_deg": 90}]
    config = RunConfig(lines=lines, sensors=["across:3", "0:1"])
    lattice = build_packing(config)
    beads = sensor_beads(config.sensors, lattice)
    assert list(beads) == ["across:3", "0:1"] and tuple(lattice.labels[beads["across:3"]]) == (-14, 10)
    with pytest.raises(HexdemError, match="line one of 0, [+]30, -30, across"):
        build_model(RunConfig(lines=lines, sensors=["acros:3"]))


def test_sensor_files_follow_the_run(sensor_run):
    out, analysis = sensor_run
    header, rows = read_csv(out / "sensors.csv")
    assert header == SENSOR_COLUMNS
    times = np.array([float(r["time"]) for r in rows if r["sensor"] == "0:1"])
    np.testing.assert_allclose(np.diff(times), 2e-6, rtol=1e-9)
    assert len(rows) == len(SENSORS) * len(times)
    header, peaks = read_csv(out / "sensor_peaks.csv")
    assert header == SENSOR_PEAK_COLUMNS and [p["sensor"] for p in peaks] == SENSORS
    assert float(peaks[0]["relative_arrival_time"]) == 0.0
    _, lines = read_csv(out / "peaks.csv")
    by_bead = {r["bead_id"]: r for r in lines}
    for p in peaks:
        assert float(p["peak_speed"]) == float(by_bead[p["bead_id"]]["peak_speed"])
        assert float(p["relative_arrival_time"]) == pytest.approx(
            float(p["arrival_time"]) - float(peaks[0]["arrival_time"]), abs=1e-15
        )


def test_recorded_accelerations_integrate_to_the_recorded_velocities(sensor_run):
    """Newton's law inside the sensor: ∫ a dt = Δv (trapezoids at 2 µs), within 1 % of the peak."""
    out, _ = sensor_run
    _, rows = read_csv(out / "sensors.csv")
    for sensor in SENSORS:
        record = np.array([[float(r[c]) for c in ("time", "vx", "ax")] for r in rows if r["sensor"] == sensor])
        t, vx, ax = record.T
        integrated = np.concatenate([[0.0], np.cumsum(0.5 * (ax[1:] + ax[:-1]) * np.diff(t))])
        assert np.max(np.abs(integrated - vx)) < 0.01 * np.max(np.abs(vx))


def test_heavier_sensor_beads_in_both_engines(tmp_path):
    """sensor_mass_factor = 1.5: both engines agree within the default tolerances on every line's
    bead, and the heavier first bead of the 0° line moves slower than a plain one."""
    config = CONFIG.replace(sensor_mass_factor=1.5)
    model = build_model(config)
    bead = model.sensor_beads[0]
    assert model.masses_kg[bead] == pytest.approx(1.5 * float(sphere_mass(config.diameter_m)))
    lammps, reference = (simulate(config.replace(engine=name), tmp_path / name) for name in ("lammps", "reference"))
    comparison = compare_analyses(lammps, reference, config.v0)
    assert comparison.n_checked == sum(len(beads) for beads in lammps.results.lines.values())
    assert comparison.agree, comparison.verdict()
    plain = simulate(CONFIG, tmp_path / "plain")
    assert lammps.results.peak_speed[bead] < plain.results.peak_speed[bead]


def test_measured_signals_are_aligned_and_compared(sensor_run, tmp_path):
    """Synthetic measurements: the run's accelerations with noise, 123.4 µs later: the offset
    comes back within 0.1 µs, peak speeds within 1 %, relative arrivals within 0.5 µs."""
    out, _ = sensor_run
    _, rows = read_csv(out / "sensors.csv")
    rng = np.random.default_rng(3)
    measured = tmp_path / "measured.csv"
    with open(measured, "w") as fh:
        fh.write("sensor,time,ax,ay\n")
        for r in rows:
            fh.write(
                f"{r['sensor']},{float(r['time']) + 123.4e-6!r},{float(r['ax']) + rng.normal(0, 1.0)!r},"
                f"{float(r['ay']) + rng.normal(0, 1.0)!r}\n"
            )
    assert main(["signals", "--measured", str(measured), "--run", str(out), "--out", str(tmp_path)]) == 0
    header, table = read_csv(tmp_path / "signals.csv")
    assert header == SIGNAL_COLUMNS and len(table) == len(SENSORS)
    for row in table:
        assert float(row["peak_ratio"]) == pytest.approx(1.0, abs=0.01)
        assert abs(float(row["arrival_difference"])) < 5e-7
    assert json.loads((tmp_path / "signals.json").read_text())["time_offset_s"] == pytest.approx(123.4e-6, abs=1e-7)
    assert (tmp_path / "signals.png").stat().st_size > 0


def test_measured_file_without_accelerations_is_a_one_line_error(sensor_run, tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("sensor,time,vx\n0:1,0.0,1.0\n")
    assert main(["signals", "--measured", str(bad), "--run", str(sensor_run[0])]) == 3
    assert "lacks the column(s) ax, ay" in capsys.readouterr().err


def test_both_engines_record_the_same_sensor_signals(tmp_path):
    """Velocities and accelerations of every sensor sample, t = 0 included, within 0.5 % of each
    signal's largest value."""
    lammps, reference = (
        simulate(CONFIG.replace(engine=name), tmp_path / name).tracked for name in ("lammps", "reference")
    )
    np.testing.assert_allclose(lammps.sensor_times, reference.sensor_times, rtol=1e-12)
    scale = np.max(np.abs(reference.sensor_states), axis=0)
    assert np.all(np.abs(lammps.sensor_states - reference.sensor_states) <= 5e-3 * scale + 1e-12)
