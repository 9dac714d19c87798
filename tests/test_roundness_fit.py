"""The roundness law A(R) = A∞ + B R^−p is recovered from exact and noisy synthetic fronts."""

import numpy as np
import pytest

from hexdem.analysis.roundness_fit import fit_roundness
from hexdem.errors import HexdemError

RADII = np.geomspace(5.0, 150.0, 30)


@pytest.mark.parametrize("a_inf, b, p", [(0.0, 0.4, 0.8), (0.012, 0.3, 1.2)])
def test_an_exact_law_is_recovered(a_inf, b, p):
    fit = fit_roundness(RADII, a_inf + b * RADII**-p)
    assert (fit.a_inf, fit.b, fit.p) == pytest.approx((a_inf, b, p), abs=1e-7)
    assert fit.rms < 1e-9 and fit.n_fronts == 30
    assert fit(RADII) == pytest.approx(a_inf + b * RADII**-p, abs=1e-8)


def test_noise_gives_an_error_bar_that_covers_the_constant():
    rng = np.random.default_rng(7)
    amplitude = 0.01 + 0.3 * RADII**-1.0 + rng.normal(0.0, 5e-4, RADII.size)
    fit = fit_roundness(RADII, amplitude)
    assert abs(fit.a_inf - 0.01) < 3 * fit.a_inf_se and fit.finite
    assert fit.rms < fit.rms_zero, "the constant is needed"


def test_fronts_inside_the_minimum_radius_are_left_out_and_too_few_are_refused():
    amplitude = 0.2 * RADII**-0.5 + np.random.default_rng(1).normal(0.0, 1e-4, RADII.size)
    assert fit_roundness(RADII, amplitude, radius_min_d=20.0).radius_min_d >= 20.0
    with pytest.raises(HexdemError, match="at least 6 fronts"):
        fit_roundness(RADII[:4], amplitude[:4])


def test_a_signed_component_that_turns_over_is_fitted_and_its_constant_is_finite():
    """a6/a0 = −0.01 + 0.3 R^−0.8 crosses zero at R = 30^(1/0.8) ≈ 70 d: the law is recovered, its
    negative constant is finite, and the pure power law (positive data only) is not fitted."""
    amplitude = -0.01 + 0.3 * RADII**-0.8 + np.random.default_rng(3).normal(0.0, 1e-4, RADII.size)
    fit = fit_roundness(RADII, amplitude)
    assert fit.a_inf == pytest.approx(-0.01, abs=3 * fit.a_inf_se) and fit.finite
    assert fit.p == pytest.approx(0.8, rel=0.1) and np.isnan(fit.p_zero)
