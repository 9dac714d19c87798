"""Bayesian calibration by an emulator refined where the posterior lies, sampled by emcee.

The posterior of the unit-cube coordinates u of the priors (:mod:`~hexdem.calibration.priors`)
is p(u | data) ∝ p(y_1, …, y_R | u) on [0, 1]^p, the records y_r
(:mod:`~hexdem.calibration.observables`) modelled as

    y_r = μ(u) + e + δ_r + ε_r,   e ~ N(0, C(u)),  δ_r ~ N(0, Σ_K(u)),  ε_r ~ N(0, Σ_r):

μ(u) the emulated mean of the model's observables over the K packings simulated at u
(:mod:`~hexdem.calibration.emulator`); ε_r record r's accelerometer noise; δ_r its packing's
deviation from the mean, Σ_K(u) the spread between packings (:mod:`~hexdem.calibration.spread`;
zero on the ideal lattice), independent between records, each record being one packing; and e
the error of μ(u) itself, common to every record: the emulator's variance s²(u), and Σ_K(u)/K,
for a mean over K packings is not the mean over all. With D_r = Σ_r + Σ_K, P = Σ_r D_r⁻¹ and
b = Σ_r D_r⁻¹ (y_r − μ), integrating e out gives

    log p = Σ_r log N(y_r; μ, D_r) − ½ log det(I + C P) + ½ bᵀ (I + C P)⁻¹ C b,

which for one record is log N(y_1; μ, Σ_1 + Σ_K + C).

**Stages.** Stage 0 simulates :func:`initial_points` points of a Latin hypercube over the
whole prior. Every later stage fits the emulator to all simulations so far, samples its posterior
with emcee's affine-invariant ensemble (Goodman & Weare 2010) and simulates
:func:`round_points` new points drawn from that posterior, so that the emulator is refined where
the posterior puts its mass. The last fit's posterior is the result. After stage 0, the
posterior's most likely sample is also run at half the time step (:func:`step_error`): the runs'
own integration error enters the likelihood, shared by all records, so that records measured
without any time step are not fitted more closely than the runs can resolve. Every random choice derives
from the seed, so the same seed, data and simulations give the same posterior.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

from hexdem.calibration.emulator import Emulator
from hexdem.calibration.spread import Spread
from hexdem.errors import HexdemError

WALKERS = 64
BURN_IN_STEPS = 300
KEPT_STEPS = 500
THIN = 10
#: How far below the median walker's log probability a walker is a straggler (plus the dimension).
STRAGGLER_DROP = 10.0
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


def stage_sizes(dimension: int, budget: int, realizations: int = 1) -> list[int]:
    """Points simulated at each stage within ``budget`` parameter sets (each simulated on
    ``realizations`` packings): the initial design, then as many whole rounds as fit; a budget
    with no room for one round is refused."""
    first, size = initial_points(dimension), round_points(dimension)
    if budget < first + size:
        runs = "" if realizations == 1 else f" ({budget * realizations} simulations on {realizations} packings each)"
        raise HexdemError(f"a budget of {budget} parameter sets{runs} is too small for {dimension} parameter(s): "
                          f"the method needs {first} for its initial design and {size} for each refinement "
                          f"(at least {first + size} parameter sets)")
    return [first] + [size] * ((budget - first) // size)


@dataclass(frozen=True)
class Data:
    """The measured records' observables ``records`` (R, m), their noise covariances
    ``covariances`` (R, m, m), and the observables' ``names``."""

    records: np.ndarray
    covariances: np.ndarray
    names: tuple[str, ...]


class Likelihood:
    """log p(data | u) through ``emulator`` and the packings' ``spread`` (see the module docstring)."""

    def __init__(self, data: Data, emulator: Emulator, spread: Spread, model_error=None):
        self.data, self.emulator, self.spread = data, emulator, spread
        self.model_error = 0.0 if model_error is None else np.asarray(model_error, float)

    def __call__(self, unit) -> np.ndarray:
        unit = np.atleast_2d(unit)
        inside = np.all((unit >= 0) & (unit <= 1), axis=1)
        result = np.full(len(unit), -np.inf)
        if not inside.any():
            return result
        mean, variance = self.emulator.predict(unit[inside])
        spread = self.spread(unit[inside])
        identity = np.eye(mean.shape[1])
        common = variance[:, :, None] * identity + spread / self.spread.realizations + self.model_error
        total, precision, pulled = 0.0, 0.0, 0.0
        for record, covariance in zip(self.data.records, self.data.covariances):
            own = covariance + spread
            solved = np.linalg.solve(own, (record - mean)[:, :, None])[:, :, 0]
            total = total - 0.5 * (np.einsum("ki,ki->k", record - mean, solved) + np.linalg.slogdet(own)[1])
            precision = precision + np.linalg.inv(own)
            pulled = pulled + solved
        shrink = identity + common @ precision
        gain = np.linalg.solve(shrink, (common @ pulled[:, :, None]))[:, :, 0]
        result[inside] = total - 0.5 * np.linalg.slogdet(shrink)[1] + 0.5 * np.einsum("ki,ki->k", pulled, gain)
        return result


