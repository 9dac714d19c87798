"""Bayesian calibration by an emulator refined where the posterior lies, sampled by emcee.

The posterior of the unit-cube coordinates u of the priors (:mod:`~hexdem.calibration.priors`)
is p(u | data) ∝ p(y_1, …, y_R | u) on [0, 1]^p, the records y_r
(:mod:`~hexdem.calibration.observables`) modelled as

    y_r = μ(u) + e + δ_r + ε_r,   e ~ N(0, C(u)),  δ_r ~ N(0, λ_r Σ_K(u) + V(u)),  ε_r ~ N(0, Σ_r):

μ(u) the emulated centre (median) of the model's observables over the K packings simulated at u
(:mod:`~hexdem.calibration.emulator`); ε_r record r's accelerometer noise; δ_r its packing's
deviation from the mean, Σ_K(u) the spread between packings (:mod:`~hexdem.calibration.spread`;
zero on the ideal lattice), and its striker's speed off the calibrated one, V(u)
(:class:`~hexdem.calibration.nuisance.Instruments`), independent between records, each record
being one packing and one strike; and e the error common to every record: the emulator's
variance s²(u), Σ_K(u) (π/2)/K, for a median over K packings is not the centre of all, each sensor's
gain, the same in all its records (:class:`~hexdem.calibration.nuisance.Instruments`), and what
the model cannot represent, a discrepancy of relative size τ
(:class:`~hexdem.calibration.nuisance.Discrepancy`, Kennedy & O'Hagan's δ, whose τ is sampled
with u). Σ_K is known only to a scale λ, as K packings tell it
(:meth:`~hexdem.calibration.spread.Spread.scale`): λ is sampled with u too, so that the records,
independent packings, tell it further, and integrated out it gives them a joint Student-t rather
than a Gaussian of a spread taken as known. And each record's packing deviates with a scale λ_r
of its own, δ_r ~ N(0, λ_r Σ_K + V), λ_r inverse-gamma of shape ν/2 and mean 1
(:meth:`~hexdem.calibration.spread.Spread.record_scale`), sampled with u: integrated out, each
packing's deviation is a Student-t of ν degrees of freedom. A packing's observables are not
Gaussian: where its pulse finds a weak path past a sensor, the sensor's peak falls 50-fold, and
one such record among Gaussian ones would count as impossible at every parameter but where the
emulated spread happens to be widest. With
D_r = Σ_r + λ_r Σ_K + V, P = Σ_r D_r⁻¹ and b = Σ_r D_r⁻¹ (y_r − μ), integrating e out gives

    log p = Σ_r log N(y_r; μ, D_r) − ½ log det(I + C P) + ½ bᵀ (I + C P)⁻¹ C b,

which for one record is log N(y_1; μ, Σ_1 + Σ_K + C). On disordered packings the records kept
are those whose pulse the sensors detect, a selection: R_d log P(u) + R_u log(1 − P(u)) adds what
the count of records detected and left out tells (:mod:`~hexdem.calibration.detection`).

**Stages.** Stage 0 simulates :func:`initial_points` points of a Latin hypercube over the
whole prior. Every later stage fits the emulator to all simulations so far, samples its posterior
with emcee's ensembles (:mod:`~hexdem.calibration.sampler`: one for a stage that only picks the
next points, four independent ones for the last, whose agreement is checked) and simulates
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

from hexdem.calibration.detection import Detection
from hexdem.calibration.emulator import Emulator
from hexdem.calibration.nuisance import Discrepancy, Instruments
from hexdem.calibration.sampler import Chain, sample_posterior
from hexdem.calibration.spread import (
    MEDIAN_VARIANCE,
    NOISY_NUGGET,
    Spread,
    ideal_sets,
    level_groups,
    packing_centres,
)
from hexdem.errors import HexdemError


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
        raise HexdemError(
            f"a budget of {budget} parameter sets{runs} is too small for {dimension} parameter(s): "
            f"the method needs {first} for its initial design and {size} for each refinement "
            f"(at least {first + size} parameter sets)"
        )
    return [first] + [size] * ((budget - first) // size)


@dataclass(frozen=True)
class Data:
    """The measured records' observables ``records`` (R, m), their noise covariances
    ``covariances`` (R, m, m), the observables' ``names``, the records' own names
    ``record_names`` (their ``record`` column), and how many records were ``undetected`` (a sensor
    without a pulse: left out, :mod:`~hexdem.calibration.detection`)."""

    records: np.ndarray
    covariances: np.ndarray
    names: tuple[str, ...]
    record_names: tuple[str, ...] = ()
    undetected: int = 0


class Likelihood:
    """log p(data | u) through ``emulator``, the packings' ``spread`` and the records' ``instruments``
    (see the module docstring; without instruments, none of their errors)."""

    def __init__(
        self,
        data: Data,
        emulator: Emulator,
        spread: Spread,
        model_error=None,
        instruments: Instruments | None = None,
        discrepancy: Discrepancy | None = None,
        detection: Detection | None = None,
    ):
        self.data, self.emulator, self.spread = data, emulator, spread
        self.model_error = 0.0 if model_error is None else np.asarray(model_error, float)
        self.instruments = instruments or Instruments(1 + data.records.shape[1] // 2)
        self.discrepancy = discrepancy
        self.detection = detection

    @property
    def scaled_spread(self) -> bool:
        """Whether the spread between packings carries an unknown scale λ (:meth:`Spread.scale`), the
        sampler's coordinate after the parameters': on K ≥ 2 packings a parameter set."""
        return self.spread.realizations >= 2

    @property
    def record_scales(self) -> int:
        """How many records carry a scale λ_r of their own packing's deviation
        (:meth:`Spread.record_scale`), the sampler's coordinates after λ's: every record on K ≥ 2
        packings a parameter set, none on the ideal lattice."""
        return len(self.data.records) if self.scaled_spread else 0

    @property
    def dimension(self) -> int:
        """The sampler's coordinates: the parameters', the spread's scale λ's and each record's λ_r's
        on disordered packings, and τ's with a :class:`~hexdem.calibration.nuisance.Discrepancy`."""
        return self.emulator.x.shape[1] + self.scaled_spread + self.record_scales + (self.discrepancy is not None)

    def _parts(self, unit) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(μ (k, m), C (k, m, m), λ Σ_K (k, m, m), V (k, m, m)) at the sampler's points ``unit``."""
        count = self.emulator.x.shape[1]
        parameters = unit[:, :count]
        mean, variance = self.emulator.predict(parameters)
        spread = self.spread(parameters)
        if self.scaled_spread:
            spread = spread * self.spread.scale(unit[:, count])[:, None, None]
        common = (
            variance[:, :, None] * np.eye(mean.shape[1])
            + spread * MEDIAN_VARIANCE / self.spread.realizations
            + self.model_error
            + self.instruments.common()
        )
        if self.discrepancy is not None:
            common = common + self.discrepancy.covariance(mean, unit[:, -1])
        return mean, common, spread, self.instruments.per_record(mean)

    def moments(self, unit) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """At the sampler's unit-cube points ``unit`` (k, :attr:`dimension`): the emulated mean μ
        (k, m), the common error's covariance C (k, m, m) and what a new record adds to its own
        noise, Σ_K + V (k, m, m), its packing's scale λ_r taken as 1."""
        mean, common, spread, speed = self._parts(np.atleast_2d(unit))
        return mean, common, spread + speed

    def record_moments(self, unit) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
        """At the sampler's unit-cube points ``unit``: μ (k, m), C (k, m, m) and, for each record,
        what it adds to its own noise, λ_r Σ_K + V (k, m, m), with its packing's scale λ_r at ``unit``."""
        unit = np.atleast_2d(unit)
        mean, common, spread, speed = self._parts(unit)
        if not self.record_scales:
            return mean, common, [spread + speed] * len(self.data.records)
        scales = self.packing_scales(unit)
        return mean, common, [spread * scales[:, r, None, None] + speed for r in range(self.record_scales)]

    def packing_scales(self, unit) -> np.ndarray:
        """Each record's packing scale λ_r (k, R) at the sampler's points ``unit`` (k, :attr:`dimension`),
        from its coordinates after the spread's scale (:meth:`Spread.record_scale`)."""
        first = self.emulator.x.shape[1] + 1
        return self.spread.record_scale(np.atleast_2d(unit)[:, first : first + self.record_scales])

    def _pooled(self, mean, owns):
        """(Σ_r log N(y_r; μ, D_r), P, b) at each point (see the module docstring)."""
        total, precision, pulled = 0.0, 0.0, 0.0
        for record, covariance, own in zip(self.data.records, self.data.covariances, owns):
            scatter = covariance + own
            solved = np.linalg.solve(scatter, (record - mean)[:, :, None])[:, :, 0]
            total = total - 0.5 * (np.einsum("ki,ki->k", record - mean, solved) + np.linalg.slogdet(scatter)[1])
            precision = precision + np.linalg.inv(scatter)
            pulled = pulled + solved
        return total, precision, pulled

    def __call__(self, unit) -> np.ndarray:
        unit = np.atleast_2d(unit)
        inside = np.all((unit >= 0) & (unit <= 1), axis=1)
        result = np.full(len(unit), -np.inf)
        if not inside.any():
            return result
        mean, common, owns = self.record_moments(unit[inside])
        total, precision, pulled = self._pooled(mean, owns)
        shrink = np.eye(mean.shape[1]) + common @ precision
        gain = np.linalg.solve(shrink, (common @ pulled[:, :, None]))[:, :, 0]
        result[inside] = total - 0.5 * np.linalg.slogdet(shrink)[1] + 0.5 * np.einsum("ki,ki->k", pulled, gain)
        if self.detection is not None:
            parameters = unit[inside, : self.emulator.x.shape[1]]
            result[inside] += self.detection.log_likelihood(parameters, len(self.data.records), self.data.undetected)
        return result

    def log_gains(self, unit) -> tuple[np.ndarray, np.ndarray]:
        """(mean (k, n), variance (k, n)) of each sensor's log gain given the records, at the
        sampler's points ``unit`` (:meth:`moments`): g is part of the common error e, so with G its covariance,
        E[g | y] = G (I + P C)⁻¹ b and Cov[g | y] = G − G (I + P C)⁻¹ P G."""
        mean, common, owns = self.record_moments(unit)
        _, precision, pulled = self._pooled(mean, owns)
        gains = self.instruments.common()
        shrink = np.eye(mean.shape[1]) + precision @ common
        centre = (gains @ np.linalg.solve(shrink, pulled[:, :, None]))[:, :, 0]
        covariance = gains - gains @ np.linalg.solve(shrink, precision @ gains)
        n = self.instruments.sensors
        return centre[:, :n], np.diagonal(covariance, axis1=1, axis2=2)[:, :n]

    def without_discrepancy(self) -> Likelihood:
        """This likelihood with the model taken as exact: no :class:`~hexdem.calibration.nuisance.Discrepancy`,
        its coordinates those of this one less τ's (the last), the others' the same."""
        return Likelihood(
            self.data, self.emulator, self.spread, self.model_error, self.instruments, detection=self.detection
        )

    def misfit(self, unit) -> tuple[float, list[float]]:
        """(χ² of all the records together, [χ² of each record]) at the sampler's point ``unit``
        (:meth:`moments`), each with the full covariance that the likelihood gives it there: the stacked
        records N(1 ⊗ μ, blockdiag(Σ_r + λ_r Σ_K + V) + 11ᵀ ⊗ C), and record r alone
        N(μ, Σ_r + λ_r Σ_K + V + C), each record's packing scale λ_r at ``unit``'s."""
        mean, common, owns = self.record_moments(unit)
        mean, common, owns = mean[0], common[0], [own[0] for own in owns]
        records, m = self.data.records, len(mean)
        joint = np.kron(np.ones((len(records), len(records))), common)
        alone = []
        for r, (covariance, own) in enumerate(zip(self.data.covariances, owns)):
            block = slice(r * m, (r + 1) * m)
            joint[block, block] += covariance + own
            residual = records[r] - mean
            alone.append(float(residual @ np.linalg.solve(covariance + own + common, residual)))
        stacked = (records - mean).ravel()
        return float(stacked @ np.linalg.solve(joint, stacked)), alone


