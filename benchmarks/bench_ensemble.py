"""Speed of Sec. VI's work: the default ensemble, and the half-hexagon snapshot run on one vs two ranks.

Usage: python benchmarks/bench_ensemble.py [--workers 2] [--repeats 3] [--steps 700,140] [--skip-ensemble]
       [--skip-ranks] [--quick]

1. ``run_ensemble`` with its defaults (20 realizations x 0.25, 0.40, 0.70 m/s, 11 per
   edge) in a fresh directory, once per ``--steps`` (the impacts' steps per contact; default:
   the former 700 beside today's 140, in one run): wall time per phase (compact, settle,
   impacts; the impacts are analysed inside their runs) and LAMMPS's own time for settling a
   realization vs one impact. Target at today's step: <= 60 s on 2 cores.
2. The half-hexagon of Fig. 4 (91/46, 3151 beads + striker, 0.4 m/s, the snapshot run's
   time step and length, fields taken at its 6 snapshot times inside the run): hexdem's
   ``take_snapshots`` on one rank (in-process) and two ranks (mpiexec), and bare
   ``mpiexec -n N lmp -in in.nooutput`` of the same deck without output, alternately, so
   that all see the same machine load. Prints the wall time (hexdem's includes starting
   the MPI job), LAMMPS's wall time inside hexdem, its "Loop time", and atom-steps/s.
   Target: two ranks >= 1.6 x one rank.

``--quick``: a 2-realization ensemble of 4-per-edge hexagons struck at one speed, and the
snapshot run on a 5-per-edge hexagon up to 0.1 ms, one repeat (the same code paths, seconds).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

from harness import NOOUTPUT_NAME, nooutput_deck
from machine import describe

from hexdem.disorder.ensemble import EnsembleConfig
from hexdem.disorder.runner import run_ensemble
from hexdem.engines.lammps.partitions import loop_time_s
from hexdem.engines.lammps.runner import run_bare
from hexdem.experiments.snapshots import DEFAULT_TIMES_MS, snapshot_config, take_snapshots
from hexdem.model.config import STEPS_PER_CONTACT, RunConfig

ENSEMBLE_TARGET_S = 60.0
SPEED_UP_TARGET = 1.6
QUICK_ENSEMBLE = EnsembleConfig(realizations=2, velocities_m_s=(0.4,), edge_beads=4)
SNAPSHOT_RUN = (RunConfig(shape="half-hexagon", impact="striker", v0=0.4),
                tuple(t * 1e-3 for t in DEFAULT_TIMES_MS["half-hexagon"]))
QUICK_SNAPSHOT_RUN = (RunConfig(shape="hexagon", edge_beads=5, impact="striker", v0=0.4), (0.05e-3, 0.1e-3))


def quiet(message: str) -> None:
    pass


def bench_ensemble(work: Path, workers: int, config: EnsembleConfig) -> None:
    start = time.perf_counter()
    summary = run_ensemble(config, work / f"ensemble-{config.steps_per_contact}", workers=workers, log=quiet)
    total = time.perf_counter() - start
    lammps, phases = summary["lammps_time_s"], summary["this_run"]["wall_time_s"]
    verdict = (f"target <= {ENSEMBLE_TARGET_S:g} s: {'met' if total <= ENSEMBLE_TARGET_S else 'NOT met'}"
               if config.steps_per_contact == STEPS_PER_CONTACT else "(the former default step)")
    print(f"ensemble: {config.realizations} realizations x {len(config.velocities_m_s)} striker speed(s), "
          f"{config.edge_beads} per edge, {workers} workers, {config.steps_per_contact} steps per contact: "
          f"{total:.1f} s wall; {verdict}")
    print(f"  {'phase':<10} {'wall [s]':>9}")
    for name, seconds in phases.items():
        print(f"  {name:<10} {seconds:>9.2f}")
    print(f"  {'other':<10} {total - sum(phases.values()):>9.2f}  (decks, statistics, figures)")
    print(f"  LAMMPS per realization: settle (compact + settle) {lammps['settle_per_realization']:.2f} s, "
          f"one impact {lammps['impact_per_run']:.2f} s; totals: settle {lammps['settle_total']:.1f} s, "
          f"impacts {lammps['impact_total']:.1f} s", flush=True)


def bench_ranks(work: Path, repeats: int, base: RunConfig, times_s) -> None:
    config = snapshot_config(base, sorted(times_s))
    model = config.model()
    settings = config.settings(model)
    atom_steps = model.n_bodies * settings.n_steps
    runners = [(f"hexdem, {ranks} rank{'s' * (ranks > 1)}", "hexdem", ranks) for ranks in (1, 2)]
    runners += [(f"bare lmp, {ranks} rank{'s' * (ranks > 1)}", "bare", ranks) for ranks in (1, 2)]
    decks = {ranks: nooutput_deck(model, settings, work / f"bare{ranks}") for ranks in (1, 2)}
    times = {name: {"wall": [], "lammps": [], "loop": []} for name, _, _ in runners}
    for repeat in range(repeats):
        for name, kind, ranks in runners:
            if kind == "hexdem":
                directory = work / f"hexdem{ranks}-{repeat}"
                start = time.perf_counter()
                engine = take_snapshots(base.replace(ranks=ranks), times_s, directory).engine
                times[name]["wall"].append(time.perf_counter() - start)
                times[name]["lammps"].append(engine["wall_time_s"])
                times[name]["loop"].append(loop_time_s(directory / "log.lammps"))
                shutil.rmtree(directory)
            else:
                info = run_bare(decks[ranks], ranks, NOOUTPUT_NAME)
                times[name]["wall"].append(info.wall_time_s)
                times[name]["lammps"].append(info.wall_time_s)
                times[name]["loop"].append(loop_time_s(decks[ranks].log_path))
    print(f"snapshot run, {model.lattice.shape}: {model.n_bodies} atoms x {settings.n_steps} steps, "
          f"{len(times_s)} fields; median of {repeats} alternating run(s)")
    print(f"  {'runner':<18} {'wall [s]':>9} {'LAMMPS [s]':>11} {'loop [s]':>9} {'M atom-steps/s (loop)':>22}")
    median = {name: {key: statistics.median(values) for key, values in t.items()} for name, t in times.items()}
    for name, m in median.items():
        print(f"  {name:<18} {m['wall']:>9.2f} {m['lammps']:>11.2f} {m['loop']:>9.2f} "
              f"{atom_steps / m['loop'] / 1e6:>22.2f}")
    for kind in ("hexdem", "bare lmp"):
        one, two = median[f"{kind}, 1 rank"], median[f"{kind}, 2 ranks"]
        speed_up = one["loop"] / two["loop"]
        print(f"  {kind}: 2 ranks / 1 rank: {speed_up:.2f} x (loop), {one['wall'] / two['wall']:.2f} x (wall); "
              f"target >= {SPEED_UP_TARGET:g} (loop): {'met' if speed_up >= SPEED_UP_TARGET else 'NOT met'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--skip-ensemble", action="store_true")
    parser.add_argument("--skip-ranks", action="store_true")
    parser.add_argument("--steps", default=f"700,{STEPS_PER_CONTACT}",
                        help=f"the impacts' steps per contact, one ensemble each (default 700,{STEPS_PER_CONTACT})")
    parser.add_argument("--quick", action="store_true", help="a tiny ensemble and a small hexagon (seconds)")
    args = parser.parse_args()
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-ensemble-"))
    try:
        if not args.skip_ranks:
            base, times_s = QUICK_SNAPSHOT_RUN if args.quick else SNAPSHOT_RUN
            bench_ranks(work, 1 if args.quick else args.repeats, base, times_s)
        if not args.skip_ensemble:
            for steps in (int(n) for n in args.steps.split(",")):
                config = QUICK_ENSEMBLE if args.quick else EnsembleConfig()
                bench_ensemble(work, args.workers, replace(config, steps_per_contact=steps))
    finally:
        shutil.rmtree(work)


if __name__ == "__main__":
    main()
