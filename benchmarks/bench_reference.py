"""Throughput of the reference integrator (RK4) and of LAMMPS (velocity Verlet) on the same lattices.

Usage: python benchmarks/bench_reference.py [--repeats 3] [--dump-every 500] [--quick]

For the experiment's hexagon (331 beads) and Fig. 4's half-hexagon (3151 beads), with the
default impact and time step, runs in alternation (so that all see the same machine load)
and prints the median throughput of:

* the reference engine, one thread: bead-steps/s, one step = one classical RK4 step (four
  force evaluations), timed by the engine around its compiled loop, after a warm-up that
  loads the compiled kernels; its samples go to an observer that does nothing;
* LAMMPS in-process on 1 rank, as hexdem runs it (``LammpsEngine``, samples to an observer
  that does nothing): atom-steps/s, one step = one Verlet step (one force evaluation),
  from LAMMPS's own "Loop time";
* bare LAMMPS on 1 and 2 ranks: ``mpiexec -n N lmp -in in.nooutput`` on the same deck
  without its output section (``run_bare``), from its "Loop time".

Samples every ``--dump-every`` steps, so that the integrators and not the observers are
measured. Target: reference >= 20 M bead-steps/s on 3151 beads.
``--quick``: 61- and 331-bead hexagons, few steps, one repeat (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tempfile
from pathlib import Path

from harness import NOOUTPUT_NAME, nooutput_deck
from machine import describe

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.lammps.partitions import loop_time_s
from hexdem.engines.lammps.runner import run_bare
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.model.config import RunConfig
from hexdem.model.granular import RunSettings

#: (config, steps per timed run) of each benchmarked lattice.
LATTICES = ((RunConfig(shape="hexagon"), 20000), (RunConfig(shape="half-hexagon"), 4000))
QUICK_LATTICES = ((RunConfig(shape="hexagon", edge_beads=5), 2000), (RunConfig(shape="hexagon"), 1000))
TARGET_M_BEAD_STEPS = 20.0
TARGET_BEADS = 3151


def ignore(sample) -> None:
    pass


def reference_seconds(model, settings, directory: Path) -> float:
    return ReferenceEngine().run(model, settings, directory, ignore, show_progress=False)["wall_time_s"]


def lammps_seconds(model, settings, directory: Path) -> float:
    LammpsEngine().run(model, settings, directory, ignore, show_progress=False)
    return loop_time_s(directory / "log.lammps")


def bare_seconds(ranks: int):
    def timer(model, settings, directory: Path) -> float:
        deck = nooutput_deck(model, settings, directory)
        run_bare(deck, ranks, NOOUTPUT_NAME)
        return loop_time_s(deck.log_path)
    return timer


ENGINES = {"reference (RK4, 1 thread)": reference_seconds,
           "LAMMPS in hexdem, 1 rank": lammps_seconds,
           "LAMMPS bare, 1 rank": bare_seconds(1),
           "LAMMPS bare, 2 ranks": bare_seconds(2)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--dump-every", type=int, default=500)
    parser.add_argument("--quick", action="store_true", help="small lattices, few steps, one repeat (seconds)")
    args = parser.parse_args()
    repeats, lattices = (1, QUICK_LATTICES) if args.quick else (args.repeats, LATTICES)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-reference-"))
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    print(f"median of {repeats} alternating run(s), a sample every {args.dump_every} steps "
          "(other processes slow every engine down)")
    print(f"{'lattice':<36} {'beads':>6} {'engine':<26} {'steps':>6} {'time [s]':>9} {'M (bead|atom)-steps/s':>22}")
    rates = {}
    try:
        for config, steps in lattices:
            model = config.model()
            settings = RunSettings(config.settings(model).dt_s, steps, args.dump_every)
            reference_seconds(model, RunSettings(settings.dt_s, 2, 1), work / "warm-up")
            seconds = {name: [] for name in ENGINES}
            for repeat in range(repeats):
                for k, (name, timer) in enumerate(ENGINES.items()):
                    directory = work / f"{model.n_bodies}-{k}-{repeat}"
                    seconds[name].append(timer(model, settings, directory))
                    shutil.rmtree(directory)
            for name, times in seconds.items():
                rate = model.n_bodies * steps / statistics.median(times) / 1e6
                rates[name, len(model.lattice)] = rate
                print(f"{model.lattice.shape:<36} {model.n_bodies:>6} {name:<26} {steps:>6} "
                      f"{statistics.median(times):>9.3f} {rate:>22.2f}", flush=True)
    finally:
        shutil.rmtree(work)
    beads = max(n for _, n in rates)
    rate = rates[next(iter(ENGINES)), beads]
    note = "" if beads == TARGET_BEADS else f" (quick: the target is for {TARGET_BEADS} beads)"
    print(f"reference on {beads} beads: {rate:.1f} M bead-steps/s; target >= {TARGET_M_BEAD_STEPS:g}: "
          f"{'met' if rate >= TARGET_M_BEAD_STEPS else 'NOT met'}{note}")
    one, two = rates["LAMMPS bare, 1 rank", beads], rates["LAMMPS bare, 2 ranks", beads]
    print(f"LAMMPS bare on {beads} beads: 2 ranks / 1 rank = {two / one:.2f} x")


if __name__ == "__main__":
    main()
