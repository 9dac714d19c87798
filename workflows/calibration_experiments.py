"""What the paper's experiments can tell: the disorder's σ and the restitution from synthetic records of its protocol.

    python workflows/calibration_experiments.py --out results/calibration-experiments
        [--packings 20] [--realizations 8] [--budget N] [--noise 5] [--sigma 7.62e-5] [--restitution 0.95]
        [--workers 2 | --parsl CONFIG.py] [--quick]

The paper's protocol (Sec. II): 4 sensors at a time, in three configurations that share the
sensor nearest the impact (along 0°; across the 0° line near the impact; across it further
away), 20 packings for each, struck at 0.40 m/s, and configuration 1 also at 0.25 and 0.70 m/s;
accelerometers sampled at 500 kS/s, records and runs of 3 ms (:data:`RECORD_DURATION_S`). The sensors' beads are the
text's positions on the 11-per-edge lattice (Fig. 1's exact beads are not in the text;
:data:`hexdem.design.candidates.PAPER_CONFIGURATIONS`):

* configuration 1: ``0:1, 0:3, 0:5, 0:7``;
* configuration 2: ``0:1, +30:2, -30:2, +30:3`` (the row through 0:1 and its neighbours);
* configuration 3: ``0:1, 0:4, +30:8, -30:8`` (the row four layers further, and 0:1).

Each data set's records are synthetic (:mod:`hexdem.calibration.synthetic`): a truth (``--sigma``,
``--restitution``), one record per packing, each packing prepared by the paper's scheme from
diameters of its own (a seed the calibration is not told), the impact at twice the calibration's
time step, white accelerometer noise of ``--noise`` m/s² and a clock offset. Every data set is then
calibrated alone, priors σ ~ uniform(0, 2e-4) m and restitution ~ uniform(0.8, 0.99), so that the
table says what each configuration and speed tells about each parameter. Writes
``OUT/<data set>/`` (``data.csv`` and the calibration's files), ``OUT/calibration_experiments.csv``
(``data_set,sensors,v0,key,truth,median,q05,q95,width_ratio,correlation``),
``OUT/calibration_experiments.png`` and ``OUT/workflow.json``. ``--quick``: configurations 1 and 2 at
0.40 m/s, 3 packings, 2 per parameter set and the smallest budget (45 parameter sets): the same
path in a tenth of the simulations. (A smaller lattice would not do: in a 5-per-edge packing with
σ = 6 tol, some packings pass the pulse around the first sensor.)
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from hexdem.analysis.plotting import save, subplots
from hexdem.calibration.priors import Prior
from hexdem.calibration.study import calibrate, prepare
from hexdem.calibration.synthetic import synthetic_rows, write_measured
from hexdem.cli.main import exit_status
from hexdem.common.io import ensure_writable_dir, write_csv, write_json
from hexdem.design.candidates import PAPER_CONFIGURATIONS
from hexdem.errors import HexdemError
from hexdem.model.config import RunConfig

CONFIGURATIONS = {int(name): sensors for name, sensors in PAPER_CONFIGURATIONS.items()}
DATA_SETS = ((1, 0.40), (2, 0.40), (3, 0.40), (1, 0.25), (1, 0.70))
QUICK_DATA_SETS = ((1, 0.40), (2, 0.40))
QUICK_BUDGET = 90
PRIORS = ("diameter_sigma_m=uniform(0, 2e-4)", "restitution=uniform(0.8, 0.99)")
#: Length of the records and of the runs [s]: the default duration follows the ideal lattice's pulse
#: to the far wall (1.43 ms), but at σ = 6 tol the pulse reaches 0:7 as late as 2.3 ms in some packings.
RECORD_DURATION_S = 3e-3
#: Seeds of the data's packings, apart from every seed a calibration draws its own packings from.
DATA_SEED = 9001
COLUMNS = ("data_set", "sensors", "v0", "key", "truth", "median", "q05", "q95", "width_ratio", "correlation")


def data_set_name(configuration: int, v0: float) -> str:
    return f"config{configuration}_v{v0:.2f}"


def make_records(base: dict, truth: dict, packings: int, noise: float, path: Path, rng) -> None:
    """One synthetic record per packing of the truth, into the measured file ``path``."""
    config = RunConfig.from_dict(base | {"restitution": truth["restitution"]})
    rows = []
    for k in range(packings):
        rows += synthetic_rows(
            config,
            str(k),
            noise,
            float(rng.uniform(0, 5e-3)),
            rng,
            disorder=(truth["diameter_sigma_m"], DATA_SEED, k),
            packings=path.parent / "truth-packings",
        )
    write_measured(path, rows)


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--packings", type=int, default=20, help="packings (records) per data set (default 20)")
    parser.add_argument("--realizations", type=int, default=8, help="packings per simulated parameter set (default 8)")
    parser.add_argument("--budget", type=int, help="simulations per calibration (default: hexdem calibrate's)")
    parser.add_argument("--noise", type=float, default=5.0, help="accelerometer noise [m/s² rms] (default 5)")
    parser.add_argument("--sigma", type=float, default=7.62e-5, help="the truth's σ [m] (default 6 tol = 7.62e-5)")
    parser.add_argument("--restitution", type=float, default=0.95, help="the truth's restitution (default 0.95)")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--parsl", metavar="CONFIG.py")
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    log = lambda message: print(f"calibration_experiments: {message}", file=sys.stderr, flush=True)  # noqa: E731
    truth = {"diameter_sigma_m": args.sigma, "restitution": args.restitution}
    data_sets = QUICK_DATA_SETS if args.quick else DATA_SETS
    packings, realizations, budget = (
        (3, 2, QUICK_BUDGET) if args.quick else (args.packings, args.realizations, args.budget)
    )
    start = time.perf_counter()
    rows = []
    try:
        out = ensure_writable_dir(args.out)
        rng = np.random.default_rng(DATA_SEED)
        for configuration, v0 in data_sets:
            name = data_set_name(configuration, v0)
            folder = ensure_writable_dir(out / name)
            base = {"sensors": list(CONFIGURATIONS[configuration]), "v0": v0, "duration": RECORD_DURATION_S}
            if not (folder / "data.csv").exists():
                log(f"{name}: {packings} synthetic records")
                make_records(base, truth, packings, args.noise, folder / "data.csv", rng)
            log(f"{name}: calibrating")
            calibration = prepare(base, folder / "data.csv", PRIORS, budget, seed=0, realizations=realizations)
            summary = calibrate(
                calibration, folder / "data.csv", folder / "calibration", args.workers, args.parsl, log=log
            )
            keys = list(summary["parameters"])
            for key, entry in summary["parameters"].items():
                other = next(k for k in keys if k != key)
                rows.append(
                    (
                        name,
                        " ".join(base["sensors"]),
                        v0,
                        key,
                        truth[key],
                        entry["median"],
                        entry["q05"],
                        entry["q95"],
                        entry["width_ratio"],
                        summary["correlations"][key][other],
                    )
                )
        write_csv(out / "calibration_experiments.csv", COLUMNS, rows)
        intervals(rows, truth, out / "calibration_experiments.png")
    except HexdemError as exc:
        print(f"calibration_experiments: error: {exc}", file=sys.stderr)
        return exit_status(exc)
    write_json(
        out / "workflow.json",
        {
            "command": "python workflows/calibration_experiments.py "
            + " ".join(sys.argv[1:] if argv is None else argv),
            "truth": truth,
            "wall_time_s": time.perf_counter() - start,
        },
    )
    for row in rows:
        print(
            f"{row[0]} {row[3]}: median {row[5]:.4g}, 90 % [{row[6]:.4g}, {row[7]:.4g}] (truth {row[4]:.4g}, "
            f"{row[8]:.0%} of the prior)"
        )
    return 0


#: Each key as the figure draws it: (axis label, factor from the key's unit).
AXES = {"diameter_sigma_m": ("σ of the diameters [µm]", 1e6), "restitution": ("restitution e", 1.0)}


def intervals(rows, truth: dict, path) -> None:
    """Each data set's 90 % interval and median of each parameter across its prior's range, the truth drawn across."""
    priors = {prior.key: prior for prior in map(Prior.parse, PRIORS)}
    fig, axes = subplots(
        1, len(truth), figsize=(5 * len(truth), 1.6 + 0.5 * len(rows) / len(truth)), layout="constrained", squeeze=False
    )
    for ax, key in zip(axes[0], truth):
        label, factor = AXES[key]
        mine = [row for row in rows if row[3] == key]
        y = np.arange(len(mine))
        medians, lows, highs = (np.array([r[i] for r in mine]) * factor for i in (5, 6, 7))
        ax.errorbar(
            medians,
            y,
            xerr=[medians - lows, highs - medians],
            fmt="o",
            color="C0",
            capsize=3,
            label="posterior median, 90 %",
        )
        ax.axvline(truth[key] * factor, color="C3", ls="--", label="truth")
        ax.set_xlim(*(factor * bound for bound in priors[key].support))
        ax.set_ylim(-0.5, len(mine) - 0.5)
        ax.set_yticks(y, [r[0] for r in mine])
        ax.set_xlabel(f"{label} (the prior's range)")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("What each sensor configuration and striker speed tells")
    save(fig, path)


if __name__ == "__main__":
    sys.exit(run())
