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
from pathlib import Path

import numpy as np

from hexdem.calibration import inference, plots
from hexdem.calibration.observables import noise_covariance, read_measured, reduce_record
from hexdem.calibration.packings import DISORDER_REALIZATIONS, SIGMA_KEY, on_sigma_levels
from hexdem.calibration.priors import parse_priors, to_parameters
from hexdem.calibration.report import summarize, write_posterior
from hexdem.calibration.simulations import SIMULATIONS, Problem, check_problem, finished, simulate_point, simulation_name
from hexdem.common.checks import positive_int
from hexdem.common.io import ensure_writable_dir, keep_plan, locked_directory, write_json
from hexdem.errors import HexdemError, RunFailed, one_line
from hexdem.experiments.executors import check_study_options, holding, parsl_session, run_phase

PLAN_NAME = "calibration-plan.json"
#: The folder of the time-step check's run (and ``-half-step`` of its run at half the step).
STEP_CHECK = "step-check"
#: Posterior predictive draws behind ``predictive.png``.
PREDICTIVE_DRAWS = 2000


@dataclass(frozen=True)
class Calibration:
    """A checked calibration: the ``problem``, the measured ``data``, the stage sizes, ``seed``."""

    problem: Problem
    data: inference.Data
    noise_m_s2: tuple[float, ...]
    stages: tuple[int, ...]
    seed: int


def _realizations(priors, realizations: int | None) -> int:
    """Packings per parameter set: as asked, else 1 on the ideal lattice and
    :data:`~hexdem.calibration.packings.DISORDER_REALIZATIONS` when σ is calibrated, whose
    spread between packings one packing cannot measure."""
    calibrates_sigma = any(prior.key == SIGMA_KEY for prior in priors)
    if realizations is None:
        return DISORDER_REALIZATIONS if calibrates_sigma else 1
    realizations = positive_int("--realizations", realizations)
    if calibrates_sigma and realizations < 2:
        raise HexdemError(f"--realizations {realizations}: a prior on {SIGMA_KEY} needs at least 2 packings per "
                          "parameter set, whose spread the comparison accounts for")
    return realizations


