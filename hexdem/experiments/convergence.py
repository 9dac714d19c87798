"""Convergence in the time step: one configuration at several steps per contact, each measured
against a Richardson-extrapolated answer.

Both integrators converge at a known order p in the step h (velocity Verlet in LAMMPS: 2,
classical RK4 in the reference engine: 4). For a quantity :math:`Q(h) = Q_0 + C h^p + …`, the two
finest runs h and h·r (r the ratio of their steps) give
:math:`Q_0 ≈ Q(h) + (Q(h) − Q(h r)) / (r^p − 1)`, and
every run's error is its distance from that. The sampling interval is the same for every run
(a fixed time, ``dump_every`` scaled with the step), so that only the integration changes.
The sampling's own error is measured apart (:func:`sampling_error`): the same run sampled at
the default interval and at every step.

Measured quantities, over the observation lines' beads whose peak exceeds ``threshold`` V0:
the largest relative peak-speed error, the largest arrival-time error (in the run's time unit
and in contact times), each bead's arrival-time error, and the energy drift
(:mod:`hexdem.analysis.energy`). :func:`arrival_growth` bounds the arrival-time errors by a
straight line in the time the pulse has travelled: a second-order integrator's error in the
pulse's speed accumulates along its path.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import SAMPLES_PER_CONTACT, run_settings

#: Order of the error in the time step of each engine's integrator.
ORDERS = {"lammps": 2, "reference": 4}
#: Beads with a peak above this fraction of V0 are measured (as in ``hexdem compare``).
THRESHOLD = 0.01
#: A chain of 150 beads struck along its axis: its solitary wave keeps the struck bead's contact
#: time, so its arrival errors grow fastest (:func:`arrival_growth`); a LAMMPS study takes seconds.
CHAIN = RunConfig(shape="sites", site_walls_deg=[], strike_angle_deg=30.0, sites=[[k, k] for k in range(150)])


@dataclass(frozen=True)
class StepError:
    """One run of a convergence study: ``steps_per_contact``, ``dt`` (run units), the largest
    relative ``peak_error``, the largest ``arrival_error`` (run units) and ``arrival_error_contacts``
    (in contact times at V0), ``energy_drift``, the run's ``wall_time_s``, and ``arrival_errors``:
    each measured bead's arrival minus the extrapolated one, in contact times."""

    steps_per_contact: int
    dt: float
    peak_error: float
    arrival_error: float
    arrival_error_contacts: float
    energy_drift: float
    wall_time_s: float
    arrival_errors: np.ndarray = field(repr=False, compare=False)


@dataclass(frozen=True)
class Convergence:
    """A study's runs (coarse to fine), the engine's ``order``, the observed orders of the
    peak error between successive runs, the number of beads measured, and ``arrivals``: their
    extrapolated arrival times in contact times."""

    engine: str
    order: int
    runs: tuple[StepError, ...]
    observed_orders: tuple[float, ...]
    n_beads: int
    arrivals: np.ndarray = field(repr=False, compare=False)

    def at(self, steps_per_contact: int) -> StepError:
        return next(run for run in self.runs if run.steps_per_contact == steps_per_contact)


def measured_beads(results, v0: float) -> np.ndarray:
    """The observation lines' beads whose peak exceeds :data:`THRESHOLD` ``v0``."""
    line_beads = np.unique(np.concatenate(list(results.lines.values())))
    return line_beads[results.peak_speed[line_beads] > THRESHOLD * v0]


def richardson(fine: np.ndarray, coarse: np.ndarray, ratio: float, order: int) -> np.ndarray:
    """The extrapolated limit of a quantity computed with steps h (``fine``) and h·``ratio``."""
    return fine + (fine - coarse) / (ratio**order - 1.0)


def steps_config(config: RunConfig, steps_per_contact: int) -> RunConfig:
    """``config`` at ``steps_per_contact`` with its samples every 1/SAMPLES_PER_CONTACT of the
    contact time (the steps per contact must be a multiple of it so that every run samples at
    the same times)."""
    if steps_per_contact % SAMPLES_PER_CONTACT:
        raise HexdemError(
            f"a convergence study needs multiples of {SAMPLES_PER_CONTACT} steps per contact "
            f"(the same sampling times in every run), got {steps_per_contact}"
        )
    return config.replace(dt=None, dump_every=None, steps_per_contact=steps_per_contact)


