"""Speed of ``hexdem paper``: the whole paper, part by part, at the former and today's time step.

Usage: python benchmarks/bench_paper.py [--workers 2] [--quick] [--steps 700,140] [--out DIR]

Runs ``hexdem paper --steps-per-contact N`` (a subprocess, as a user would) into a fresh
directory for each N of ``--steps`` (default: the former default 700 beside today's 140, in one
run), or resumes the run in ``--out`` (at today's step only), and prints the wall time of every
part as recorded when it was computed, their sum, and each invocation's wall time. The V0
sweep keeps its own 140 steps per contact either way. Targets on 2 cores with ``--workers 2``,
at today's step: the full paper <= 4 min, ``--quick`` <= 2 min.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from machine import describe

from hexdem.model.config import STEPS_PER_CONTACT

TARGETS_S = {False: 240.0, True: 120.0}


def paper(out: Path, steps: int, workers: int, quick: bool) -> tuple[dict, float] | int:
    """({part: wall time [s]}, this invocation's wall time [s]) of ``hexdem paper`` in ``out``, or
    its exit status if it failed."""
    command = [sys.executable, "-m", "hexdem.cli.main", "paper", "--out", str(out), "--workers", str(workers),
               "--steps-per-contact", str(steps), *(["--quick"] if quick else [])]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    if done.returncode:
        print(done.stderr, file=sys.stderr)
        return done.returncode
    return {p.stem: json.loads(p.read_text())["wall_time_s"] for p in sorted((out / "parts").glob("*.json"))}, wall


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="time hexdem paper --quick")
    parser.add_argument("--steps", default=f"700,{STEPS_PER_CONTACT}",
                        help=f"steps per contact of the runs to compare (default 700,{STEPS_PER_CONTACT})")
    parser.add_argument("--out", metavar="DIR", help="resume (or report) the paper run in DIR, at today's step only")
    args = parser.parse_args(argv)
    steps = [STEPS_PER_CONTACT] if args.out else [int(n) for n in args.steps.split(",")]
    print(f"machine: {describe()}", flush=True)
    runs = {}
    with tempfile.TemporaryDirectory(prefix="hexdem-bench-paper-") as scratch:
        for n in steps:
            out = Path(args.out) if args.out else Path(scratch) / f"paper-{n}"
            result = paper(out, n, args.workers, args.quick)
            if isinstance(result, int):
                return result
            runs[n] = result
    names = list(runs[steps[-1]][0])
    print(f"hexdem paper{' --quick' if args.quick else ''} --workers {args.workers}, wall [s] per part at each "
          "number of steps per contact")
    print(f"  {'part':<28}" + "".join(f" {f'{n} steps':>11}" for n in steps))
    for name in names:
        print(f"  {name:<28}" + "".join(f" {runs[n][0].get(name, float('nan')):>11.1f}" for n in steps))
    print(f"  {'sum of parts':<28}" + "".join(f" {sum(runs[n][0].values()):>11.1f}" for n in steps))
    print(f"  {'this invocation':<28}" + "".join(f" {runs[n][1]:>11.1f}" for n in steps)
          + "  (a resumed run only writes the report)")
    if len(steps) > 1:
        print(f"  {'ratio of sums':<28} {sum(runs[steps[0]][0].values()) / sum(runs[steps[-1]][0].values()):>11.2f} "
              f"({steps[0]} / {steps[-1]} steps)")
    target, total = TARGETS_S[args.quick], sum(runs[steps[-1]][0].values())
    print(f"target <= {target:g} s for the parts at {steps[-1]} steps per contact: {'met' if total <= target else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(run())
