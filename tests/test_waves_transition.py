"""The transition from the nonlinear front to the linear regime (hexdem.waves.transition): the
impact's overlap against the collision's energy balance, the leading pulse's arrival against a
signal worked out by hand, then the quick sweep's runs against c_L, the Hertz lattice's scale
invariance and each other."""

import csv
import math
from dataclasses import replace

import numpy as np
import pytest

from hexdem.common.io import write_csv
from hexdem.errors import HexdemError
from hexdem.model.materials import STEEL_316, hertz_coefficient, sphere_mass
from hexdem.model.precompression import static_overlap
from hexdem.waves.transition import (
    COLUMNS,
    QUICK,
    TransitionMap,
    TransitionSettings,
    leading_arrivals,
    overlap_ratio,
    run_transition,
    transition_figure,
)

D = 0.01905
A = float(hertz_coefficient(D, STEEL_316))
M = float(sphere_mass(D, STEEL_316))


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """The quick sweep (21 per edge; 0 and 20 N; 0.1 mm/s and 0.1 m/s), about 5 s."""
    return run_transition(QUICK, tmp_path_factory.mktemp("transition"))


def run_of(sweep: TransitionMap, force_n: float, speed_m_s: float) -> int:
    return int(np.flatnonzero((sweep.forces_n == force_n) & (sweep.speeds_m_s == speed_m_s))[0])


@pytest.mark.parametrize("speed", [1e-4, 0.1, 1.0])
def test_the_impact_overlap_stores_the_collision_energy(speed):
    """Two beads meeting at V0: in the centre-of-mass frame ½ (m/2) V0² is all in the Hertz
    potential (2/5) A δ^(5/2) at the largest overlap; the ratio's δ0 is (f0/A)^(2/3)."""
    delta = overlap_ratio(20.0, speed, A, M) * static_overlap(20.0, A)
    assert 0.4 * A * delta**2.5 == pytest.approx(0.5 * (M / 2) * speed**2, rel=1e-12)
    assert static_overlap(20.0, A) == pytest.approx((20.0 / A) ** (2 / 3), rel=1e-12)


def test_the_uncompressed_overlap_ratio_is_infinite():
    assert overlap_ratio(0.0, 0.1, A, M) == math.inf


def test_the_leading_pulse_arrival_ignores_a_larger_echo():
    """A triangle pulse rising 0 → 1 from t = 5 to 10, back to 0 at 15, then an echo of 3 at
    40: half of the leading pulse is crossed at t = 7.5; half of the largest speed (1.5) only
    in the echo. A bead that never moves has no arrival."""
    times = np.arange(60.0)
    pulse = np.interp(times, [0, 5, 10, 15, 35, 40, 45, 59], [0, 0, 1, 0, 0, 3, 0, 0])
    arrivals = leading_arrivals(times, np.column_stack([pulse, np.zeros_like(times)]))
    assert arrivals[0] == pytest.approx(7.5, abs=1e-12)
    assert np.isnan(arrivals[1])


def test_a_weak_impact_on_a_precompressed_packing_travels_at_the_sound_speed(quick):
    """20 N, 0.1 mm/s (δ_impact/δ0 = 0.008): a linear front, at c_L."""
    weak = run_of(quick, 20.0, 1e-4)
    assert quick.overlap_ratio[weak] < 0.01
    assert quick.speed_ratio[weak] == pytest.approx(1.0, abs=0.02)


def test_the_uncompressed_front_is_more_hexagonal_than_the_linear_one(quick):
    """At the same radius the strongly struck uncompressed front's sixfold amplitude is several
    times the weak linear front's (measured: 0.021 against 0.0021 at 18 d)."""
    assert quick.sixfold_amplitude[run_of(quick, 0.0, 0.1)] > 3 * quick.sixfold_amplitude[run_of(quick, 20.0, 1e-4)]


def test_the_uncompressed_front_scales_as_the_hertz_lattice_does(quick):
    """Without precompression V0 sets the only time scale: a thousandfold V0 leaves the front's
    shape and multiplies its speed by 1000^(1/5)."""
    slow, fast = run_of(quick, 0.0, 1e-4), run_of(quick, 0.0, 0.1)
    assert quick.sixfold_amplitude[fast] == pytest.approx(quick.sixfold_amplitude[slow], rel=0.01)
    assert quick.front_speed_m_s[fast] / quick.front_speed_m_s[slow] == pytest.approx(1000**0.2, rel=0.02)
    assert np.isinf(quick.overlap_ratio[[slow, fast]]).all() and np.isnan(quick.speed_ratio[[slow, fast]]).all()


