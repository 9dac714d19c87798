"""``hexdem calibrate``: measured records → the model's parameters, with their uncertainties.

Checks everything before the first simulation (:func:`prepare`), then runs the stages of
:mod:`~hexdem.calibration.inference`, every simulation one task of the study executor
(:mod:`~hexdem.calibration.simulations`), and writes into DIR ``posterior.csv``,
``calibration.json``, ``posterior.png`` and ``predictive.png``
(:mod:`~hexdem.calibration.report`, :mod:`~hexdem.calibration.plots`).

``calibration-plan.json`` in DIR records what was asked (configuration, priors, the measured
file's records, seed, budget); a calibration run again in the same DIR resumes it, and one that
asks for something else is refused rather than mixed with it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path

import numpy as np

from hexdem.calibration import assessment, diagnostics, inference, nuisance, plots, sampler
from hexdem.calibration.observables import (
    MIN_SIGNAL_TO_NOISE,
    NoPulse,
    noise_covariance,
    read_measured,
    reduce_record,
)
from hexdem.calibration.packings import DISORDER_REALIZATIONS, SIGMA_KEY, on_sigma_levels
from hexdem.calibration.priors import parse_priors, to_parameters
from hexdem.calibration.report import summarize, write_posterior
from hexdem.calibration.simulations import (
    SIMULATIONS,
    Problem,
    check_problem,
    finished,
    simulate_point,
    simulation_name,
)
from hexdem.common.checks import positive_int
from hexdem.common.io import ensure_writable_dir, keep_plan, locked_directory, write_json
from hexdem.errors import HexdemError, RunFailed, one_line
from hexdem.experiments.executors import check_study_options, holding, parsl_session, run_phase

PLAN_NAME = "calibration-plan.json"
#: The folder of the time-step check's run (and ``-half-step`` of its run at half the step).
STEP_CHECK = "step-check"
#: Posterior predictive draws behind ``predictive.png``.
PREDICTIVE_DRAWS = 2000


#: ``--sensor-gain-sd``'s default: a calibrated accelerometer's sensitivity is known to about 2 %
#: (its calibration certificate's uncertainty, before it is glued into a particle).
DEFAULT_GAIN_SD = 0.02
#: ``--speed-scatter``'s default: a striker released the same way each time, to about 1 % in speed.
DEFAULT_SPEED_SCATTER = 0.01
#: The largest relative standard deviation ``--sensor-gain-sd`` and ``--speed-scatter`` take: the
#: instruments' errors enter the likelihood to first order.
LARGEST_INSTRUMENT_SD = 0.2
#: A record whose sampling rate differs from the configuration's ``sensor_rate_hz`` by more than
#: this share has its simulations sampled at its own rate.
RATE_RTOL = 0.01


@dataclass(frozen=True)
class Calibration:
    """A checked calibration: the ``problem``, the measured ``data``, each record's noise per channel
    ``channel_noise_m_s2`` (R, n_sensors, 2; NaN for an axis not measured), the stage sizes, ``seed``,
    the records' ``instruments``, the ``acceleration_unit`` they were read in, their
    ``rate_hz``, ``notes`` on how they were read, the model's ``discrepancy`` (None: the model
    taken as exact), and the records ``left_out`` (a sensor without a pulse)."""

    problem: Problem
    data: inference.Data
    channel_noise_m_s2: np.ndarray
    stages: tuple[int, ...]
    seed: int
    instruments: nuisance.Instruments
    acceleration_unit: str = "m/s2"
    rate_hz: float = 0.0
    notes: tuple[str, ...] = ()
    discrepancy: nuisance.Discrepancy | None = None
    left_out: tuple[str, ...] = ()


def realizations_of(priors, realizations: int | None) -> int:
    """Packings per parameter set: as asked, else 1 on the ideal lattice and
    :data:`~hexdem.calibration.packings.DISORDER_REALIZATIONS` when σ is calibrated, whose
    spread between packings one packing cannot measure."""
    calibrates_sigma = any(prior.key == SIGMA_KEY for prior in priors)
    if realizations is None:
        return DISORDER_REALIZATIONS if calibrates_sigma else 1
    realizations = positive_int("--realizations", realizations)
    if calibrates_sigma and realizations < 2:
        raise HexdemError(
            f"--realizations {realizations}: a prior on {SIGMA_KEY} needs at least 2 packings per "
            "parameter set, whose spread the comparison accounts for"
        )
    return realizations


def instrument_sd(option: str, value) -> float:
    """``value`` of ``option`` (``--sensor-gain-sd``, ``--speed-scatter``): a relative standard
    deviation in [0, :data:`LARGEST_INSTRUMENT_SD`], or a one-line HexdemError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 <= value <= LARGEST_INSTRUMENT_SD:
        raise HexdemError(
            f"{option} {value!r}: a relative standard deviation in [0, {LARGEST_INSTRUMENT_SD}] (0.02 is 2 %)"
        )
    return float(value)


