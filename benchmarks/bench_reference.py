"""Throughput of the reference integrator (RK4) and of LAMMPS (velocity Verlet) on the same lattices.

Usage: python benchmarks/bench_reference.py [--repeats 3]

For the experiment's hexagon (331 beads) and Fig. 4's half-hexagon (3151 beads), with the
default impact and time step, runs the reference engine and LAMMPS on 1 and 2 ranks in
alternation (so that all see the same machine load) and prints the median throughput:
reference bead-steps/s (one step = one classical RK4 step, four force evaluations; timed
around the compiled loop, after a warm-up that compiles it) and LAMMPS atom-steps/s (one
step = one Verlet step, one force evaluation; LAMMPS's own "Loop time"). Both sample
every ``--dump-every`` steps, so that the integrators and not the output are measured.
Target: reference >= 20 M bead-steps/s on 3151 beads.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
from pathlib import Path

from bench_run import loop_time
from machine import describe

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.model.config import RunConfig
from hexdem.model.granular import RunSettings

#: (config, steps per timed run) of each benchmarked lattice.
LATTICES = ((RunConfig(shape="hexagon"), 20000), (RunConfig(shape="half-hexagon"), 4000))
TARGET_M_BEAD_STEPS = 20.0


def reference_seconds(engine, model, settings, directory: Path) -> float:
    return engine.run(model, settings, directory).engine["wall_time_s"]


def lammps_seconds(engine, model, settings, directory: Path) -> float:
    engine.run(model, settings, directory)
    return loop_time(directory / "log.lammps")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--dump-every", type=int, default=500)
    args = parser.parse_args()
    engines = {"reference (RK4, 1 thread)": (ReferenceEngine(), reference_seconds),
               "LAMMPS, 1 rank": (LammpsEngine(ranks=1), lammps_seconds),
               "LAMMPS, 2 ranks": (LammpsEngine(ranks=2), lammps_seconds)}
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-reference-"))
    print(f"machine: {describe()}")
    print(f"median of {args.repeats} alternating runs, a sample every {args.dump_every} steps; "
          f"1-min load average before: {os.getloadavg()[0]:.2f} (other processes slow every engine down)")
    print(f"{'lattice':<42} {'beads':>6} {'engine':<26} {'steps':>6} {'time [s]':>9} {'M (bead|atom)-steps/s':>22}")
    verdict = []
    for config, steps in LATTICES:
        model = config.model()
        settings = RunSettings(config.settings().dt_s, steps, args.dump_every)
        ReferenceEngine().run(model, RunSettings(settings.dt_s, 2, 1), work / "warm-up")
        seconds = {name: [] for name in engines}
        for repeat in range(args.repeats):
            for name, (engine, timer) in engines.items():
                seconds[name].append(timer(engine, model, settings, work / f"{engine.name}-{repeat}"))
        for name, times in seconds.items():
            rate = model.n_bodies * steps / statistics.median(times) / 1e6
            print(f"{model.lattice.shape:<42} {model.n_bodies:>6} {name:<26} {steps:>6} "
                  f"{statistics.median(times):>9.3f} {rate:>22.1f}")
            if name.startswith("reference") and model.n_bodies > 3000:
                verdict.append(rate)
    rate = verdict[0]
    print(f"reference on {LATTICES[1][0].model().n_bodies} beads: {rate:.1f} M bead-steps/s; target >= "
          f"{TARGET_M_BEAD_STEPS:g}: {'met' if rate >= TARGET_M_BEAD_STEPS else 'NOT met'}")


if __name__ == "__main__":
    main()
