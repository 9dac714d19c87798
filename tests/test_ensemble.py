"""Disorder ensembles (hexdem.disorder.ensemble) on real LAMMPS: contract, statistics,
determinism per seed and across workers, resuming after a kill, bad input.

The ensembles are small (4 beads per edge, 37 beads, 3 realizations, 2 striker speeds) so
that each runs in seconds.
"""

import fcntl
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from conftest import read_csv

from hexdem.cli.main import main
from hexdem.disorder.ensemble import Ensemble, EnsembleConfig
from hexdem.disorder.preparation import Preparation
from hexdem.disorder.runner import run_ensemble
from hexdem.disorder.sharing import adopt_ideal_impacts, adopt_preparation
from hexdem.disorder.stats import STATS_COLUMNS
from hexdem.engines.lammps.standalone import DONE_MARKER, run_deck
from hexdem.errors import HexdemError

VELOCITIES = (0.4, 0.7)
SMALL = {"edge_beads": 4, "velocities_m_s": VELOCITIES, "realizations": 3}
CLI_SMALL = ["--edge-beads", "4", "--velocities", "0.4,0.7"]
RESULT_ARRAYS = ("diameters_m", "positions_m", "peak_speed", "t_peak", "arrival_time")


def quiet(message):
    pass


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The small ensemble on two workers."""
    out = tmp_path_factory.mktemp("reference")
    config = EnsembleConfig(**SMALL)
    summary = run_ensemble(config, out, workers=2, log=quiet)
    return Ensemble(config, out), summary


def results(ensemble, k):
    with np.load(ensemble.result_path(k)) as data:
        return {name: data[name] for name in data.files}


def test_the_ensemble_writes_its_tables_and_figures(reference):
    ensemble, summary = reference
    header, rows = read_csv(ensemble.out / "peaks_stats.csv")
    assert header == STATS_COLUMNS
    assert len(rows) == len(VELOCITIES) * sum(len(beads) for beads in ensemble.ideal.lines().values())
    assert {int(row["count"]) for row in rows} <= {0, 1, 2, 3}
    for name in (
        "ideal_peaks.csv",
        "arrival_map.csv",
        "disorder_effect.csv",
        "fig9_all_directions.png",
        "fig8_expnumsim_v0.400.png",
        "fig8_expnumsim_v0.700.png",
        "ensemble.json",
    ):
        assert (ensemble.out / name).stat().st_size > 0
    assert {row["line"] for row in summary["disorder_effect"]} == {"0", "+30", "-30", "±30"}
    assert summary["lammps_time_s"]["settle_per_realization"] > 0 < summary["lammps_time_s"]["impact_per_run"]


def test_statistics_are_the_mean_and_sample_deviation_of_the_realizations(reference):
    ensemble, _ = reference
    peaks = np.array([results(ensemble, k)["peak_speed"] for k in range(3)])
    lines = ensemble.ideal.lines()
    _, rows = read_csv(ensemble.out / "peaks_stats.csv")
    assert any(int(row["count"]) > 1 for row in rows)
    for row in rows:
        values = peaks[:, VELOCITIES.index(float(row["v_striker"])), lines[row["line"]][int(row["n"])]]
        values = values[np.isfinite(values)]
        assert int(row["count"]) == len(values)
        mean = values.mean() if len(values) else np.nan
        std = values.std(ddof=1) if len(values) > 1 else np.nan  # no spread from fewer than two
        assert float(row["mean_peak_speed"]) == pytest.approx(mean, rel=1e-12, nan_ok=True)
        assert float(row["std_peak_speed"]) == pytest.approx(std, rel=1e-9, nan_ok=True)


def test_every_impact_is_prepared_settled_and_conserves_energy(reference):
    ensemble, _ = reference
    for k in range(3):
        r = results(ensemble, k)
        assert np.all(r["energy_drift"] < 1e-4)  # Verlet at 140 steps per contact: about 0.9/140²
        assert r["compact_kinetic_energy_j"] > 0 and r["settle_max_force_n"] < 1e-4
        assert np.all(r["peak_speed"][:, ensemble.ideal.struck] > 0.5 * np.array(VELOCITIES))


def test_the_same_seed_gives_identical_results_on_one_worker(reference, tmp_path):
    ensemble, _ = reference
    run_ensemble(EnsembleConfig(**SMALL), tmp_path, workers=1, log=quiet)
    again = Ensemble(EnsembleConfig(**SMALL), tmp_path)
    for k in range(3):
        first, second = results(ensemble, k), results(again, k)
        for name in RESULT_ARRAYS:
            np.testing.assert_array_equal(first[name], second[name])


def test_another_seed_draws_other_diameters(reference):
    ensemble, _ = reference
    other = Ensemble(EnsembleConfig(**SMALL, seed=1), ensemble.out)
    assert np.all(other.diameters_m(0) != ensemble.diameters_m(0))
    np.testing.assert_allclose(results(ensemble, 2)["diameters_m"], ensemble.diameters_m(2), rtol=1e-15)


def test_adopting_another_ensembles_identical_runs_gives_what_running_them_gives(reference, tmp_path):
    """Walls stood back (another settle) share the compactions and the ideal impacts; another
    seed shares only the ideal impacts; another size shares nothing."""
    ensemble, _ = reference
    slack = EnsembleConfig(**SMALL, preparation=Preparation(wall_slack_m=1e-6))
    run_ensemble(slack, tmp_path / "adopted", workers=2, log=quiet, share_from=(ensemble,))
    run_ensemble(slack, tmp_path / "own", workers=2, log=quiet)
    adopted, own = Ensemble(slack, tmp_path / "adopted"), Ensemble(slack, tmp_path / "own")
    for k in (None, 0, 1, 2):
        for name in ("peak_speed", "t_peak", "arrival_time") + (() if k is None else ("positions_m",)):
            np.testing.assert_array_equal(results(adopted, k)[name], results(own, k)[name])
    for k in range(3):  # copied, not rerun: even LAMMPS's timings in the log are the reference's
        assert (adopted.stage_dir(k, "compact") / "log.lammps").read_bytes() == (
            ensemble.stage_dir(k, "compact") / "log.lammps"
        ).read_bytes()
        assert not np.array_equal(results(adopted, k)["wall_offsets_m"], results(ensemble, k)["wall_offsets_m"])
    seeded = Ensemble(EnsembleConfig(**SMALL, seed=1), tmp_path / "seed")
    assert adopt_preparation(seeded, ensemble) == 0 and adopt_ideal_impacts(seeded, ensemble) == 2
    larger = Ensemble(EnsembleConfig(**{**SMALL, "edge_beads": 5}), tmp_path / "larger")
    assert adopt_preparation(larger, ensemble) == 0 and adopt_ideal_impacts(larger, ensemble) == 0


def test_a_frictional_ensemble_strikes_the_frictionless_preparation(reference, tmp_path):
    """Friction acts in the impacts only: the whole preparation (compaction and settling) is
    adopted from the frictionless ensemble, byte for byte, while every impact is run anew and
    the struck bead's neighbours, met at 30° to the strike, now turn."""
    ensemble, _ = reference
    rough = EnsembleConfig(**SMALL, friction=0.3)
    run_ensemble(rough, tmp_path, workers=2, log=quiet, share_from=(ensemble,))
    adopted = Ensemble(rough, tmp_path)
    for k in range(3):
        for stage in ("compact", "settle"):
            assert (adopted.stage_dir(k, stage) / "log.lammps").read_bytes() == (
                ensemble.stage_dir(k, stage) / "log.lammps"
            ).read_bytes()
        np.testing.assert_array_equal(results(adopted, k)["positions_m"], results(ensemble, k)["positions_m"])
        assert not np.array_equal(results(adopted, k)["peak_speed"], results(ensemble, k)["peak_speed"])
    assert "nve/sphere" in (adopted.impact_dir(0, 0.4) / "in.hexdem").read_text()
    assert "nve/sphere" not in (adopted.stage_dir(0, "settle") / "in.hexdem").read_text()
    assert not np.array_equal(results(adopted, None)["peak_speed"], results(ensemble, None)["peak_speed"])


