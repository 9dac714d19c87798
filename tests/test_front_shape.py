"""Roundness of a wavefront on synthetic arrival-time fields whose fronts are known exactly.

Beads sit on a triangular lattice of spacing 1 (lengths in bead diameters). A front moving
at speed C from the origin is a circle of radius C·t; a front with hexagonal arrival times is
a regular hexagon whose relative sixfold amplitude is derived here by quadrature.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from hexdem.analysis.front_shape import (
    FRONT_SHAPE_COLUMNS,
    HEXAGON_SIXFOLD,
    FrontShape,
    front_radius,
    front_shape,
    front_times,
    sixfold_roundness,
)
from hexdem.analysis.plotting import front_shape_figure
from hexdem.errors import HexdemError
from hexdem.model.triangular import hexagon

C = 2.0  # front speed, bead diameters per time unit
ORIGIN = np.zeros(2)


def triangular_disc(radius, half_plane=False):
    """Triangular-lattice points (spacing 1) within ``radius`` of the origin, optionally only x >= 0."""
    i, j = np.meshgrid(np.arange(-radius - 1, radius + 2), np.arange(-radius - 1, radius + 2))
    points = np.column_stack([(i + 0.5 * j).ravel(), (j * np.sqrt(3) / 2).ravel()])
    keep = np.hypot(*points.T) <= radius
    if half_plane:
        keep &= points[:, 0] >= -1e-9
    return points[keep]


def hexagon_gauge(points, theta0):
    """Circumradius of the regular hexagon through each point, centred on the origin, a vertex at ``theta0``."""
    r, theta = np.hypot(*points.T), np.arctan2(points[:, 1], points[:, 0])
    phi = np.mod(theta - theta0, np.pi / 3) - np.pi / 6
    return r * np.cos(phi) / np.cos(np.pi / 6)


def hexagon_fourier():
    """(a0, |a6|) of a unit-apothem regular hexagon's polar radius, by quadrature over its six corners."""

    def radius(theta):
        return 1.0 / np.cos(np.mod(theta, np.pi / 3) - np.pi / 6)

    corners = np.arange(1, 6) * np.pi / 3
    a0 = quad(radius, 0, 2 * np.pi, points=corners, limit=200)[0] / (2 * np.pi)
    a6 = quad(lambda t: radius(t) * np.cos(6 * t), 0, 2 * np.pi, points=corners, limit=200)[0] / np.pi
    b6 = quad(lambda t: radius(t) * np.sin(6 * t), 0, 2 * np.pi, points=corners, limit=200)[0] / np.pi
    return a0, np.hypot(a6, b6)


def test_the_module_constant_is_the_hexagons_amplitude():
    a0, a6 = hexagon_fourier()
    assert a0 == pytest.approx(3 * np.log(3) / np.pi, rel=1e-10)
    assert a6 / a0 == pytest.approx(HEXAGON_SIXFOLD, rel=1e-9)
    assert HEXAGON_SIXFOLD == pytest.approx(0.058156, abs=1e-6)


@pytest.mark.parametrize("theta0", [0.0, 0.4, 1.0])
def test_the_fit_recovers_a_pure_sixfold_shape_over_a_half_plane_at_any_orientation(theta0):
    theta = np.linspace(-np.pi / 2, np.pi / 2, 37)[1:-1]
    mean, amplitude = sixfold_roundness(theta, 10.0 + 0.7 * np.cos(6 * (theta - theta0)))
    assert mean == pytest.approx(10.0, rel=1e-12)
    assert amplitude == pytest.approx(0.07, rel=1e-12)


def test_a_circular_front_is_round_with_radius_speed_times_time():
    points = triangular_disc(40)
    arrival = np.hypot(*points.T) / C
    for time in (2.5, 5.0, 10.0, 17.5):
        theta, radius = front_radius(points, arrival, ORIGIN, time)
        assert np.isfinite(radius).all()
        mean, amplitude = sixfold_roundness(theta, radius)
        assert amplitude < 1e-2
        assert mean == pytest.approx(C * time, abs=0.1)