@dataclass(frozen=True)
class Fit:
    """One stage's fit: the simulated ``points`` (n, p) and their ``observables`` (n, K, m), the
    ``emulator`` of their mean over packings, the packings' ``spread``, the posterior
    ``states`` the sampler visited (unit cube: the parameters', then the spread's scale λ's on
    disordered packings, then τ's with a discrepancy), the
    ``likelihood`` they sample, and how the ``chain`` mixed."""

    points: np.ndarray
    observables: np.ndarray
    emulator: Emulator
    spread: Spread
    states: np.ndarray
    likelihood: Likelihood
    chain: Chain

    @property
    def samples(self) -> np.ndarray:
        """The posterior's samples of the parameters (unit cube, (n, p))."""
        return self.states[:, : self.points.shape[1]]

    @property
    def spread_scales(self) -> np.ndarray | None:
        """The posterior's samples of the spread's scale λ (:meth:`Spread.scale`), or None on one packing."""
        count = self.points.shape[1]
        return self.spread.scale(self.states[:, count]) if self.likelihood.scaled_spread else None

    @property
    def record_scales(self) -> np.ndarray | None:
        """The posterior's samples (n, R) of each record's packing scale λ_r
        (:meth:`Spread.record_scale`), or None on one packing."""
        return self.likelihood.packing_scales(self.states) if self.likelihood.record_scales else None

    @property
    def discrepancy_sizes(self) -> np.ndarray | None:
        """The posterior's samples of the discrepancy's relative size τ, or None without one."""
        discrepancy = self.likelihood.discrepancy
        return None if discrepancy is None else discrepancy.size(self.states[:, -1])