def sample_posterior(likelihood: Likelihood, dimension: int, seed: int) -> np.ndarray:
    """Unit-cube samples (WALKERS · KEPT_STEPS / THIN, p) of the posterior of ``likelihood``: the
    walkers start at the best of START_CANDIDATES prior points, and after the burn-in every
    straggler (:func:`stragglers`) restarts beside a walker in the posterior and the burn-in runs
    again."""
    import emcee

    rng = np.random.default_rng(seed)
    candidates = qmc.LatinHypercube(dimension, seed=rng).random(START_CANDIDATES)
    best = candidates[np.argsort(likelihood(candidates))[-WALKERS:]]
    start = np.clip(best + rng.normal(0.0, 1e-3, best.shape), 1e-6, 1 - 1e-6)
    sampler = emcee.EnsembleSampler(WALKERS, dimension, likelihood, vectorize=True)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    state = sampler.run_mcmc(start, BURN_IN_STEPS)
    lost = stragglers(sampler.get_log_prob(discard=BURN_IN_STEPS // 2), dimension)
    if lost.any():
        coords = state.coords.copy()
        kept = np.flatnonzero(~lost)
        coords[lost] = np.clip(coords[rng.choice(kept, lost.sum())] + rng.normal(0.0, 1e-6, (lost.sum(), dimension)),
                               0.0, 1.0)
        sampler.reset()
        state = sampler.run_mcmc(coords, BURN_IN_STEPS)
    sampler.reset()
    sampler.run_mcmc(state, KEPT_STEPS)
    return sampler.get_chain(thin=THIN, flat=True)


def stragglers(log_probability, dimension: int) -> np.ndarray:
    """Walkers stuck where the posterior has no mass: their median log probability over the
    burn-in's second half (``log_probability`` (steps, walkers)) is more than STRAGGLER_DROP +
    ``dimension`` below the median walker's, a density e^-(10 + p) of the typical one, where the
    typical set of a p-dimensional posterior lies within about p/2 of its median. An affine-invariant
    stretch move brings such a walker back only along straight lines through the others, which a
    curved ridge of the posterior can cross only where it has no mass."""
    typical = np.median(log_probability, axis=0)
    return typical < np.median(typical) - (STRAGGLER_DROP + dimension)


@dataclass(frozen=True)
class Fit:
    """One stage's fit: the simulated ``points`` (n, p) and their ``observables`` (n, K, m), the
    ``emulator`` of their mean over packings, the packings' ``spread``, the posterior
    ``samples`` (unit cube) and the ``likelihood`` they sample."""

    points: np.ndarray
    observables: np.ndarray
    emulator: Emulator
    spread: Spread
    samples: np.ndarray
    likelihood: Likelihood


def fit_stage(data: Data, points, observables, seed: int, model_error=None) -> Fit:
    """Fit the emulator to the simulations and sample the posterior it implies (``model_error``:
    the covariance of the model's own integration error, :func:`step_error`)."""
    points, observables = np.asarray(points, float), np.asarray(observables, float)
    emulator = Emulator(points, observables.mean(axis=1))
    spread = Spread(points, observables)
    likelihood = Likelihood(data, emulator, spread, model_error)
    samples = sample_posterior(likelihood, points.shape[1], seed)
    return Fit(points, observables, emulator, spread, samples, likelihood)


def step_error(coarse, fine) -> np.ndarray:
    """The covariance of the runs' integration error from one parameter set run at the
    calibration's time step (``coarse`` observables) and at half of it (``fine``): the error
    converges at first order in the step (the sensors' samples fall on whole steps), so the runs
    miss the limit of a vanishing step by about b = 2 (coarse − fine). The likelihood treats b as
    unknown within its size, the rank-one covariance b bᵀ: a record, measured without any time
    step, may then sit off the runs by b in either direction."""
    bias = 2.0 * (np.asarray(coarse, float) - np.asarray(fine, float))
    return np.outer(bias, bias)


def next_points(fit: Fit, count: int, seed: int) -> np.ndarray:
    """``count`` distinct posterior samples of ``fit`` to simulate next."""
    rng = np.random.default_rng(seed)
    return fit.samples[rng.choice(len(fit.samples), size=count, replace=False)]


def design(dimension: int, count: int, seed: int) -> np.ndarray:
    """Stage 0's space-filling points (a Latin hypercube) in the unit cube."""
    return qmc.LatinHypercube(dimension, seed=np.random.default_rng(seed)).random(count)
