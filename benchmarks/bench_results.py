"""The result files by packing size, now and before, in runs where most beads never moved.

Usage: python benchmarks/bench_results.py [--edges 11,35,100,200] [--durations 3e-4,1e-3,1e-3,3e-4] [--ranks 2]
[--repeats 3]
[--before REV] [--quick]

For a hexagon of each of ``--edges`` beads per edge (11: 331 beads; 35: 3,571; 100: 29,701; 200:
119,401), one run of its ``--durations`` seconds on ``--ranks`` ranks (:func:`~hexdem.experiments.run.run_experiment`,
in this process): a short run, so that the front has crossed a small part of the packing and most
beads never moved (the share is printed; 1 ms leaves 74 % of the 35-per-edge hexagon unmoved, and
none of the 11-per-edge one). Its analysis is kept (pickled), and the result files
(:func:`~hexdem.experiments.run.write_results`: the tables, ``summary.json`` and the figures) are
written from it ``--repeats`` times by each version in turn, hexdem now and hexdem at ``--before``
(default :data:`BEFORE`, before the maps drew their beads without a value unhatched; unpacked by
:func:`baseline.baseline_tree`), each in a fresh process that has imported what the run imports
before its results (a run loads the figures' modules while LAMMPS runs), so that both write the
same analysis on the same machine load.

It prints, per size, the run (``summary.json``'s ``wall_time_s``: model, MPI job, analysis, up to
the result files), the median result files' time of each version, and the target: the result
files <= max(:data:`TARGET_FLOOR_S`, :data:`TARGET_SHARE` x the run). ``--quick``: a hexagon of 4
per edge for 0.2 ms on one rank, one repeat (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import io
import json
import os
import pickle
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from baseline import baseline_tree, hexdem_env
from machine import describe

#: The revision before the maps' beads without a value were drawn in greys (hatched before).
BEFORE = "1802d2f"
#: Target: the result files take at most the larger of these seconds and this share of the run.
TARGET_FLOOR_S, TARGET_SHARE = 1.5, 0.5
#: What a run imports before its result files (``run_experiment`` loads them while LAMMPS runs; a
#: version imports those of them it has).
PRELOADED = (
    "hexdem.experiments.run",
    "hexdem.analysis.plotting",
    "hexdem.analysis.run_maps",
    "hexdem.analysis.decay_figure",
    "scipy.spatial",
)


def quiet(message: str) -> None:
    pass


def write_once(pickled: Path, out: Path) -> None:
    """In a child process (``--write``): the result files of the pickled (config, analysis) in
    ``out``, timed after the run's imports; prints the seconds."""
    import importlib.util

    for name in PRELOADED:
        if importlib.util.find_spec(name) is not None:
            importlib.import_module(name)
    from hexdem.experiments.run import write_results

    config, analysis, wall = pickle.loads(pickled.read_bytes())
    out.mkdir(parents=True)
    start = time.perf_counter()
    write_results(config, analysis, out, wall, {}, quiet)
    print(f"{time.perf_counter() - start:.6f}")


class _PlainTuples(pickle.Pickler):
    """A pickler that writes named tuples as plain tuples, which a version without their class
    (``LabelLine`` came after the revision compared with) reads as it always read them."""

    def reducer_override(self, obj):
        if isinstance(obj, tuple) and hasattr(obj, "_fields"):
            return tuple, (tuple(obj),)
        return NotImplemented


def as_plain_tuples(value) -> bytes:
    buffer = io.BytesIO()
    _PlainTuples(buffer).dump(value)
    return buffer.getvalue()


