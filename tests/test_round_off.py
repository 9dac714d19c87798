"""Every packing read right: round-off is not motion, and the reading of a run (never moved,
still rising, the far wall reached, first-pass peaks) follows the packing, in both engines.

A square crystal struck along a row moves that row alone: its neighbours touch it at 90°, where
a normal force has no component along the row. LAMMPS leaves them at 4e-17 m/s of round-off and
the reference integrator at 1e-58 m/s; both are below the run's noise floor
(:func:`~hexdem.analysis.peaks.noise_floor`, 1.5e-8 V0), so both engines read every such bead as
never moved, with peak 0, not as a pulse still rising."""

from pathlib import Path

import numpy as np
import pytest

from hexdem.analysis.peaks import ROUND_OFF_SPEED, noise_floor, pulse_times
from hexdem.analysis.run_maps import peak_scale
from hexdem.experiments.run import simulate
from hexdem.model.config import RunConfig

GALLERY = Path(__file__).resolve().parent.parent / "docs" / "gallery" / "configs"
CRYSTALS = {
    "square": {"shape": "square", "rows": 15, "columns": 15},
    "centered-square": {"shape": "centered-square", "rows": 9, "columns": 12, "interstitial_material": "brass"},
    "chain": {"shape": "chain", "beads": 20},
}


def _reading(analysis) -> dict:
    peaks = analysis.results.peak_speed
    return {"never moved": set(np.flatnonzero(peaks == 0.0)), "still rising": set(np.flatnonzero(np.isnan(peaks)))}


@pytest.fixture(scope="module")
def crystal_runs(tmp_path_factory):
    return {
        (name, engine): simulate(RunConfig(**changes, engine=engine), tmp_path_factory.mktemp(name), trace_lines=["0"])
        for name, changes in CRYSTALS.items()
        for engine in ("lammps", "reference")
    }


def test_the_noise_floor_is_the_square_root_of_a_doubles_precision():
    assert ROUND_OFF_SPEED == pytest.approx(1.4901e-8, rel=1e-4)
    assert noise_floor(0.4) == pytest.approx(0.4 * 1.4901e-8, rel=1e-4)


def test_round_off_below_the_floor_never_moved_and_above_it_a_pulse():
    """A bead that creeps at 1e-17 (LAMMPS's round-off at 0.4 m/s) or 1e-58 (the reference
    integrator's) never moved; one whose pulse rises to 1e-3 of V0 has a peak."""
    times = np.linspace(0.0, 1.0, 201)
    pulse = np.exp(-(((times - 0.5) / 0.05) ** 2))
    speeds = np.column_stack([1e-17 * times, 1e-58 * times, 4e-4 * pulse, 1e-17 * times[::-1]])
    result = pulse_times(times, speeds, noise_floor(0.4))
    np.testing.assert_array_equal(result.peak_speed[[0, 1, 3]], 0.0)
    assert result.peak_speed[2] == pytest.approx(4e-4, rel=1e-3)
    assert np.isnan(result.arrival_time[[0, 1, 3]]).all()
    assert np.isnan(pulse_times(times, speeds).peak_speed[0])  # without the floor: "still rising"


@pytest.mark.parametrize("name", CRYSTALS)
def test_both_engines_read_every_bead_alike(crystal_runs, name):
    """The same beads never moved, and the same beads are still rising, in LAMMPS and in the
    reference integrator."""
    lammps, reference = _reading(crystal_runs[name, "lammps"]), _reading(crystal_runs[name, "reference"])
    assert lammps == reference


def test_the_square_moves_its_struck_row_alone(crystal_runs):
    """All 210 beads off the struck row never moved; the 15 of the row all have first-pass peaks."""
    for engine in ("lammps", "reference"):
        analysis = crystal_runs["square", engine]
        r, row = analysis.results, analysis.results.lines["0"]
        off_row = np.setdiff1d(np.arange(len(r.peak_speed)), row)
        assert len(off_row) == 210 and np.all(r.peak_speed[off_row] == 0.0)
        assert np.all(r.peak_speed[row] > 0.25 * 0.4) and np.isfinite(r.t_peak[row[1:]]).all()
        assert r.far_wall_reached


def _first_pass(times, speeds, threshold) -> np.ndarray:
    """Time of each bead's first local maximum above ``threshold`` (NaN if none)."""
    rises = (speeds[1:-1] >= speeds[:-2]) & (speeds[1:-1] > speeds[2:]) & (speeds[1:-1] > threshold)
    first = np.argmax(rises, axis=0)
    return np.where(rises.any(axis=0), times[1:-1][first], np.nan)


@pytest.mark.parametrize("name", CRYSTALS)
def test_the_default_duration_reports_first_pass_peaks(tmp_path, crystal_runs, name):
    """Each bead of the struck row peaks at its first pass: its reported time of peak is its first
    maximum in a run three times as long (where the far wall's reflection comes back), within a
    sample; and the far end's bead has peaked too (the run was long enough)."""
    analysis = crystal_runs[name, "lammps"]
    settings, row = analysis.settings, analysis.results.lines["0"][1:]
    long = simulate(RunConfig(**CRYSTALS[name], duration=3 * settings.duration_s), tmp_path, trace_lines=["0"])
    times, speeds = long.line_trace("0")
    first = _first_pass(times, speeds[:, 1:], 0.05 * 0.4)
    interval = settings.dt_s * settings.dump_every
    turned = np.isfinite(first)  # (a chain's free end flies off at its peak speed: no maximum)
    assert turned.sum() >= len(row) - 1
    np.testing.assert_allclose(analysis.results.t_peak[row][turned], first[turned], rtol=0, atol=interval)
    assert np.isfinite(analysis.results.peak_speed[row]).all()


def test_the_far_wall_follows_what_moves(tmp_path):
    """A 5 × 7 square at its default duration has crossed (the other rows never move, so longer
    runs could not help); a 15 × 15 square stopped after 0.2 ms has not (its row's pulse is 5
    beads in); a packing file's rattlers, which never move, do not hold the flag back."""
    small = simulate(RunConfig(shape="square", rows=5, columns=7), tmp_path / "small")
    assert small.results.far_wall_reached
    early = simulate(RunConfig(shape="square", rows=15, columns=15, duration=2e-4), tmp_path / "early")
    assert not early.results.far_wall_reached
    packing = RunConfig.from_toml(GALLERY / "packing.toml").replace(walls="none")
    loose = simulate(packing, tmp_path / "packing")
    assert (loose.results.peak_speed == 0.0).sum() >= 1 and loose.results.far_wall_reached


def test_the_peak_maps_scale_follows_the_peaks():
    """A square's row (0.68 to 1 V0) spans the whole scale; a decaying front keeps its own range;
    equal peaks span a tenth below their value; beads that never moved or are still rising do not
    stretch it."""
    assert peak_scale([1.0, 0.75, 0.68, 0.0, np.nan]) == (0.68, 1.0)
    assert peak_scale([0.5, 0.5]) == (pytest.approx(0.45), 0.5)
    assert peak_scale([1.0, 0.2, 0.004]) == (0.004, 1.0)
    assert peak_scale([1.0, 1e-5]) == (1e-3, 1.0)
