"""Bayesian calibration by an emulator refined where the posterior lies, sampled by emcee.

The posterior of the unit-cube coordinates u of the priors (:mod:`~hexdem.calibration.priors`)
is p(u | data) ∝ Π_r N(y_r; μ(u), Σ_r + Σ_K + diag s²(u)) on [0, 1]^p: the records y_r
(:mod:`~hexdem.calibration.observables`) with their noise covariances Σ_r, the emulated mean
μ(u) of the model's observables and the emulator's own variance s²(u)
(:mod:`~hexdem.calibration.emulator`), and Σ_K, the spread of the observables between the K
packings simulated at one parameter set (zero for one packing).

**Stages.** Stage 0 simulates :func:`initial_points` points of a Latin hypercube over the
whole prior. Every later stage fits the emulator to all simulations so far, samples its posterior
with emcee's affine-invariant ensemble (Goodman & Weare 2010) and simulates
:func:`round_points` new points drawn from that posterior, so that the emulator is refined where
the posterior puts its mass. The last fit's posterior is the result. Every random choice derives
from the seed, so the same seed, data and simulations give the same posterior.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from hexdem.calibration.emulator import Emulator
from hexdem.errors import HexdemError

WALKERS = 64
BURN_IN_STEPS = 300
KEPT_STEPS = 500
THIN = 10
#: Prior points at which the emulated posterior is evaluated to start the walkers.
START_CANDIDATES = 4096


def initial_points(dimension: int) -> int:
    """Simulations of stage 0 (a space-filling design over the prior)."""
    return 10 * dimension + 10


def round_points(dimension: int) -> int:
    """Simulations of each later stage (drawn from the current posterior)."""
    return 5 * dimension + 5


def default_budget(dimension: int) -> int:
    """Parameter sets of a calibration whose budget is not given: the initial design and four rounds."""
    return initial_points(dimension) + 4 * round_points(dimension)


def stage_sizes(dimension: int, budget: int) -> list[int]:
    """Points simulated at each stage within ``budget`` parameter sets: the initial design, then
    as many whole rounds as fit; a budget with no room for one round is refused."""
    first, size = initial_points(dimension), round_points(dimension)
    if budget < first + size:
        raise HexdemError(f"a budget of {budget} parameter sets is too small for {dimension} parameter(s): the "
                          f"method needs {first} for its initial design and {size} for each refinement "
                          f"(at least {first + size})")
    return [first] + [size] * ((budget - first) // size)


@dataclass(frozen=True)
class Data:
    """The measured records' observables ``records`` (R, m), their noise covariances
    ``covariances`` (R, m, m), and the observables' ``names``."""

    records: np.ndarray
    covariances: np.ndarray
    names: tuple[str, ...]


class Likelihood:
    """log p(data | u) through ``emulator``, with the packings' spread ``spread`` (m, m)."""

    def __init__(self, data: Data, emulator: Emulator, spread):
        self.data, self.emulator, self.spread = data, emulator, np.asarray(spread, float)

    def __call__(self, unit) -> np.ndarray:
        unit = np.atleast_2d(unit)
        inside = np.all((unit >= 0) & (unit <= 1), axis=1)
        result = np.full(len(unit), -np.inf)
        if not inside.any():
            return result
        mean, variance = self.emulator.predict(unit[inside])
        total = 0.0
        for record, covariance in zip(self.data.records, self.data.covariances):
            cov = covariance + self.spread + variance[:, :, None] * np.eye(len(record))
            residual = record - mean
            _, logdet = np.linalg.slogdet(cov)
            chi2 = np.einsum("ki,ki->k", residual, np.linalg.solve(cov, residual[:, :, None])[:, :, 0])
            total = total - 0.5 * (chi2 + logdet)
        result[inside] = total
        return result


def sample_posterior(likelihood: Likelihood, dimension: int, seed: int) -> np.ndarray:
    """Unit-cube samples (WALKERS · KEPT_STEPS / THIN, p) of the posterior of ``likelihood``."""
    import emcee

    rng = np.random.default_rng(seed)
    candidates = qmc.LatinHypercube(dimension, seed=rng).random(START_CANDIDATES)
    best = candidates[np.argsort(likelihood(candidates))[-WALKERS:]]
    start = np.clip(best + rng.normal(0.0, 1e-3, best.shape), 1e-6, 1 - 1e-6)
    sampler = emcee.EnsembleSampler(WALKERS, dimension, likelihood, vectorize=True)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    state = sampler.run_mcmc(start, BURN_IN_STEPS)
    sampler.reset()
    sampler.run_mcmc(state, KEPT_STEPS)
    return sampler.get_chain(thin=THIN, flat=True)


def pooled_spread(observables: np.ndarray) -> np.ndarray:
    """Σ_K: the covariance between the K packings of each parameter set, pooled over the sets
    (observables (n, K, m)); zero for K = 1."""
    n, k, m = observables.shape
    if k < 2:
        return np.zeros((m, m))
    centred = observables - observables.mean(axis=1, keepdims=True)
    return np.einsum("nki,nkj->ij", centred, centred) / (n * (k - 1))


@dataclass(frozen=True)
class Fit:
    """One stage's fit: the simulated ``points`` (n, p) and their ``observables`` (n, K, m), the
    ``emulator`` of their mean over packings, the packings' ``spread`` and the posterior
    ``samples`` (unit cube)."""

    points: np.ndarray
    observables: np.ndarray
    emulator: Emulator
    spread: np.ndarray
    samples: np.ndarray


def fit_stage(data: Data, points, observables, seed: int) -> Fit:
    """Fit the emulator to the simulations and sample the posterior it implies."""
    points, observables = np.asarray(points, float), np.asarray(observables, float)
    emulator = Emulator(points, observables.mean(axis=1))
    spread = pooled_spread(observables)
    samples = sample_posterior(Likelihood(data, emulator, spread), points.shape[1], seed)
    return Fit(points, observables, emulator, spread, samples)


def next_points(fit: Fit, count: int, seed: int) -> np.ndarray:
    """``count`` distinct posterior samples of ``fit`` to simulate next."""
    rng = np.random.default_rng(seed)
    return fit.samples[rng.choice(len(fit.samples), size=count, replace=False)]


def design(dimension: int, count: int, seed: int) -> np.ndarray:
    """Stage 0's space-filling points (a Latin hypercube) in the unit cube."""
    return qmc.LatinHypercube(dimension, seed=np.random.default_rng(seed)).random(count)
