"""The spread of a record's observables between packings, as a function of the parameters.

On disordered packings the observables of one parameter set differ from packing to packing,
and a measured record is one packing: its likelihood holds that spread Σ_K(u) besides its
noise (:mod:`~hexdem.calibration.inference`). Σ_K depends on the parameters: it vanishes with
the disorder, grows with σ, and changes with the striker speed or the dissipation. On packings
prepared as the paper's (:mod:`~hexdem.disorder.preparation`) it grows within the compaction's
overlaps (a few 0.1 µm) and is as large at 5 µm as at 140 µm: which neighbours touch is then set
by the signs of the diameters' deviations. It is modelled as

    Σ_K(u) = diag s(u) · R · diag s(u),

with s_j(u) the standard deviation of observable j between packings, emulated
(:class:`~hexdem.calibration.emulator.Emulator`, a linear trend and a process that may be nearly
all nugget: the sets share their packings, so what varies between them is small) from each
parameter set's sample standard deviation over its K packings whose pulse the sensors detect, less
its bias (:func:`sd_bias`), and R the correlation between the
observables (a slow packing's arrivals are late at every later sensor together), pooled over the
parameter sets from the deviations scaled by the emulated s (each set's own sample standard
deviation would bias the correlation towards zero: with K = 8, 0.77 for 0.8), with the records'
own scatter where there are several records (each an independent packing: R − 1 more directions
than the K packings' K − 1), and shrunk towards the identity only as far as those directions
fall short of the observables (:func:`shrunk_correlation`).

**What K packings cannot tell.** Every parameter set is simulated on the same K packings, so the
sample standard deviations share one error: their scale is known from K − 1 degrees of freedom
only, to some 25 % at K = 8, the same for every σ. The likelihood therefore takes
Σ_K,true = λ Σ_K with λ unknown, inverse-gamma as (K − 1)/X with X of the χ² law of K − 1
degrees of freedom (:meth:`Spread.scale`), sampled with the parameters
(:mod:`~hexdem.calibration.inference`): the records, independent packings, tell λ further.
One packing per set (the ideal lattice) has no spread.
"""

from __future__ import annotations

import numpy as np
from scipy.special import gammaln

from hexdem.calibration.emulator import Emulator

#: The emulator's nugget bound for what the K shared packings' sampling error makes jump from one
#: parameter set to another: s's (its error common to every set the scale λ takes), and along σ the
#: mean's too (:func:`~hexdem.calibration.inference.fit_stage`).
NOISY_NUGGET = 10.0
#: The degrees of freedom of a record's deviation between packings (:meth:`Spread.record_scale`): a
#: tail heavy enough for a packing whose pulse takes a weak path (a deviation of 15 standard deviations
#: costs 10 in log density where a Gaussian's costs 112), with a finite variance.
RECORD_TAIL_DOF = 4
#: Standard deviations between packings are floored here (observables are of order one): a
#: parameter set whose packings agree exactly (σ = 0) keeps a spread of full rank.
SD_FLOOR = 1e-9


def sd_bias(realizations: int) -> float:
    """E[s] / σ of the sample standard deviation s of K normal values, c₄(K) =
    √(2/(K − 1)) Γ(K/2) / Γ((K − 1)/2)."""
    return float(
        np.sqrt(2.0 / (realizations - 1)) * np.exp(gammaln(realizations / 2) - gammaln((realizations - 1) / 2))
    )


def variance_ratio(unit, dof: float) -> np.ndarray:
    """The quantiles ``unit`` of ν/X, X of the χ² law of ν = ``dof`` degrees of freedom: inverse-gamma
    with shape and scale ν/2, the true variance over one estimated from ν degrees of freedom."""
    from scipy.stats import invgamma

    half = dof / 2
    return invgamma.ppf(np.clip(np.asarray(unit, float), 1e-12, 1 - 1e-12), half, scale=half)


def shrunk_correlation(sample, dof: int) -> np.ndarray:
    """The correlation between observables from ``sample``, the correlation of ``dof`` = ν
    independent deviations, shrunk towards the identity: (ν R̂ + w I) / (ν + w), w = max(m + 1 − ν, 1).

    Every parameter set is simulated on the same K packings (:mod:`~hexdem.calibration.packings`),
    so their deviations from the mean, however many sets are pooled, are K − 1 independent vectors
    (and the records R − 1 more): for ν < m observables R̂ is singular, and a record whose packing
    deviates in a direction the packings never took would count as impossible. The estimate is
    that of an inverse-Wishart prior centred on the identity, updated with the ν deviations, and
    worth as many packings as ν falls short of m + 1 (at least one): it stays positive definite.
    A prior worth m + 1 packings whatever ν is would flatten correlations the data hold (0.9 read
    as 0.42 at ν = 7, m = 7), and widen the spread across the common direction where the
    packings deviate least: a record's σ then came out low (docs/validation/benchmarks.md)."""
    size = len(sample)
    weight = max(size + 1 - dof, 1)
    return (dof * np.asarray(sample, float) + weight * np.eye(size)) / (dof + weight)