def timed_results(pickled: Path, out: Path, tree: Path | None) -> float:
    """Seconds the version at ``tree`` (None: today's) takes to write the result files of ``pickled``."""
    done = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), "--write", str(pickled), str(out)],
        env=hexdem_env(tree),
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        raise SystemExit(f"writing the result files failed ({'before' if tree else 'now'}):\n{done.stderr[-3000:]}")
    shutil.rmtree(out)
    return float(done.stdout.split()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--edges", default="11,35,100,200", help="beads per edge of each hexagon (default 11,35,100,200)"
    )
    parser.add_argument(
        "--durations",
        default="3e-4,1e-3,1e-3,3e-4",
        help="each run's duration [s], one per edge (default 3e-4,1e-3,1e-3,3e-4)",
    )
    parser.add_argument("--ranks", type=int, default=2, help="MPI ranks of each run (default 2)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--before", default=BEFORE, metavar="REV", help=f"the revision to compare with (default {BEFORE})"
    )
    parser.add_argument("--quick", action="store_true", help="a small hexagon, one repeat (seconds)")
    parser.add_argument("--write", nargs=2, metavar=("PICKLE", "OUT"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.write:
        write_once(Path(args.write[0]), Path(args.write[1]))
        return
    from hexdem.experiments.run import run_experiment
    from hexdem.model.config import RunConfig

    edges = [4] if args.quick else [int(edge) for edge in args.edges.split(",")]
    durations = [2e-4] if args.quick else [float(value) for value in args.durations.split(",")]
    if len(durations) != len(edges):
        parser.error(f"--durations needs one duration per edge ({len(edges)}), not {len(durations)}")
    ranks, repeats = (1, 1) if args.quick else (args.ranks, args.repeats)
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-results-"))
    rows = []
    try:
        before = baseline_tree(work, args.before)
        for edge, duration in zip(edges, durations):
            config = RunConfig(edge_beads=edge, duration=duration, ranks=ranks)
            analysis = run_experiment(config, work / f"run-{edge}", log=quiet)
            wall = json.loads((work / f"run-{edge}" / "summary.json").read_text())["wall_time_s"]
            shutil.rmtree(work / f"run-{edge}")
            pickled = {version: work / f"analysis-{edge}-{version}.pickle" for version in ("now", "before")}
            pickled["now"].write_bytes(pickle.dumps((config, analysis, wall)))
            pickled["before"].write_bytes(as_plain_tuples((config, analysis, wall)))
            peaks = analysis.results.peak_speed
            times = {"now": [], "before": []}
            for repeat in range(repeats):
                order = ("before", "now") if repeat % 2 else ("now", "before")  # neither always first
                for version in order:
                    if version == "before" and before is None:
                        continue
                    tree = before if version == "before" else None
                    times[version].append(timed_results(pickled[version], work / f"out-{edge}-{version}", tree))
            rows.append(
                {
                    "edge": edge,
                    "duration": duration,
                    "beads": len(peaks),
                    "still": float((peaks == 0).mean()),
                    "run": wall,
                    **{k: statistics.median(v) if v else None for k, v in times.items()},
                }
            )
            print(f"... {edge} per edge done", file=sys.stderr, flush=True)
    finally:
        shutil.rmtree(work)
    print(
        f"hexagons run on {ranks} rank(s); the result files written {repeats} time(s) by each version from the same "
        "analysis, alternating; medians"
    )
    print(
        f"{'beads':>8} {'duration [ms]':>14} {'never moved':>12} {'run [s]':>8} {'results, before [s]':>20} "
        f"{'results, now [s]':>17} {'before / now':>13} {'target [s]':>11}  met"
    )
    for row in rows:
        target = max(TARGET_FLOOR_S, TARGET_SHARE * row["run"])
        before_s = f"{row['before']:.2f}" if row["before"] is not None else "–"
        ratio = f"{row['before'] / row['now']:.1f}" if row["before"] is not None else "–"
        print(
            f"{row['beads']:>8,} {row['duration'] * 1e3:>14.3g} {row['still']:>11.1%} {row['run']:>8.2f} "
            f"{before_s:>20} "
            f"{row['now']:>17.2f} {ratio:>13} {target:>11.2f}  {'met' if row['now'] <= target else 'NOT met'}"
        )
    print(
        f"target: the result files <= max({TARGET_FLOOR_S:g} s, {TARGET_SHARE:g} x the run) at every size"
        + (f"; before: hexdem at {args.before}" if before is not None else f"; before: {args.before} not in this clone")
    )


if __name__ == "__main__":
    main()
