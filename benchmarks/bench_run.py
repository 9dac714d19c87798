"""hexdem-driven LAMMPS vs bare ``lmp -in`` on the same deck (the default experiment).

Usage: python benchmarks/bench_run.py [--repeats 3]

Renders the default ``hexdem run`` deck once, then alternates the two ways of running it,
so that both see the same machine load, and prints atom-steps/s for each: from wall-clock
time (hexdem: the in-process run; bare: the whole ``lmp`` process), from LAMMPS's own
"Loop time", and from the loop without its Output section (the 30 MB full-precision dump,
whose write time varies with the disk cache from run to run). Target: hexdem >= 0.9 x bare.
"""

from __future__ import annotations

import argparse
import re
import shutil
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from machine import describe

from hexdem.engines.lammps.deck import DECK_NAME, write_deck
from hexdem.engines.lammps.library import environment_command
from hexdem.engines.lammps.runner import run_in_process
from hexdem.model.config import RunConfig


def loop_times(log: Path) -> tuple[float, float]:
    """(loop time, loop time without the Output section) from a LAMMPS log [s]."""
    text = log.read_text()
    loop = float(re.search(r"Loop time of ([0-9.eE+-]+)", text).group(1))
    output = float(re.search(r"^Output\s+\|\s+[0-9.eE+-]+\s+\|\s+([0-9.eE+-]+)", text, re.MULTILINE).group(1))
    return loop, loop - output


def bare_lmp(directory: Path) -> float:
    start = time.perf_counter()
    subprocess.run([environment_command("lmp"), "-in", DECK_NAME, "-screen", "none", "-log", "log.lammps"],
                   cwd=directory, check=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    config = RunConfig()
    model = config.model()
    settings = config.settings(model)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-"))
    deck = write_deck(model, settings, work / "hexdem")
    shutil.copytree(work / "hexdem", work / "bare")
    atom_steps = model.n_bodies * settings.n_steps
    timings = {name: {"wall": [], "loop": [], "no output": []} for name in ("hexdem", "bare lmp")}

    def record(name, wall, log):
        loop, compute = loop_times(log)
        for key, value in (("wall", wall), ("loop", loop), ("no output", compute)):
            timings[name][key].append(value)

    for _ in range(args.repeats):
        record("hexdem", run_in_process(deck).wall_time_s, deck.log_path)
        record("bare lmp", bare_lmp(work / "bare"), work / "bare" / "log.lammps")
    shutil.rmtree(work)
    print(f"machine: {describe()}")
    print(f"deck: default experiment, {model.n_bodies} atoms x {settings.n_steps} steps, "
          f"dump every {settings.dump_every} steps; median of {args.repeats} alternating runs")
    print(f"{'runner':<10} {'wall [s]':>9}   M atom-steps/s: {'wall':>7} {'loop':>7} {'no output':>10}")
    rates = {name: {key: atom_steps / statistics.median(values) / 1e6 for key, values in t.items()}
             for name, t in timings.items()}
    for name, rate in rates.items():
        print(f"{name:<10} {statistics.median(timings[name]['wall']):>9.3f}   {'':>15} "
              f"{rate['wall']:>7.2f} {rate['loop']:>7.2f} {rate['no output']:>10.2f}")
    ratios = ", ".join(f"{rates['hexdem'][key] / rates['bare lmp'][key]:.3f} ({key})" for key in ("wall", "loop", "no output"))
    print(f"hexdem / bare: {ratios}; target >= 0.9")


if __name__ == "__main__":
    main()