def records_correlation(scatter) -> np.ndarray:
    """The correlation of the packings' deviations that the records' own ``scatter`` shows (their
    covariance less what their noise and the striker's speed add, (m, m)), its eigenvalues floored
    at a thousandth of the largest so that it is one."""
    values, vectors = np.linalg.eigh(np.asarray(scatter, float))
    values = np.maximum(values, 1e-3 * max(values.max(), SD_FLOOR**2))
    covariance = (vectors * values) @ vectors.T
    norm = np.sqrt(np.diag(covariance))
    return covariance / np.outer(norm, norm)


class Spread:
    """Σ_K(u) fitted to simulations at unit-cube ``points`` (n, p) with ``observables`` (n, K, m), NaN
    for a packing whose pulse the sensors do not detect (left out; a set with fewer than two
    detected packings tells no spread);
    with ``scatter``, the records' own covariance between packings (:func:`records_correlation`)
    from ``scatter_dof`` independent records' deviations, pooled into the correlation: records of
    independent packings are more independent directions than the K packings' K − 1; ``smooth``,
    the dimensions along which s is smooth over the whole prior
    (:class:`~hexdem.calibration.emulator.Emulator`)."""

    def __init__(self, points, observables, scatter=None, scatter_dof: int = 0, smooth=()):
        observables = np.asarray(observables, float)
        n, self.realizations, self.size = observables.shape
        if self.realizations < 2:
            return
        valid = np.isfinite(observables[..., 0])
        counts = valid.sum(axis=1)
        usable = counts >= 2
        points, observables, valid, counts = points[usable], observables[usable], valid[usable], counts[usable]
        mean = np.nanmean(observables, axis=1, keepdims=True)
        centred = np.where(valid[..., None], observables - mean, 0.0)
        sd = np.sqrt(np.sum(centred**2, axis=1) / (counts - 1)[:, None])
        bias = np.array([sd_bias(count) for count in counts])
        self.sd = Emulator(points, sd / bias[:, None], nugget_max=NOISY_NUGGET, smooth=smooth)
        self.dof = int(np.median(counts)) - 1
        scaled = centred / self._sd(points)[:, None, :]
        pooled = np.einsum("nki,nkj->ij", scaled, scaled)
        norm = np.sqrt(np.diag(pooled))
        simulated, dof = pooled / np.outer(norm, norm), self.dof
        if scatter is not None and scatter_dof > 0:
            simulated = (dof * simulated + scatter_dof * records_correlation(scatter)) / (dof + scatter_dof)
            dof += scatter_dof
        self.correlation = shrunk_correlation(simulated, dof)

    def __call__(self, unit) -> np.ndarray:
        """Σ_K (k, m, m) at unit-cube points ``unit`` (k, p)."""
        unit = np.atleast_2d(unit)
        if self.realizations < 2:
            return np.zeros((len(unit), self.size, self.size))
        sd = self._sd(unit)
        return sd[:, :, None] * self.correlation * sd[:, None, :]

    def scale(self, unit) -> np.ndarray:
        """The spread's scale λ (Σ_K,true = λ Σ_K) at unit coordinates ``unit`` (k,): the K packings'
        sample variances, shared by every parameter set, carry K − 1 degrees of freedom (the median
        set's detected packings less one), so the true variance over theirs is (K − 1)/X, X of the χ²
        law of K − 1 degrees of freedom: inverse-gamma with shape and scale (K − 1)/2."""
        return variance_ratio(unit, self.dof)

    def record_scale(self, unit) -> np.ndarray:
        """Each record's packing scale λ_r (its deviation ~ N(0, λ_r Σ_K)) at unit coordinates ``unit``:
        inverse-gamma with shape and scale ν/2, ν = :data:`RECORD_TAIL_DOF`, so that a record's
        deviation is a Student-t of ν degrees of freedom."""
        return variance_ratio(unit, RECORD_TAIL_DOF)

    def _sd(self, unit) -> np.ndarray:
        return np.maximum(self.sd.predict(unit)[0], SD_FLOOR)
