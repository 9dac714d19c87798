"""What a lab's records hold besides the model's observables: the instruments' errors and the
model's own (the likelihood's nuisance terms, :mod:`~hexdem.calibration.inference`).

Both enter the likelihood as Gaussian covariances of a record's observables (the first n log peak
speeds of n sensors, the next n − 1 arrivals relative to the first sensor's,
:func:`~hexdem.calibration.observables.observation_names`), to first order in their sizes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Instruments:
    """What a lab's instruments add to the model's observables of ``sensors`` sensors (the first
    ``sensors`` observables are log peak speeds, the next ``sensors`` − 1 arrivals relative to the
    first sensor's, :func:`~hexdem.calibration.observables.observation_names`).

    ``gain_sd``: each sensor's sensitivity is an unknown gain g ~ N(1, gain_sd), the same in every
    record of that sensor. The velocity integrated from its acceleration, and so its peak, scale with
    g; its half-maximum arrival does not. log g, N(0, gain_sd²) to first order, adds to the sensor's
    log peak speed in every record alike: a term of the common error e, marginalised analytically.

    ``speed_scatter``: the striker's speed differs from record to record, v (1 + speed_scatter z_r)
    around the calibrated v. A Hertzian lattice has no scale of its own: a speed λ v gives
    :math:`x_λ(t) = λ^{4/5} x(λ^{1/5} t)`, every velocity λ times larger at times :math:`λ^{-1/5}` later (also with
    Tsuji's damping, whose restitution does not depend on the speed; gravity breaks it only where
    the pulse has nearly died). To first order in z_r every log peak moves by speed_scatter z_r and
    each relative arrival t_j by −t_j speed_scatter z_r / 5: the covariance
    V = speed_scatter² J Jᵀ, J = (1, …, 1, −t_2/5, …), independent between records, with t_j the
    emulated arrivals at u."""

    sensors: int
    gain_sd: float = 0.0
    speed_scatter: float = 0.0

    def common(self) -> np.ndarray:
        """The gains' covariance (m, m), common to every record."""
        return np.diag(np.r_[np.full(self.sensors, self.gain_sd**2), np.zeros(self.sensors - 1)])

    def per_record(self, mean) -> np.ndarray:
        """The speed scatter's covariance (k, m, m) of one record at the emulated means ``mean`` (k, m)."""
        mean = np.atleast_2d(mean)
        slope = np.column_stack([np.ones((len(mean), self.sensors)), -mean[:, self.sensors :] / 5.0])
        return self.speed_scatter**2 * slope[:, :, None] * slope[:, None, :]


@dataclass(frozen=True)
class Discrepancy:
    """What the model cannot represent (Kennedy & O'Hagan 2001): a discrepancy δ between the model's
    observables and the records', the same in every record of one experiment, δ ~ N(0, τ² W) with
    W = diag(1, …, 1, t_2², …): a relative error τ of every peak speed (its log moves by τ) and of
    every relative arrival t_j (emulated at u), whatever its cause (another preparation, friction,
    a wall of other stiffness). τ is unknown: its prior is log-uniform on [``low``, ``high``], and
    it is sampled with the parameters, the last coordinate of the sampler's unit cube. Records that
    the model fits leave τ below their noise, where it changes nothing; records it does not fit
    raise it, and the parameters' intervals widen to what the misfit allows."""

    sensors: int
    low: float = 1e-4
    high: float = 0.2

    def size(self, unit) -> np.ndarray:
        """τ (k,) of the unit-cube coordinates ``unit`` (k,)."""
        return self.low * (self.high / self.low) ** np.asarray(unit, float)

    def weights(self, mean) -> np.ndarray:
        """W's diagonal (k, m) at the emulated means ``mean`` (k, m): 1 for a log peak, t_j² for an arrival."""
        mean = np.atleast_2d(mean)
        return np.column_stack([np.ones((len(mean), self.sensors)), mean[:, self.sensors :] ** 2])

    def covariance(self, mean, unit) -> np.ndarray:
        """τ² W (k, m, m) at the emulated means ``mean`` (k, m) and τ's coordinates ``unit`` (k,)."""
        weights = self.weights(mean)
        return (self.size(unit) ** 2)[:, None, None] * weights[:, :, None] * np.eye(weights.shape[1])

    def as_dict(self) -> dict:
        return {"prior": f"loguniform({self.low:g}, {self.high:g})", "meaning": "relative size of the model's error"}