@pytest.mark.parametrize("theta0_deg", [0.0, 30.0])
def test_a_hexagonal_front_over_a_half_plane_has_the_hexagons_amplitude(theta0_deg):
    a0_unit, a6_unit = hexagon_fourier()
    points = triangular_disc(45, half_plane=True)
    arrival = hexagon_gauge(points, np.radians(theta0_deg)) / C
    shape = front_shape(points, arrival, ORIGIN, [5.0, 10.0, 15.0])
    assert (shape.bins_used > 60).all()
    assert shape.sixfold_amplitude == pytest.approx(np.full(3, a6_unit / a0_unit), rel=0.03)
    apothem = C * shape.time * np.cos(np.pi / 6)
    assert shape.mean_radius == pytest.approx(a0_unit * apothem, rel=0.005)


def test_rays_outside_the_beads_and_beads_never_reached_give_no_front():
    points = triangular_disc(40, half_plane=True)
    r = np.hypot(*points.T)
    arrival = np.where(r <= 25.0, r / C, np.nan)
    theta, radius = front_radius(points, arrival, ORIGIN, 7.5)
    assert np.isnan(radius[np.abs(theta) > np.pi / 2]).all()
    assert np.isfinite(radius[np.abs(theta) < np.radians(85)]).all()
    assert radius[np.isfinite(radius)] == pytest.approx(15.0, abs=0.1)
    _, beyond = front_radius(points, arrival, ORIGIN, 15.0)
    assert np.isnan(beyond).all()
    assert np.isnan(sixfold_roundness(theta, beyond)).all()


def test_beads_with_unknown_arrival_times_are_ignored():
    points = triangular_disc(40)
    arrival = np.hypot(*points.T) / C
    lost = np.random.default_rng(3).random(len(points)) < 0.2
    lost[np.hypot(*points.T) == 0] = False
    arrival[lost] = np.nan
    theta, radius = front_radius(points, arrival, ORIGIN, 10.0)
    assert np.isfinite(radius).all()
    mean, amplitude = sixfold_roundness(theta, radius)
    assert amplitude < 1e-2
    assert mean == pytest.approx(20.0, abs=0.1)


def test_too_few_finite_bins_give_nan():
    theta = np.linspace(-1, 1, 10)
    radius = np.full(10, np.nan)
    radius[:3] = 5.0
    assert np.isnan(sixfold_roundness(theta, radius)).all()


def test_front_times_without_enough_bins_are_nan_rows():
    points = triangular_disc(20, half_plane=True)
    shape = front_shape(points, np.hypot(*points.T) / C, ORIGIN, [-1.0, 5.0, 50.0])
    assert shape.bins_used.tolist()[0::2] == [0, 0]
    assert np.isnan(shape.mean_radius[0::2]).all() and np.isnan(shape.sixfold_amplitude[0::2]).all()
    assert shape.mean_radius[1] == pytest.approx(10.0, abs=0.1)
    assert [len(row) for row in shape.rows()] == [len(FRONT_SHAPE_COLUMNS)] * 3


def test_front_times_end_when_the_front_is_readable_over_only_60_degrees():
    """A circular front in the 11-per-edge hexagon struck at the centre of its vertical left edge
    (edge length L = 10): rays within ±16° leave through the far wall (x = √3 L), the others
    through the slanted walls, at 3√3 L / (4 sin(30° + |θ|)) beyond ±16°, nearer the further
    they turn. The 24 rays of 2.5° (60°) that reach farthest end at ±28.75°: the front is readable
    over 60° until it is within the margin of that wall there."""
    lattice = hexagon(11, 1.0)
    points = lattice.positions_m
    origin = points[lattice.struck]
    arrival = np.hypot(*(points - origin).T) / C
    for margin in (0.0, 2.0):
        times = front_times(points, arrival, origin, count=5, wall_margin=margin)
        assert times[-1] * C == pytest.approx(3 * np.sqrt(3) * 10 / 4 / np.sin(np.radians(58.75)) - margin, abs=0.05)
        assert times[0] == pytest.approx(np.quantile(arrival, 0.05))
        assert np.all(np.diff(times) > 0) and len(times) == 5
        shape = front_shape(points, arrival, origin, [times[-1] * 0.999, times[-1] * 1.01], wall_margin=margin)
        assert shape.bins_used.tolist() == [24, 22] and shape.sixfold_amplitude[0] < 1e-2
    geometric = front_times(points, arrival, origin, count=5, geometric=True)
    assert np.diff(np.log(geometric)) == pytest.approx(np.full(4, np.log(geometric[1] / geometric[0])))