def wait_for_unlock(out, timeout_s=60):
    deadline = time.time() + timeout_s
    fd = os.open(out / ".lock", os.O_RDWR)
    try:
        while True:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                return
            except BlockingIOError:
                assert time.time() < deadline, "the killed ensemble's processes kept the lock"
                time.sleep(0.1)
    finally:
        os.close(fd)


#: ``hexdem ARGS`` that kills itself (SIGKILL) once it has published realization 1's result, with
#: the other realizations' impacts still running in its workers: kill -9 at a known point, which
#: a test polling for the first result from outside can miss on a busy machine (the small
#: ensemble's last impacts end within a tenth of a second of its first result).
KILLED_AFTER_TWO_REALIZATIONS = """
import os, signal, sys
from hexdem.cli.main import command
from hexdem.disorder import runner

publish = runner.publish_result
published = []


def publish_then_die(ensemble, k):
    publish(ensemble, k)
    published.append(k)
    if len(published) == 2:
        os.kill(os.getpid(), signal.SIGKILL)


runner.publish_result = publish_then_die
sys.exit(command())
"""


def test_an_ensemble_killed_midway_resumes_with_every_realization_intact(reference, tmp_path):
    ensemble, _ = reference
    out = tmp_path / "killed"
    args = ["ensemble", "--out", str(out), *CLI_SMALL, "--realizations", "5", "--workers", "2"]
    process = subprocess.run(
        [sys.executable, "-c", KILLED_AFTER_TWO_REALIZATIONS, *args],
        stderr=subprocess.DEVNULL,
        timeout=120,
        check=False,
    )
    assert process.returncode == -signal.SIGKILL
    finished = {path: path.stat().st_mtime_ns for path in out.glob("realizations/*/result.npz")}
    # two workers: the second realization published may be any of the first three, whichever finished
    assert len(finished) == 2 and {path.parent.name for path in finished} <= {"r0000", "r0001", "r0002"}
    wait_for_unlock(out)
    assert main(args) == 0
    for path, mtime in finished.items():
        assert path.stat().st_mtime_ns == mtime
    resumed = Ensemble(EnsembleConfig(**{**SMALL, "realizations": 5}), out)
    for k in range(3):
        first, second = results(ensemble, k), results(resumed, k)
        for name in RESULT_ARRAYS:
            np.testing.assert_array_equal(first[name], second[name])
    for k in range(5):
        peaks = results(resumed, k)["peak_speed"]
        assert peaks.shape == (len(VELOCITIES), len(resumed.ideal)) and np.all(peaks[:, resumed.ideal.struck] > 0)
    assert not list(out.rglob("*.part"))
    _, rows = read_csv(out / "peaks_stats.csv")
    assert max(int(row["count"]) for row in rows) == 5


