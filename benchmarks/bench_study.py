"""The study executors' overhead per run: the same ``hexdem sweep`` in the local process pool and
on Parsl (a HighThroughputExecutor on this machine, LocalProvider), side by side.

Usage: python benchmarks/bench_study.py [--repeats 3] [--runs 8] [--workers 2] [--quick]

The sweeps vary the striker's speed of the default experiment (0.30 m/s up, in steps of
0.01). After a discarded warm-up of each, the two executors alternate, so that both see the
same machine load, each sweep into a fresh folder: a sweep of N = ``--runs`` runs and one of 2N,
and one run of the sweep in this process, without an executor (``run_one``: model, LAMMPS,
analysis, result files and figures). A sweep's wall time (planning, start-up of the pool's
processes or of Parsl's interchange and block, the runs, the table and figure, shutdown) grows
by N (a run's own time + the overhead per run) / workers from N to 2N runs, so (medians over
the repeats):

* **a run, in-process**: the run without an executor;
* **overhead per run** of each executor: (T(2N) - T(N)) x workers / N - a run in-process, what
  each task costs beyond its run (hand-over, scheduling, the result's return, and the runs
  slowing each other down on shared cores, which both executors pay alike);
* **start-up and end**: 2 T(N) - T(2N), what a sweep costs once whatever its size (process or
  block start, imports in the workers, the table, shutdown).

The target: Parsl's overhead per run exceeds the pool's by at most 0.2 s, or 5 % of a run.
The two executors' sweeps must give equal peaks.csv (checked). ``--quick``: sweeps of 1 and 2
runs of a 5-per-edge hexagon for 0.2 ms on one worker, one repeat, no warm-up (the same code
path, seconds).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import time
from pathlib import Path

from machine import describe

from hexdem.experiments.sweep import RUNS_NAME, run_one, run_sweep
from hexdem.experiments.sweep_plan import Variation, plan_sweep

QUICK_BASE = {"edge_beads": 5, "duration": 2e-4}
TARGET_S, TARGET_SHARE = 0.2, 0.05
PARSL_CONFIG = """
from parsl.config import Config
from parsl.executors import HighThroughputExecutor
from parsl.providers import LocalProvider

config = Config(executors=[HighThroughputExecutor(
    label="local", address="127.0.0.1", max_workers_per_node={workers},
    provider=LocalProvider(init_blocks=1, min_blocks=1, max_blocks=1))], run_dir="{run_dir}"{quick})
"""
#: ``--quick``'s Parsl starts its block at its strategy's first look after 0.5 s, not 5 s: the quick
#: mode checks the benchmark's path, and its table's Parsl start-up is not the one a user meets.
QUICK_PARSL = ", strategy_period=0.5"


def quiet(message: str) -> None:
    pass


def timed_sweep(base: dict, variation: Variation, out: Path, workers: int, parsl: str | None) -> float:
    """Wall time of the sweep [s]."""
    start = time.perf_counter()
    run_sweep(base, [variation], out, workers, parsl, log=quiet)
    return time.perf_counter() - start


def timed_run(base: dict, variation: Variation, out: Path) -> float:
    """Wall time of the sweep's first run in this process, without an executor [s]."""
    (out / RUNS_NAME).mkdir(parents=True)
    start = time.perf_counter()
    run_one(plan_sweep(base, [variation])[0], out)
    return time.perf_counter() - start


def peaks(out: Path) -> dict:
    return {path.parent.name: path.read_text() for path in (out / "runs").glob("*/peaks.csv")}


def speeds(count: int) -> Variation:
    return Variation.parse("v0=" + ",".join(f"{0.30 + 0.01 * i:.2f}" for i in range(count)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--runs", type=int, default=8, help="N: sweeps of N and 2N runs (default 8)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--quick", action="store_true", help="sweeps of 1 and 2 small runs on one worker, one repeat")
    args = parser.parse_args()
    repeats, n, workers = (1, 1, 1) if args.quick else (args.repeats, args.runs, args.workers)
    base = QUICK_BASE if args.quick else {}
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-study-"))
    config = work / "parsl_local.py"
    config.write_text(
        PARSL_CONFIG.format(workers=workers, run_dir=work / "runinfo", quick=QUICK_PARSL if args.quick else "")
    )
    executors = {"process pool": None, "Parsl (HighThroughputExecutor, local)": str(config)}
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    times = {(name, size): [] for name in executors for size in (n, 2 * n)}
    alone = []
    try:
        if not args.quick:
            timed_run(base, speeds(n), work / "warm-up-alone")
            for parsl in executors.values():
                timed_sweep(base, speeds(n), work / f"warm-up-{'pool' if parsl is None else 'parsl'}", workers, parsl)
        for repeat in range(repeats):
            alone.append(timed_run(base, speeds(n), work / f"{repeat}-alone"))
            for size in (n, 2 * n):
                outs = {}
                for name, parsl in executors.items():
                    outs[name] = work / f"{repeat}-{size}-{'pool' if parsl is None else 'parsl'}"
                    times[name, size].append(timed_sweep(base, speeds(size), outs[name], workers, parsl))
                first, *others = (peaks(out) for out in outs.values())
                if len(first) != size or any(other != first for other in others):
                    raise SystemExit("the executors' sweeps differ: the comparison would be unfair")
                for out in outs.values():
                    shutil.rmtree(out)
    finally:
        shutil.rmtree(work)
    print(
        f"sweeps of {n} and {2 * n} runs of "
        f"{'a 5-per-edge hexagon for 0.2 ms' if args.quick else 'the default experiment'}"
        f" (v0 from 0.30 m/s), {workers} worker{'s' * (workers > 1)}; medians of {repeats} alternating repeat(s)"
        f"{'' if args.quick else ', after a warm-up'}"
    )
    run_s = statistics.median(alone)
    print(f"a run, in-process (no executor): {run_s:.2f} s")
    print(
        f"{'executor':<38} {f'{n} runs [s]':>11} {f'{2 * n} runs [s]':>11} {'start-up and end [s]':>21} "
        f"{'overhead per run [s]':>21}"
    )
    overhead = {}
    for name in executors:
        small, large = (statistics.median(times[name, size]) for size in (n, 2 * n))
        overhead[name] = (large - small) * workers / n - run_s
        print(f"{name:<38} {small:>11.2f} {large:>11.2f} {2 * small - large:>21.2f} {overhead[name]:>21.3f}")
    pool, parsl = overhead.values()
    extra = parsl - pool
    limit = max(TARGET_S, TARGET_SHARE * run_s)
    print(f"Parsl's overhead per run over the pool's: {extra:+.3f} s = {extra / run_s:+.1%} of a run ({run_s:.2f} s)")
    print(
        f"target <= {TARGET_S:g} s or {TARGET_SHARE:.0%} of a run ({limit:.3f} s): "
        f"{'met' if extra <= limit else 'NOT met'}"
    )


if __name__ == "__main__":
    main()
