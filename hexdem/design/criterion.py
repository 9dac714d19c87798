r"""The design criterion: the expected information a design's records carry about the keys.

**Model.** A design is N sensors (beads) struck at one speed, R records (on R packings where the
packings are disordered). Its observables are those of ``hexdem calibrate``: the N log peak
speeds and the N − 1 arrivals relative to the sensor the pulse reaches first. Their mean μ(θ) over
packings is emulated in the keys θ by the calibration's Gaussian process (a linear trend and a
Matérn 5/2 process per observable, :mod:`hexdem.calibration.emulator`), whose slopes give J; a record's
covariance is the calibration's likelihood's (:mod:`hexdem.calibration.nuisance`): the
accelerometers' noise (a bootstrap per bead, :mod:`~hexdem.design.records`), the striker's speed
scatter, the packings' spread (their pooled residual covariance, scaled as σ² where σ is a key),
and each sensor's gain, common to all R records:

.. math:: Σ(θ) = (V_\text{noise} + V_\text{speed} + V_\text{spread}) / R + G.

**Criterion.** In the keys standardised by their priors (z = (θ − mean)/sd, prior covariance I),
linearised at θ, the posterior covariance is :math:`P(θ) = (I + J^T Σ^{-1} J)^{-1}` with J = ∂μ/∂z
(central differences of the emulator), and the information gain is :math:`-\tfrac12 \log\det P(θ)`
nats (Lindley's, for a Gaussian prior of the priors' variances). The criterion is its mean over the
simulated parameter sets: the expected information gain, larger for a better design. Each key's
expected 90 % width is the mean of 2 × 1.645 √P_kk × sd, at most the prior's own central 90 % width.
The information gain rewards designs that measure every key; the widths say which key a design
leaves at its prior. It is the Laplace (local Gaussian) approximation: a posterior that is far from
Gaussian, or a model discrepancy that the calibration would find, is not foreseen."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hexdem.calibration.emulator import Emulator
from hexdem.calibration.packings import SIGMA_KEY

#: z of the central 90 % interval of a normal distribution.
Z90 = 1.6448536269514722
#: Points on the unit interval at which a prior's mean, standard deviation and 90 % width are taken.
PRIOR_GRID = 4001
#: The step in the standardised keys of the emulator's central differences.
SLOPE_STEP = 1e-3


def prior_moments(prior) -> tuple[float, float, float]:
    """(mean, standard deviation, central 90 % width) of ``prior`` in its key's units."""
    values = prior.from_unit((np.arange(PRIOR_GRID) + 0.5) / PRIOR_GRID)
    low, high = prior.from_unit(np.array([0.05, 0.95]))
    return float(np.mean(values)), float(np.std(values)), float(high - low)


