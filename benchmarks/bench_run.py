"""hexdem end to end vs bare ``lmp -in`` of the same deck without output, and vs hexdem before (the default experiment).

Usage: python benchmarks/bench_run.py [--repeats 5] [--before REV] [--quick]

Renders the default ``hexdem run`` deck once, with ``in.nooutput`` beside it (the deck's
set-up and its ``run``, no dump: LAMMPS's bare work, no Python in the loop). Then, after a
discarded warm-up, it alternates, so that all see the same machine load (the two versions'
``hexdem run`` in turn first, so that neither always follows the other):

* ``hexdem run`` (CLI): ``python -m hexdem.cli.main run`` in a subprocess, Python start-up and
  imports included;
* the same command with hexdem as it was at ``--before`` (default e8fb865, the last commit
  before the speed work, warmed up; see ``baseline.py``), skipped when this clone lacks that
  revision;
* ``run_experiment`` (in-process): the same run and result files from an imported hexdem;
* the stream alone (in-process): the deck run through hexdem's driver with an observer that does
  nothing, so that its loop time over the bare loop is what handing samples to Python costs
  before any analysis;
* the import floor: ``python -c "import numpy, lammps, matplotlib.figure,
  matplotlib.backends.backend_agg, scipy.spatial"``, what a run truly needs to import;
* ``python -c "import hexdem.experiments.run"``: what hexdem's run imports before it starts;
* bare ``lmp``: ``mpiexec -n 1 lmp -in in.nooutput``.

It prints median wall times, LAMMPS's "Loop time" (hexdem's includes the sampling callback
that feeds the analysis every ``dump_every`` steps), the ratio of each wall time to the bare
loop, the in-run analysis's share of the loop (hexdem's loop over the bare loop, minus 1), where
the CLI's time goes, and the targets: end to end <= import floor + 1.3 x bare loop + 0.6 s; the
in-run analysis <= 0.25 x the bare loop. ``--quick``: a 5-per-edge hexagon for 0.2 ms, one
repeat, no warm-up (the same code path, seconds).
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

from baseline import BEFORE, baseline_tree, hexdem_command, hexdem_env
from harness import NOOUTPUT_NAME, nooutput_deck, write_config
from machine import describe

from hexdem.engines.lammps.deck import DECK_NAME
from hexdem.engines.lammps.driver import run_streaming
from hexdem.engines.lammps.runner import run_bare
from hexdem.engines.lammps.standalone import loop_time_s
from hexdem.experiments.run import run_experiment
from hexdem.model.config import RunConfig
from hexdem.model.model_builder import build_model
from hexdem.model.run_settings import run_settings

QUICK = RunConfig(edge_beads=5, duration=2e-4)
TARGET_FACTOR, TARGET_OFFSET_S = 1.3, 0.6
ANALYSIS_SHARE_TARGET = 0.25
#: What a run truly needs to import: the floor of its fixed costs.
FLOOR_IMPORTS = "import numpy, lammps, matplotlib.figure, matplotlib.backends.backend_agg, scipy.spatial"


def quiet(message: str) -> None:
    pass


def timed_cli(config_path: Path, out: Path, tree: Path | None = None) -> tuple[float, dict]:
    """Wall time of ``hexdem run --config FILE --out DIR`` (of the version unpacked at ``tree``,
    None: today's) and its summary.json."""
    start = time.perf_counter()
    done = subprocess.run(
        hexdem_command("run", "--config", str(config_path), "--out", str(out)),
        cwd=out.parent,
        env=hexdem_env(tree),
        check=False,
        capture_output=True,
        text=True,
    )
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"hexdem run failed:\n{done.stderr}")
    return wall, json.loads((out / "summary.json").read_text())


def time_before(config_path: Path, out: Path, tree: Path, times: dict) -> None:
    """Time the version unpacked at ``tree`` once into ``times`` ("before": end to end, "before loop")."""
    times["before"].append(timed_cli(config_path, out, tree)[0])
    times["before loop"].append(loop_time_s(out / "deck" / "log.lammps"))
    shutil.rmtree(out)