def prepare(
    base: dict,
    measured,
    prior_texts,
    budget: int | None,
    seed: int,
    realizations: int | None = None,
    gain_sd: float = DEFAULT_GAIN_SD,
    speed_scatter: float = DEFAULT_SPEED_SCATTER,
    acceleration_unit: str = "m/s2",
    model_discrepancy: bool = True,
) -> Calibration:
    """Every check of the input, in one line each and before any simulation. ``budget`` counts
    simulations: parameter sets times ``realizations``. The records' sampling rate, where it is not
    the configuration's ``sensor_rate_hz``, becomes the simulations'; their measured axes, those
    with which the simulations' records are reduced."""
    priors = parse_priors(prior_texts)
    realizations = realizations_of(priors, realizations)
    gain_sd, speed_scatter = instrument_sd("--sensor-gain-sd", gain_sd), instrument_sd("--speed-scatter", speed_scatter)
    problem = Problem(base, tuple(priors), realizations, seed)
    check_problem(problem)
    records = read_measured(measured, problem.sensors, acceleration_unit)
    problem, notes = _as_measured(problem, records)
    dimension = len(priors)
    budget = inference.default_budget(dimension) * realizations if budget is None else positive_int("--budget", budget)
    stages = inference.stage_sizes(dimension, budget // realizations, realizations)
    kept, left_out, observed, covariances, noise = [], [], [], [], []
    for k, record in enumerate(records):
        try:
            covariance, levels = noise_covariance(record, problem.sensors, seed + k)
            observed.append(reduce_record(record.times, record.accelerations, record.axes))
        except NoPulse as exc:
            if len(records) == 1 or (not kept and k == len(records) - 1):
                raise HexdemError(f"{measured}, record {record.name}: {exc}") from None
            notes.append(f"record {record.name} left out: {str(exc).split(' (')[0]}")
            left_out.append(record.name)
            continue
        except HexdemError as exc:
            raise HexdemError(f"{measured}, record {record.name}: {exc}") from None
        kept.append(record)
        covariances.append(covariance)
        noise.append(levels)
    problem = replace(problem, detection_m_s2=detection_levels(np.array(noise)))
    data = inference.Data(
        np.array(observed),
        np.array(covariances),
        tuple(problem.names),
        tuple(record.name for record in kept),
        len(left_out),
    )
    instruments = nuisance.Instruments(len(problem.sensors), gain_sd, speed_scatter)
    discrepancy = nuisance.Discrepancy(len(problem.sensors)) if model_discrepancy else None
    return Calibration(
        problem,
        data,
        np.array(noise),
        tuple(stages),
        seed,
        instruments,
        acceleration_unit,
        kept[0].rate_hz,
        tuple(notes),
        discrepancy,
        tuple(left_out),
    )


def detection_levels(noise) -> tuple[float, ...]:
    """Each sensor's smallest detectable peak acceleration [m/s²]: :data:`MIN_SIGNAL_TO_NOISE` times
    the median over the records of its noisier measured axis's noise (``noise`` (R, n_sensors, 2)).
    A simulated packing whose pulse stays below it at a sensor is left out of the fit, as a record
    without a pulse is: both are then of the packings whose pulse the sensors detect."""
    return tuple(float(MIN_SIGNAL_TO_NOISE * level) for level in np.median(np.nanmax(noise, axis=2), axis=0))


def _as_measured(problem: Problem, records) -> tuple[Problem, list[str]]:
    """``problem`` simulated as ``records`` were measured, and notes saying how: sampled at their
    rate where it is not the configuration's ``sensor_rate_hz``, reduced with their axes."""
    notes, rate = [], records[0].rate_hz
    configured = problem.config([prior.from_unit(0.5) for prior in problem.priors]).sensor_rate_hz
    if abs(rate / configured - 1) > RATE_RTOL:
        notes.append(
            f"the records are sampled at {rate / 1e3:.6g} kS/s, not the configuration's "
            f"{configured / 1e3:.6g} kS/s: the simulations sample at the records' rate"
        )
        problem = replace(problem, base=problem.base | {"sensor_rate_hz": rate})
        check_problem(problem)
    axes = records[0].axes
    if not axes.all():
        left_out = [f"{problem.sensors[s]} {'xy'[j]}" for s, j in zip(*np.nonzero(~axes))]
        notes.append(f"axes not measured, left out of the records and the simulations alike: {', '.join(left_out)}")
    return replace(problem, axes=tuple(tuple(bool(a) for a in row) for row in axes)), notes


def _plan(calibration: Calibration, measured) -> dict:
    return {
        "base": calibration.problem.base,
        "priors": [p.as_dict() | {"key": p.key} for p in calibration.problem.priors],
        "realizations": calibration.problem.realizations,
        "stages": list(calibration.stages),
        "seed": calibration.seed,
        "measured": str(measured),
        "records": calibration.data.records.tolist(),
        "axes": calibration.problem.axes,
        "instruments": {
            "sensor_gain_sd": calibration.instruments.gain_sd,
            "speed_scatter": calibration.instruments.speed_scatter,
            "acceleration_unit": calibration.acceleration_unit,
        },
        "model_discrepancy": calibration.discrepancy is not None,
    }


def _simulate_stage(
    calibration: Calibration, unit_points, first_index: int, out: Path, workers: int, parsl, label: str
) -> tuple[np.ndarray, np.ndarray, int]:
    """Simulate ``unit_points`` (those not finished before); (points kept, observables (n, K, m),
    failed count). A failed simulation is left out of the fit and counted."""
    problem = calibration.problem
    values = to_parameters(problem.priors, unit_points)
    folders = {
        (i, k): out / SIMULATIONS / simulation_name(first_index + i, k, problem.realizations)
        for i in range(len(values))
        for k in range(problem.realizations)
    }
    results = {key: finished(folder, values[key[0]]) for key, folder in folders.items()}
    tasks = {
        key: (simulate_point, problem, values[key[0]].tolist(), str(folder), key[1])
        for key, folder in folders.items()
        if results[key] is None
    }
    failed = set()
    for key, error in run_phase(tasks, workers, parsl, label, "simulation", done_before=len(folders) - len(tasks)):
        if error is None:
            results[key] = finished(folders[key], values[key[0]])
        else:
            failed.add(key[0])
    kept = [i for i in range(len(values)) if i not in failed]
    observables = np.array([[results[(i, k)] for k in range(problem.realizations)] for i in kept])
    return unit_points[kept], observables, len(failed)


def calibrate(calibration: Calibration, measured, out, workers: int = 1, parsl=None, log=print) -> dict:
    """Run ``calibration`` into ``out``; the summary written to ``calibration.json``."""
    check_study_options(workers)
    parsl = parsl_session(parsl)
    out = ensure_writable_dir(out)
    problem, seed = calibration.problem, calibration.seed
    dimension = len(problem.priors)
    started = time.perf_counter()
    for note in calibration.notes:
        log(f"note: {note}")
    with locked_directory(out, "another hexdem calibrate"), holding(parsl, workers):
        keep_plan(out / PLAN_NAME, _plan(calibration, measured), "calibration")
        points, observables, failed, index, fit = np.empty((0, dimension)), None, 0, 0, None
        step_check, model_error = None, None
        smooth = (problem.keys.index(SIGMA_KEY),) if SIGMA_KEY in problem.keys else ()
        for stage, size in enumerate(calibration.stages):
            new = (
                inference.design(dimension, size, seed)
                if fit is None
                else inference.next_points(fit, size, seed + stage)
            )
            if SIGMA_KEY in problem.keys:
                new = on_sigma_levels(new, problem.keys.index(SIGMA_KEY))
            label = f"stage {stage + 1}/{len(calibration.stages)}"
            log(
                f"{label}: {size} parameter set(s) x {problem.realizations} packing(s)"
                + (" over the prior" if fit is None else " from the posterior")
            )
            kept, simulated, lost = _simulate_stage(calibration, new, index, out, workers, parsl, label)
            index, failed = index + size, failed + lost
            points = np.vstack([points, kept])
            observables = simulated if observables is None else np.concatenate([observables, simulated])
            if len(points) < inference.initial_points(dimension) // 2:
                raise HexdemError(
                    f"{failed} of {index} simulations failed (see {out / SIMULATIONS}); too few are left to calibrate"
                )
            fitted = partial(
                inference.fit_stage,
                calibration.data,
                points,
                observables,
                seed + 1000 + stage,
                instruments=calibration.instruments,
                discrepancy=calibration.discrepancy,
                smooth=smooth,
            )
            if step_check is None:
                step_check = _check_time_step(calibration, fitted(), out, workers, parsl)
                model_error = inference.step_error(step_check["coarse"], step_check["half"])
            final = stage == len(calibration.stages) - 1
            fit = fitted(model_error=model_error, chains=sampler.CHAINS if final else 1)
        summary = _write_results(calibration, fit, out, failed, time.perf_counter() - started, step_check)
    for note in summary["identifiability"]:
        log(f"note: {note}")
    for warning in summary["warnings"]:
        log(f"warning: {warning}")
    return summary


def _check_time_step(calibration: Calibration, fit: inference.Fit, out: Path, workers: int, parsl) -> dict:
    """The stage-0 posterior's most likely sample run at the calibration's time step and at half
    of it, on packing 0, two tasks of the study executor (:func:`~hexdem.calibration.inference.step_error`)."""
    problem = calibration.problem
    unit = fit.samples[int(np.argmax(fit.likelihood(fit.states)))][None]
    if SIGMA_KEY in problem.keys:  # on a level, so that it runs on a packing of the calibration's
        unit = on_sigma_levels(unit, problem.keys.index(SIGMA_KEY))
    values = to_parameters(problem.priors, unit)[0].tolist()
    steps = problem.config(values).steps_per_contact
    half = replace(problem, base=problem.base | {"steps_per_contact": 2 * steps})
    folders = {"coarse": out / SIMULATIONS / STEP_CHECK, "half": out / SIMULATIONS / f"{STEP_CHECK}-half-step"}
    tasks = {
        name: (simulate_point, run, values, str(folders[name]))
        for name, run in (("coarse", problem), ("half", half))
        if finished(folders[name], values) is None
    }
    for name, error in run_phase(tasks, workers, parsl, "time-step check", "simulation"):
        if error is not None:
            step = "at half the time step" if name == "half" else "at the calibration's time step"
            raise RunFailed(f"the time-step check's run {step} failed: {one_line(error)}")
    return {
        "parameters": dict(zip(problem.keys, values)),
        "steps_per_contact": [steps, 2 * steps],
        **{name: finished(folder, values).tolist() for name, folder in folders.items()},
    }


def _write_results(
    calibration: Calibration, fit: inference.Fit, out: Path, failed: int, seconds: float, step_check: dict
) -> dict:
    problem, data = calibration.problem, calibration.data
    samples = to_parameters(problem.priors, fit.samples)
    write_posterior(out / "posterior.csv", problem.priors, samples)
    summary = summarize(problem.priors, samples)
    summary["method"] = {
        "name": "Gaussian-process emulator refined on the posterior, sampled by emcee",
        "stages": list(calibration.stages),
        "chains": fit.chain.chains,
        "walkers": fit.chain.walkers,
        "burn_in_steps": sampler.chain_steps(fit.likelihood.dimension)[0],
        "kept_steps": fit.chain.steps,
        "thin": sampler.THIN,
        "seed": calibration.seed,
    }
    summary["simulations"] = {
        "parameter_sets": int(sum(calibration.stages)),
        "realizations": problem.realizations,
        "runs": int(sum(calibration.stages)) * problem.realizations,
        "failed": failed,
        "undetected": int(np.sum(~np.isfinite(fit.observables[..., 0]))),
        "wall_time_s": seconds,
    }
    summary["time_step_check"] = step_check | {
        "bias": (2.0 * (np.array(step_check["coarse"]) - np.array(step_check["half"]))).tolist()
    }
    summary["data"] = {
        "records": len(data.records),
        "records_left_out": list(calibration.left_out),
        "detection_m_s2": dict(zip(problem.sensors, problem.detection_m_s2 or ())),
        "sensors": problem.sensors,
        "observables": list(data.names),
        "accelerometer_noise_m_s2": [
            float(np.sqrt(np.nanmean(levels**2))) for levels in calibration.channel_noise_m_s2
        ],
        "channel_noise_m_s2": [
            {
                sensor: [None if np.isnan(v) else float(v) for v in levels]
                for sensor, levels in zip(problem.sensors, record)
            }
            for record in calibration.channel_noise_m_s2
        ],
        "axes": {
            sensor: [axis for axis, measured in zip("xy", row) if measured]
            for sensor, row in zip(problem.sensors, problem.axes)
        },
        "sampling_rate_hz": calibration.rate_hz,
        "acceleration_unit": calibration.acceleration_unit,
    }
    summary |= assessment.assess(fit, problem, data, calibration.instruments, calibration.discrepancy, calibration.seed)
    write_json(out / "calibration.json", summary)
    plots.corner(problem.priors, samples, out / "posterior.png")
    rng = np.random.default_rng(calibration.seed)
    draws = fit.states[rng.choice(len(fit.states), PREDICTIVE_DRAWS)]
    mean, common, own = fit.likelihood.moments(draws)
    predicted = diagnostics.gaussian_draws(rng, mean, np.mean(data.covariances, axis=0) + common + own)
    misfit = diagnostics.misfit_records(summary["fit"], assessment.MISFIT_P)
    plots.predictive(
        problem.sensors,
        _sensor_distances(problem, samples),
        data.records,
        data.covariances,
        predicted,
        diagnostics.predictive_residuals(fit.likelihood, draws, rng),
        out / "predictive.png",
        [name in misfit for name in data.record_names],
    )
    return summary


def _sensor_distances(problem: Problem, samples) -> np.ndarray:
    """Each sensor's distance from the struck bead [nominal diameters], in the configuration at the
    posterior median."""
    from hexdem.model.model_builder import build_model
    from hexdem.model.sensors import sensor_beads

    config = problem.config(np.median(samples, axis=0).tolist())
    packing = build_model(config).packing
    beads = list(sensor_beads(config.sensors, packing).values())
    offsets = packing.positions_m[beads] - packing.positions_m[packing.struck]
    return np.hypot(*offsets.T) / packing.diameter_m
