"""hexdem end to end vs bare ``lmp -in`` of the same deck without output (the default experiment).

Usage: python benchmarks/bench_run.py [--repeats 5] [--quick]

Renders the default ``hexdem run`` deck once, with ``in.nooutput`` beside it (the deck's
set-up and its ``run``, no dump: LAMMPS's bare work, no Python in the loop). Then, after a
discarded in-process warm-up, it alternates, so that all see the same machine load:

* ``hexdem run`` (CLI): the command in a subprocess, Python start-up and imports included;
* ``run_experiment`` (in-process): the same run and result files from an imported hexdem;
* ``python -c "import hexdem.experiments.run"``: the import cost alone;
* bare ``lmp``: ``mpiexec -n 1 lmp -in in.nooutput``.

It prints median wall times, LAMMPS's "Loop time" (hexdem's includes the sampling callback
that feeds the analysis every ``dump_every`` steps), the ratio of each wall time to the bare
loop, where the CLI's time goes, and the target: end to end <= 1.3 x bare loop + 2 s.
``--quick``: a 5-per-edge hexagon for 0.2 ms, one repeat (the same code path, seconds).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from harness import NOOUTPUT_NAME, nooutput_deck, write_config
from machine import describe

from hexdem.engines.lammps.deck import DECK_NAME
from hexdem.engines.lammps.library import environment_command
from hexdem.engines.lammps.partitions import loop_time_s
from hexdem.engines.lammps.runner import run_bare
from hexdem.experiments.run import run_experiment
from hexdem.model.config import RunConfig

QUICK = RunConfig(edge_beads=5, duration=2e-4)
TARGET_FACTOR, TARGET_OFFSET_S = 1.3, 2.0


def quiet(message: str) -> None:
    pass


def timed_cli(config_path: Path, out: Path) -> tuple[float, dict]:
    """Wall time of ``hexdem run --config FILE --out DIR`` and its summary.json."""
    start = time.perf_counter()
    done = subprocess.run([environment_command("hexdem"), "run", "--config", str(config_path), "--out", str(out)],
                          check=False, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"hexdem run failed:\n{done.stderr}")
    return wall, json.loads((out / "summary.json").read_text())


def timed_import() -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", "import hexdem.experiments.run"], check=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="a small deck, one repeat (seconds)")
    args = parser.parse_args()
    repeats = 1 if args.quick else args.repeats
    config = QUICK if args.quick else RunConfig()
    model = config.model()
    settings = config.settings(model)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-run-"))
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    try:
        deck = nooutput_deck(model, settings, work / "bare")
        config_path = write_config(config, work / "run.toml")
        run_experiment(config, work / "warm-up", log=quiet)
        t = {key: [] for key in ("cli", "cli loop", "cli summary", "cli engine", "inproc", "inproc loop",
                                 "import", "bare", "bare loop")}
        for repeat in range(repeats):
            out = work / f"cli-{repeat}"
            wall, summary = timed_cli(config_path, out)
            if (out / "deck" / DECK_NAME).read_text() != deck.input_path.read_text():
                raise SystemExit(f"hexdem run wrote another deck than {deck.input_path}: the comparison would be unfair")
            t["cli"].append(wall)
            t["cli loop"].append(loop_time_s(out / "deck" / "log.lammps"))
            t["cli summary"].append(summary.get("wall_time_s", math.nan))
            t["cli engine"].append(summary.get("engine_wall_time_s", math.nan))
            out = work / f"inproc-{repeat}"
            start = time.perf_counter()
            run_experiment(config, out, log=quiet)
            t["inproc"].append(time.perf_counter() - start)
            t["inproc loop"].append(loop_time_s(out / "deck" / "log.lammps"))
            t["import"].append(timed_import())
            t["bare"].append(run_bare(deck, 1, NOOUTPUT_NAME).wall_time_s)
            t["bare loop"].append(loop_time_s(deck.log_path))
            shutil.rmtree(work / f"cli-{repeat}")
            shutil.rmtree(out)
    finally:
        shutil.rmtree(work)
    m = {key: statistics.median(values) for key, values in t.items()}
    bare_loop = m["bare loop"]
    atom_steps = model.n_bodies * settings.n_steps
    print(f"deck: {'quick: ' if args.quick else 'default experiment, '}{model.lattice.shape}, {model.n_bodies} atoms x "
          f"{settings.n_steps} steps, a sample every {settings.dump_every} steps; median of {repeats} alternating "
          "run(s), after an in-process warm-up")
    print(f"{'runner':<34} {'wall [s]':>9} {'loop [s]':>9} {'wall / bare loop':>17} {'M atom-steps/s (loop)':>22}")
    rows = (("hexdem run (CLI, subprocess)", m["cli"], m["cli loop"]),
            ("run_experiment (in-process)", m["inproc"], m["inproc loop"]),
            (f"bare lmp -in {NOOUTPUT_NAME}", m["bare"], bare_loop))
    for name, wall, loop in rows:
        print(f"{name:<34} {wall:>9.3f} {loop:>9.3f} {wall / bare_loop:>17.2f} {atom_steps / loop / 1e6:>22.2f}")
    target = TARGET_FACTOR * bare_loop + TARGET_OFFSET_S
    for name, wall in (("CLI", m["cli"]), ("in-process", m["inproc"])):
        margin = target - wall
        print(f"target end to end ({name}) <= {TARGET_FACTOR:g} x bare loop + {TARGET_OFFSET_S:g} s = {target:.2f} s: "
              f"{wall:.2f} s, {'met' if margin >= 0 else 'NOT met'} ({'+' if margin >= 0 else '-'}"
              f"{abs(margin):.2f} s)")
    parts = (("python start-up + imports (alone)", m["import"]),
             ("result files, exit (rest)", m["cli"] - m["cli summary"] - m["import"]),
             ("model, deck, tracker, analysis", m["cli summary"] - m["cli engine"]),
             ("LAMMPS start-up + set-up", m["cli engine"] - m["cli loop"]),
             ("sampling callbacks in the loop", m["cli loop"] - bare_loop),
             ("bare loop", bare_loop))
    print("where the CLI's time goes [s]: " + ", ".join(f"{name} {value:.2f}" for name, value in parts))


if __name__ == "__main__":
    main()