def test_other_parameters_in_the_same_directory_are_refused(reference):
    ensemble, _ = reference
    with pytest.raises(HexdemError, match="other parameters \\(seed\\)"):
        run_ensemble(EnsembleConfig(**SMALL, seed=5), ensemble.out, log=quiet)


def test_a_directory_in_use_is_refused(reference):
    ensemble, _ = reference
    fd = os.open(ensemble.out / ".lock", os.O_RDWR)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        with pytest.raises(HexdemError, match="in use by another hexdem ensemble"):
            run_ensemble(EnsembleConfig(**SMALL), ensemble.out, log=quiet)
    finally:
        os.close(fd)


@pytest.mark.parametrize(
    "options, message",
    [
        (["--sigma-mm", "-0.01"], "standard deviation sigma must be >= 0"),
        (["--realizations", "0"], "number of realizations must be a positive integer"),
        (["--velocities", "0.25;0.40"], "--velocities must be comma-separated numbers in m/s"),
        (["--velocities", "fast"], "--velocities must be comma-separated numbers in m/s"),
        (["--velocities", "0.4,-0.7"], "distinct positive speeds"),
        (["--workers", "0"], "--workers must be a positive integer"),
        (["--reference-bead", "0,1"], "reference bead {0, 1} is not in the hexagon"),
        (["--scaling", "missing.json"], "cannot read scaling laws missing.json"),
    ],
)
def test_bad_input_is_one_clear_line(tmp_path, capsys, options, message):
    out = tmp_path / "out"
    assert main(["ensemble", "--out", str(out), *CLI_SMALL, *options]) == 3
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("hexdem: error: ") and message in lines[0]
    assert not out.exists()


