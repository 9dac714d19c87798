"""Does a design's prediction hold? ``hexdem design``'s expected widths against calibrations.

Usage: python benchmarks/bench_design.py [--truths 10] [--workers 2] [--noise 5] [--seed 2026] [--out DIR]
                                         [--quick]

The quick case of ``hexdem calibrate`` (the paper's 11-per-edge lattice, restitution ~
uniform(0.7, 0.99) and V0 ~ uniform(0.2, 0.7)), one record a calibration, accelerometer noise of
``--noise`` m/s² rms. ``hexdem design`` picks the best 4 sensors among every bead and predicts each
key's median 90 % width for it and for the paper's configuration 1 (``0:1 0:3 0:5 0:7``). Then, for
each of the two designs, ``--truths`` truths are drawn from the prior, a record of each made as a
lab's instruments make it (:func:`bench_calibration.truth_record`: twice the time resolution, each
sensor's gain, the striker's speed, each channel's noise of 0.5 to 2 × ``--noise`` and offset drawn)
and calibrated with the defaults. The table gives each key's predicted and measured median 90 %
width per design, and the ratio best / configuration 1 of both: the prediction holds where the
measured ratio is within 30 % of the predicted.

The design's criterion takes each channel's noise at ``--noise``; the records' levels are drawn
around it (a factor of 0.5 to 2), so their mean variance is 1.75 times the design's. ``--quick``:
the tiny case (a 5-per-edge hexagon, V0 alone, 2 sensors among the lines' beads, 30 simulations a
calibration), one truth a design, the best design against the last of ``design.csv``'s ranking (the
paper's configurations are not on that lattice): the same path in a minute.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np
from bench_calibration import CASES, truth_record
from machine import describe

from hexdem.calibration.priors import Prior
from hexdem.calibration.study import calibrate, prepare
from hexdem.design.candidates import PAPER_CONFIGURATIONS, sensor_value
from hexdem.design.study import prepare_design, run_design


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--truths", type=int, default=10)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--noise", type=float, default=5.0, help="accelerometer noise [m/s² rms]")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--out", help="keep the design and the calibrations here (default: a temporary folder)")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    root = Path(args.out or tempfile.mkdtemp(prefix="hexdem-bench-design-"))
    case, sensors, candidates = ("tiny", 2, "lines") if args.quick else ("quick", 4, "all")
    base, prior_texts, budget = CASES[case]
    base = {key: value for key, value in base.items() if key != "sensors"}
    priors = [Prior.parse(text) for text in prior_texts]
    truths = 1 if args.quick else args.truths
    start = time.perf_counter()
    study = prepare_design(
        base, prior_texts, sensors, candidates, None, 1, args.noise, 0.02, 0.01, None, None, args.seed
    )
    summary = run_design(study, root / "design", args.workers, log=lambda message: None)
    print(
        f"design: {summary['simulations']['runs']} simulations, {time.perf_counter() - start:.0f} s; best "
        f"{summary['best']['sensors']}",
        flush=True,
    )
    designs = {"best": (summary["best"]["sensors"].split(), [summary["best"][f"width_{p.key}"] for p in priors])}
    if "paper_configurations" in summary:
        reference = "configuration 1"
        designs[reference] = (
            list(PAPER_CONFIGURATIONS["1"]),
            [summary["paper_configurations"]["1"]["widths"][p.key] for p in priors],
        )
    else:
        with open(root / "design" / "design.csv") as fh:
            last = list(csv.DictReader(fh))[-1]
        reference = f"rank {last['rank']}"
        designs[reference] = (last["sensors"].split(), [float(last[f"width_{p.key}"]) for p in priors])
    rng = np.random.default_rng(args.seed)
    measured = {}
    for name, (chosen, _) in designs.items():
        config = base | {"sensors": [sensor_value(sensor) for sensor in chosen]}
        widths = []
        for t in range(truths):
            folder = root / name.replace(" ", "-") / f"truth-{t}"
            folder.mkdir(parents=True, exist_ok=True)
            truth_record(config, priors, rng, args.noise, folder / "data.csv", t)
            calibration = prepare(config, folder / "data.csv", prior_texts, budget, seed=args.seed + t)
            result = calibrate(
                calibration, folder / "data.csv", folder / "calibration", args.workers, log=lambda m: None
            )
            widths.append([result["parameters"][p.key]["q95"] - result["parameters"][p.key]["q05"] for p in priors])
            print(f"{name}, truth {t}: widths " + ", ".join(f"{w:.4g}" for w in widths[-1]), flush=True)
        measured[name] = np.median(widths, axis=0)
    print("\n| key | design | predicted 90 % width | measured median 90 % width |")
    print("|---|---|---|---|")
    for j, prior in enumerate(priors):
        for name, (_, predicted) in designs.items():
            print(f"| {prior.key} | {name} | {predicted[j]:.4g} | {measured[name][j]:.4g} |")
    print(f"\n| key | predicted ratio best / {reference} | measured ratio | measured / predicted | within 30 % |")
    print("|---|---|---|---|---|")
    for j, prior in enumerate(priors):
        predicted = designs["best"][1][j] / designs[reference][1][j]
        ratio = measured["best"][j] / measured[reference][j]
        agreement = ratio / predicted
        print(
            f"| {prior.key} | {predicted:.3f} | {ratio:.3f} | {agreement:.3f} | "
            f"{'yes' if abs(agreement - 1) <= 0.3 else 'NO'} |"
        )
    (root / "bench_design.json").write_text(
        json.dumps(
            {
                name: {"sensors": d[0], "predicted": d[1], "measured": measured[name].tolist()}
                for name, d in designs.items()
            }
        )
    )


if __name__ == "__main__":
    main()
