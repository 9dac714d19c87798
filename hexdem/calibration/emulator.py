"""A Gaussian-process emulator of a record's observables over the unit cube of the priors.

Each observable gets its own process: a linear trend fitted by least squares, and a zero-mean
Gaussian process on the residuals with the Matérn 5/2 kernel

    k(x, x') = s² (1 + √5 r + 5 r²/3) exp(−√5 r),   r² = Σ_j (x_j − x'_j)² / ℓ_j²,

plus a nugget τ² for the simulations' own round-off and sampling jitter. The hyperparameters
(ℓ_j, s², τ²) maximize the residuals' log marginal likelihood (Rasmussen & Williams, eq. 2.30).
The prediction at x is the trend plus the posterior mean, with the posterior variance
(eqs. 2.25-2.26): the emulator says where it is unsure, and the calibration's likelihood adds
that variance to the data's, so that a coarse emulator widens the posterior rather than
narrowing it.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import cho_factor, cho_solve, solve_triangular
from scipy.optimize import minimize

#: Bounds of log ℓ (unit-cube widths), log s² and log τ² of the standardized residuals (τ²'s
#: upper bound is the emulator's ``nugget_max``).
LOG_BOUNDS = {
    "length": (np.log(0.02), np.log(20.0)),
    "signal": (np.log(1e-4), np.log(1e2)),
    "nugget": (np.log(1e-10), np.log(1e-1)),
}


#: The shortest length (in the unit cube) of a dimension along which the response is smooth.
SMOOTH_LENGTH = 1.0


def matern52_of_distance(r) -> np.ndarray:
    """The Matérn 5/2 correlation at scaled distance ``r``."""
    return (1.0 + np.sqrt(5.0) * r + 5.0 / 3.0 * r * r) * np.exp(-np.sqrt(5.0) * r)


def matern52(a, b, lengths) -> np.ndarray:
    """The Matérn 5/2 correlation between the rows of ``a`` (n, p) and ``b`` (k, p)."""
    d = (a[:, None, :] - b[None, :, :]) / lengths
    return matern52_of_distance(np.sqrt(np.sum(d * d, axis=-1)))


def _design(x, trend) -> np.ndarray:
    """The trend's regressors at ``x`` (n, p): a constant and the dimensions ``trend`` (a mask (p,))."""
    return np.column_stack([np.ones(len(x)), x[:, trend]])


class _Process:
    """One observable's trend and residual process, fitted to (x, y), its length along each
    dimension at least ``shortest`` (p,); with ``same`` (n, n), 1 where two points share a group
    (their σ level), an effect η² common to each group's points, fitted with the rest and left out
    of predictions."""

    def __init__(self, x, y, nugget_max: float, shortest, same=None, trend=None):
        self.x, self.nugget_max, self.shortest, self.same = x, nugget_max, shortest, same
        trend = np.ones(x.shape[1], bool) if trend is None else trend
        self.beta = np.linalg.lstsq(_design(x, trend), y, rcond=None)[0]
        residual = y - _design(x, trend) @ self.beta
        self.scale = float(np.std(residual)) or 1.0
        self.z = residual / self.scale
        self.theta = self._optimize()
        k = self._covariance(self.theta)
        factor = cho_factor(k, lower=True)
        self.alpha = cho_solve(factor, self.z)
        self.whitener = solve_triangular(factor[0], np.eye(len(x)), lower=True)
        self.lengths, self.signal = self._unpack(self.theta)[:2]

    def _unpack(self, theta):
        p = self.x.shape[1]
        group = np.exp(theta[p + 2]) if self.same is not None else 0.0
        return np.exp(theta[:p]), np.exp(theta[p]), np.exp(theta[p + 1]), group

    def _covariance(self, theta) -> np.ndarray:
        lengths, signal, nugget, group = self._unpack(theta)
        k = signal * matern52(self.x, self.x, lengths) + (nugget + 1e-12) * np.eye(len(self.x))
        return k if self.same is None else k + group * self.same

    def _negative_log_likelihood(self, theta) -> float:
        try:
            factor = cho_factor(self._covariance(theta), lower=True)
        except np.linalg.LinAlgError:
            return 1e25
        alpha = cho_solve(factor, self.z)
        return float(0.5 * self.z @ alpha + np.sum(np.log(np.diag(factor[0]))))

    def _optimize(self) -> np.ndarray:
        low = np.log(self.shortest)
        noise = (LOG_BOUNDS["nugget"][0], np.log(self.nugget_max))
        bounds = [(a, LOG_BOUNDS["length"][1]) for a in low] + [LOG_BOUNDS["signal"], noise]
        bounds += [noise] if self.same is not None else []
        extra = [np.log(1e-4)] if self.same is not None else []
        starts = [np.r_[np.maximum(np.log(length), low), 0.0, np.log(1e-4), extra] for length in (0.3, 1.0)]
        fits = [minimize(self._negative_log_likelihood, start, method="L-BFGS-B", bounds=bounds) for start in starts]
        return min(fits, key=lambda fit: fit.fun).x


