"""Speed of ``hexdem paper``: the whole paper, part by part.

Usage: python benchmarks/bench_paper.py [--workers 2] [--quick] [--out DIR]

Runs ``hexdem paper`` (a subprocess, as a user would) into a fresh directory, or resumes the
run in ``--out``, and prints the wall time of every part as recorded when it was computed,
their sum, and this invocation's wall time. Targets on 2 cores with ``--workers 2``: the
full paper <= 10 min, ``--quick`` <= 2 min.
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

TARGETS_S = {False: 600.0, True: 120.0}


def run(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="time hexdem paper --quick")
    parser.add_argument("--out", metavar="DIR", help="resume (or report) the paper run in DIR instead of a fresh one")
    args = parser.parse_args(argv)
    print(f"machine: {describe()}", flush=True)
    with tempfile.TemporaryDirectory(prefix="hexdem-bench-paper-") as scratch:
        out = Path(args.out) if args.out else Path(scratch) / "paper"
        command = [sys.executable, "-m", "hexdem.cli.main", "paper", "--out", str(out), "--workers",
                   str(args.workers), *(["--quick"] if args.quick else [])]
        start = time.perf_counter()
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        wall = time.perf_counter() - start
        if done.returncode:
            print(done.stderr, file=sys.stderr)
            return done.returncode
        parts = {p.stem: json.loads(p.read_text())["wall_time_s"] for p in sorted((out / "parts").glob("*.json"))}
    target = TARGETS_S[args.quick]
    total = sum(parts.values())
    print(f"hexdem paper{' --quick' if args.quick else ''} --workers {args.workers}")
    print(f"  {'part':<28} {'wall [s]':>9}")
    for name, seconds in parts.items():
        print(f"  {name:<28} {seconds:>9.1f}")
    print(f"  {'sum of parts':<28} {total:>9.1f}")
    print(f"  {'this invocation':<28} {wall:>9.1f}  (a resumed run only writes the report)")
    print(f"target <= {target:g} s for the parts: {'met' if total <= target else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(run())
