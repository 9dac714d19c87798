"""Throughput of the reference integrator (RK4) and of LAMMPS (velocity Verlet) on the same lattices.

Usage: python benchmarks/bench_reference.py [--repeats 3] [--dump-every 500] [--hexagons 40,100]
       [--before REV] [--quick]

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
``--hexagons``: also hexagons of these many beads per edge, each for about as many bead-steps
as the experiment's. ``--before REV``: also the reference engine as it was at REV (unpacked by
``baseline.baseline_tree``), in alternation with the others, and today's bead-steps/s over its;
both versions then run in a subprocess of their own that imports them (after a warm-up, timed
by the engine as above).
``--quick``: 61- and 331-bead hexagons, few steps, one repeat (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from baseline import baseline_tree, hexdem_env
from harness import NOOUTPUT_NAME, nooutput_deck, write_config
from machine import describe

from hexdem.engines.lammps.engine import LammpsEngine
from hexdem.engines.lammps.runner import run_bare
from hexdem.engines.lammps.standalone import loop_time_s
from hexdem.engines.reference.engine import ReferenceEngine
from hexdem.model.config import RunConfig
from hexdem.model.granular import RunSettings
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

#: (config, steps per timed run) of each benchmarked lattice.
LATTICES = ((RunConfig(shape="hexagon"), 20000), (RunConfig(shape="half-hexagon"), 4000))
QUICK_LATTICES = ((RunConfig(shape="hexagon", edge_beads=5), 2000), (RunConfig(shape="hexagon"), 1000))
TARGET_M_BEAD_STEPS = 20.0
TARGET_BEADS = 3151
#: Bead-steps of each timed run of an extra hexagon (about the experiment's: 331 x 20000).
HEXAGON_BEAD_STEPS = 6.6e6


def ignore(sample) -> None:
    pass


def reference_seconds(model, settings, directory: Path) -> float:
    return ReferenceEngine().run(model, settings, directory, ignore, show_progress=False)["wall_time_s"]


def reference_subprocess(tree: Path | None, config: RunConfig):
    """A timer of the reference engine unpacked at ``tree`` (None: today's) on ``config``'s model: this
    script's ``--time-reference`` in a subprocess that imports that version first (``config`` in a TOML
    file, read by that version)."""

    def timer(model, settings, directory: Path) -> float:
        path = write_config(config, directory / "config.toml")
        command = [
            sys.executable,
            __file__,
            "--time-reference",
            str(path),
            str(settings.n_steps),
            str(settings.dump_every),
        ]
        return float(
            subprocess.run(command, env=hexdem_env(tree), capture_output=True, text=True, check=True).stdout.split()[-1]
        )

    return timer


def time_reference(path: str, steps: str, dump_every: str) -> None:
    """Print the reference engine's seconds for ``steps`` steps of the config at ``path``, after a warm-up."""
    config = RunConfig.from_toml(Path(path))
    model = build_model(config)
    settings = RunSettings(run_settings(config, model).dt_s, int(steps), int(dump_every))
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-reference-"))
    try:
        reference_seconds(model, RunSettings(settings.dt_s, 2, 1), work / "warm-up")
        print(reference_seconds(model, settings, work / "run"))
    finally:
        shutil.rmtree(work)


def lammps_seconds(model, settings, directory: Path) -> float:
    LammpsEngine().run(model, settings, directory, ignore, show_progress=False)
    return loop_time_s(directory / "log.lammps")


def bare_seconds(ranks: int):
    def timer(model, settings, directory: Path) -> float:
        deck = nooutput_deck(model, settings, directory)
        run_bare(deck, ranks, NOOUTPUT_NAME)
        return loop_time_s(deck.log_path)

    return timer


