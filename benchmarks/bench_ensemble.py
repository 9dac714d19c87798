"""Speed of Sec. VI's work: the default ensemble, and the half-hexagon on one vs two ranks.

Usage: python benchmarks/bench_ensemble.py [--workers 2] [--repeats 3] [--skip-ensemble] [--skip-ranks]

1. ``hexdem ensemble`` with its defaults (20 realizations x 0.25, 0.40, 0.70 m/s, 11 per
   edge) in a fresh directory: wall time per phase and LAMMPS's own time for settling a
   realization vs one impact. Target: < 5 min on 2 cores.
2. The half-hexagon of Fig. 4 (91/46, 3151 beads + striker, 0.4 m/s, the snapshot run's
   steps, dumps only at its 6 snapshot times): one rank (in-process) and two ranks
   (mpiexec) alternately, so that both see the same machine load; atom-steps/s from LAMMPS's
   "Loop time" and from wall time. Target: two ranks >= 1.6 x one rank.
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

from hexdem.disorder.ensemble import EnsembleConfig
from hexdem.disorder.runner import run_ensemble
from hexdem.engines.lammps.deck import write_deck
from hexdem.engines.lammps.partitions import loop_time_s
from hexdem.engines.lammps.runner import run_deck
from hexdem.experiments.snapshots import DEFAULT_TIMES_MS, snapshot_config
from hexdem.model.config import RunConfig


def bench_ensemble(work: Path, workers: int) -> None:
    start = time.perf_counter()
    summary = run_ensemble(EnsembleConfig(), work / "ensemble", workers=workers, log=lambda message: None)
    total = time.perf_counter() - start
    lammps, phases = summary["lammps_time_s"], summary["this_run"]["wall_time_s"]
    print(f"ensemble: 20 realizations x 3 striker speeds, 11 per edge, {workers} workers: {total:.1f} s wall "
          f"(target < 300 s)")
    print("  wall time per phase: " + ", ".join(f"{name} {t:.1f} s" for name, t in phases.items())
          + "  (analysis: summed over its worker processes, overlapping the impacts)")
    print(f"  LAMMPS per realization: settle (compact + settle) {lammps['settle_per_realization']:.2f} s, "
          f"one impact {lammps['impact_per_run']:.2f} s; totals: settle {lammps['settle_total']:.1f} s, "
          f"impacts {lammps['impact_total']:.1f} s")


def bench_ranks(work: Path, repeats: int) -> None:
    config = snapshot_config(RunConfig(shape="half-hexagon", impact="striker", v0=0.4),
                             [t * 1e-3 for t in DEFAULT_TIMES_MS["half-hexagon"]])
    model = config.model()
    settings = config.settings(model)
    decks = {ranks: write_deck(model, settings, work / f"ranks{ranks}") for ranks in (1, 2)}
    atom_steps = model.n_bodies * settings.n_steps
    times = {ranks: {"wall": [], "loop": []} for ranks in decks}
    for _ in range(repeats):
        for ranks, deck in decks.items():
            times[ranks]["wall"].append(run_deck(deck, ranks).wall_time_s)
            times[ranks]["loop"].append(loop_time_s(deck.log_path))
    print(f"half-hexagon 91/46: {model.n_bodies} atoms x {settings.n_steps} steps, median of {repeats} "
          "alternating runs")
    print(f"  {'ranks':<6} {'wall [s]':>9} {'loop [s]':>9} {'M atom-steps/s (loop)':>22}")
    loop = {}
    for ranks, t in times.items():
        loop[ranks] = statistics.median(t["loop"])
        print(f"  {ranks:<6} {statistics.median(t['wall']):>9.2f} {loop[ranks]:>9.2f} "
              f"{atom_steps / loop[ranks] / 1e6:>22.2f}")
    wall = {ranks: statistics.median(t["wall"]) for ranks, t in times.items()}
    print(f"  2 ranks / 1 rank: {loop[1] / loop[2]:.2f} x (loop), {wall[1] / wall[2]:.2f} x (wall); target >= 1.6")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--skip-ensemble", action="store_true")
    parser.add_argument("--skip-ranks", action="store_true")
    args = parser.parse_args()
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}")
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-ensemble-"))
    try:
        if not args.skip_ranks:
            bench_ranks(work, args.repeats)
        if not args.skip_ensemble:
            bench_ensemble(work, args.workers)
    finally:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