def test_a_run_lasts_past_the_reading_radius_but_not_to_the_far_wall(quick):
    """Each run's measured front speed times its duration lies between ``radius_d`` and the far
    wall, √3 (E − 1) d away."""
    for force, speed, front in zip(quick.forces_n, quick.speeds_m_s, quick.front_speed_m_s):
        reach_d = front * QUICK.config(force, speed).duration / D
        assert QUICK.radius_d < reach_d < math.sqrt(3) * (QUICK.edge_beads - 1)


def test_equal_overlap_ratios_give_equal_fronts(tmp_path):
    """In units of δ0, f0 and sqrt(m δ0/f0) the only parameter left is δ_impact/δ0: 2 N at
    1 mm/s and 20 N at 10^(5/6) mm/s (the same ratio) make the same front."""
    settings = TransitionSettings(edge_beads=21, forces_n=(2.0,), speeds_m_s=(1e-3,), radius_d=18.0, speed_from_d=8.0)
    low = run_transition(settings, tmp_path)
    high = run_transition(replace(settings, forces_n=(20.0,), speeds_m_s=(1e-3 * 10 ** (5 / 6),)), tmp_path)
    assert high.overlap_ratio[0] == pytest.approx(low.overlap_ratio[0], rel=1e-9)
    assert high.speed_ratio[0] == pytest.approx(low.speed_ratio[0], rel=0.003)
    assert high.sixfold_amplitude[0] == pytest.approx(low.sixfold_amplitude[0], rel=0.05)


def test_the_csv_rows_write_nan_empty_and_read_back(quick, tmp_path):
    write_csv(tmp_path / "transition.csv", COLUMNS, quick.rows())
    with open(tmp_path / "transition.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    assert tuple(rows[0]) == COLUMNS and len(rows) == 4
    for row, force, ratio in zip(rows, quick.forces_n, quick.speed_ratio):
        assert float(row["precompression_n"]) == force
        assert (row["speed_ratio"] == "") == (force == 0)
        assert row["speed_ratio"] == "" or float(row["speed_ratio"]) == ratio
        assert (row["overlap_ratio"] == "inf") == (force == 0)


def test_the_finding_reads_the_transition_off_the_numbers():
    """A made-up sweep: at c_L up to δ_impact/δ0 = 1, 30 % faster at 50, whose sixfold amplitude
    passes half the uncompressed front's."""
    sweep = TransitionMap(
        np.array([0.0, 20.0, 20.0, 20.0]),
        np.array([1.0, 1e-3, 0.1, 3.0]),
        np.array([math.inf, 0.01, 1.0, 50.0]),
        np.array([0.02, 0.001, 0.004, 0.015]),
        np.array([400.0, 510.0, 515.0, 660.0]),
        np.array([math.nan, 1.0, 1.01, 1.3]),
        QUICK,
    )
    finding = sweep.finding()
    assert "within 2 % up to δ_impact/δ0 = 1," in finding
    assert "5 % faster from 50 on and reach 1.30 c_L at 50" in finding
    assert "half the uncompressed front's 0.02 at 50." in finding


def test_the_map_is_drawn(quick, tmp_path):
    transition_figure(quick, tmp_path / "transition_map.png")
    assert (tmp_path / "transition_map.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "changes, words",
    [
        ({"forces_n": ()}, "forces_n must be a non-empty list"),
        ({"speeds_m_s": (0.1, -0.01)}, "speeds_m_s must hold numbers > 0 m/s"),
        ({"forces_n": (0.0, float("nan"))}, "forces_n must hold numbers ≥ 0 N"),
        ({"radius_d": 40.0}, "needs a hexagon of at least 33 per edge"),
        ({"speed_from_d": 20.0}, "need 0 < speed_from_d < radius_d"),
        ({"impact": "hammer"}, "unknown impact 'hammer'"),
    ],
)
def test_bad_settings_are_refused_in_one_line(changes, words):
    with pytest.raises(HexdemError) as error:
        TransitionSettings(**{"edge_beads": 21, "radius_d": 18.0, "speed_from_d": 8.0, **changes})
    assert words in str(error.value) and "\n" not in str(error.value)
