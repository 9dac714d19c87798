"""Disorder figures of Sec. VI (Figs. 8 and 9) and the tables behind them in one command.

    python workflows/disorder_figures.py --out results/disorder \\
        [--scaling results/scaling/scaling.json] [--workers 2]          # about 3 min on 2 cores

Runs ``hexdem ensemble`` (20 weakly disordered packings, striker at 0.25, 0.40 and 0.70 m/s,
seed 0) into ``OUT/ensemble`` and, as a control, the same preparation with σ = 0 (one
realization: equal beads compacted, walled and settled under gravity exactly like the
disordered ones) into ``OUT/control``. ``OUT/disorder_vs_control.csv`` then splits the
transmission change of each line into the preparation's share (control / ideal) and the
disorder's own (disordered / control); ``OUT/workflow.json`` records the commands and wall
times. Figures: ``OUT/ensemble/fig9_all_directions.png``, ``OUT/ensemble/fig8_expnumsim_*.png``.
"""

from __future__ import annotations

import argparse
import csv
import sys
import time
from pathlib import Path

from hexdem.cli.main import main as hexdem
from hexdem.common.io import write_csv, write_json

COLUMNS = ("v_striker", "line", "disordered_over_ideal", "sem", "control_over_ideal", "disordered_over_control")


def effect(directory: Path) -> dict:
    with open(directory / "disorder_effect.csv", newline="") as fh:
        return {(row["v_striker"], row["line"]): row for row in csv.DictReader(fh)}


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--realizations", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--scaling", metavar="scaling.json", help="fitted laws of hexdem scaling for Fig. 9")
    args = parser.parse_args(argv)
    out = Path(args.out)
    common = ["--workers", str(args.workers), "--seed", str(args.seed)]
    commands = {
        "ensemble": [
            "ensemble",
            "--out",
            str(out / "ensemble"),
            "--realizations",
            str(args.realizations),
            *common,
            *(["--scaling", args.scaling] if args.scaling else []),
        ],
        "control": ["ensemble", "--out", str(out / "control"), "--realizations", "1", "--sigma-mm", "0", *common],
    }
    wall = {}
    for name, command in commands.items():
        start = time.perf_counter()
        status = hexdem(command)
        if status:
            return status
        wall[name] = time.perf_counter() - start
    disordered, control = effect(out / "ensemble"), effect(out / "control")
    rows = [
        (
            float(v),
            line,
            float(row["mean_ratio"]),
            float(row["sem_ratio"]),
            float(control[(v, line)]["mean_ratio"]),
            float(row["mean_ratio"]) / float(control[(v, line)]["mean_ratio"]),
        )
        for (v, line), row in disordered.items()
    ]
    write_csv(out / "disorder_vs_control.csv", COLUMNS, rows)
    write_json(
        out / "workflow.json",
        {
            "command": "python workflows/disorder_figures.py " + " ".join(sys.argv[1:] if argv is None else argv),
            "hexdem_commands": {name: "hexdem " + " ".join(command) for name, command in commands.items()},
            "wall_time_s": wall,
        },
    )
    for v, line, ratio, sem, _, over_control in rows:
        if line in ("0", "±30"):
            print(
                f"V = {v:g} m/s, line {line}: disordered/ideal {ratio:.3f} ± {sem:.3f}, "
                f"disordered/control {over_control:.3f}",
                file=sys.stderr,
            )
    print(f"disorder_figures: {sum(wall.values()):.1f} s wall time, results in {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(run())
