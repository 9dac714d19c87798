"""The default experiment (``hexdem run``) on real LAMMPS: files, energy, symmetry, ranks, units."""

import json

import numpy as np
import pytest
from conftest import read_csv

from hexdem.analysis.impact import PEAK_COLUMNS
from hexdem.experiments.run import BEAD_COLUMNS, RESULT_FILES, run_experiment, simulate
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model


def test_default_run_writes_the_contracted_files(default_run):
    out, analysis = default_run
    for name in RESULT_FILES:
        assert (out / name).stat().st_size > 0
    assert (out / "deck" / "in.hexdem").exists() and (out / "deck" / "hexdem.json").exists()
    assert not (out / "deck" / "dump.lammpstrj").exists(), "no dump unless asked for"
    header, rows = read_csv(out / "peaks.csv")
    assert header == PEAK_COLUMNS
    assert {row["line"] for row in rows} == {"0", "+30", "-30"}
    assert [int(r["n"]) for r in rows if r["line"] == "0"] == list(range(11))
    summary = json.loads((out / "summary.json").read_text())
    assert summary["lattice"]["n_beads"] == 331
    assert summary["lammps_version"].startswith("LAMMPS")
    assert summary["far_wall_reached"] is True
    cpu_s = summary["analysis_cpu_s"]  # the analysis's own CPU time, a share of the engine's run
    assert sorted(cpu_s) == ["audit", "gathering", "tracker"] and cpu_s["tracker"] > 0 and cpu_s["audit"] > 0
    assert sum(cpu_s.values()) < summary["engine_wall_time_s"]
    assert not (out / "movie.gif").exists(), "no movie unless asked for"
    header, beads = read_csv(out / "beads.csv")
    assert header == BEAD_COLUMNS and len(beads) == 331
    by_id = {int(row["bead_id"]): row for row in beads}
    for row in rows:  # the lines' beads carry the same pulse in both tables
        bead = by_id[int(row["bead_id"])]
        assert (bead["peak_speed"], bead["arrival_time"], bead["x"]) == (
            row["peak_speed"],
            row["arrival_time"],
            row["x"],
        )
        assert {bead["material"]} == {"steel316"}


def test_run_movie_animates_the_speed_field_sampled_in_the_run(tmp_path):
    """``hexdem run --movie``: 60 frames from the tracker's fields; the first is t = 0, when only
    the struck bead moves, at V0."""
    from PIL import Image

    from hexdem.cli.main import main

    config = tmp_path / "small.toml"
    config.write_text('edge_beads = 5\nengine = "reference"\n')
    assert main(["run", "--config", str(config), "--out", str(tmp_path / "out"), "--movie"]) == 0
    with Image.open(tmp_path / "out" / "movie.gif") as movie:
        assert movie.n_frames == 60
    analysis = simulate(RunConfig(edge_beads=5, engine="reference", movie=True), tmp_path / "again")
    first = analysis.tracked.field_speeds[0]
    assert first[analysis.model.packing.struck] == 0.4 and np.count_nonzero(first) == 1
    assert len(analysis.tracked.field_times) == 60 and analysis.tracked.field_times[0] == 0.0


def test_default_run_conserves_energy(default_run):
    """Velocity Verlet's energy error is about 0.9/N² for N steps per contact
    (benchmarks/bench_accuracy.py): 4.5e-5 at the default 140."""
    _, analysis = default_run
    assert analysis.results.energy_drift < 1e-4


def test_zero_degree_strike_is_mirror_symmetric(default_run):
    r = default_run[1].results
    upper, lower = r.lines["+30"], r.lines["-30"]
    np.testing.assert_allclose(r.peak_speed[upper], r.peak_speed[lower], rtol=1e-9)
    np.testing.assert_allclose(r.arrival_time[upper], r.arrival_time[lower], rtol=0, atol=1e-12)


def test_struck_bead_starts_at_v0_and_the_wave_decays_along_every_line(default_run):
    r = default_run[1].results
    for beads in r.lines.values():
        assert r.peak_speed[beads[0]] == pytest.approx(0.4, rel=1e-12)
        assert np.all(np.diff(r.peak_speed[beads][:8]) < 0)
        assert np.all(np.diff(r.arrival_time[beads]) > 0)


def test_one_and_two_ranks_give_the_same_peaks(default_run, tmp_path):
    one = default_run[1].results
    two = simulate(RunConfig(ranks=2), tmp_path).results
    assert default_run[1].engine["ranks"] == 1
    np.testing.assert_allclose(two.peak_speed, one.peak_speed, rtol=1e-9)
    np.testing.assert_allclose(two.t_peak, one.t_peak, rtol=1e-9)


def _numbers(path):
    """(the text columns, the numeric columns as a float array) of a result table."""
    header, rows = read_csv(path)
    text = {key for key in header if any(not _is_number(row[key]) for row in rows)}
    return (
        [[row[key] for key in header if key in text] for row in rows],
        np.array([[float(row[key]) for key in header if key not in text] for row in rows]),
    )


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _assert_same_tables(one, many) -> None:
    """``peaks.csv`` and ``beads.csv`` in directories ``one`` and ``many`` equal to round-off."""
    for name in ("peaks.csv", "beads.csv"):
        (text_one, numbers_one), (text_many, numbers_many) = _numbers(one / name), _numbers(many / name)
        assert text_many == text_one and numbers_many.shape == numbers_one.shape and len(numbers_one) > 20, name
        np.testing.assert_allclose(numbers_many, numbers_one, rtol=1e-9, atol=1e-15, err_msg=name)


