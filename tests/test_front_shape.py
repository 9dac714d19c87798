"""Roundness of a wavefront on synthetic arrival-time fields whose fronts are known exactly.

Beads sit on a triangular lattice of spacing 1 (lengths in bead diameters). A front moving
at speed C from the origin is a circle of radius C·t; a front with hexagonal arrival times is
a regular hexagon whose relative sixfold amplitude is derived here by quadrature.
"""

import numpy as np
import pytest
from scipy.integrate import quad

from hexdem.analysis.figures import front_shape_figure
from hexdem.analysis.front_shape import (
    FRONT_SHAPE_COLUMNS,
    HEXAGON_SIXFOLD,
    FrontShape,
    default_front_times,
    front_radius,
    front_shape,
    sixfold_roundness,
)
from hexdem.errors import HexdemError
from hexdem.model.lattice import hexagon

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


def test_default_times_end_when_the_front_reaches_the_corners_of_the_struck_edge():
    lattice = hexagon(11, 1.0)
    points = lattice.positions_m
    origin = points[lattice.struck]
    arrival = np.hypot(*(points - origin).T) / C
    times = default_front_times(points, arrival, origin, count=5)
    # The struck edge runs 5 beads either side of the struck bead; every other wall is farther.
    assert times[-1] == pytest.approx(5.0 / C)
    assert times[0] == pytest.approx(np.quantile(arrival, 0.05))
    assert np.all(np.diff(times) > 0) and len(times) == 5


@pytest.mark.parametrize("call, message", [
    (lambda: front_radius(np.zeros((5, 2)), np.zeros(4), ORIGIN, 1.0), "arrival times"),
    (lambda: front_radius(triangular_disc(5), np.zeros(len(triangular_disc(5))), ORIGIN, 1.0, n_bins=6), "n_bins"),
    (lambda: front_radius(np.zeros((3, 3)), np.zeros(3), ORIGIN, 1.0), "positions"),
    (lambda: front_radius(np.eye(2), np.zeros(2), ORIGIN, 1.0), "too few"),
    (lambda: sixfold_roundness(np.zeros(5), np.zeros(4)), "matching"),
])
def test_bad_input_is_a_one_line_hexdem_error(call, message):
    with pytest.raises(HexdemError, match=message) as error:
        call()
    assert "\n" not in str(error.value)


def test_front_shape_figure_is_written(tmp_path):
    points = triangular_disc(30, half_plane=True)
    times = [4.0, 8.0, 12.0]
    curves = {"circle": front_shape(points, np.hypot(*points.T) / C, ORIGIN, times),
              "hexagon": front_shape(points, hexagon_gauge(points, 0.0) / C, ORIGIN, times)}
    assert all(isinstance(shape, FrontShape) for shape in curves.values())
    front_shape_figure(curves, tmp_path / "front_shape.png")
    assert (tmp_path / "front_shape.png").read_bytes().startswith(b"\x89PNG")