def fit_stage(
    data: Data,
    points,
    observables,
    seed: int,
    model_error=None,
    instruments: Instruments | None = None,
    discrepancy: Discrepancy | None = None,
    smooth=(),
    chains: int = 1,
) -> Fit:
    """Fit the emulator to the simulations and sample the posterior it implies: the emulator to each
    parameter set's centre over its packings whose pulse the sensors detect (their median,
    :func:`~hexdem.calibration.spread.packing_centres`; the others' observables are NaN,
    :func:`~hexdem.calibration.simulations.detected`), the spread to their deviations; both
    smooth over the whole prior along the dimensions ``smooth`` (σ's: every set at one σ strikes the same
    K packings, whose contact networks change at a few σ, so that the K packings' centre and spread
    jump from one σ to the next by their sampling error; the nugget takes the jumps, and the
    likelihood's Σ_K/K their size), and held at the σ simulated with packings that differ
    (:func:`~hexdem.calibration.spread.disordered_range`: the ideal lattice's sets, σ = 0, enter
    neither) (``model_error``:
    the covariance of the model's own integration error, :func:`step_error`; ``instruments``: the
    records' gains and speed scatter; ``discrepancy``: what the model cannot represent; ``chains``:
    the sampler's independent ensembles, several for the posterior reported, whose convergence they
    check, one for a stage that only picks the next points)."""
    points, observables = np.asarray(points, float), np.asarray(observables, float)
    detected = np.isfinite(observables[..., 0]).sum(axis=1)
    seen = detected >= min(2, observables.shape[1])
    if seen.sum() < initial_points(points.shape[1]) // 2:
        raise HexdemError(
            f"the sensors would detect a pulse on {'enough packings of ' if observables.shape[1] > 1 else ''}only "
            f"{seen.sum()} of {len(points)} simulated parameter sets: too few to calibrate (a sensor the pulse "
            "seldom reaches, or records noisier than its pulse)"
        )
    spread = Spread(points, observables, *records_scatter(data, instruments), smooth=smooth)
    told = detected > 0
    if spread.held is not None:
        told &= ~ideal_sets(observables)
    emulator = Emulator(
        points[told],
        packing_centres(observables[told]),
        nugget_max=NOISY_NUGGET if smooth else 0.1,
        smooth=smooth,
        held=spread.held,
        groups=level_groups(points[told], smooth),
    )
    detection = Detection(points, observables, smooth) if observables.shape[1] >= 2 else None
    likelihood = Likelihood(data, emulator, spread, model_error, instruments, discrepancy, detection)
    states, chain = sample_posterior(likelihood, likelihood.dimension, seed, chains)
    return Fit(points, observables, emulator, spread, states, likelihood, chain)


