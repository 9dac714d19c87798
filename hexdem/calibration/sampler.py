"""The posterior's sampler: independent ensembles of emcee's walkers, and how they mixed.

A calibration's posterior (:class:`~hexdem.calibration.inference.Likelihood` on the priors' unit
cube) is sampled by :data:`CHAINS` independent ensembles of :data:`WALKERS` walkers each
(Goodman & Weare 2010's affine-invariant ensemble; past :data:`FEW_COORDINATES` coordinates,
differential evolution and its snooker update, which mix faster over skewed coordinates), each
started at the best of its own :data:`START_CANDIDATES` prior points. Independent ensembles are
what a convergence check needs: one ensemble's walkers share their moves, so an ensemble stuck
in one mode of the posterior looks converged to itself.

**Convergence** is checked as the field checks it (:class:`Chain`): each ensemble's kept chain
runs until it holds :data:`AUTOCORRELATION_LENGTHS` integrated autocorrelation times τ (emcee's
rule; Foreman-Mackey et al. 2013), up to :data:`MOST_KEPT` times its first length; and
over every walker of every ensemble, taken as a chain, the rank-normalised split R̂ and the bulk
and tail effective sample sizes (Vehtari, Gelman, Simpson, Carpenter & Bürkner 2021, computed by
ArviZ) of every coordinate must reach :data:`RHAT_LIMIT` and :data:`ESS_MINIMUM`. Laid end to end,
an ensemble whose walkers sit in two modes in other shares than another's, or whose first
walkers differ from its last, shows in R̂; taken one walker a chain instead, R̂ of 128 chains of a
few dozen independent samples each reads 1.02-1.04 on a normal posterior that mixed well.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.stats import qmc

#: Independent ensembles whose agreement R̂ measures.
CHAINS = 4
#: Walkers of each ensemble.
WALKERS = 32
BURN_IN_STEPS = 300
KEPT_STEPS = 500
#: The most coordinates on which the walkers take BURN_IN_STEPS and KEPT_STEPS (:func:`chain_steps`).
FEW_COORDINATES = 3
THIN = 10
#: How far below the median walker's log probability a walker is a straggler (plus the dimension).
STRAGGLER_DROP = 10.0
#: Prior points at which the posterior is evaluated to start each ensemble's walkers.
START_CANDIDATES = 4096
#: Integrated autocorrelation times that each ensemble's kept chain must hold (emcee's rule).
AUTOCORRELATION_LENGTHS = 50
#: The most times an ensemble's kept chain grows to hold them, each time to EXTENSION_MARGIN times
#: AUTOCORRELATION_LENGTHS τ as then estimated, and never past MOST_KEPT times its first length.
EXTENSIONS = 3
EXTENSION_MARGIN = 1.5
MOST_KEPT = 4
#: The rank-normalised split R̂ below which the chains agree (Vehtari et al. 2021).
RHAT_LIMIT = 1.01
#: The bulk and tail effective sample sizes each coordinate must reach (Vehtari et al. 2021: 100 a chain).
ESS_MINIMUM = 400
#: The tail effective sample size's quantiles: the ends of the 90 % intervals that calibrate reports.
TAIL_QUANTILES = (0.05, 0.95)


def chain_steps(dimension: int) -> tuple[int, int]:
    """(burn-in, first kept) steps of each ensemble on a posterior of ``dimension`` coordinates: the
    autocorrelation time τ grows with the dimension (some 10 steps a coordinate past
    :data:`FEW_COORDINATES`, with differential evolution), so past it the walkers take 100 steps a
    coordinate to burn in and keep 250 at first; :data:`BURN_IN_STEPS` and :data:`KEPT_STEPS` up to it."""
    if dimension <= FEW_COORDINATES:
        return BURN_IN_STEPS, KEPT_STEPS
    return 100 * dimension, 250 * dimension


@dataclass(frozen=True)
class Chain:
    """How the sampler mixed. Per coordinate of the sampler's unit cube: ``autocorrelation_steps``,
    the largest over the ensembles of emcee's integrated autocorrelation time τ; ``rhat``, the
    rank-normalised split R̂ over the ensembles (each its walkers end to end); ``ess_bulk`` and ``ess_tail``,
    the bulk and tail (5 % and 95 % quantiles) effective sample sizes. And the walkers' mean
    ``acceptance_fraction``, the ``steps`` each ensemble kept, its ``walkers``, the ``chains``
    (independent ensembles)."""

    autocorrelation_steps: tuple[float, ...]
    acceptance_fraction: float
    steps: int
    walkers: int
    chains: int = 1
    rhat: tuple[float, ...] = ()
    ess_bulk: tuple[float, ...] = ()
    ess_tail: tuple[float, ...] = ()

    @property
    def autocorrelation_lengths(self) -> float:
        """The kept steps over the largest τ: emcee's rule asks :data:`AUTOCORRELATION_LENGTHS`."""
        return self.steps / max(self.autocorrelation_steps)

    @property
    def problems(self) -> list[str]:
        """What falls short of the checks (:data:`AUTOCORRELATION_LENGTHS`, :data:`RHAT_LIMIT`,
        :data:`ESS_MINIMUM`), one phrase each; empty when the chains converged."""
        found = []
        if self.autocorrelation_lengths < AUTOCORRELATION_LENGTHS:
            found.append(
                f"the kept chain holds {self.autocorrelation_lengths:.3g} autocorrelation times "
                f"(τ = {max(self.autocorrelation_steps):.3g} steps; emcee's rule asks {AUTOCORRELATION_LENGTHS})"
            )
        if self.rhat and max(self.rhat) >= RHAT_LIMIT:
            found.append(f"R̂ reaches {max(self.rhat):.4g} over {self.chains} independent chains (≥ {RHAT_LIMIT})")
        for kind, sizes in (("bulk", self.ess_bulk), ("tail", self.ess_tail)):
            if sizes and min(sizes) < ESS_MINIMUM:
                found.append(f"the {kind} effective sample size falls to {min(sizes):.0f} (< {ESS_MINIMUM})")
        return found

    @property
    def converged(self) -> bool:
        return not self.problems

    def as_dict(self) -> dict:
        return {
            "chains": self.chains,
            "walkers": self.walkers,
            "kept_steps": self.steps,
            "acceptance_fraction": self.acceptance_fraction,
            "autocorrelation_steps": list(self.autocorrelation_steps),
            "autocorrelation_lengths": self.autocorrelation_lengths,
            "rhat": list(self.rhat),
            "ess_bulk": list(self.ess_bulk),
            "ess_tail": list(self.ess_tail),
            "converged": self.converged,
        }