def test_a_ray_is_read_only_until_the_front_nears_the_packings_edge():
    """The half disc of radius 30 of triangular_disc (cut at |y| <= 31 √3/2 = 26.8): every ray of
    the half plane leaves it between 26.8 and 30. A circular front is seen along all 72 rays of the
    half plane until it comes within the margin of that edge, and along none once it is past."""
    points = triangular_disc(30, half_plane=True)
    arrival = np.hypot(*points.T) / C
    for margin in (0.0, 3.0):
        shape = front_shape(points, arrival, ORIGIN, (np.array([26.7, 30.1]) - margin) / C, wall_margin=margin)
        assert shape.bins_used.tolist() == [72, 0]


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: front_radius(np.zeros((5, 2)), np.zeros(4), ORIGIN, 1.0), "arrival times"),
        (lambda: front_radius(triangular_disc(5), np.zeros(len(triangular_disc(5))), ORIGIN, 1.0, n_bins=6), "n_bins"),
        (lambda: front_radius(np.zeros((3, 3)), np.zeros(3), ORIGIN, 1.0), "positions"),
        (lambda: front_radius(np.eye(2), np.zeros(2), ORIGIN, 1.0), "3 beads or more"),
        (
            lambda: front_radius(np.outer(np.arange(5.0), [np.cos(0.5), np.sin(0.5)]), np.arange(5.0), ORIGIN, 1.0),
            "one line",
        ),
        (lambda: sixfold_roundness(np.zeros(5), np.zeros(4)), "matching"),
    ],
)
def test_bad_input_is_a_one_line_hexdem_error(call, message):
    with pytest.raises(HexdemError, match=message) as error:
        call()
    assert "\n" not in str(error.value)


def test_front_shape_figure_is_written(tmp_path):
    points = triangular_disc(30, half_plane=True)
    times = [4.0, 8.0, 12.0]
    curves = {
        "circle": front_shape(points, np.hypot(*points.T) / C, ORIGIN, times),
        "hexagon": front_shape(points, hexagon_gauge(points, 0.0) / C, ORIGIN, times),
    }
    assert all(isinstance(shape, FrontShape) for shape in curves.values())
    front_shape_figure(curves, tmp_path / "front_shape.png")
    assert (tmp_path / "front_shape.png").read_bytes().startswith(b"\x89PNG")


def test_the_front_study_follows_a_hexagonal_front_that_rounds_as_it_grows(tmp_path):
    """The study on a half-disc of radius 34 d (its 60° window readable from 5 to 24 d) and a
    24-per-edge control: the uncompressed front starts as a hexagon (A within 15 % of a regular
    hexagon's at 5 d) and its sixfold amplitude falls as it grows; both packings are fitted and
    every file is written."""
    from hexdem.experiments.front_study import STUDY_COLUMNS, FrontStudy, run_front_study

    study = FrontStudy(
        edge_beads=24, radius_beads=34, ranks=1, fronts=16, fit_range_d=(5.0, 25.0), control_fit_range_d=(5.0, 25.0)
    )
    summary = run_front_study(study, tmp_path, log=lambda message: None)
    with open(tmp_path / "front_shape.csv") as fh:
        header, *rows = [line.strip().split(",") for line in fh]
    assert tuple(header) == STUDY_COLUMNS
    uncompressed = np.array([[float(r[2]), float(r[3])] for r in rows if r[0] == "uncompressed"])
    uncompressed = uncompressed[np.isfinite(uncompressed).all(axis=1)]
    radius, amplitude = uncompressed.T
    assert radius.min() < 5.5 and radius.max() > 20.0
    assert amplitude[np.argmin(np.abs(radius - 5.0))] == pytest.approx(HEXAGON_SIXFOLD, rel=0.15)
    assert np.all(np.diff(amplitude) < 0)
    assert set(summary["fits"]) == {"uncompressed", "precompressed"}
    assert (tmp_path / "front_shape.png").read_bytes().startswith(b"\x89PNG")