@pytest.fixture
def more_ranks_than_cores(monkeypatch):
    """More ranks than the machine has cores (4 or 8 on CI's 2): MPICH's ranks wait for each other in a
    busy loop that takes the cores from the ranks that have work, and from the suite's other
    worker (measured on the benchmarks page). Its heavy yield, a sleep between polls, gives them
    back; the ranks compute the same numbers."""
    monkeypatch.setenv("MPIR_CVAR_ENABLE_HEAVY_YIELD", "1")


def test_eight_ranks_write_the_peaks_and_beads_of_one(default_run, tmp_path, more_ranks_than_cores):
    """``peaks.csv`` and ``beads.csv`` of the default run on 8 ranks equal one rank's to round-off."""
    run_experiment(RunConfig(ranks=8), tmp_path, log=lambda message: None)
    _assert_same_tables(default_run[0], tmp_path)


def test_beads_that_migrate_in_lammps_keep_their_pulses(tmp_path, more_ranks_than_cores):
    """A hard strike whose LAMMPS rebuilds its neighbour lists (when the ranks' atoms may migrate and
    are sorted anew): ``peaks.csv`` and ``beads.csv`` on 4 ranks equal one rank's to round-off."""
    config = RunConfig(edge_beads=8, v0=8.0, duration=6e-4)
    run_experiment(config, tmp_path / "one", log=lambda message: None)
    run_experiment(config.replace(ranks=4), tmp_path / "four", log=lambda message: None)
    assert "Neighbor list builds = 0" not in (tmp_path / "four" / "deck" / "log.lammps").read_text()
    _assert_same_tables(tmp_path / "one", tmp_path / "four")


def test_nondimensional_deck_reproduces_the_si_run(default_run, tmp_path):
    si = default_run[1]
    nondim_config = RunConfig(units="nondimensional")
    units = nondim_config.unit_system
    config = nondim_config.replace(
        v0=0.4 / units.velocity_m_s, dt=si.settings.dt_s / units.time_s, duration=si.settings.duration_s / units.time_s
    )
    nd = simulate(config, tmp_path)
    assert "units           lj" in (tmp_path / "in.hexdem").read_text()
    np.testing.assert_allclose(nd.results.peak_speed * units.velocity_m_s, si.results.peak_speed, rtol=1e-7)
    np.testing.assert_allclose(nd.results.t_peak * units.time_s, si.results.t_peak, rtol=1e-7, atol=1e-12)


def test_peaks_are_sampled_finely_enough(default_run, tmp_path):
    """Default sampling vs every-step sampling: peaks within 0.5 %, times of peak within 1 µs."""
    config = RunConfig(edge_beads=7, duration=6e-4)
    coarse = simulate(config, tmp_path / "coarse").results
    fine = simulate(config.replace(dump_every=1), tmp_path / "fine").results
    seen = np.isfinite(fine.peak_speed) & (fine.peak_speed > 0.01 * 0.4)
    assert seen.sum() > 50
    np.testing.assert_allclose(coarse.peak_speed[seen], fine.peak_speed[seen], rtol=5e-3)
    np.testing.assert_allclose(coarse.t_peak[seen], fine.t_peak[seen], rtol=0, atol=1e-6)
    np.testing.assert_allclose(coarse.arrival_time[seen], fine.arrival_time[seen], rtol=0, atol=1e-6)


def test_striker_impact_matches_initial_velocity_impact(default_run, tmp_path):
    """Sec. II: a striker at V0 and V0 given to the struck bead give nearly the same wave."""
    ideal = default_run[1].results
    struck = simulate(RunConfig(impact="striker"), tmp_path)
    assert "group           impactor id 332" in (tmp_path / "in.hexdem").read_text()
    assert struck.results.energy_drift < 1e-4
    for beads in ideal.lines.values():
        far = beads[2:]
        np.testing.assert_allclose(struck.results.peak_speed[far], ideal.peak_speed[far], rtol=0.03)
        assert struck.results.peak_speed[beads[0]] < 0.8 * 0.4, "the struck bead shares V0 with the striker"


def test_config_file_sets_parameters(tmp_path):
    path = tmp_path / "run.toml"
    path.write_text(
        'edge_beads = 5\nstrike_angle_deg = 30.0\nimpact = "striker"\nunits = "nondimensional"\nv0 = 0.05\n'
    )
    config = RunConfig.from_toml(path)
    model = build_model(config)
    assert len(model.packing) == 61 and model.has_striker
    np.testing.assert_allclose(model.impact.direction, [np.sqrt(3) / 2, 0.5])
    assert model.impact.speed_m_s == pytest.approx(0.05 * config.unit_system.velocity_m_s)


def test_ranks_that_own_no_bead_take_part(tmp_path, more_ranks_than_cores):
    """Seven beads on 8 ranks (some own none of them): the same peaks as on one rank."""
    config = RunConfig(edge_beads=2)
    one = simulate(config, tmp_path / "one").results
    eight = simulate(config.replace(ranks=8), tmp_path / "eight").results
    np.testing.assert_allclose(eight.peak_speed, one.peak_speed, rtol=1e-9)
    np.testing.assert_allclose(eight.arrival_time, one.arrival_time, rtol=1e-9)


@pytest.mark.parametrize("dump", [False, True])
def test_a_run_builds_its_model_once(tmp_path, monkeypatch, dump):
    """The dump's disk check, the time step and the engine all read the one model the run built
    (every model is built through ``configured_packing``)."""
    import hexdem.model.model_builder as builder

    built = []
    packing = builder.configured_packing
    monkeypatch.setattr(builder, "configured_packing", lambda config: built.append(config) or packing(config))
    run_experiment(RunConfig(edge_beads=3, dump=dump), tmp_path / "out", log=lambda message: None)
    assert len(built) == 1