def prepare(base: dict, measured, prior_texts, budget: int | None, seed: int,
            realizations: int | None = None) -> Calibration:
    """Every check of the input, in one line each and before any simulation. ``budget`` counts
    simulations: parameter sets times ``realizations``."""
    priors = parse_priors(prior_texts)
    realizations = _realizations(priors, realizations)
    problem = Problem(base, tuple(priors), realizations, seed)
    check_problem(problem)
    dimension = len(priors)
    budget = (inference.default_budget(dimension) * realizations if budget is None
              else positive_int("--budget", budget))
    stages = inference.stage_sizes(dimension, budget // realizations, realizations)
    records = read_measured(measured, problem.sensors)
    observed, covariances, noise = [], [], []
    for k, record in enumerate(records):
        try:
            covariance, level = noise_covariance(record, problem.sensors, seed + k)
            observed.append(reduce_record(record.times, record.accelerations))
        except HexdemError as exc:
            raise HexdemError(f"{measured}, record {record.name}: {exc}") from None
        covariances.append(covariance)
        noise.append(level)
    data = inference.Data(np.array(observed), np.array(covariances), tuple(problem.names))
    return Calibration(problem, data, tuple(noise), tuple(stages), seed)


def _plan(calibration: Calibration, measured) -> dict:
    return {"base": calibration.problem.base, "priors": [p.as_dict() | {"key": p.key} for p in calibration.problem.priors],
            "realizations": calibration.problem.realizations, "stages": list(calibration.stages),
            "seed": calibration.seed, "measured": str(measured),
            "records": calibration.data.records.tolist()}


def _simulate_stage(calibration: Calibration, unit_points, first_index: int, out: Path, workers: int, parsl,
                    label: str) -> tuple[np.ndarray, np.ndarray, int]:
    """Simulate ``unit_points`` (those not finished before); (points kept, observables (n, K, m),
    failed count). A failed simulation is left out of the fit and counted."""
    problem = calibration.problem
    values = to_parameters(problem.priors, unit_points)
    folders = {(i, k): out / SIMULATIONS / simulation_name(first_index + i, k, problem.realizations)
               for i in range(len(values)) for k in range(problem.realizations)}
    results = {key: finished(folder, values[key[0]]) for key, folder in folders.items()}
    tasks = {key: (simulate_point, problem, values[key[0]].tolist(), str(folder), key[1])
             for key, folder in folders.items() if results[key] is None}
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
    with locked_directory(out, "another hexdem calibrate"), holding(parsl, workers):
        keep_plan(out / PLAN_NAME, _plan(calibration, measured), "calibration")
        points, observables, failed, index, fit = np.empty((0, dimension)), None, 0, 0, None
        step_check, model_error = None, None
        for stage, size in enumerate(calibration.stages):
            new = (inference.design(dimension, size, seed) if fit is None
                   else inference.next_points(fit, size, seed + stage))
            if SIGMA_KEY in problem.keys:
                new = on_sigma_levels(new, problem.keys.index(SIGMA_KEY))
            label = f"stage {stage + 1}/{len(calibration.stages)}"
            log(f"{label}: {size} parameter set(s) x {problem.realizations} packing(s)"
                + (" over the prior" if fit is None else " from the posterior"))
            kept, simulated, lost = _simulate_stage(calibration, new, index, out, workers, parsl, label)
            index, failed = index + size, failed + lost
            points = np.vstack([points, kept])
            observables = simulated if observables is None else np.concatenate([observables, simulated])
            if len(points) < inference.initial_points(dimension) // 2:
                raise HexdemError(f"{failed} of {index} simulations failed (see {out / SIMULATIONS}); too few are "
                                  "left to calibrate")
            fit = inference.fit_stage(calibration.data, points, observables, seed + 1000 + stage, model_error)
            if step_check is None:
                step_check = _check_time_step(calibration, fit, out, workers, parsl)
                model_error = inference.step_error(step_check["coarse"], step_check["half"])
                fit = inference.fit_stage(calibration.data, points, observables, seed + 1000 + stage, model_error)
        summary = _write_results(calibration, fit, out, failed, time.perf_counter() - started, step_check)
    for note in summary["identifiability"]:
        log(f"note: {note}")
    return summary


def _check_time_step(calibration: Calibration, fit: inference.Fit, out: Path, workers: int, parsl) -> dict:
    """The stage-0 posterior's most likely sample run at the calibration's time step and at half
    of it, on packing 0, two tasks of the study executor (:func:`~hexdem.calibration.inference.step_error`)."""
    problem = calibration.problem
    unit = fit.samples[int(np.argmax(fit.likelihood(fit.samples)))][None]
    if SIGMA_KEY in problem.keys:  # on a level, so that it runs on a packing of the calibration's
        unit = on_sigma_levels(unit, problem.keys.index(SIGMA_KEY))
    values = to_parameters(problem.priors, unit)[0].tolist()
    steps = problem.config(values).steps_per_contact
    half = replace(problem, base=problem.base | {"steps_per_contact": 2 * steps})
    folders = {"coarse": out / SIMULATIONS / STEP_CHECK, "half": out / SIMULATIONS / f"{STEP_CHECK}-half-step"}
    tasks = {name: (simulate_point, run, values, str(folders[name]))
             for name, run in (("coarse", problem), ("half", half)) if finished(folders[name], values) is None}
    for name, error in run_phase(tasks, workers, parsl, "time-step check", "simulation"):
        if error is not None:
            step = "at half the time step" if name == "half" else "at the calibration's time step"
            raise RunFailed(f"the time-step check's run {step} failed: {one_line(error)}")
    return {"parameters": dict(zip(problem.keys, values)), "steps_per_contact": [steps, 2 * steps],
            **{name: finished(folder, values).tolist() for name, folder in folders.items()}}


def _write_results(calibration: Calibration, fit: inference.Fit, out: Path, failed: int, seconds: float,
                   step_check: dict) -> dict:
    problem, data = calibration.problem, calibration.data
    samples = to_parameters(problem.priors, fit.samples)
    write_posterior(out / "posterior.csv", problem.priors, samples)
    summary = summarize(problem.priors, samples)
    summary["method"] = {"name": "Gaussian-process emulator refined on the posterior, sampled by emcee",
                         "stages": list(calibration.stages), "walkers": inference.WALKERS,
                         "burn_in_steps": inference.BURN_IN_STEPS, "kept_steps": inference.KEPT_STEPS,
                         "thin": inference.THIN, "seed": calibration.seed}
    summary["simulations"] = {"parameter_sets": int(sum(calibration.stages)), "realizations": problem.realizations,
                              "runs": int(sum(calibration.stages)) * problem.realizations, "failed": failed,
                              "wall_time_s": seconds}
    summary["time_step_check"] = step_check | {
        "bias": (2.0 * (np.array(step_check["coarse"]) - np.array(step_check["half"]))).tolist()}
    summary["data"] = {"records": len(data.records), "sensors": problem.sensors, "observables": list(data.names),
                       "accelerometer_noise_m_s2": list(calibration.noise_m_s2)}
    write_json(out / "calibration.json", summary)
    plots.corner(problem.priors, samples, out / "posterior.png")
    rng = np.random.default_rng(calibration.seed)
    draws = fit.samples[rng.choice(len(fit.samples), PREDICTIVE_DRAWS)]
    mean, variance = fit.emulator.predict(draws)
    noise = np.mean(data.covariances, axis=0)
    spread = fit.spread(draws) * (1 + 1 / problem.realizations)
    predicted = np.array([rng.multivariate_normal(m, noise + s + np.diag(v)) for m, s, v in zip(mean, spread, variance)])
    plots.predictive(problem.sensors, data.records, data.covariances, predicted, out / "predictive.png")
    return summary