def sample_posterior(log_probability, dimension: int, seed: int, chains: int = CHAINS) -> tuple[np.ndarray, Chain]:
    """Unit-cube samples (``chains`` · WALKERS · kept steps / THIN, ``dimension``) of the posterior
    whose log density (vectorised over rows) is ``log_probability``, and how the ``chains``
    independent ensembles mixed (see the module docstring). The ensembles keep the same number of
    steps: their first length, grown until every one holds AUTOCORRELATION_LENGTHS of the largest
    τ (at most EXTENSIONS times, to at most MOST_KEPT times the first length); one ensemble alone,
    for a stage that only picks the next points or a second look at the posterior, keeps its first
    length."""
    rng = np.random.default_rng(seed)
    burn_in, kept = chain_steps(dimension)
    ensembles = [
        _burned_in(log_probability, dimension, burn_in, np.random.default_rng(rng.integers(2**63)))
        for _ in range(chains)
    ]
    states = [sampler.run_mcmc(state, kept) for sampler, state in ensembles]
    tau = _largest_tau(ensembles)
    for _ in range(EXTENSIONS if chains > 1 else 0):
        done = ensembles[0][0].iteration
        wanted = min(
            THIN * int(np.ceil(EXTENSION_MARGIN * AUTOCORRELATION_LENGTHS * np.max(tau) / THIN)), MOST_KEPT * kept
        )
        if done >= AUTOCORRELATION_LENGTHS * np.max(tau) or wanted <= done:
            break
        states = [sampler.run_mcmc(state, wanted - done) for (sampler, _), state in zip(ensembles, states)]
        tau = _largest_tau(ensembles)
    draws = np.stack([sampler.get_chain() for sampler, _ in ensembles])  # (chains, steps, WALKERS, dimension)
    steps = draws.shape[1]
    diagnosis = Chain(
        tuple(float(t) for t in tau),
        float(np.mean([sampler.acceptance_fraction for sampler, _ in ensembles])),
        steps,
        WALKERS,
        chains,
        *_rank_diagnostics(draws.transpose(0, 2, 1, 3).reshape(chains, WALKERS * steps, dimension)),
    )
    return draws[:, ::THIN].reshape(-1, dimension), diagnosis


