"""Simulation-based calibration of ``hexdem calibrate``: coverage and rank histograms over truths drawn
from the prior, the records made as a lab's instruments make them.

Usage: python benchmarks/bench_calibration.py [--case tiny|quick|disordered] [--truths 50] [--records 1]
                                              [--workers 2] [--noise 5] [--seed 2026] [--out DIR] [--quick]
                                              [--no-model-discrepancy | --draw-discrepancy | --misspecified]
                                              [--cost N] [--toy K,R]
                                              [--spread-in-sigma S1,S2,...]

**Simulation-based calibration** (Talts, Betancourt, Simpson, Vehtari & Gelman 2018): draw a truth θ
from the prior, make a record of it, calibrate, and take the rank of θ among L = 99 draws of the
posterior. A calibration whose posteriors are right gives ranks uniform on 0..L, whatever the
truth, and central intervals that hold θ as often as they claim. The table gives, per key, the
coverage of the 50 % and 90 % central intervals with the binomial 95 % band of the number of
truths, and the rank histogram with the χ² test of its uniformity; then each key's rank ECDF against
its simultaneous 95 % band (Säilynoja, Bürkner & Vehtari 2022), the expected coverage of the joint
posterior over every credibility level (TARP, Lemos et al. 2023) against the same band, the band's
power at this many truths (the under-coverage it would see), and how many intervals missed their
truth with no warning from the calibration (:mod:`hexdem.calibration.coverage`).

**The records differ from the calibration's runs as a lab's do.** Each record is made at twice the
calibration's time resolution, sampled at 500 kS/s after a 100 µs lead-in, with a clock offset
drawn in [0, 5] ms (:mod:`hexdem.calibration.synthetic`); and with the instruments' errors drawn as
the calibration's defaults assume them: each sensor's gain ~ N(1, 0.02), the record's striker
speed v0 (1 + 0.01 z), each channel's noise level uniform in [0.5, 2] × ``--noise`` m/s² rms and
a DC offset uniform in ±20 m/s². Nothing of the truth reaches the calibration but the record.

``--draw-discrepancy``: each truth's records also differ from the model as the calibration's
discrepancy term says they may (:class:`~hexdem.calibration.nuisance.Discrepancy`): its relative size
τ drawn from that term's log-uniform prior, and each sensor's log peak and relative arrival off by
τ z (z ~ N(0, 1)), the same in every record of the truth (:func:`~hexdem.calibration.synthetic.model_error_applied`).
Talts et al.'s check then draws every unknown of the calibration's model from its prior. Without it the
records hold no model error (τ = 0), a truth at the discrepancy prior's lower end, where its
intervals are conservative.

``--misspecified``: the misspecified arm. The records differ from the model in ways the calibration
does not model (:class:`~hexdem.calibration.synthetic.LabFaults`): sampled off the runs' instants,
each sensor's channels skewed by up to 1 µs, a gain per axis, coloured noise, a slow drift, and a
model error structured along the line (each later sensor's peak lower and arrival later by a share
that grows with its place). Here the intervals must hold or the calibration must warn: the table's
last line counts the intervals that missed in silence.

**Cases.**

* ``tiny``: a 5-per-edge hexagon, sensors ``0:1, 0:3``, ``v0`` ~ uniform(0.2, 0.7); 30
  simulations a truth (the budget of ``hexdem calibrate``'s test).
* ``quick``: the paper's 11-per-edge lattice, four sensors along 0° (``0:1, 0:3, 0:5, 0:7``),
  ``restitution`` ~ uniform(0.7, 0.99) and ``v0`` ~ uniform(0.2, 0.7); the default budget, 90.
* ``disordered``: a 4-per-edge hexagon, sensors ``0:1, 0:3``, ``diameter_sigma_m`` ~
  uniform(0, 1.5e-4) and ``restitution`` ~ uniform(0.8, 1.0), on the default 8 packings per
  parameter set, each truth's records struck on packings of their own seeds (ones the calibration
  never prepares).

``--records R``: R records a truth (the paper's protocol strikes 20 packings a configuration), each
sensor's gain shared by all of them, everything else drawn anew a record.

``--toy K,R``: the disorder toy, no LAMMPS: m = 7 observables correlated 0.9 whose mean shifts as
σ² and whose spread between packings grows as σ (σ in [0, 1]), 40 parameter sets on σ's levels,
each on the same K packings (shared deviates, as the calibration's own), and R records of
independent packings with a little noise; the coverage of σ's 90 % interval over ``--truths``
truths, through the calibration's own likelihood and sampler.

``--spread-in-sigma S1,S2,...``: the observables of 8 packings (the calibration's own, seed 0) of the
``--case``'s lattice and sensors at each σ [m], restitution 0.95: whether they vary smoothly with σ
on shared deviates.

``--quick``: one truth of the tiny case on one worker. ``--cost N``: N simulations of the quick case,
one after another in this process after one to warm up (as a worker runs them), each timed whole
(configuration, LAMMPS, the sensors' reduction, its folder written) beside its LAMMPS loop (the
log's "Loop time"); the target: at most the loop plus 0.3 s.
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

from hexdem.calibration import coverage
from hexdem.calibration.nuisance import Discrepancy
from hexdem.calibration.packings import DISORDER_REALIZATIONS, SIGMA_KEY
from hexdem.calibration.priors import Prior, to_parameters
from hexdem.calibration.simulations import Problem, simulate_point
from hexdem.calibration.study import DEFAULT_GAIN_SD, DEFAULT_SPEED_SCATTER, calibrate, prepare
from hexdem.calibration.synthetic import LabFaults, synthetic_rows, write_measured
from hexdem.engines.lammps.standalone import loop_time_s
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig

#: name → (base configuration, priors, budget in parameter sets (None: the default)).
CASES = {
    "tiny": ({"sensors": ["0:1", "0:3"], "edge_beads": 5}, ("v0=uniform(0.2, 0.7)",), 30),
    "quick": (
        {"sensors": ["0:1", "0:3", "0:5", "0:7"]},
        ("restitution=uniform(0.7, 0.99)", "v0=uniform(0.2, 0.7)"),
        None,
    ),
    "disordered": (
        {"sensors": ["0:1", "0:3"], "edge_beads": 4},
        ("diameter_sigma_m=uniform(0, 1.5e-4)", "restitution=uniform(0.8, 1.0)"),
        None,
    ),
}
#: Posterior draws among which a truth is ranked.
RANK_DRAWS = 99
#: A record's channels' noise levels, as multiples of ``--noise``, and their DC offsets [m/s²].
NOISE_FACTORS, OFFSET_M_S2 = (0.5, 2.0), 20.0
#: The seed of a disordered truth's packing: far from the calibration's own packings' (its seed, k).
TRUTH_PACKING_SEED = 100_000


def truth_record(
    base: dict,
    priors,
    rng,
    noise: float,
    path: Path,
    index: int,
    records: int = 1,
    discrepancy: bool = False,
    misspecified: bool = False,
) -> tuple[np.ndarray, float]:
    """A truth drawn from ``priors`` and ``records`` records of it, as a lab's instruments make them,
    written to ``path``: each sensor's gain the same in every record, the striker's speed, the
    channels' noise and offsets and the clock drawn anew for each, and on disordered packings each
    record struck on a packing of its own; with ``discrepancy``, a model error drawn from the
    discrepancy term's prior, the same in every record; ``misspecified``, the records as the
    calibration does not model them: each record's :class:`~hexdem.calibration.synthetic.LabFaults`
    (off the runs' instants, skewed channels, a gain per axis, coloured noise, drift) and a model error
    structured along the line, the same in every record: sensor i of n (0 the first) reads its peak
    exp(−κ i) lower and its arrival (1 + ε i/(n − 1)) later, κ uniform in [0, 0.05] and ε in
    [−0.02, 0.02]. Returns the truth and the model error's τ (κ for the misspecified arm)."""
    truth = to_parameters(priors, rng.random((1, len(priors))))[0]
    values = {prior.key: float(v) for prior, v in zip(priors, truth)}
    sigma = values.pop(SIGMA_KEY, None)
    config = RunConfig.from_dict(base | values)
    sensors = len(config.sensors)
    gains = 1 + DEFAULT_GAIN_SD * rng.standard_normal(sensors)
    tau, model_error = 0.0, None  # (drawn only where asked: the other tables' truths stay as they were)
    if discrepancy:
        tau = float(Discrepancy(sensors).size(rng.random()))
        model_error = tau * rng.standard_normal((sensors, 2))
    if misspecified:
        tau, stretch = float(rng.uniform(0.0, 0.05)), float(rng.uniform(-0.02, 0.02))
        along = np.arange(sensors) / max(sensors - 1, 1)
        model_error = np.column_stack([-tau * np.arange(sensors), stretch * along])
    rows = []
    for r in range(records):
        striker = config.replace(v0=config.v0 * (1 + DEFAULT_SPEED_SCATTER * rng.standard_normal()))
        levels = noise * rng.uniform(*NOISE_FACTORS, (sensors, 2))
        offsets = rng.uniform(-OFFSET_M_S2, OFFSET_M_S2, (sensors, 2))
        disorder = None if sigma is None else (sigma, TRUTH_PACKING_SEED + records * index + r, 0)
        rows += synthetic_rows(
            striker,
            str(r),
            levels,
            float(rng.uniform(0, 5e-3)),
            rng,
            disorder=disorder,
            packings=path.parent / "truth-packing",
            gains=gains,
            offsets_m_s2=offsets,
            model_error=model_error,
            faults=LabFaults.drawn(sensors, rng) if misspecified else None,
        )
    write_measured(path, rows)
    (path.parent / "truth.json").write_text(
        json.dumps({prior.key: float(v) for prior, v in zip(priors, truth)} | {"model_error_tau": tau})
    )
    return truth, tau


def binomial_band(level: float, count: int) -> tuple[float, float]:
    """The central 95 % range of the share of ``count`` truths inside an interval of ``level``."""
    from scipy.stats import binom

    return binom.ppf(0.025, count, level) / count, binom.ppf(0.975, count, level) / count


def rank_histogram(ranks, bins: int) -> tuple[list[int], float]:
    """(counts of ``ranks`` (0..RANK_DRAWS) in ``bins`` equal bins, the χ² test's p-value of their uniformity)."""
    from scipy.stats import chisquare

    counts = np.histogram(ranks, bins=bins, range=(-0.5, RANK_DRAWS + 0.5))[0]
    return counts.tolist(), float(chisquare(counts).pvalue)


def disorder_toy(packings: int, records: int, truths: int, seed: int) -> None:
    """The table of ``--toy``: σ's 90 % coverage on the disorder toy (see the module docstring)."""
    from hexdem.calibration import inference
    from hexdem.calibration.packings import on_sigma_levels

    m, rng = 7, np.random.default_rng(seed)
    shift, curvature, scale = rng.normal(size=m), rng.normal(0, 0.5, m), rng.uniform(0.5, 1.5, m)
    factor = np.linalg.cholesky(0.9 * np.ones((m, m)) + 0.1 * np.eye(m))
    noise = 0.02**2 * np.eye(m)
    held, widths = 0, []
    for t in range(truths):
        truth = rng.uniform(0.2, 0.9)
        shared = rng.standard_normal((packings, m)) @ factor.T
        points = on_sigma_levels(inference.design(1, 40, seed + t), 0)
        sigma = points[:, 0]
        simulated = (shift + curvature * sigma[:, None] ** 2)[:, None, :] + sigma[:, None, None] * scale * shared
        own = rng.standard_normal((records, m)) @ factor.T
        measured = (
            shift + curvature * truth**2 + truth * scale * own + rng.multivariate_normal(np.zeros(m), noise, records)
        )
        data = inference.Data(measured, np.array([noise] * records), tuple(f"y{j}" for j in range(m)))
        fit = inference.fit_stage(data, points, simulated, seed + t)
        low, high = np.quantile(fit.samples[:, 0], [0.05, 0.95])
        held += bool(low <= truth <= high)
        widths.append(high - low)
    band = binomial_band(0.9, truths)
    print("| K | R | truths | coverage 90 % | binomial band (95 %) | median width |")
    print("|---|---|---|---|---|---|")
    print(
        f"| {packings} | {records} | {truths} | {held / truths:.2f} | [{band[0]:.2f}, {band[1]:.2f}] | "
        f"{np.median(widths):.3f} |"
    )


def spread_in_sigma(sigmas, root: Path, case: str) -> None:
    """The table of ``--spread-in-sigma``: each packing's observables at each σ, on ``case``'s lattice."""
    from hexdem.calibration.observables import at_rest_before, reduce_record
    from hexdem.calibration.simulations import analysed_impact
    from hexdem.common.progress import silenced

    prior_texts = CASES["disordered"][1]
    problem = Problem(CASES[case][0], tuple(Prior.parse(text) for text in prior_texts), DISORDER_REALIZATIONS)
    print("| σ µm | packing | " + " | ".join(problem.names) + " |")
    print("|---" * (2 + len(problem.names)) + "|")
    for sigma in sigmas:
        for k in range(problem.realizations):
            with silenced():
                analysis = analysed_impact(problem, [sigma, 0.95], k, root / f"s{sigma:g}-k{k}", root / "packings")
            units, tracked = analysis.settings.units, analysis.tracked
            accelerations = np.moveaxis(tracked.sensor_states[:, :, 2:4], 1, 0) * (units.length_m / units.time_s**2)
            observed = reduce_record(*at_rest_before(tracked.sensor_times * units.time_s, accelerations))
            print(f"| {sigma * 1e6:.0f} | {k} | " + " | ".join(f"{v:.3g}" for v in observed) + " |", flush=True)


def simulation_cost(count: int, root: Path) -> None:
    """The table of ``--cost``: each simulation's whole time beside its LAMMPS loop."""
    base, prior_texts, _ = CASES["quick"]
    problem = Problem(base, tuple(Prior.parse(text) for text in prior_texts))
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=sorted(CASES), default="tiny")
    parser.add_argument("--truths", type=int, default=50)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--noise", type=float, default=5.0, help="accelerometer noise [m/s² rms]")
    parser.add_argument("--records", type=int, default=1, help="records a truth, each on a packing of its own")
    discrepancy = parser.add_mutually_exclusive_group()
    discrepancy.add_argument(
        "--no-model-discrepancy", action="store_true", help="calibrate with the model taken as exact"
    )
    discrepancy.add_argument(
        "--draw-discrepancy", action="store_true", help="records off the model by an error drawn from its prior"
    )
    discrepancy.add_argument(
        "--misspecified",
        action="store_true",
        help="records as the calibration does not model them: lab faults and a model error along the line",
    )
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--out", help="keep the calibrations here (default: a temporary folder)")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--cost", type=int, metavar="N", help="time N simulations against their LAMMPS loop, only")
    parser.add_argument("--toy", metavar="K,R", help="the disorder toy on K packings a set and R records, only")
    parser.add_argument("--spread-in-sigma", metavar="S1,S2", help="the disordered case's packings at σ [m], only")
    args = parser.parse_args()
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    if args.toy:
        packings, records = (int(value) for value in args.toy.split(","))
        disorder_toy(packings, records, args.truths, args.seed)
        return
    root = Path(args.out or tempfile.mkdtemp(prefix="hexdem-bench-calibration-"))
    if args.cost:
        simulation_cost(args.cost, root)
        return
    if args.spread_in_sigma:
        spread_in_sigma([float(value) for value in args.spread_in_sigma.split(",")], root, args.case)
        return
    case = "tiny" if args.quick else args.case
    base, prior_texts, budget = CASES[case]
    truths, workers = (1, 1) if args.quick else (args.truths, args.workers)
    priors = [Prior.parse(text) for text in prior_texts]
    rng = np.random.default_rng(args.seed)
    print(
        f"case {case}: {', '.join(prior_texts)}; noise {args.noise:g} m/s^2 rms; {truths} truth(s) of "
        f"{args.records} record(s); workers {workers}"
        + ("; the model taken as exact" if args.no_model_discrepancy else "")
        + ("; the records' model error drawn from the discrepancy's prior" if args.draw_discrepancy else "")
        + ("; the records misspecified: lab faults and a model error along the line" if args.misspecified else "")
    )
    print(
        "| truth | "
        + " | ".join(f"{p.key} true | {p.key} 90 % interval | {p.key} rank" for p in priors)
        + " | model error τ | records kept | simulations | fit p | wall s |"
    )
    print("|---" * (1 + 3 * len(priors) + 5) + "|")
    ranks, inside = {p.key: [] for p in priors}, {(p.key, level): 0 for p in priors for level in (0.5, 0.9)}
    refused, unit_draws, unit_truths, silent = [], [], [], []
    for t in range(truths):
        folder = root / f"truth-{t}"
        folder.mkdir(parents=True, exist_ok=True)
        truth, tau = truth_record(
            base,
            priors,
            rng,
            args.noise,
            folder / "data.csv",
            t,
            args.records,
            args.draw_discrepancy,
            args.misspecified,
        )
        start = time.perf_counter()
        try:
            calibration = prepare(
                base,
                folder / "data.csv",
                prior_texts,
                None if budget is None else budget,
                seed=args.seed + t,
                model_discrepancy=not args.no_model_discrepancy,
            )
        except HexdemError as exc:
            refused.append(t)
            print(f"| {t} | refused: {exc} |", flush=True)
            continue
        summary = calibrate(calibration, folder / "data.csv", folder / "calibration", workers, log=lambda message: None)
        seconds = time.perf_counter() - start
        samples = np.loadtxt(folder / "calibration" / "posterior.csv", delimiter=",", skiprows=1, ndmin=2)
        draws = samples[np.random.default_rng(t).choice(len(samples), RANK_DRAWS, replace=False)]
        unit_draws.append(np.column_stack([prior.to_unit(draws[:, j]) for j, prior in enumerate(priors)]))
        unit_truths.append([prior.to_unit(truth[j]) for j, prior in enumerate(priors)])
        cells = []
        for j, prior in enumerate(priors):
            rank = int(np.sum(draws[:, j] < truth[j]))
            ranks[prior.key].append(rank)
            for level in (0.5, 0.9):
                low, high = np.quantile(samples[:, j], [(1 - level) / 2, (1 + level) / 2])
                inside[(prior.key, level)] += bool(low <= truth[j] <= high)
            q05, q95 = np.quantile(samples[:, j], [0.05, 0.95])
            held = "" if q05 <= truth[j] <= q95 else " MISSED"
            if held and not summary["warnings"]:
                silent.append((t, prior.key))
            cells.append(f"{truth[j]:.6g} | [{q05:.6g}, {q95:.6g}]{held} | {rank}")
        print(
            f"| {t} | " + " | ".join(cells) + f" | {tau:.2g} | {len(calibration.data.records)} of {args.records} | "
            f"{summary['simulations']['runs']} | "
            f"{summary['fit']['p_value']:.2f} | {seconds:.0f} |",
            flush=True,
        )
    if refused:
        print(f"\n{len(refused)} of {truths} truths refused by the calibration (truths {refused}): left out below")
    truths -= len(refused)
    if not truths:
        return
    bins = max(2, min(10, truths // 5))
    print(
        "\n| key | coverage 50 % | binomial band (95 %) | coverage 90 % | binomial band (95 %) | "
        f"rank histogram ({bins} bins of 0..{RANK_DRAWS}) | uniformity p |"
    )
    print("|---|---|---|---|---|---|---|")
    for prior in priors:
        cells = []
        for level in (0.5, 0.9):
            low, high = binomial_band(level, truths)
            cells.append(f"{inside[(prior.key, level)] / truths:.2f} | [{low:.2f}, {high:.2f}]")
        counts, p_value = rank_histogram(ranks[prior.key], bins)
        print(f"| {prior.key} | " + " | ".join(cells) + f" | {' '.join(map(str, counts))} | {p_value:.2f} |")
    coverage_checks(priors, ranks, np.array(unit_draws), np.array(unit_truths), args.seed)
    print(
        f"\nmissed in silence (a 90 % interval missing its truth, no warning): {len(silent)} of "
        f"{truths * len(priors)} intervals ({', '.join(f'truth {t} {key}' for t, key in silent) or 'none'})"
    )


def coverage_checks(priors, ranks: dict, unit_draws, unit_truths, seed: int) -> None:
    """Each key's rank ECDF against its simultaneous 95 % band, TARP's expected coverage of the joint
    posterior against the same band, and the band's power at this many truths
    (:mod:`hexdem.calibration.coverage`)."""
    count = len(unit_truths)
    band = coverage.ecdf_band(count, seed=seed)
    jitter = np.random.default_rng(seed).random(count)
    print("\n| check | statistic | inside its simultaneous 95 % band |")
    print("|---|---|---|")
    for prior in priors:
        fractions = (np.array(ranks[prior.key]) + jitter) / (RANK_DRAWS + 1)
        inside = not coverage.outside_band(fractions, band)
        print(f"| rank ECDF of {prior.key} | {count} truths | {'yes' if inside else 'NO'} |")
    references = np.random.default_rng(seed + 1).random(unit_truths.shape)
    _, _, area, shares = coverage.tarp(unit_draws, unit_truths, references)
    inside = not coverage.outside_band(shares, band)
    print(f"| TARP, every key at once | area to the diagonal {area:+.3f} | {'yes' if inside else 'NO'} |")
    for scale in (0.7, 0.8):
        print(
            f"power at {count} truths: a posterior {scale} times too narrow (its 90 % intervals covering "
            f"{coverage.central_coverage(scale):.2f}) leaves the band with probability "
            f"{coverage.ecdf_power(count, scale, seed=seed):.2f}"
        )


if __name__ == "__main__":
    main()