ENGINES = {
    "reference (RK4, 1 thread)": reference_seconds,
    "LAMMPS in hexdem, 1 rank": lammps_seconds,
    "LAMMPS bare, 1 rank": bare_seconds(1),
    "LAMMPS bare, 2 ranks": bare_seconds(2),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--dump-every", type=int, default=500)
    parser.add_argument("--hexagons", default="", help="also hexagons of these beads per edge, e.g. 40,100")
    parser.add_argument("--before", metavar="REV", help="also the reference engine as it was at REV")
    parser.add_argument("--quick", action="store_true", help="small lattices, few steps, one repeat (seconds)")
    parser.add_argument("--time-reference", nargs=3, metavar=("TOML", "STEPS", "DUMP_EVERY"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.time_reference:
        time_reference(*args.time_reference)
        return
    repeats, lattices = (1, QUICK_LATTICES) if args.quick else (args.repeats, LATTICES)
    for edge in filter(None, args.hexagons.split(",")):
        config = RunConfig(shape="hexagon", edge_beads=int(edge))
        steps = max(1, round(HEXAGON_BEAD_STEPS / config.n_beads() / args.dump_every)) * args.dump_every
        lattices = (*lattices, (config, steps))
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-reference-"))
    tree = args.before and baseline_tree(work, args.before)
    if args.before and tree is None:
        raise SystemExit(f"this clone lacks {args.before}")
    (reference, timer), *others = ENGINES.items()
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    print(
        f"median of {repeats} alternating run(s), a sample every {args.dump_every} steps "
        "(other processes slow every engine down)"
    )
    print(f"{'lattice':<36} {'beads':>6} {'engine':<26} {'steps':>6} {'time [s]':>9} {'M (bead|atom)-steps/s':>22}")
    rates = {}
    try:
        for config, steps in lattices:
            model = build_model(config)
            settings = RunSettings(run_settings(config, model).dt_s, steps, args.dump_every)
            reference_seconds(model, RunSettings(settings.dt_s, 2, 1), work / "warm-up")
            references = (
                [
                    (reference, reference_subprocess(None, config)),
                    (f"reference at {args.before}", reference_subprocess(tree, config)),
                ]
                if tree
                else [(reference, timer)]
            )
            engines = dict([*references, *others])
            seconds = {name: [] for name in engines}
            for repeat in range(repeats):
                for k, (name, timer) in enumerate(engines.items()):
                    directory = work / f"{model.n_bodies}-{k}-{repeat}"
                    directory.mkdir(parents=True)
                    seconds[name].append(timer(model, settings, directory))
                    shutil.rmtree(directory)
            for name, times in seconds.items():
                rate = model.n_bodies * steps / statistics.median(times) / 1e6
                rates[name, len(model.packing)] = rate
                print(
                    f"{model.packing.shape:<36} {model.n_bodies:>6} {name:<26} {steps:>6} "
                    f"{statistics.median(times):>9.3f} {rate:>22.2f}",
                    flush=True,
                )
    finally:
        shutil.rmtree(work)
    beads = TARGET_BEADS if (reference, TARGET_BEADS) in rates else max(n for _, n in rates)
    rate = rates[reference, beads]
    note = "" if beads == TARGET_BEADS else f" (quick: the target is for {TARGET_BEADS} beads)"
    print(
        f"reference on {beads} beads: {rate:.1f} M bead-steps/s; target >= {TARGET_M_BEAD_STEPS:g}: "
        f"{'met' if rate >= TARGET_M_BEAD_STEPS else 'NOT met'}{note}"
    )
    one, two = rates["LAMMPS bare, 1 rank", beads], rates["LAMMPS bare, 2 ranks", beads]
    print(f"LAMMPS bare on {beads} beads: 2 ranks / 1 rank = {two / one:.2f} x")
    for n in sorted({n for _, n in rates}) if tree else ():
        print(
            f"reference on {n} beads: today's bead-steps/s / at {args.before}: "
            f"{rates[reference, n] / rates[f'reference at {args.before}', n]:.2f} x"
        )


if __name__ == "__main__":
    main()