def _largest_tau(ensembles) -> np.ndarray:
    """Each coordinate's integrated autocorrelation time, the largest over the ``ensembles``."""
    return np.max([sampler.get_autocorr_time(quiet=True, tol=0) for sampler, _ in ensembles], axis=0)


def _rank_diagnostics(draws) -> tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]:
    """(R̂, bulk ESS, tail ESS) per coordinate of ``draws`` (chains, draws, coordinates), by ArviZ."""
    from arviz_stats.base import array_stats

    options = {"chain_axis": 0, "draw_axis": 1}
    rhat = array_stats.rhat(draws, **options)
    bulk = array_stats.ess(draws, method="bulk", **options)
    tail = array_stats.ess(draws, method="tail", prob=TAIL_QUANTILES, **options)
    return tuple(tuple(float(v) for v in np.atleast_1d(values)) for values in (rhat, bulk, tail))


def _burned_in(log_probability, dimension: int, burn_in: int, rng):
    """(emcee's sampler, its state) of one ensemble after its burn-in, its kept chain empty: the
    walkers start at the best of START_CANDIDATES prior points; after the burn-in every straggler
    (:func:`stragglers`) restarts beside a walker in the posterior and the burn-in runs again."""
    import emcee

    candidates = qmc.LatinHypercube(dimension, seed=rng).random(START_CANDIDATES)
    best = candidates[np.argsort(log_probability(candidates))[-WALKERS:]]
    start = np.clip(best + rng.normal(0.0, 1e-3, best.shape), 1e-6, 1 - 1e-6)
    moves = None if dimension <= FEW_COORDINATES else [(emcee.moves.DEMove(), 0.8), (emcee.moves.DESnookerMove(), 0.2)]
    sampler = emcee.EnsembleSampler(WALKERS, dimension, log_probability, vectorize=True, moves=moves)
    sampler.random_state = np.random.RandomState(int(rng.integers(2**31))).get_state()
    state = sampler.run_mcmc(start, burn_in)
    lost = stragglers(sampler.get_log_prob(discard=burn_in // 2), dimension)
    if lost.any():
        coords = state.coords.copy()
        found = np.flatnonzero(~lost)
        coords[lost] = np.clip(
            coords[rng.choice(found, lost.sum())] + rng.normal(0.0, 1e-6, (lost.sum(), dimension)), 0.0, 1.0
        )
        sampler.reset()
        state = sampler.run_mcmc(coords, burn_in)
    sampler.reset()
    return sampler, state


def stragglers(log_probability, dimension: int) -> np.ndarray:
    """Walkers stuck where the posterior has no mass: their median log probability over the
    burn-in's second half (``log_probability`` (steps, walkers)) is more than STRAGGLER_DROP +
    ``dimension`` below the median walker's, a density e^-(10 + p) of the typical one, where the
    typical set of a p-dimensional posterior lies within about p/2 of its median. An affine-invariant
    stretch move brings such a walker back only along straight lines through the others, which a
    curved ridge of the posterior can cross only where it has no mass."""
    typical = np.median(log_probability, axis=0)
    return typical < np.median(typical) - (STRAGGLER_DROP + dimension)