class Emulator:
    """Gaussian processes of every observable, fitted to simulations at unit-cube points ``x``
    (n, p) with observables ``y`` (n, m); ``nugget_max`` bounds the nugget τ² (a share of the
    residuals' variance): small for simulations that are smooth in the parameters, larger for
    noisy outputs; ``smooth`` the dimensions along which the response is taken as smooth over the
    whole prior (lengths of at least :data:`SMOOTH_LENGTH`), its wiggles from one simulated value
    to the next left to the nugget; ``held``, (lowest (p,), highest (p,)): each predicted point is
    moved inside them first, so that the response is held at its ends rather than extrapolated;
    ``groups`` (n,), labels of points that share an error (the K packings of one σ level, which
    every parameter set at that level strikes): an effect common to each group, fitted as the
    nugget is and left out of the prediction, so that many sets at one level count as one draw of
    its packings, not as many independent ones; and no linear trend along the ``smooth``
    dimensions, whose slope a few levels' draws would set by chance (the process alone, of lengths
    of at least the prior's, carries what changes along them)."""

    def __init__(self, x, y, nugget_max: float = 0.1, smooth=(), held=None, groups=None):
        x, y = np.asarray(x, float), np.asarray(y, float)
        self.held = held
        shortest = np.full(x.shape[1], np.exp(LOG_BOUNDS["length"][0]))
        shortest[list(smooth)] = SMOOTH_LENGTH
        same = None if groups is None else (np.asarray(groups)[:, None] == np.asarray(groups)[None, :]).astype(float)
        self.trend = np.ones(x.shape[1], bool)
        if groups is not None:
            self.trend[list(smooth)] = False
        processes = [_Process(x, y[:, j], nugget_max, shortest, same, self.trend) for j in range(y.shape[1])]
        self.x = x
        self.inverse_squared_lengths = np.array([1.0 / p.lengths**2 for p in processes])  # (m, p)
        self.beta = np.column_stack([p.beta for p in processes])  # (p + 1, m)
        self.signal = np.array([p.signal for p in processes])
        self.scale = np.array([p.scale for p in processes])
        self.weights = np.column_stack([p.signal * p.alpha for p in processes])  # (n, m)
        self.whiteners = np.array([p.signal * p.whitener for p in processes])  # (m, n, n)

    def leave_one_out(self) -> np.ndarray:
        """Each simulation's observables less the emulator's prediction there fitted without it
        (n, m), in closed form (Rasmussen & Williams, eq. 5.12: α_i / [K⁻¹]_ii, the trend held): how
        far the emulator is off where it was not told."""
        diagonal = np.sum(self.whiteners**2, axis=1).T  # (n, m): [K⁻¹]_ii times each process's s⁴
        return self.scale * self.weights * self.signal / diagonal

    def predict(self, xs) -> tuple[np.ndarray, np.ndarray]:
        """(mean (k, m), variance (k, m)) of the observables at unit-cube points ``xs`` (k, p): every
        observable's correlations from one table of squared distances."""
        xs = np.atleast_2d(np.asarray(xs, float))
        if self.held is not None:
            xs = np.clip(xs, *self.held)
        squared = (xs[:, None, :] - self.x[None, :, :]) ** 2  # (k, n, p)
        correlation = matern52_of_distance(np.sqrt(squared @ self.inverse_squared_lengths.T))  # (k, n, m)
        mean = _design(xs, self.trend) @ self.beta + self.scale * np.einsum("knm,nm->km", correlation, self.weights)
        whitened = np.moveaxis(correlation, 2, 0) @ np.transpose(self.whiteners, (0, 2, 1))  # (m, k, n)
        variance = np.maximum(self.signal - np.sum(whitened * whitened, axis=-1).T, 0.0)
        return mean, self.scale**2 * variance
