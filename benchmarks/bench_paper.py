"""Speed of ``hexdem paper``: the whole paper, part by part, now and before.

Usage: python benchmarks/bench_paper.py [--workers 2] [--quick] [--before REV] [--out DIR]

Runs ``hexdem paper`` (a subprocess, as a user would, at today's 140 steps per contact) into a
fresh directory with today's hexdem and with hexdem as it was at ``--before`` (default
e8fb865, the last commit before the speed work, warmed up; skipped when this clone lacks it),
one after the other, or resumes the run in ``--out`` (today's only), and prints the wall time of
every part as recorded when it was computed, their sum, and each invocation's wall time.
Targets on 2 cores with ``--workers 2``: the parts the paper had when they were set (the TCA,
Figs. 3-4, the scaling laws, the fit protocols, the disorder study) <= 4 min (``--quick`` <= 2 min),
and at least 1.5 x faster than before; the crossover sweep and the friction study, added since,
bring the whole paper to about 500 s (2026-11-24).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from baseline import BEFORE, baseline_tree, hexdem_command, hexdem_env
from machine import describe

TARGETS_S = {False: 240.0, True: 120.0}
SPEED_UP_TARGET = 1.5


def paper(out: Path, workers: int, quick: bool, tree: Path | None = None) -> tuple[dict, float] | int:
    """({part: wall time [s]}, this invocation's wall time [s]) of ``hexdem paper`` in ``out``
    with the version unpacked at ``tree`` (None: today's), or its exit status if it failed."""
    command = hexdem_command("paper", "--out", str(out), "--workers", str(workers), *(["--quick"] if quick else []))
    start = time.perf_counter()
    done = subprocess.run(command, cwd=out.parent, env=hexdem_env(tree), capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    if done.returncode:
        print(done.stderr, file=sys.stderr)
        return done.returncode
    return {p.stem: json.loads(p.read_text())["wall_time_s"] for p in sorted((out / "parts").glob("*.json"))}, wall


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="time hexdem paper --quick")
    parser.add_argument(
        "--before", default=BEFORE, metavar="REV", help=f"the revision to compare with (default {BEFORE})"
    )
    parser.add_argument("--out", metavar="DIR", help="resume (or report) the paper run in DIR, today's hexdem only")
    args = parser.parse_args(argv)
    print(f"machine: {describe()}", flush=True)
    runs = {}
    with tempfile.TemporaryDirectory(prefix="hexdem-bench-paper-") as scratch:
        versions = {"now": None}
        if not args.out:
            versions[f"{args.before}"] = baseline_tree(Path(scratch), args.before)
            if versions[args.before] is None:
                print(f"(this clone lacks {args.before}: today's hexdem only)")
                del versions[args.before]
        for name, tree in versions.items():
            out = Path(args.out) if args.out else Path(scratch) / f"paper-{name}"
            out.parent.mkdir(parents=True, exist_ok=True)
            result = paper(out, args.workers, args.quick, tree)
            if isinstance(result, int):
                return result
            runs[name] = result
    names = list(runs["now"][0])
    print(
        f"hexdem paper{' --quick' if args.quick else ''} --workers {args.workers}, wall [s] per part, "
        "now and before, 140 steps per contact"
    )
    print(f"  {'part':<28}" + "".join(f" {name:>11}" for name in runs))
    for part in names:
        print(f"  {part:<28}" + "".join(f" {run[0].get(part, float('nan')):>11.1f}" for run in runs.values()))
    print(f"  {'sum of parts':<28}" + "".join(f" {sum(run[0].values()):>11.1f}" for run in runs.values()))
    print(
        f"  {'this invocation':<28}"
        + "".join(f" {run[1]:>11.1f}" for run in runs.values())
        + "  (a resumed run only writes the report)"
    )
    total = sum(runs["now"][0].values())
    for name, (parts, _) in runs.items():
        if name != "now":
            speed_up = sum(parts.values()) / total
            print(
                f"  before / now (sums of parts): {speed_up:.2f} x; target >= {SPEED_UP_TARGET:g}: "
                f"{'met' if speed_up >= SPEED_UP_TARGET else 'NOT met'}"
            )
    target = TARGETS_S[args.quick]
    print(f"target <= {target:g} s for the parts: {'met' if total <= target else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(run())