def timed_python(code: str) -> float:
    """Wall time of ``python -c CODE``."""
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", code], check=True)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--before", default=BEFORE, metavar="REV", help=f"the revision to compare with (default {BEFORE})"
    )
    parser.add_argument("--quick", action="store_true", help="a small deck, one repeat, no warm-up (seconds)")
    args = parser.parse_args()
    repeats = 1 if args.quick else args.repeats
    config = QUICK if args.quick else RunConfig()
    model = build_model(config)
    settings = run_settings(config, model)
    work = Path(tempfile.mkdtemp(prefix="hexdem-bench-run-"))
    print(f"machine: {describe()}; load average {os.getloadavg()[0]:.2f}", flush=True)
    try:
        before = baseline_tree(work, args.before)
        deck = nooutput_deck(model, settings, work / "bare")
        config_path = write_config(config, work / "run.toml")
        if not args.quick:
            run_experiment(config, work / "warm-up", log=quiet)
        t = {
            key: []
            for key in (
                "cli",
                "cli loop",
                "cli summary",
                "cli engine",
                "before",
                "before loop",
                "inproc",
                "inproc loop",
                "stream loop",
                "floor",
                "import",
                "bare",
                "bare loop",
            )
        }
        for repeat in range(repeats):
            before_first = before is not None and repeat % 2 == 1  # neither version always runs first
            if before_first:
                time_before(config_path, work / f"before-{repeat}", before, t)
            out = work / f"cli-{repeat}"
            wall, summary = timed_cli(config_path, out)
            if (out / "deck" / DECK_NAME).read_text() != deck.input_path.read_text():
                raise SystemExit(
                    f"hexdem run wrote another deck than {deck.input_path}: the comparison would be unfair"
                )
            t["cli"].append(wall)
            t["cli loop"].append(loop_time_s(out / "deck" / "log.lammps"))
            t["cli summary"].append(summary.get("wall_time_s", math.nan))
            t["cli engine"].append(summary.get("engine_wall_time_s", math.nan))
            shutil.rmtree(out)
            if before is not None and not before_first:
                time_before(config_path, work / f"before-{repeat}", before, t)
            out = work / f"inproc-{repeat}"
            start = time.perf_counter()
            run_experiment(config, out, log=quiet)
            t["inproc"].append(time.perf_counter() - start)
            t["inproc loop"].append(loop_time_s(out / "deck" / "log.lammps"))
            shutil.rmtree(out)
            run_streaming(deck, lambda sample: None, show_progress=False)
            t["stream loop"].append(loop_time_s(deck.log_path))
            t["floor"].append(timed_python(FLOOR_IMPORTS))
            t["import"].append(timed_python("import hexdem.experiments.run"))
            t["bare"].append(run_bare(deck, 1, NOOUTPUT_NAME).wall_time_s)
            t["bare loop"].append(loop_time_s(deck.log_path))
    finally:
        shutil.rmtree(work)
    m = {key: statistics.median(values) if values else math.nan for key, values in t.items()}
    bare_loop = m["bare loop"]
    atom_steps = model.n_bodies * settings.n_steps
    print(
        f"deck: {'quick: ' if args.quick else 'default experiment, '}{model.packing.shape}, {model.n_bodies} atoms x "
        f"{settings.n_steps} steps, a sample every {settings.dump_every} steps; median of {repeats} alternating "
        f"run(s){'' if args.quick else ', after a warm-up'}"
    )
    print(f"{'runner':<34} {'wall [s]':>9} {'loop [s]':>9} {'wall / bare loop':>17} {'M atom-steps/s (loop)':>22}")
    rows = [
        ("hexdem run (CLI, subprocess)", m["cli"], m["cli loop"]),
        ("run_experiment (in-process)", m["inproc"], m["inproc loop"]),
        (f"bare lmp -in {NOOUTPUT_NAME}", m["bare"], bare_loop),
    ]
    if before is not None:
        rows.insert(1, (f"hexdem run at {args.before} (before)", m["before"], m["before loop"]))
    for name, wall, loop in rows:
        print(f"{name:<34} {wall:>9.3f} {loop:>9.3f} {wall / bare_loop:>17.2f} {atom_steps / loop / 1e6:>22.2f}")
    print(
        f"import floor ({FLOOR_IMPORTS.removeprefix('import ')}): {m['floor']:.3f} s; "
        f"import hexdem.experiments.run: {m['import']:.3f} s"
    )
    if before is not None:
        print(f"end to end, before / now: {m['before']:.2f} / {m['cli']:.2f} s = {m['before'] / m['cli']:.2f} x")
    target = m["floor"] + TARGET_FACTOR * bare_loop + TARGET_OFFSET_S
    for name, wall in (("CLI", m["cli"]), ("in-process", m["inproc"])):
        margin = target - wall
        print(
            f"target end to end ({name}) <= import floor + {TARGET_FACTOR:g} x bare loop + {TARGET_OFFSET_S:g} s = "
            f"{target:.2f} s: {wall:.2f} s, {'met' if margin >= 0 else 'NOT met'} ({'+' if margin >= 0 else '-'}"
            f"{abs(margin):.2f} s)"
        )
    print(
        f"streaming alone (an observer that does nothing): loop {m['stream loop']:.3f} s, "
        f"{m['stream loop'] / bare_loop - 1:.2f} x the bare loop"
    )
    for name, loop in (("now", m["cli loop"]), *((("before", m["before loop"]),) if before is not None else ())):
        share = loop / bare_loop - 1
        print(
            f"in-run analysis ({name}): hexdem's loop / bare loop - 1 = {share:.2f} (target <= "
            f"{ANALYSIS_SHARE_TARGET:g}: {'met' if share <= ANALYSIS_SHARE_TARGET else 'NOT met'})"
        )
    parts = (
        ("python start-up + imports (alone)", m["import"]),
        ("result files, exit (rest)", m["cli"] - m["cli summary"] - m["import"]),
        ("model, deck, tracker, analysis", m["cli summary"] - m["cli engine"]),
        ("LAMMPS start-up + set-up", m["cli engine"] - m["cli loop"]),
        ("sampling callbacks in the loop", m["cli loop"] - bare_loop),
        ("bare loop", bare_loop),
    )
    print("where the CLI's time goes [s]: " + ", ".join(f"{name} {value:.2f}" for name, value in parts))


if __name__ == "__main__":
    main()
