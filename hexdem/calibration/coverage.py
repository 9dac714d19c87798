"""Checks of a calibration's coverage over truths drawn from its prior: rank ECDFs with simultaneous
bands, the expected coverage over every credibility level, and the power of both.

**Ranks** (simulation-based calibration, Talts et al. 2018). For each of N truths θ drawn from the
prior, the fraction of the posterior's draws below θ (one key at a time) is uniform on [0, 1]
when the posteriors are right. :func:`ecdf_band` gives the simultaneous band of the fractions'
empirical distribution function (Säilynoja, Bürkner & Vehtari 2022): pointwise binomial bands at
a level γ chosen so that a uniform sample's ECDF leaves the band at any of the evaluation points
with probability α, found by simulating uniform samples. A table of central-interval coverages
tests one level at a time; the band tests them all at once, at the stated α.

**Expected coverage** (TARP, Lemos, Coogan, Hezaveh & Perreault-Levasseur 2023): for each truth
a reference point θ_ref drawn from the prior, and the share f of the posterior's draws nearer to
θ_ref than θ is (in the priors' unit cube). The expected coverage of the balls around θ_ref at
credibility 1 − α is the share of truths with f < 1 − α; a calibrated posterior gives the
diagonal (f uniform), and the joint posterior of every key is tested at once, against the same
simultaneous band as the ranks. Its summary, the area between the curve and the diagonal
(:func:`tarp`), sees a bias; a spread too narrow or too wide bends the curve both ways about the
diagonal, which the band sees.

**Power** (:func:`ecdf_power`): the chance that the band sees a posterior whose spread is off by a
factor s (a normal posterior s times as wide as the right one, so that its 90 % central interval
covers 2Φ(1.645 s) − 1), with N truths: what a table of N truths can and cannot detect.
"""

from __future__ import annotations

import numpy as np
from scipy.stats import binom, norm

#: Points at which a rank ECDF is checked against its band (the fractions' deciles and finer).
BAND_POINTS = 99
#: Uniform samples simulated to set a band's pointwise level.
BAND_SIMULATIONS = 4000


def fractional_ranks(draws, truths) -> np.ndarray:
    """The fraction (N,) of each truth's posterior ``draws`` (N, L) below its ``truths`` (N,)."""
    return np.mean(np.asarray(draws, float) < np.asarray(truths, float)[:, None], axis=1)


def _ecdf(fractions, points) -> np.ndarray:
    """The ECDF of each row of ``fractions`` (S, N) at ``points`` (P,): (S, P)."""
    return np.mean(np.asarray(fractions)[..., None] <= points, axis=-2)


def ecdf_band(count: int, alpha: float = 0.05, seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(points (P,), lower (P,), upper (P,)): the simultaneous 1 − ``alpha`` band of the ECDF of
    ``count`` uniform fractions at BAND_POINTS evenly spaced points (Säilynoja et al. 2022)."""
    points = np.arange(1, BAND_POINTS + 1) / (BAND_POINTS + 1)
    rng = np.random.default_rng(seed)
    ecdf = _ecdf(rng.random((BAND_SIMULATIONS, count)), points) * count
    tail = np.minimum(binom.cdf(ecdf, count, points), binom.sf(ecdf - 1, count, points))
    gamma = 2 * float(np.quantile(tail.min(axis=1), alpha))
    return points, binom.ppf(gamma / 2, count, points) / count, binom.isf(gamma / 2, count, points) / count


def outside_band(fractions, band):
    """Whether the ECDF of ``fractions`` (N,) leaves ``band`` (:func:`ecdf_band`) anywhere; for
    ``fractions`` (S, N), whether each row's does (S,)."""
    points, lower, upper = band
    fractions = np.asarray(fractions)
    ecdf = _ecdf(np.atleast_2d(fractions), points)
    outside = np.any((ecdf < lower) | (ecdf > upper), axis=1)
    return bool(outside[0]) if fractions.ndim == 1 else outside


def ecdf_power(count: int, scale: float, alpha: float = 0.05, trials: int = 2000, seed: int = 0) -> float:
    """The chance that :func:`ecdf_band` of ``count`` truths sees a normal posterior ``scale`` times as
    wide as the right one: the truth's fraction is then Φ(z / scale), z standard normal."""
    band = ecdf_band(count, alpha, seed)
    rng = np.random.default_rng(seed + 1)
    fractions = norm.cdf(rng.standard_normal((trials, count)) / scale)
    return float(np.mean(outside_band(fractions, band)))


def central_coverage(scale: float, level: float = 0.9) -> float:
    """The true coverage of a ``level`` central interval of a normal posterior ``scale`` times as wide
    as the right one."""
    return float(2 * norm.cdf(norm.ppf(0.5 + level / 2) * scale) - 1)


def tarp(draws, truths, references) -> tuple[np.ndarray, np.ndarray, float, np.ndarray]:
    """(credibility levels (101,), expected coverage at each, the area between the curve and the
    diagonal, each truth's share f (N,)) of posteriors ``draws`` (N, L, p) of ``truths`` (N, p) with
    ``references`` (N, p), all in the priors' unit cube (see the module docstring). The shares are
    uniform for calibrated posteriors: :func:`outside_band` tests them at every level at once."""
    draws, truths, references = (np.asarray(a, float) for a in (draws, truths, references))
    near = np.linalg.norm(draws - references[:, None, :], axis=-1)
    radius = np.linalg.norm(truths - references, axis=-1)
    shares = np.mean(near < radius[:, None], axis=1)
    levels = np.linspace(0, 1, 101)
    coverage = np.mean(shares[:, None] < levels, axis=0)
    return levels, coverage, float(np.trapezoid(coverage - levels, levels)), shares