def slopes(z: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """(M, o, p): the derivatives of the o observables ``mean`` (M, o) in ``z`` (M, p) at every
    point, from a Gaussian-process emulator of each (:class:`~hexdem.calibration.emulator.Emulator`,
    the calibration's own) by central differences of :data:`SLOPE_STEP`."""
    emulator = Emulator(z, mean)
    out = np.empty((len(z), mean.shape[1], z.shape[1]))
    for j in range(z.shape[1]):
        step = np.zeros(z.shape[1])
        step[j] = SLOPE_STEP
        out[:, :, j] = (emulator.predict(z + step)[0] - emulator.predict(z - step)[0]) / (2 * SLOPE_STEP)
    return out


def bootstrapped(noise: np.ndarray) -> np.ndarray:
    """(M,) whether each parameter set's ``noise`` (M, n, 3) was bootstrapped: a set that was not
    holds NaN only; one that was may hold NaN at a bead without a pulse."""
    return np.any(np.isfinite(noise), axis=(1, 2))


@dataclass
class Moments:
    """What the simulations of one striker speed say about every candidate bead (n of them):
    ``mean`` (M, n, 2) log peak and arrival [µs] averaged over packings at the M parameter sets;
    ``slope`` (M, n, 2, p) their derivatives in the standardised keys; ``noise`` (M, n, 3) the
    bootstrap moments; ``residuals`` (M, K, n, 2) each packing's departure from the mean (zeros on
    the ideal lattice); ``spread_scale`` (M,) the spread's factor at each set (σ²/mean σ², or 1);
    ``sd`` and ``prior_width`` (p,) the priors' standard deviations and central 90 % widths."""

    mean: np.ndarray
    slope: np.ndarray
    noise: np.ndarray
    residuals: np.ndarray
    spread_scale: np.ndarray
    sd: np.ndarray
    prior_width: np.ndarray

    @classmethod
    def of(cls, keys, values: np.ndarray, observables: np.ndarray, noise: np.ndarray, priors) -> Moments:
        """From the parameter sets ``values`` (M, p) in key units, each packing's ``observables``
        (M, K, n, 2), and the bootstrap's ``noise`` (M, n, 3) of each set's first packing, NaN at
        the sets not bootstrapped, which take the nearest bootstrapped set's (in the standardised keys)."""
        moments = [prior_moments(prior) for prior in priors]
        centre, sd = np.array([m[0] for m in moments]), np.array([m[1] for m in moments])
        z = (values - centre) / np.where(sd > 0, sd, 1.0)
        mean = observables.mean(axis=1)
        slope = slopes(z, mean.reshape(len(mean), -1)).reshape(*mean.shape, z.shape[1])
        scale = np.ones(len(values))
        if SIGMA_KEY in keys:
            sigma = values[:, list(keys).index(SIGMA_KEY)]
            scale = sigma**2 / max(float(np.mean(sigma**2)), 1e-300)
        width = np.array([m[2] for m in moments])
        measured = np.flatnonzero(bootstrapped(noise))
        nearest = measured[np.argmin(np.sum((z[:, None, :] - z[None, measured, :]) ** 2, axis=-1), axis=1)]
        return cls(mean, slope, noise[nearest], observables - mean[:, None], scale, sd, width)

    def design_map(self, beads) -> tuple[np.ndarray, np.ndarray]:
        """(the beads ordered by their mean arrival, the map A (2N − 1, 2N) from their (log peak,
        arrival) pairs to the design's observables)."""
        order = np.asarray(beads)[np.argsort(self.mean[:, beads, 1].mean(axis=0))]
        n = len(order)
        a = np.zeros((2 * n - 1, 2 * n))
        a[np.arange(n), 2 * np.arange(n)] = 1.0
        a[n + np.arange(n - 1), 2 * np.arange(1, n) + 1] = 1.0
        a[n:, 1] = -1.0
        return order, a

    def posterior(self, beads, records: int, gain_sd: float, speed_scatter: float) -> np.ndarray:
        """(M, p, p): the linearised posterior covariance of the standardised keys at each set."""
        order, a = self.design_map(beads)
        n, m, p = len(order), 2 * len(order) - 1, self.slope.shape[-1]
        jacobian = np.einsum("oj,mjp->mop", a, self.slope[:, order].reshape(len(self.mean), 2 * n, p))
        noise = np.zeros((len(self.mean), 2 * n, 2 * n))
        pairs = self.noise[:, order]
        noise[:, 0::2, 0::2] = _diag(pairs[:, :, 0])
        noise[:, 1::2, 1::2] = _diag(pairs[:, :, 1])
        noise[:, 0::2, 1::2] = noise[:, 1::2, 0::2] = _diag(pairs[:, :, 2])
        per_record = a @ noise @ a.T
        mean = np.einsum("oj,mj->mo", a, self.mean[:, order].reshape(len(self.mean), 2 * n))
        speed = np.concatenate([np.ones((len(mean), n)), -mean[:, n:] / 5.0], axis=1)
        per_record += speed_scatter**2 * speed[:, :, None] * speed[:, None, :]
        if self.residuals.shape[1] > 1:
            deviations = np.einsum("oj,mkj->mko", a, self.residuals[:, :, order].reshape(*self.residuals.shape[:2], -1))
            dof = len(self.mean) * (self.residuals.shape[1] - 1)
            pooled = np.einsum("mko,mkq->oq", deviations, deviations) / dof
            per_record += self.spread_scale[:, None, None] * pooled
        common = np.diag(np.r_[np.full(n, gain_sd**2), np.zeros(n - 1)])
        covariance = per_record / records + common + 1e-12 * np.eye(m)
        information = jacobian.transpose(0, 2, 1) @ np.linalg.solve(covariance, jacobian)
        return np.linalg.inv(np.eye(p) + information)

    def score(self, beads, records: int, gain_sd: float, speed_scatter: float) -> tuple[float, np.ndarray]:
        """(the expected information gain [nats], each key's expected 90 % width in its units)."""
        posterior = self.posterior(beads, records, gain_sd, speed_scatter)
        gain = float(np.mean(-0.5 * np.linalg.slogdet(posterior)[1]))
        widths = np.mean(2 * Z90 * np.sqrt(np.diagonal(posterior, axis1=1, axis2=2)), axis=0) * self.sd
        return gain, np.minimum(widths, self.prior_width)


def _diag(values: np.ndarray) -> np.ndarray:
    """(M, n, n) diagonal matrices of ``values`` (M, n)."""
    out = np.zeros((*values.shape, values.shape[-1]))
    index = np.arange(values.shape[-1])
    out[:, index, index] = values
    return out