def records_scatter(data: Data, instruments: Instruments | None = None) -> tuple[np.ndarray | None, int]:
    """(the covariance between the records that their packings make, its degrees of freedom): the
    records' sample covariance less their mean noise covariance and the striker's speed scatter
    (at the records' mean), from R − 1 deviations; (None, 0) for fewer than two records."""
    records = data.records
    if len(records) < 2:
        return None, 0
    scatter = np.cov(records, rowvar=False) - np.mean(data.covariances, axis=0)
    if instruments is not None:
        scatter = scatter - instruments.per_record(records.mean(axis=0))[0]
    return scatter, len(records) - 1


def step_error(coarse, fine) -> np.ndarray:
    """The covariance of the runs' integration error from one parameter set run at the
    calibration's time step (``coarse`` observables) and at half of it (``fine``): the error
    converges at first order in the step (the sensors' samples fall on whole steps), so the runs
    miss the limit of a vanishing step by about b = 2 (coarse − fine). The likelihood treats b as
    unknown within its size, the rank-one covariance b bᵀ: a record, measured without any time
    step, may then sit off the runs by b in either direction. A packing whose pulse the sensors do not
    detect (NaN observables) measures no error: none is added."""
    bias = np.nan_to_num(2.0 * (np.asarray(coarse, float) - np.asarray(fine, float)))
    return np.outer(bias, bias)


def next_points(fit: Fit, count: int, seed: int) -> np.ndarray:
    """``count`` distinct posterior samples of ``fit`` to simulate next."""
    rng = np.random.default_rng(seed)
    return fit.samples[rng.choice(len(fit.samples), size=count, replace=False)]


def design(dimension: int, count: int, seed: int) -> np.ndarray:
    """Stage 0's space-filling points (a Latin hypercube) in the unit cube."""
    return qmc.LatinHypercube(dimension, seed=np.random.default_rng(seed)).random(count)
