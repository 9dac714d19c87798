"""hexdem-driven LAMMPS vs bare ``lmp -in`` on the same deck (the default experiment).

Usage: python benchmarks/bench_run.py [--repeats 3]

Renders the default ``hexdem run`` deck once, then alternates the two ways of running it,
so that both see the same machine load, and prints atom-steps/s for each: from wall-clock
time (hexdem: the in-process run; bare: the whole ``lmp`` process) and from LAMMPS's own
"Loop time". Target: hexdem >= 0.9 x bare.
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

from hexdem.config import RunConfig
from hexdem.lammps.deck import DECK_NAME, write_deck
from hexdem.lammps.library import environment_command
from hexdem.lammps.runner import run_in_process


def loop_time(log: Path) -> float:
    return float(re.search(r"Loop time of ([0-9.eE+-]+)", log.read_text()).group(1))


def bare_lmp(directory: Path) -> float:
    start = time.perf_counter()
    subprocess.run([environment_command("lmp"), "-in", DECK_NAME, "-screen", "none", "-log", "log.lammps"],
                   cwd=directory, check=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    config = RunConfig()
    model, settings = config.model(), config.settings()
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-"))
    deck = write_deck(model, settings, work / "hexdem")
    shutil.copytree(work / "hexdem", work / "bare")
    atom_steps = model.n_bodies * settings.n_steps
    timings = {"hexdem": {"wall": [], "loop": []}, "bare lmp": {"wall": [], "loop": []}}
    for _ in range(args.repeats):
        timings["hexdem"]["wall"].append(run_in_process(deck).wall_time_s)
        timings["hexdem"]["loop"].append(loop_time(deck.log_path))
        timings["bare lmp"]["wall"].append(bare_lmp(work / "bare"))
        timings["bare lmp"]["loop"].append(loop_time(work / "bare" / "log.lammps"))
    shutil.rmtree(work)
    print(f"machine: {describe()}")
    print(f"deck: default experiment, {model.n_bodies} atoms x {settings.n_steps} steps, "
          f"dump every {settings.dump_every} steps; median of {args.repeats} alternating runs")
    print(f"{'runner':<10} {'wall [s]':>9} {'M atom-steps/s (wall)':>22} {'M atom-steps/s (loop)':>22}")
    rates = {}
    for name, t in timings.items():
        wall, loop = statistics.median(t["wall"]), statistics.median(t["loop"])
        rates[name] = (atom_steps / wall / 1e6, atom_steps / loop / 1e6)
        print(f"{name:<10} {wall:>9.3f} {rates[name][0]:>22.2f} {rates[name][1]:>22.2f}")
    ratio_wall = rates["hexdem"][0] / rates["bare lmp"][0]
    ratio_loop = rates["hexdem"][1] / rates["bare lmp"][1]
    print(f"hexdem / bare: {ratio_wall:.3f} (wall), {ratio_loop:.3f} (loop); target >= 0.9")


if __name__ == "__main__":
    main()