def test_the_impacts_that_warned_are_named_per_striker_speed():
    """An impact whose wave had not crossed the packing (far_wall_reached false) warns as a run
    does; peaks_stats.csv's warnings column names those of each striker speed."""
    from hexdem.disorder.stats import EnsembleResults, impact_warnings

    reached = np.array([[True, False], [True, True], [False, False]])  # 3 realizations x 2 speeds
    results = EnsembleResults(
        np.array([0.2, 0.4]),
        *[None] * 6,
        per_realization={"far_wall_reached": reached, "ideal_far_wall_reached": np.array([True, False])},
    )
    assert impact_warnings(results) == ["far_wall_not_reached (r0002)", "far_wall_not_reached (ideal, r0000, r0002)"]


def test_a_failing_deck_is_named_with_lammps_error(tmp_path):
    good, bad = tmp_path / "good", tmp_path / "bad"
    for directory, text in ((good, 'print "fine"\n'), (bad, "units si\nbogus_command 1\n")):
        directory.mkdir()
        (directory / "in.hexdem").write_text(text)
    run_deck(good)
    with pytest.raises(HexdemError, match=r"LAMMPS failed on .*bad/in.hexdem: ERROR: Unknown command: bogus_command"):
        run_deck(bad)
    assert (good / DONE_MARKER).exists() and not (bad / DONE_MARKER).exists()


def test_a_failing_deck_in_an_ensemble_is_named_after_the_others_ran(tmp_path, capsys):
    """A preparation deck that LAMMPS refuses: the phase's other decks still run, and the error
    names the realization and LAMMPS's message, as a run that failed (exit status 4), not as input
    refused (3)."""
    from hexdem.disorder.runner import _run_phase
    from hexdem.errors import RunFailed

    decks = [tmp_path / name for name in ("a", "b", "c")]
    for directory, text in zip(decks, ('print "fine"\n', "units si\nbogus_command 1\n", 'print "fine"\n')):
        directory.mkdir()
        (directory / "in.hexdem").write_text(text)
    with pytest.raises(
        RunFailed,
        match=r"1 of 3 compact decks failed .*; realization 1: LAMMPS failed on "
        r".*b/in.hexdem: ERROR: Unknown command: bogus_command",
    ):
        _run_phase("compact", {f"realization {k}": (run_deck, deck) for k, deck in enumerate(decks)}, 2, None)
    assert [(deck / DONE_MARKER).exists() for deck in decks] == [True, False, True]


def test_fitted_laws_follow_the_papers_rule_for_physical_units(tmp_path):
    """eq. (10) with nondimensional coefficients, evaluated in m/s: every V becomes V/U."""
    from hexdem.disorder.ensemble_figures import fitted_laws
    from hexdem.model.materials import PAPER_DIAMETER_M
    from hexdem.model.units import nondimensional

    entry = {"m": 0.13, "b": 0.91, "alpha": -0.26, "beta": -0.097, "gamma": 0.215}
    path = tmp_path / "scaling.json"
    path.write_text(json.dumps({"0/0": {**entry, "start_bead": 2}, "0/30": {**entry, "start_bead": 1}}))
    laws = fitted_laws(path, PAPER_DIAMETER_M)
    unit = nondimensional(PAPER_DIAMETER_M).velocity_m_s
    v, n = 0.4, np.arange(2, 11)
    u = v / unit
    amplitude = entry["alpha"] * u**2 + entry["beta"] * u + entry["gamma"]
    expected = unit * u * amplitude * (entry["m"] * u + entry["b"]) ** (n - 2)
    np.testing.assert_allclose(laws["0"](v, n), expected, rtol=1e-12)
    np.testing.assert_allclose(laws["-30"](v, n), expected * (entry["m"] * u + entry["b"]), rtol=1e-12)
    path.write_text(json.dumps({"0/0": entry}))
    with pytest.raises(HexdemError, match="is not a scaling.json of hexdem scaling"):
        fitted_laws(path, PAPER_DIAMETER_M)
