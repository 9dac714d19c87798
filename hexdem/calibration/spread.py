"""The spread of a record's observables between packings, as a function of the parameters.

On disordered packings the observables of one parameter set differ from packing to packing,
and a measured record is one packing: its likelihood holds that spread Σ_K(u) besides its
noise (:mod:`~hexdem.calibration.inference`). Σ_K depends on the parameters: it vanishes with
the disorder, grows with σ (as σ² while the disorder is weak, the observables' deviations then
being linear in the diameters' deviations σ z), and changes with the striker speed or the
dissipation. It is modelled as

    Σ_K(u) = diag s(u) · R · diag s(u),

with s_j(u) the standard deviation of observable j between packings, emulated as log s_j
(:class:`~hexdem.calibration.emulator.Emulator`, its nugget free to take the sampling noise)
from each parameter set's sample standard deviation over its K packings, less its bias
(:func:`log_sd_bias`), and R the correlation between the observables (a slow packing's
arrivals are late at every later sensor together), pooled over the parameter sets from the
deviations scaled by the emulated s (each set's own sample standard deviation would bias the
correlation towards zero: with K = 8, 0.77 for 0.8), and shrunk towards the identity, as the sets
share their K packings (:func:`shrunk_correlation`). One packing per set (the ideal lattice) has
no spread.
"""

from __future__ import annotations

import numpy as np
from scipy.special import digamma

from hexdem.calibration.emulator import Emulator

#: The emulator's nugget bound for log s, whose sampling noise, 1/(2 (K − 1)) for K packings, is a
#: large share of its variance between parameter sets.
NOISY_NUGGET = 10.0
#: Standard deviations between packings are floored here (observables are of order one): a
#: parameter set whose packings agree exactly (σ = 0) keeps a finite logarithm.
SD_FLOOR = 1e-9


def log_sd_bias(realizations: int) -> float:
    """E[log s] − log σ of the sample standard deviation s of K normal values:
    ½ (ψ((K − 1)/2) − log((K − 1)/2)), as (K − 1) s²/σ² is χ² with K − 1 degrees of freedom."""
    half = (realizations - 1) / 2
    return 0.5 * (float(digamma(half)) - np.log(half))


def shrunk_correlation(sample, dof: int) -> np.ndarray:
    """The correlation between observables from ``sample``, the correlation of ``dof`` independent
    deviations, shrunk towards the identity: (ν R̂ + (m + 1) I) / (ν + m + 1).

    Every parameter set is simulated on the same K packings (:mod:`~hexdem.calibration.packings`),
    so their deviations from the mean, however many sets are pooled, are K − 1 = ν independent
    vectors: for ν < m observables R̂ is singular, and a record whose packing deviates in a
    direction the K packings never took would count as impossible. The estimate is that of an
    inverse-Wishart prior centred on the identity and worth m + 1 packings (the fewest for which its
    mean exists), updated with the ν deviations: it stays positive definite, its smallest
    eigenvalue at least (m + 1)/(ν + m + 1), and tends to R̂ as the packings grow in number."""
    size = len(sample)
    return (dof * np.asarray(sample, float) + (size + 1) * np.eye(size)) / (dof + size + 1)


class Spread:
    """Σ_K(u) fitted to simulations at unit-cube ``points`` (n, p) with ``observables`` (n, K, m)."""

    def __init__(self, points, observables):
        observables = np.asarray(observables, float)
        n, self.realizations, self.size = observables.shape
        if self.realizations < 2:
            return
        centred = observables - observables.mean(axis=1, keepdims=True)
        sd = np.maximum(np.sqrt(np.sum(centred**2, axis=1) / (self.realizations - 1)), SD_FLOOR)
        self.log_sd = Emulator(points, np.log(sd) - log_sd_bias(self.realizations), nugget_max=NOISY_NUGGET)
        scaled = centred / np.exp(self.log_sd.predict(points)[0])[:, None, :]
        pooled = np.einsum("nki,nkj->ij", scaled, scaled)
        norm = np.sqrt(np.diag(pooled))
        self.correlation = shrunk_correlation(pooled / np.outer(norm, norm), self.realizations - 1)

    def __call__(self, unit) -> np.ndarray:
        """Σ_K (k, m, m) at unit-cube points ``unit`` (k, p)."""
        unit = np.atleast_2d(unit)
        if self.realizations < 2:
            return np.zeros((len(unit), self.size, self.size))
        sd = np.exp(self.log_sd.predict(unit)[0])
        return sd[:, :, None] * self.correlation * sd[:, None, :]
