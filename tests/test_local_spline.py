"""The NumPy cubic spline of the peak refinement and the Delaunay field of the front shape
against the SciPy interpolators they replace, on random samples."""

import numpy as np
import pytest
from scipy.interpolate import CubicSpline, LinearNDInterpolator

from hexdem.analysis.front_shape import linear_field
from hexdem.analysis.local_spline import LocalSpline


@pytest.mark.parametrize("points", [2, 3, 4, 5, 7])
def test_the_local_spline_is_scipys_not_a_knot_spline(points):
    rng = np.random.default_rng(points)
    for _ in range(200):
        t = np.cumsum(rng.uniform(0.5, 1.5, points)) * 1e-6
        y = rng.uniform(0.0, 1.0, points)
        ours, theirs = LocalSpline(t, y), CubicSpline(t, y)
        grid = np.linspace(t[0], t[-1], 41)
        np.testing.assert_allclose(ours(grid), theirs(grid), rtol=0, atol=1e-13)
        np.testing.assert_allclose(
            ours.stationary_points(), np.sort(theirs.derivative().roots(extrapolate=False)), rtol=0, atol=1e-18
        )
        np.testing.assert_allclose(
            ours.crossings(0.5), np.sort(theirs.solve(0.5, extrapolate=False)), rtol=0, atol=1e-18
        )


def test_a_spline_through_a_cubic_is_that_cubic():
    t = np.array([0.0, 0.3, 1.0, 1.1, 2.0, 2.5, 3.0])
    cubic = np.polynomial.Polynomial([0.2, -1.0, 0.5, 0.1])
    spline = LocalSpline(t, cubic(t))
    grid = np.linspace(0, 3, 31)
    np.testing.assert_allclose(spline(grid), cubic(grid), atol=1e-12)
    stationary = np.sort(cubic.deriv().roots().real)
    np.testing.assert_allclose(
        spline.stationary_points(), stationary[(stationary >= 0) & (stationary <= 3)], atol=1e-12
    )


def test_the_linear_field_is_scipys_linear_interpolator():
    rng = np.random.default_rng(1)
    points, values = rng.uniform(-1, 1, (300, 2)), rng.uniform(0, 1, 300)
    xi = rng.uniform(-1.2, 1.2, (50, 40, 2))
    ours, theirs = linear_field(points, values)(xi), LinearNDInterpolator(points, values)(xi)
    assert np.array_equal(np.isnan(ours), np.isnan(theirs))
    np.testing.assert_allclose(ours, theirs, atol=1e-14)
