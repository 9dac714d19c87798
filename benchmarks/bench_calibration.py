"""Calibration on the quick case: coverage on truths the method is not told, and the methods side by side.

Usage: python benchmarks/bench_calibration.py [--truths 10] [--methods emulator,filter] [--workers 2]
                                              [--noise 5] [--out DIR] [--quick]

**The quick case.** The ideal 11-per-edge lattice of the paper's experiment, four sensors along 0°
(beads 1, 3, 5, 7), and two parameters: ``restitution`` ~ uniform(0.7, 0.99) and ``v0`` ~
uniform(0.2, 0.7). Each truth is drawn from that prior (seeded). Its record is made at twice the
calibration's time step, sampled at 500 kS/s after a 100 µs lead-in, with white accelerometer
noise of ``--noise`` m/s² rms and a clock offset drawn in [0, 5] ms
(:mod:`hexdem.calibration.synthetic`). Nothing of the truth reaches the method but that record.

**Methods**, each given the same records, priors and likelihood:

* ``emulator``: hexdem's (:mod:`hexdem.calibration.inference`), a Gaussian-process emulator
  refined on the posterior, sampled by emcee, 90 simulations;
* ``filter``: the iterative Bayesian filter of GrainLearning (Cheng et al. 2019), written here
  because GrainLearning 2.0.5 requires NumPy below 2.0: each iteration simulates
  ``FILTER_SAMPLES`` parameter sets, weighs them by the likelihood of the records, and draws
  the next iteration's from a Gaussian mixture fitted to the weighted sets (one component per
  set, the weighted covariance as bandwidth); ``FILTER_ITERATIONS`` iterations.

**A simulation's cost** (``--cost N``): N simulations of the quick case, one after another in
this process after one to warm up (as a worker runs them), each timed whole (configuration,
LAMMPS, the sensors' reduction, its folder written) beside its LAMMPS loop (the log's "Loop
time"); the target: at most the loop plus 0.3 s.

For every truth and method the table gives the simulations, the wall time, each key's 90 %
interval width over the prior's and whether it holds the truth; the last rows count, per
method and key, the truths inside their 90 % interval (the target: at least 7 of 10).
``--quick``: one truth, a 5-per-edge hexagon with sensors 0:1 and 0:3, ``v0`` alone, 30 simulations,
one worker.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from machine import describe

from hexdem.calibration.priors import Prior, to_parameters
from hexdem.calibration.simulations import Problem, simulate_point
from hexdem.calibration.study import calibrate, prepare
from hexdem.calibration.synthetic import synthetic_rows, write_measured
from hexdem.engines.lammps.standalone import loop_time_s
from hexdem.experiments.executors import run_phase
from hexdem.model.config import RunConfig

QUICK_CASE = ({"sensors": ["0:1", "0:3", "0:5", "0:7"]},
              ("restitution=uniform(0.7, 0.99)", "v0=uniform(0.2, 0.7)"))
TINY_CASE = ({"sensors": ["0:1", "0:3"], "edge_beads": 5}, ("v0=uniform(0.2, 0.7)",))
FILTER_SAMPLES, FILTER_ITERATIONS = 60, 5
#: ``--quick``'s budget: the initial design and one refinement.
QUICK_BUDGET = 30


def truth_record(base: dict, priors, rng, noise: float, path: Path) -> np.ndarray:
    """A truth drawn from ``priors`` and its synthetic record written to ``path``."""
    unit = rng.random(len(priors))
    truth = to_parameters(priors, unit[None])[0]
    config = RunConfig.from_dict(base | {prior.key: float(v) for prior, v in zip(priors, truth)})
    write_measured(path, synthetic_rows(config, "0", noise, float(rng.uniform(0, 5e-3)), rng))
    (path.parent / "truth.json").write_text(json.dumps({prior.key: float(v) for prior, v in zip(priors, truth)}))
    return truth


def run_emulator(calibration, measured, out: Path, workers: int) -> tuple[np.ndarray, int]:
    calibrate(calibration, measured, out, workers, log=lambda message: None)
    samples = np.loadtxt(out / "posterior.csv", delimiter=",", skiprows=1, ndmin=2)
    return samples, int(sum(calibration.stages))


def run_filter(calibration, out: Path, workers: int, seed: int) -> tuple[np.ndarray, int]:
    """The iterative Bayesian filter (see the module docstring) on the simulator itself."""
    problem, data = calibration.problem, calibration.data
    rng = np.random.default_rng(seed)
    p = len(problem.priors)
    unit = rng.random((FILTER_SAMPLES, p))
    count = 0
    for iteration in range(FILTER_ITERATIONS):
        values = to_parameters(problem.priors, unit)
        tasks = {i: (simulate_point, problem, values[i].tolist(), str(out / f"{iteration}-{i:03d}"))
                 for i in range(len(values))}
        observables = np.full((len(values), len(data.names)), np.nan)
        for i, error in run_phase(tasks, workers, None, f"filter {iteration + 1}", "simulation"):
            if error is None:
                observables[i] = json.loads((out / f"{iteration}-{i:03d}" / "observables.json").read_text())["observables"]
        count += len(values)
        log_weight = np.zeros(len(values))
        for record, covariance in zip(data.records, data.covariances):
            residual = observables - record
            log_weight -= 0.5 * np.einsum("ki,ij,kj->k", residual, np.linalg.inv(covariance), residual)
        log_weight[~np.isfinite(log_weight)] = -np.inf
        weight = np.exp(log_weight - log_weight.max())
        weight /= weight.sum()
        if iteration == FILTER_ITERATIONS - 1:
            return values[rng.choice(len(values), size=4000, p=weight)], count
        bandwidth = np.atleast_2d(np.cov(unit, rowvar=False, aweights=weight + 1e-12)) + 1e-6 * np.eye(p)
        chosen = unit[rng.choice(len(unit), size=FILTER_SAMPLES, p=weight)]
        unit = np.clip(chosen + rng.multivariate_normal(np.zeros(p), bandwidth, FILTER_SAMPLES), 1e-6, 1 - 1e-6)


def simulation_cost(count: int, root: Path) -> None:
    """The table of ``--cost``: each simulation's whole time beside its LAMMPS loop."""
    base, prior_texts = QUICK_CASE
    problem = prepare_problem(base, prior_texts)
    rng = np.random.default_rng(0)
    print("| simulation | whole s | LAMMPS loop s | whole - loop s |")
    print("|---|---|---|---|")
    extra = []
    for i in range(count + 1):
        values = to_parameters(problem.priors, rng.random((1, len(problem.priors))))[0]
        folder = root / f"cost-{i:03d}"
        start = time.perf_counter()
        simulate_point(problem, values.tolist(), str(folder))
        whole = time.perf_counter() - start
        loop = loop_time_s(folder / "deck" / "log.lammps")
        if i:
            extra.append(whole - loop)
            print(f"| {i} | {whole:.3f} | {loop:.3f} | {whole - loop:.3f} |", flush=True)
    print(f"median beyond the loop: {np.median(extra):.3f} s (target at most 0.3 s)")