def study_time_step(config: RunConfig, steps, workdir, log=None) -> Convergence:
    """Run ``config`` at every number of steps per contact in ``steps`` (multiples of
    SAMPLES_PER_CONTACT, the two largest in the ratio of the finest pair) and measure each
    against the extrapolation."""
    from hexdem.experiments.run import simulate

    log = log or (lambda message: None)
    steps = sorted(int(n) for n in steps)
    if len(steps) < 3:
        raise HexdemError(f"a convergence study needs at least 3 time steps, got {steps}")
    results = []
    for n in steps:
        begun = time.perf_counter()
        analysis = simulate(steps_config(config, n), Path(workdir) / f"steps{n}")
        results.append((analysis, time.perf_counter() - begun))
        log(f"{n} steps per contact: {results[-1][1]:.1f} s")
    finest = results[-1][0]
    beads = measured_beads(finest.results, config.v0)
    order = ORDERS[config.engine]
    peaks = np.array([a.results.peak_speed[beads] for a, _ in results])
    arrivals = np.array([a.results.arrival_time[beads] for a, _ in results])
    ratio = steps[-1] / steps[-2]
    exact_peak = richardson(peaks[-1], peaks[-2], ratio, order)
    exact_arrival = richardson(arrivals[-1], arrivals[-2], ratio, order)
    contact = finest.settings.contact_time_s / finest.settings.units.time_s
    runs = []
    for n, (analysis, wall), peak, arrival in zip(steps, results, peaks, arrivals):
        arrival_error = float(np.max(np.abs(arrival - exact_arrival)))
        runs.append(
            StepError(
                n,
                analysis.settings.dt_s / analysis.settings.units.time_s,
                float(np.max(np.abs(peak / exact_peak - 1.0))),
                arrival_error,
                arrival_error / contact,
                float(analysis.results.energy_drift),
                wall,
                (arrival - exact_arrival) / contact,
            )
        )
    observed = tuple(
        float(np.log(a.peak_error / b.peak_error) / np.log(b.steps_per_contact / a.steps_per_contact))
        for a, b in zip(runs[:-2], runs[1:-1])
    )
    return Convergence(config.engine, order, tuple(runs), observed, len(beads), exact_arrival / contact)


@dataclass(frozen=True)
class ArrivalGrowth:
    """A bound on a second-order study's arrival-time errors as the pulse travels: at N steps per
    contact time τ, a bead reached at t has |error| <= (``floor`` τ + ``rate`` t) / N² [-, both].
    ``rate`` is the least-squares slope of |error| N² against t over the study's beads and runs,
    ``floor`` the smallest intercept that bounds them all."""

    floor: float
    rate: float


def arrival_growth(study: Convergence) -> ArrivalGrowth:
    """The :class:`ArrivalGrowth` of ``study``'s arrival-time errors (of an engine of order 2)."""
    if study.order != 2:
        raise HexdemError(
            f"the arrival errors' growth is scaled for a second-order engine, not {study.engine}'s order {study.order}"
        )
    scaled = np.abs([run.arrival_errors * run.steps_per_contact**2 for run in study.runs])
    arrivals = np.broadcast_to(study.arrivals, scaled.shape)
    rate = float(np.polyfit(arrivals.ravel(), scaled.ravel(), 1)[0])
    return ArrivalGrowth(float(np.max(scaled - rate * arrivals)), rate)


@dataclass(frozen=True)
class SamplingError:
    """The largest relative ``peak_error`` and ``arrival_error`` (run units) of ``config`` sampled
    every ``dump_every`` steps against the same run sampled at every step, over ``n_beads``."""

    dump_every: int
    peak_error: float
    arrival_error: float
    n_beads: int


def sampling_error(config: RunConfig, workdir) -> SamplingError:
    """The error of the in-run analysis's sampling alone: ``config`` at its own sampling and at
    every step, the same time step and so the same trajectory (see :class:`SamplingError`)."""
    from hexdem.experiments.run import simulate, simulate_model

    model = build_model(config)
    settings = run_settings(config, model)
    sampled = simulate_model(config, model, settings, Path(workdir) / "sampled").results
    every_step = simulate(
        config.replace(dt=settings.dt_s / settings.units.time_s, dump_every=1), Path(workdir) / "every-step"
    ).results
    beads = measured_beads(every_step, config.v0)
    peak = np.max(np.abs(sampled.peak_speed[beads] / every_step.peak_speed[beads] - 1.0))
    arrival = np.max(np.abs(sampled.arrival_time[beads] - every_step.arrival_time[beads]))
    return SamplingError(settings.dump_every, float(peak), float(arrival), len(beads))
