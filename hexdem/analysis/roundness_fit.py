r"""Where a front's roundness is heading: the sixfold amplitude A(R) against the mean radius R.

The question (Secs. III and VI-B of the paper) is whether the front of an impulse in the
uncompressed lattice becomes round as it grows, A → 0, or keeps a finite sixfold anisotropy.
:func:`fit_roundness` fits

.. math::

    A(R) = A_∞ + B\, (R/d)^{−p}

by least squares (:func:`scipy.optimize.curve_fit`) and, for comparison and where every A is
positive, the same law with A∞ = 0. A may be the signed sixfold component a6/a0 (a front whose
hexagon turns over passes through zero). The answer is A∞ with its standard error: a constant
more than two standard errors from zero is a finite anisotropy. ``radius_d`` is in bead
diameters, so B is the amplitude at R = d above A∞.
"""

from __future__ import annotations

import warnings
from dataclasses import asdict, dataclass

import numpy as np

from hexdem.errors import HexdemError

#: Fewest fronts a fit of three parameters is judged on.
MIN_FRONTS = 6


@dataclass(frozen=True)
class RoundnessFit:
    r"""``a_inf``, ``b``, ``p`` of :math:`A = a_\text{inf} + b R^{−p}` with standard errors (``*_se``); ``rms`` its
    residual; ``p_zero``, ``b_zero``, ``rms_zero`` of the law with a_inf = 0 (NaN unless every A
    is positive); the fronts used (``n_fronts``) and their radii (``radius_min_d``,
    ``radius_max_d``); ``finite``: a_inf is more than two standard errors from zero."""

    a_inf: float
    a_inf_se: float
    b: float
    b_se: float
    p: float
    p_se: float
    rms: float
    p_zero: float
    b_zero: float
    rms_zero: float
    n_fronts: int
    radius_min_d: float
    radius_max_d: float

    @property
    def finite(self) -> bool:
        return bool(abs(self.a_inf) > 2.0 * self.a_inf_se)

    def as_dict(self) -> dict:
        return {**asdict(self), "finite": self.finite}

    def __call__(self, radius_d):
        """The fitted law at ``radius_d``."""
        return self.a_inf + self.b * np.asarray(radius_d, float) ** -self.p


def _power_law(radius, a_inf, b, p):
    return a_inf + b * radius**-p


def fit_roundness(radius_d, amplitude, radius_min_d: float = 5.0, radius_max_d: float = np.inf) -> RoundnessFit:
    """Fit :math:`A(R) = A_∞ + B R^{−p}` to the fronts with ``radius_min_d`` <= R <= ``radius_max_d`` (see
    the module docstring)."""
    from scipy.optimize import OptimizeWarning, curve_fit

    radius_d, amplitude = np.asarray(radius_d, float), np.asarray(amplitude, float)
    use = np.isfinite(radius_d) & np.isfinite(amplitude) & (radius_d >= radius_min_d) & (radius_d <= radius_max_d)
    r, a = radius_d[use], amplitude[use]
    if len(r) < MIN_FRONTS or r.max() < 2 * r.min():
        raise HexdemError(
            f"a roundness fit needs at least {MIN_FRONTS} fronts over a factor 2 in radius beyond "
            f"{radius_min_d:g} d, got {len(r)}" + (f" from {r.min():.3g} to {r.max():.3g} d" if len(r) else "")
        )
    b_zero = p_zero = rms_zero = float("nan")
    if np.all(a > 0):
        slope, intercept = np.polyfit(np.log(r), np.log(a), 1)  # the pure power law on log scales: a start
        with warnings.catch_warnings():  # only the parameters of the comparison law are used, not their errors
            warnings.simplefilter("ignore", OptimizeWarning)
            try:
                (b_zero, p_zero), _ = curve_fit(
                    lambda x, b, p: _power_law(x, 0.0, b, p), r, a, p0=(float(np.exp(intercept)), -slope), maxfev=20000
                )
                rms_zero = float(np.sqrt(np.mean((_power_law(r, 0.0, b_zero, p_zero) - a) ** 2)))
            except RuntimeError:  # the comparison law does not fit: left as NaN
                pass
    start = (float(a[np.argmax(r)]), float((a[np.argmin(r)] - a[np.argmax(r)]) * r.min()), 1.0)
    try:
        params, covariance = curve_fit(_power_law, r, a, p0=start, maxfev=20000)
    except RuntimeError as exc:  # curve_fit's "optimal parameters not found"
        raise HexdemError(f"the roundness fit over {r.min():.3g}-{r.max():.3g} d did not converge: {exc}") from None
    errors = np.sqrt(np.diag(covariance))
    rms = float(np.sqrt(np.mean((_power_law(r, *params) - a) ** 2)))
    return RoundnessFit(
        float(params[0]),
        float(errors[0]),
        float(params[1]),
        float(errors[1]),
        float(params[2]),
        float(errors[2]),
        rms,
        float(p_zero),
        float(b_zero),
        rms_zero,
        int(len(r)),
        float(r.min()),
        float(r.max()),
    )