def prepare_problem(base: dict, prior_texts) -> Problem:
    return Problem(base, tuple(Prior.parse(text) for text in prior_texts))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truths", type=int, default=10)
    parser.add_argument("--methods", default="emulator")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--noise", type=float, default=5.0, help="accelerometer noise [m/s² rms]")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--out", help="keep the calibrations here (default: a temporary folder)")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--cost", type=int, metavar="N", help="time N simulations against their LAMMPS loop, only")
    args = parser.parse_args()
    if args.cost:
        print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
        simulation_cost(args.cost, Path(args.out or tempfile.mkdtemp(prefix="hexdem-bench-cost-")))
        return
    base, prior_texts = TINY_CASE if args.quick else QUICK_CASE
    truths, workers = (1, 1) if args.quick else (args.truths, args.workers)
    methods = args.methods.split(",")
    priors = [Prior.parse(text) for text in prior_texts]
    root = Path(args.out or tempfile.mkdtemp(prefix="hexdem-bench-calibration-"))
    rng = np.random.default_rng(args.seed)
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    print(f"noise {args.noise:g} m/s^2 rms, {truths} truth(s), workers {workers}")
    print("| truth | method | " + " | ".join(f"{p.key} true | {p.key} 90 % interval | {p.key} width ratio" for p in priors)
          + " | simulations | wall s |")
    print("|---" * (3 + 3 * len(priors) + 1) + "|")
    inside = {(m, p.key): 0 for m in methods for p in priors}
    for t in range(truths):
        folder = root / f"truth-{t}"
        folder.mkdir(parents=True, exist_ok=True)
        truth = truth_record(base, priors, rng, args.noise, folder / "data.csv")
        calibration = prepare(base, folder / "data.csv", prior_texts, QUICK_BUDGET if args.quick else None, seed=t)
        for method in methods:
            start = time.perf_counter()
            if method == "emulator":
                samples, count = run_emulator(calibration, folder / "data.csv", folder / method, workers)
            else:
                samples, count = run_filter(calibration, folder / method, workers, seed=t)
            seconds = time.perf_counter() - start
            cells = []
            for j, prior in enumerate(priors):
                q05, q95 = np.quantile(samples[:, j], [0.05, 0.95])
                p05, p95 = prior.from_unit([0.05, 0.95])
                hit = q05 <= truth[j] <= q95
                inside[(method, prior.key)] += hit
                cells.append(f"{truth[j]:.4f} | [{q05:.4f}, {q95:.4f}]{'' if hit else ' MISSED'} | "
                             f"{(q95 - q05) / (p95 - p05):.2f}")
            print(f"| {t} | {method} | " + " | ".join(cells) + f" | {count} | {seconds:.0f} |", flush=True)
    for (method, key), count in inside.items():
        print(f"coverage, {method}, {key}: {count} of {truths} truths inside the 90 % interval")


if __name__ == "__main__":
    main()
